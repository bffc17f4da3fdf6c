"""The arm's trajectory controller as MoveIt's simple controller manager (and teleop) expects one,
a thin adapter of `acti_motion.trajectory`:

  <controller>/follow_joint_trajectory  control_msgs/action/FollowJointTrajectory
  <controller>/joint_trajectory         trajectory_msgs/msg/JointTrajectory (in: replaces what runs)
  <controller>/joint_jog                control_msgs/msg/JointJog (in: velocities, with a deadman)

<controller> is the parameter controller_name (arm_controller); the names are relative, so a
namespace prefixes them. Goals and topics put one motion into the arm's queue: the ACT stop,
pause, resume, servo_off, the soft-limit watch and alarms govern it, and get_state says moving.
A goal the controller refuses is rejected, and the reason is logged (an error on /rosout): the
action protocol gives a rejected goal no result to carry it. The goal callbacks await their plan
(`MotionActions.off_plane`), so their servers are in a reentrant callback group: in the node's
default (exclusive) group the awaiting goal callback held back the guard condition that wakes it.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Awaitable, Callable

import numpy as np
from control_msgs.action import FollowJointTrajectory
from control_msgs.msg import JointJog
from rclpy.action import GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from trajectory_msgs.msg import JointTrajectory

from acti_bringup.serving.adapter import Plane, action_server
from acti_bringup.serving.waiting import accept_cancel, device_watch
from acti_bringup.simulation import stamp
from acti_middle_node.controller_conversions import (requested_tolerances, requested_trajectory,
                                                     seconds, trajectory_point)
from acti_motion.arm.core import ArmCore
from acti_motion.config_fields import ranged
from acti_motion.replies import Refused
from acti_motion.trajectory.follow import PREEMPTED, ArmTrajectories
from acti_motion.trajectory.jog import jog_plan
from acti_motion.trajectory.motion import TrajectoryMotion
from acti_motion.trajectory.tolerances import Tolerances
from acti_motion.trajectory.validation import INVALID_GOAL, InvalidTrajectory, validate

Result = FollowJointTrajectory.Result
LABEL = "follow_joint_trajectory"
VELOCITY_SAMPLE_S = 0.01     # measured velocities: differences of samples at least this far apart


@dataclass
class ControllerConfig:
    # the arm's trajectory controller: its action and topics are <name>/... (relative names)
    controller_name: str = "arm_controller"
    # accept trajectories that name only some of the arm's joints (the others hold)
    allow_partial_joints_goal: bool = False
    # path tolerance of every joint's position where a goal gives 0 [rad] (0: none)
    path_tolerance_rad: float = ranged(0.1, 0.0, 10.0)
    # goal tolerance of every joint's position where a goal gives 0 [rad] (0: none)
    goal_tolerance_rad: float = ranged(0.005, 0.0, 10.0)
    # goal tolerance of every joint's velocity where a goal gives 0 [rad/s] (0: none)
    stopped_velocity_tolerance: float = ranged(0.01, 0.0, 10.0)
    # how long after its end a trajectory may take to be within the goal tolerance, where a goal's
    # goal_time_tolerance is 0 [s] (0: no limit, it waits)
    goal_time_s: float = ranged(0.0, 0.0, 3600.0)
    # feedback rate of follow_joint_trajectory [Hz]
    trajectory_feedback_rate_hz: float = ranged(25.0, 20.0, 1000.0)
    # how long a joint_jog moves the arm without another one before it decelerates [s]
    jog_timeout_s: float = ranged(0.5, 0.01, 10.0)


@dataclass
class _Goal:
    """A trajectory goal the controller follows."""
    motion_id: int
    motion: TrajectoryMotion
    path: Tolerances
    goal: Tolerances
    goal_time: float
    preempted: bool = False
    canceled: bool = False
    ended_at: float | None = None           # simulated time its motion was seen over
    sample: tuple[float, np.ndarray] | None = None
    velocity: np.ndarray | None = None      # measured, by differences of samples


class TrajectoryController:
    """The arm's FollowJointTrajectory server (on the goal plane), its streaming topics (on the
    motion plane, where the arm's moves are planned) and their one ArmTrajectories."""

    def __init__(self, goals: Plane, motion: Plane, core: ArmCore, config: ControllerConfig,
                 off_plane: Callable[[Callable[[], Any]], Awaitable[Any]],
                 program_running: Callable[[], bool]) -> None:
        self.core, self.config, self.off_plane = core, config, off_plane
        self.log = goals.owner.get_logger()
        self.follower = ArmTrajectories(core, program_running)
        self.joints = list(self.follower.joints)
        n = len(self.joints)
        self.path_defaults = Tolerances.uniform(n, config.path_tolerance_rad, 0.0)
        self.goal_defaults = Tolerances.uniform(n, config.goal_tolerance_rad,
                                                config.stopped_velocity_tolerance)
        self.watch = device_watch(goals, core.device, 1.0 / config.trajectory_feedback_rate_hz)
        goals.goal_ends.append(self.watch)
        self._admitted: dict[int, tuple[Any, _Goal]] = {}
        self._active: _Goal | None = None
        name = config.controller_name
        self.server = action_server(goals, FollowJointTrajectory, f"{name}/follow_joint_trajectory",
                                    self._execute, goal_callback=self._admit,
                                    cancel_callback=accept_cancel(self.watch),
                                    callback_group=ReentrantCallbackGroup())
        self.topics = [
            motion.create_subscription(JointTrajectory, f"{name}/joint_trajectory",
                                       self._on_trajectory, 10),
            motion.create_subscription(JointJog, f"{name}/joint_jog", self._on_jog, 10)]

    # --- follow_joint_trajectory ------------------------------------------------------------------
    async def _admit(self, request: Any) -> GoalResponse:
        """Validate, plan and queue the goal's trajectory; rejected, with the reason logged, if
        any of it is refused. The running goal is preempted by an accepted one."""
        def follow() -> _Goal | str:
            try:
                if request.multi_dof_trajectory.points:
                    raise InvalidTrajectory(INVALID_GOAL, "multi_dof_trajectory is not supported "
                                            "(the arm has no multi-DOF joints)")
                valid = validate(requested_trajectory(request.trajectory), self.joints,
                                 self.follower.now(), self.config.allow_partial_joints_goal)
                path = self.path_defaults.with_requested(
                    requested_tolerances(request.path_tolerance), self.joints, "path_tolerance")
                goal = self.goal_defaults.with_requested(
                    requested_tolerances(request.goal_tolerance), self.joints, "goal_tolerance")
                motion_id, motion = self.follower.follow(valid, LABEL)
            except (InvalidTrajectory, Refused) as e:
                return str(e)
            goal_time = seconds(request.goal_time_tolerance) or self.config.goal_time_s
            return _Goal(motion_id, motion, path, goal, goal_time)
        goal = await self.off_plane(follow)
        if isinstance(goal, str):
            self.log.error(f"rejected a trajectory goal: {goal}")
            return GoalResponse.REJECT
        self._admitted[id(request)] = (request, goal)
        self._preempt(goal)
        return GoalResponse.ACCEPT

    def _preempt(self, newer: _Goal | None) -> None:
        """The running goal ends (preempted): a newer trajectory took over."""
        if self._active is not None:
            self._active.preempted = True
        self._active = newer
        self.watch.poke()

    async def _execute(self, goal_handle: Any) -> Result:
        _, goal = self._admitted.pop(id(goal_handle.request))
        end, code, message = await self.watch.until(
            lambda: self._outcome(goal_handle, goal), lambda: self._feedback(goal_handle, goal),
            closed=lambda why: ("abort", INVALID_GOAL, why))
        if self._active is goal:
            self._active = None
        getattr(goal_handle, end)()
        return Result(error_code=code, error_string=message)

    def _outcome(self, goal_handle: Any, goal: _Goal) -> tuple[str, int, str] | None:
        device, core = self.core.device, self.core
        over = device.is_over(goal.motion_id)
        if goal_handle.is_cancel_requested and not goal.canceled:
            goal.canceled = True
            if not over:
                core.stop_motion(reason="canceled by its client")
        why = device.discard_reason(goal.motion_id) if over else None
        if goal.preempted or why == PREEMPTED:
            return "abort", INVALID_GOAL, f"preempted: {PREEMPTED}"
        if goal.canceled:
            if not over:
                return None                       # decelerating
            return ("canceled", Result.SUCCESSFUL,
                    "canceled: the arm decelerated along the trajectory and holds where it stopped")
        if why is not None:
            return ("abort", Result.INVALID_GOAL,
                    f"aborted: the trajectory was discarded by {why} (the arm holds where it "
                    "stopped)")
        q = self._sample(goal)
        if not over:
            if goal.velocity is None or device.current is None \
                    or device.current.id != goal.motion_id:
                return None
            ref = goal.motion.state(device.t)
            broken = goal.path.violation(self.joints, ref.positions, q, ref.velocities,
                                         goal.velocity)
            if broken is None:
                return None
            core.stop_motion(reason="its path tolerance was broken")
            return ("abort", Result.PATH_TOLERANCE_VIOLATED,
                    f"path tolerance violated: {broken} (the arm stops)")
        now = self.follower.now()
        goal.ended_at = goal.ended_at if goal.ended_at is not None else now
        if goal.velocity is None or goal.sample[0] <= goal.ended_at:
            return None                           # a measurement after the end is needed
        broken = goal.goal.violation(self.joints, goal.motion.end, q, np.zeros(len(q)),
                                     goal.velocity)
        if broken is None:
            return "succeed", Result.SUCCESSFUL, "reached the last point within the goal tolerance"
        if goal.goal_time > 0 and now - goal.ended_at > goal.goal_time:
            return ("abort", Result.GOAL_TOLERANCE_VIOLATED,
                    f"goal tolerance violated {goal.goal_time:g} s after the trajectory's end: "
                    f"{broken}")
        return None

    def _sample(self, goal: _Goal) -> np.ndarray:
        """The measured joints, and (by difference with the last sample far enough back) their
        velocities into goal.velocity."""
        t, q = self.core.measured()
        if goal.sample is None:
            goal.sample = (t, q)
        elif t - goal.sample[0] >= VELOCITY_SAMPLE_S:
            goal.velocity = (q - goal.sample[1]) / (t - goal.sample[0])
            goal.sample = (t, q)
        return q

    def _feedback(self, goal_handle: Any, goal: _Goal) -> None:
        device = self.core.device
        cur = device.current
        t = device.t
        ref = (goal.motion.state(t) if cur is not None and cur.id == goal.motion_id
               else goal.motion.state(goal.motion.duration))
        now, q = self.core.measured()
        feedback = FollowJointTrajectory.Feedback(joint_names=self.joints)
        feedback.header.stamp = stamp(now)
        feedback.desired = trajectory_point(ref)
        feedback.actual = trajectory_point(positions=q, velocities=goal.velocity)
        feedback.error = trajectory_point(
            positions=q - ref.positions,
            velocities=None if goal.velocity is None else goal.velocity - ref.velocities)
        goal_handle.publish_feedback(feedback)

    # --- streaming topics ---------------------------------------------------------------------------
    def _on_trajectory(self, msg: JointTrajectory) -> None:
        """Follow it at once, replacing what runs (a goal that runs is preempted)."""
        try:
            valid = validate(requested_trajectory(msg), self.joints, self.follower.now(),
                             self.config.allow_partial_joints_goal)
            self.follower.follow(valid, "joint_trajectory")
        except (InvalidTrajectory, Refused) as e:
            self.log.error(f"ignored a joint_trajectory: {e}")
            return
        self._preempt(None)

    def _on_jog(self, msg: JointJog) -> None:
        """Jog the named joints at their velocities for the jog's duration (at most, and where it
        is 0, the jog timeout), then decelerate: the deadman."""
        try:
            velocities = self._jog_velocities(msg)
            hold = min(msg.duration, self.config.jog_timeout_s) if msg.duration > 0 \
                else self.config.jog_timeout_s
            self.follower.follow_plan(jog_plan(velocities, hold, self.core.accel_time_joint,
                                               self.follower.limits()), "joint_jog")
        except (InvalidTrajectory, Refused) as e:
            self.log.error(f"ignored a joint_jog: {e}")
            return
        self._preempt(None)

    def _jog_velocities(self, msg: JointJog) -> np.ndarray:
        unknown = [n for n in msg.joint_names if n not in self.joints]
        if unknown:
            raise InvalidTrajectory(INVALID_GOAL, f"unknown joint(s) {', '.join(unknown)}: this "
                                    f"controller has {', '.join(self.joints)}")
        if len(msg.displacements) or len(msg.velocities) != len(msg.joint_names):
            raise InvalidTrajectory(INVALID_GOAL, "a jog needs one velocity per joint name "
                                    f"({len(msg.velocities)} for {len(msg.joint_names)}); "
                                    "displacements are not supported")
        if not np.all(np.isfinite(msg.velocities)):
            raise InvalidTrajectory(INVALID_GOAL, "a jog velocity is not finite")
        velocities = np.zeros(len(self.joints))
        for name, v in zip(msg.joint_names, msg.velocities):
            velocities[self.joints.index(name)] = v
        return velocities
