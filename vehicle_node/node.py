"""VehicleNode: the thin ROS adapter of `acti_motion.vehicle.VehicleCore`, plus odometry."""
from __future__ import annotations

import math
from typing import Any

from nav_msgs.msg import Odometry
from rclpy.node import Node

from acti_bringup.adapter import serve_operations
from acti_bringup.parameters import declare_config
from acti_bringup.simulation import Simulation
from acti_motion.replies import Reply
from acti_motion.vehicle import VehicleConfig, VehicleCore
from acti_sim.world import World
from vehicle_node.operations import OPERATIONS

ODOM_RATE_HZ = 50.0


def write_success(response: Any, reply: Reply) -> None:
    response.success = reply.ok
    response.message = reply.comment


class VehicleNode(Node):
    """`vehicle_node`: hosts its own simulation unless given a shared one."""

    def __init__(self, simulation: Simulation | None = None) -> None:
        super().__init__("vehicle_node")
        self.simulation = simulation or Simulation(self)
        self.core = VehicleCore(self.simulation.executor, declare_config(self, VehicleConfig))
        serve_operations(self, self.core, OPERATIONS, write_success)
        self._odom = self.create_publisher(Odometry, "odom", 10)
        every = max(1, round(self.simulation.config.rate_hz / ODOM_RATE_HZ))
        self.simulation.executor.after_step(self._publish_odometry, every=every)

    def _publish_odometry(self, world: World) -> None:
        """REP 103: metres and radians, odom → base_link."""
        odo = self.core.odometry
        p = odo.pose
        msg = Odometry()
        msg.header.stamp = self.simulation.now()
        msg.header.frame_id = "odom"
        msg.child_frame_id = "base_link"
        msg.pose.pose.position.x, msg.pose.pose.position.y = p.x, p.y
        msg.pose.pose.orientation.z = math.sin(p.theta / 2)
        msg.pose.pose.orientation.w = math.cos(p.theta / 2)
        msg.twist.twist.linear.x = odo.v
        msg.twist.twist.angular.z = odo.w
        self._odom.publish(msg)
