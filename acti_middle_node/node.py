"""ArmNode: the thin ROS adapter of `acti_motion.arm.core.ArmCore`: the operation table's services,
the ~/wait_motion, ~/move and ~/run_program (STROLIC) actions, the ~/state topic, and the
controllers MoveIt drives (arm_controller/…, gripper_controller/…: see trajectory_controller and
gripper_controller)."""
from __future__ import annotations

import functools
from dataclasses import dataclass
from typing import Any, Callable

from acti_msgs.msg import Alarm, ArmState, ReturnId
from rclpy.node import Node

from acti_bringup.serving.adapter import Plane, serve_operations
from acti_bringup.serving.parameters import Setting, declare_config, sync_parameters
from acti_bringup.serving.spinning import steady_timer, warn_of_namesakes
from acti_bringup.simulation import Simulation, stamp
from acti_middle_node.actions import ActionConfig, MotionActions
from acti_middle_node.gripper_controller import GripperConfig, GripperController
from acti_middle_node.operations import OPERATIONS
from acti_middle_node.program_action import ProgramAction
from acti_middle_node.trajectory_controller import ControllerConfig, TrajectoryController
from acti_motion.arm.core import ArmConfig, ArmCore
from acti_motion.arm.poses import quaternion_xyzw
from acti_motion.replies import Reply
from acti_motion.programs.robot import ProgramDefaults
from acti_motion.config_fields import RATE_RANGE_HZ, ranged


@dataclass
class TopicConfig:
    state_rate_hz: float = ranged(20.0, *RATE_RANGE_HZ)  # ~/state publication rate [Hz]


# The parameters that take effect at run time: how each is set (through the service that sets
# it, so a bad value is refused as the service refuses it) and read (the value in force).
ARM_SETTINGS: dict[str, tuple[Callable[[ArmCore, Any], Reply], Callable[[ArmCore], Any]]] = {
    "accel_time_joint": (ArmCore.set_accel_time_joint, lambda c: c.accel_time_joint),
    "min_accel_time_joint": (ArmCore.set_min_accel_time_joint, lambda c: c.min_accel_time_joint),
    "accel_time_cartesian": (ArmCore.set_accel_time_cartesian, lambda c: c.accel_time_cartesian),
    "min_accel_time_cartesian": (ArmCore.set_min_accel_time_cartesian,
                                 lambda c: c.min_accel_time_cartesian),
    "max_speed_translation": (lambda c, v: c.set_max_speed_cartesian((v, c.max_speed_cartesian[1])),
                              lambda c: c.max_speed_cartesian[0]),
    "max_speed_rotation": (lambda c, v: c.set_max_speed_cartesian((c.max_speed_cartesian[0], v)),
                           lambda c: c.max_speed_cartesian[1]),
    "soft_limit_cartesian": (ArmCore.set_soft_limit_box, ArmCore.soft_limit_box),
    "home_joints_deg": (lambda c, v: c.set_home(list(v)), lambda c: tuple(c.home)),
}


def write_return_id(response: Any, reply: Reply) -> None:
    response.return_id = _shared_return_id(int(reply.code), reply.comment)


@functools.lru_cache(maxsize=256)
def _shared_return_id(code: int, comment: str) -> ReturnId:
    """A service response's ReturnId, made once per (code, comment) and shared: responses are
    never changed once returned (a message is converted as it is sent), and building one (a
    keyword check and two checked setters: ~1 µs warm) on every accept is spared."""
    return ReturnId(id=code, comment=comment)


class ArmNode(Node):
    """`acti_middle_node`: hosts its own simulation unless given a shared one."""

    def __init__(self, simulation: Simulation | None = None) -> None:
        super().__init__("acti_middle_node")
        self.simulation = simulation or Simulation(self)
        settings = {name: Setting(apply=lambda v, f=f: f(self.core, v),
                                  read=lambda g=g: g(self.core))
                    for name, (f, g) in ARM_SETTINGS.items()}
        self.core = ArmCore(self.simulation.executor, declare_config(self, ArmConfig, settings))
        self.motion, self.goals = Plane(self, "motion"), Plane(self, "goals")
        serve_operations(self, self.motion, self.core, OPERATIONS, write_return_id)
        actions = declare_config(self, ActionConfig)
        topics = declare_config(self, TopicConfig)
        self.actions = MotionActions(self.goals, self.core, actions)
        self.programs = ProgramAction(self.goals, self.core, actions.feedback_rate_hz,
                                      declare_config(self, ProgramDefaults))
        self.trajectories = TrajectoryController(
            self.goals, self.motion, self.core, declare_config(self, ControllerConfig),
            self.actions.off_plane, program_running=lambda: not self.programs.idle)
        self.gripper = GripperController(self.goals, self.core, declare_config(self, GripperConfig),
                                         self.actions.off_plane)
        self._state = self.create_publisher(ArmState, "~/state", 10)
        warn_of_namesakes(self, self._state)
        steady_timer(self, 1.0 / topics.state_rate_hz, self._publish_state)

    def _publish_state(self) -> None:
        sync_parameters(self)             # settings changed through the services, as parameters
        if not self._state.get_subscription_count():
            return      # a volatile topic nobody receives: the message (its FK) would be lost
        core = self.core
        t, q = core.measured()
        pose = core.tool_pose(q)
        quat = quaternion_xyzw(pose[:3, :3])
        motion_id, label, progress, queued = core.motion_status()
        msg = ArmState(
            stamp=stamp(t), state=core.state_word(), queue_length=queued,
            alarms=[Alarm(code=a.code, type=int(a.type), description=a.description)
                    for a in core.alarms],
            position=[float(x) for x in pose[:3, 3]], orientation=[float(x) for x in quat],
            elbow=float(core.kin.arm_angle(q)), struct_flag=core.kin.flags(q),
            motion_id=motion_id, motion_label=label, progress=progress)
        self._state.publish(msg)
