"""ArmNode: the thin ROS adapter of `acti_motion.arm.ArmCore`."""
from __future__ import annotations

from typing import Any

from acti_msgs.msg import ReturnId
from rclpy.node import Node

from acti_bringup.adapter import serve_operations
from acti_bringup.parameters import declare_config
from acti_bringup.simulation import Simulation
from acti_middle_node.operations import OPERATIONS
from acti_motion.arm import ArmConfig, ArmCore
from acti_motion.replies import Reply


def write_return_id(response: Any, reply: Reply) -> None:
    response.return_id = ReturnId(id=int(reply.code), comment=reply.comment)


class ArmNode(Node):
    """`acti_middle_node`: hosts its own simulation unless given a shared one."""

    def __init__(self, simulation: Simulation | None = None) -> None:
        super().__init__("acti_middle_node")
        self.simulation = simulation or Simulation(self)
        self.core = ArmCore(self.simulation.executor, declare_config(self, ArmConfig))
        serve_operations(self, self.core, OPERATIONS, write_return_id)
