"""The manipulator core: the ACT common port and the middle-level motion port, without ROS.

Each public method is one IDL operation, named as the ROS service (snake case), taking the IDL
parameters by their snake-case names and returning a `Reply`. Units are the spec's: degree, %, s.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from acti_motion.executor import MotionExecutor
from acti_motion.profiles import Trapezoid
from acti_motion.replies import (Refused, Reply, ReturnCode, answers, finite_vector,
                                 ratio_percent)
from acti_sim.world import ARM_JOINTS, World

STATE_SERVO_ON = 0x01
STATE_MOVING = 0x02
STATE_ALARM = 0x04
STATE_BUFFER_FULL = 0x08
STATE_PAUSED = 0x10


@dataclass
class ArmConfig:
    """Start-up settings of the arm (the node's parameters)."""
    queue_size: int = 32
    initial_speed_ratio: int = 0
    accel_time_joint: float = 0.3
    min_accel_time_joint: float = 0.1
    initial_joints_deg: tuple[float, ...] = (0.0, 30.0, 0.0, -60.0, 0.0, 60.0, 0.0)


@dataclass(frozen=True)
class ArmSetpoint:
    """What the arm is commanded to hold: joints (rad) and the finger position (m)."""
    joints: np.ndarray
    finger: float


class JointMotion:
    """Joint-space straight line with one synchronized trapezoid (PTP)."""

    def __init__(self, start: ArmSetpoint, goal: np.ndarray, profile: Trapezoid) -> None:
        self.start, self.goal, self.profile = start, goal, profile
        self.duration = profile.duration
        self._delta = goal - start.joints

    def at(self, t: float) -> ArmSetpoint:
        s, _ = self.profile.sample(t)
        return ArmSetpoint(self.start.joints + s * self._delta, self.start.finger)

    def apply(self, world: World, t: float, rate: float) -> None:
        s, ds = self.profile.sample(t)
        world.set_arm_targets(self.start.joints + s * self._delta, rate * ds * self._delta)


class ArmCore:
    """State, settings and motion queue of the 7-axis arm with its 1-axis gripper."""

    def __init__(self, executor: MotionExecutor, config: ArmConfig | None = None) -> None:
        self.config = config or ArmConfig()
        self.executor = executor
        world = executor.world
        world.reset_arm(np.radians(self.config.initial_joints_deg))
        limits = [world.limits[n] for n in ARM_JOINTS]
        self.axis_count = len(ARM_JOINTS)
        self.max_speed_joint = np.degrees([lim.velocity for lim in limits])
        self.soft_limit_joint = np.degrees([[lim.lower, lim.upper] for lim in limits])
        self.speed_joint = ratio_percent(self.config.initial_speed_ratio, "initial_speed_ratio")
        self.accel_time_joint = self.config.accel_time_joint
        self.servo = False
        self.alarms: list = []
        self._feedback = world.arm_positions()
        self._finger = world.gripper_position()
        self.device = executor.add_device("arm", self.config.queue_size,
                                          ArmSetpoint(self._feedback.copy(), self._finger))
        executor.after_step(self._sample)

    # --- the simulation thread's snapshot ----------------------------------------------------
    def _sample(self, world: World) -> None:
        self._feedback = world.arm_positions()
        self._finger = world.gripper_position()

    # --- common port -------------------------------------------------------------------------
    @answers
    def servo_on(self) -> None:
        self.servo = True

    @answers
    def servo_off(self) -> None:
        """All axes off; a moving arm stops first (the brakes then hold it where it stopped)."""
        self._stop_motion()
        self.servo = False

    @answers
    def get_state(self) -> dict:
        return {"state": self.state_word()}

    @answers
    def get_feedback_pos_joint(self) -> dict:
        """Measured J1 … J7 (degree), then the gripper axis as its opening (mm)."""
        opening_mm = 2000.0 * self._finger
        return {"pos": [*np.degrees(self._feedback), opening_mm]}

    # --- middle-level motion port --------------------------------------------------------------
    @answers
    def set_speed_joint(self, spd_ratio: int) -> None:
        self.speed_joint = ratio_percent(spd_ratio, "spd_ratio")

    @answers
    def move_ptp_joint_abs(self, joint_points: list[float]) -> dict:
        goal = finite_vector(joint_points, self.axis_count, "joint_points")
        return self._queue_joint_move(goal, "move_ptp_joint_abs")

    # --- shared checks and queueing ------------------------------------------------------------
    def state_word(self) -> int:
        d = self.device
        word = STATE_SERVO_ON if self.servo else 0
        if d.busy and not (d.paused and d.rate <= 0.0):
            word |= STATE_MOVING
        if self.alarms:
            word |= STATE_ALARM
        if d.full:
            word |= STATE_BUFFER_FULL
        if d.paused:
            word |= STATE_PAUSED
        return word

    def _check_can_move(self) -> None:
        if not self.servo:
            raise Refused(ReturnCode.NOT_SV_ON_ERR, "servo is off: call servo_on first")
        if self.alarms:
            raise Refused(ReturnCode.STATUS_ERR, "an alarm is active: call clear_alarms first")

    def _check_joint_limits(self, goal_deg: np.ndarray, name: str) -> None:
        lo, hi = self.soft_limit_joint[:, 0], self.soft_limit_joint[:, 1]
        for i, (q, a, b) in enumerate(zip(goal_deg, lo, hi)):
            if not a <= q <= b:
                raise Refused(ReturnCode.VALUE_ERR,
                              f"{name}: J{i + 1} = {q:g}° is outside the soft limit [{a:g}, {b:g}]°")

    def _queue_joint_move(self, goal_deg: np.ndarray, label: str) -> dict:
        self._check_can_move()
        if self.speed_joint <= 0:
            raise Refused(ReturnCode.STATUS_ERR,
                          "the joint speed ratio is 0 %: set it with set_speed_joint first")
        self._check_joint_limits(goal_deg, label)
        goal = np.radians(goal_deg)
        speed = np.radians(self.max_speed_joint) * self.speed_joint / 100.0
        ramp = self.accel_time_joint

        def plan(start: ArmSetpoint) -> JointMotion:
            return JointMotion(start, goal, Trapezoid.for_axes(goal - start.joints, speed, ramp))
        return self._submit(plan, label)

    def _submit(self, plan, label: str) -> dict:
        motion_id = self.device.submit(plan, label)
        if motion_id is None:
            raise Refused(ReturnCode.FULL_MOTION_QUEUE_ERR,
                          f"the motion queue is full ({self.device.capacity} motions): wait or stop")
        return {"motion_id": motion_id}

    def _stop_motion(self) -> None:
        self.device.stop(self.accel_time_joint)
