"""VehicleNode: the thin ROS adapter of `acti_motion.vehicle.core.VehicleCore`.

Services: one per IDL operation (operations.py). Action: ~/wait_motion (actions.py).
Topics (REP 103: m, rad):
  odom (nav_msgs/Odometry)            wheel odometry, odom → base_link, 50 Hz
  ~/ground_truth (nav_msgs/Odometry)  the simulator's true pose of base_link in the world, 50 Hz
  ~/state (acti_msgs/VehicleStatus)   state code and string of table 7 and what makes it, 10 Hz
  /diagnostics (DiagnosticArray)      battery and alarms, 1 Hz
  cmd_vel (geometry_msgs/Twist, in)   a move_jog per message (stops after the jog timeout)
  joy (sensor_msgs/Joy, in)           drives the base while set_joystick(true)
"""
from __future__ import annotations

import math
from typing import Any

from acti_msgs.msg import VehicleStatus
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from rclpy.node import Node
from sensor_msgs.msg import Joy

from acti_bringup.adapter import serve_operations
from acti_bringup.parameters import declare_config
from acti_bringup.simulation import Simulation
from acti_motion.vehicle.paths import Pose2D
from acti_motion.replies import Reply
from acti_motion.vehicle.core import VehicleConfig, VehicleCore
from acti_motion.vehicle.alarms import AlarmType
from acti_sim.world import World
from vehicle_node.actions import WaitConfig, WaitMotionServer
from vehicle_node.operations import OPERATIONS

ODOM_RATE_HZ = 50.0
STATE_RATE_HZ = 10.0
DIAGNOSTICS_RATE_HZ = 1.0


def write_success(response: Any, reply: Reply) -> None:
    response.success = reply.ok
    response.message = reply.comment


def odometry_message(stamp: Any, frame: str, pose: Pose2D, v: float, w: float) -> Odometry:
    msg = Odometry()
    msg.header.stamp = stamp
    msg.header.frame_id = frame
    msg.child_frame_id = "base_link"
    msg.pose.pose.position.x, msg.pose.pose.position.y = pose.x, pose.y
    msg.pose.pose.orientation.z = math.sin(pose.theta / 2)
    msg.pose.pose.orientation.w = math.cos(pose.theta / 2)
    msg.twist.twist.linear.x = v
    msg.twist.twist.angular.z = w
    return msg


class VehicleNode(Node):
    """`vehicle_node`: hosts its own simulation unless given a shared one."""

    def __init__(self, simulation: Simulation | None = None) -> None:
        super().__init__("vehicle_node")
        self.simulation = simulation or Simulation(self)
        self.core = VehicleCore(self.simulation.executor, declare_config(self, VehicleConfig))
        serve_operations(self, self.core, OPERATIONS, write_success)
        self.wait_motion = WaitMotionServer(self, self.core, declare_config(self, WaitConfig))
        self._odom = self.create_publisher(Odometry, "odom", 10)
        self._truth = self.create_publisher(Odometry, "~/ground_truth", 10)
        self._state = self.create_publisher(VehicleStatus, "~/state", 10)
        self._diagnostics = self.create_publisher(DiagnosticArray, "/diagnostics", 10)
        self.create_subscription(Twist, "cmd_vel", self._on_cmd_vel, 10)
        self.create_subscription(Joy, "joy", self._on_joy, 10)
        sim = self.simulation
        sim.publish_at(ODOM_RATE_HZ, self._publish_odometry, self._odom, self._truth)
        sim.publish_at(STATE_RATE_HZ, self._publish_state, self._state)
        sim.publish_at(DIAGNOSTICS_RATE_HZ, self._publish_diagnostics, self._diagnostics)

    # --- topics in ---------------------------------------------------------------------------
    def _on_cmd_vel(self, msg: Twist) -> None:
        reply = self.core.move_jog(x_vel=1000.0 * msg.linear.x, y_vel=1000.0 * msg.linear.y,
                                   theta_vel=math.degrees(msg.angular.z))
        if not reply.ok:
            self.get_logger().warn(f"cmd_vel refused: {reply.comment}", throttle_duration_sec=2.0)

    def _on_joy(self, msg: Joy) -> None:
        self.core.joy_input(list(msg.axes), list(msg.buttons))

    # --- topics out (simulation thread) -------------------------------------------------------
    def _publish_odometry(self, world: World) -> None:
        odo, stamp = self.core.odometry, self.simulation.now()
        self._odom.publish(odometry_message(stamp, "odom", odo.pose, odo.v, odo.w))
        v, w = world.base_twist()
        self._truth.publish(odometry_message(stamp, "world", Pose2D(*world.base_pose()), v, w))

    def _publish_state(self, world: World) -> None:
        core = self.core
        s = core.state()
        motion_id = core.device.status()[0]
        self._state.publish(VehicleStatus(
            stamp=self.simulation.now(), state=int(s), msg=core.state_string(s), power=core.power,
            servo=core.servo, joystick=core.joystick, digital_sensor_lock=core.digital_sensor_lock,
            queue_length=core.device.queue_length, motion_id=motion_id,
            battery_voltage=core.battery.voltage, num_of_active_alarm=len(core.alarms.active())))

    def _publish_diagnostics(self, world: World) -> None:
        core, c = self.core, self.core.config
        volts = core.battery.voltage
        battery = DiagnosticStatus(
            name="vehicle_node: battery", hardware_id="base",
            level=(DiagnosticStatus.ERROR if volts < c.battery_cutoff_voltage else
                   DiagnosticStatus.WARN if volts < c.battery_low_voltage else DiagnosticStatus.OK),
            message=f"{volts:.1f} V", values=[
                KeyValue(key="voltage [V]", value=f"{volts:.2f}"),
                KeyValue(key="charge [%]", value=f"{100.0 * core.battery.charge:.1f}"),
                KeyValue(key="power [W]", value=f"{core.battery.power:.0f}")])
        active = core.alarms.active()
        faults = [a for a in active if a.type == AlarmType.FAULT]
        alarms = DiagnosticStatus(
            name="vehicle_node: alarms", hardware_id="base",
            level=(DiagnosticStatus.ERROR if faults else
                   DiagnosticStatus.WARN if active else DiagnosticStatus.OK),
            message=core.state_string(core.state()),
            values=[KeyValue(key=str(a.code), value=f"{a.type.name}: {a.source}") for a in active])
        msg = DiagnosticArray(status=[battery, alarms])
        msg.header.stamp = self.simulation.now()
        self._diagnostics.publish(msg)
