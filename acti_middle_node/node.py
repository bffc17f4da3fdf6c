"""ArmNode: the thin ROS adapter of `acti_motion.arm.core.ArmCore`: the operation table's services,
the ~/wait_motion, ~/move and ~/run_program (STROLIC) actions, and the ~/state topic."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import pinocchio as pin
from acti_msgs.msg import Alarm, ArmState, ReturnId
from rclpy.node import Node

from acti_bringup.adapter import Plane, serve_operations
from acti_bringup.parameters import declare_config
from acti_bringup.simulation import Simulation
from acti_middle_node.actions import ActionConfig, MotionActions
from acti_middle_node.operations import OPERATIONS
from acti_middle_node.program_action import ProgramAction
from acti_motion.arm.core import ArmConfig, ArmCore
from acti_motion.replies import Reply
from acti_motion.programs.robot import ProgramDefaults


@dataclass
class TopicConfig:
    state_rate_hz: float = 20.0      # ~/state publication rate [Hz]


def write_return_id(response: Any, reply: Reply) -> None:
    response.return_id = ReturnId(id=int(reply.code), comment=reply.comment)


class ArmNode(Node):
    """`acti_middle_node`: hosts its own simulation unless given a shared one."""

    def __init__(self, simulation: Simulation | None = None) -> None:
        super().__init__("acti_middle_node")
        self.simulation = simulation or Simulation(self)
        self.core = ArmCore(self.simulation.executor, declare_config(self, ArmConfig))
        self.motion, self.goals = Plane(self, "motion"), Plane(self, "goals")
        serve_operations(self, self.motion, self.core, OPERATIONS, write_return_id)
        actions = declare_config(self, ActionConfig)
        topics = declare_config(self, TopicConfig)
        if actions.feedback_rate_hz <= 0 or topics.state_rate_hz <= 0:
            raise ValueError("feedback_rate_hz and state_rate_hz must be > 0")
        self.actions = MotionActions(self.goals, self.core, actions)
        self.programs = ProgramAction(self.goals, self.core, actions.feedback_rate_hz,
                                      declare_config(self, ProgramDefaults))
        self._state = self.create_publisher(ArmState, "~/state", 10)
        self.create_timer(1.0 / topics.state_rate_hz, self._publish_state)

    def _publish_state(self) -> None:
        core = self.core
        q = core.feedback_joints
        pose = core.tool_pose(q)
        quat = pin.Quaternion(pose[:3, :3]).coeffs()          # x, y, z, w
        motion_id, label, progress, queued = core.motion_status()
        msg = ArmState(
            stamp=self.simulation.now(), state=core.state_word(), queue_length=queued,
            alarms=[Alarm(code=a.code, type=int(a.type), description=a.description)
                    for a in core.alarms],
            position=[float(x) for x in pose[:3, 3]], orientation=[float(x) for x in quat],
            elbow=float(core.kin.arm_angle(q)), struct_flag=core.kin.flags(q),
            motion_id=motion_id, motion_label=label, progress=progress)
        self._state.publish(msg)
