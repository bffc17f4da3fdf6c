"""The gripper's controllers, as MoveIt's gripper handles expect them (a thin adapter of the arm's
gripper moves, through the same queue as open_gripper and move_gripper):

  <gripper_controller>/gripper_cmd           control_msgs/action/GripperCommand
  <parallel_gripper_controller>/gripper_cmd  control_msgs/action/ParallelGripperCommand

Positions are the finger joint's (gripper_finger_left_joint, m from the centre; the right finger
mimics it), as MoveIt sends them. reached_goal and stalled: `acti_motion.arm.gripper.grip_outcome`
of the finger once at rest (a goal that ends otherwise has neither).
The simulation does not measure the fingers' effort (reported 0) and applies no effort cap
(max_effort): the fingers push with the URDF's effort limit. The goal callbacks await their
plan, so the servers are in a reentrant callback group (as the trajectory controller's).
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Awaitable, Callable

from control_msgs.action import GripperCommand, ParallelGripperCommand
from rclpy.action import GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from sensor_msgs.msg import JointState

from acti_bringup.serving.adapter import Plane, action_server
from acti_bringup.serving.waiting import accept_cancel, device_watch
from acti_motion.arm.core import ArmCore
from acti_motion.arm.gripper import grip_outcome
from acti_motion.config_fields import RATE_RANGE_HZ, ranged
from acti_motion.replies import Refused
from acti_sim.world import GRIPPER_JOINTS

AT_REST_M = 1e-5          # finger travel within AT_REST_WINDOW_S that counts as at rest
AT_REST_WINDOW_S = 0.02


@dataclass
class GripperConfig:
    # the gripper's GripperCommand controller: its action is <name>/gripper_cmd (relative)
    gripper_controller_name: str = "gripper_controller"
    # the gripper's ParallelGripperCommand controller: its action is <name>/gripper_cmd (relative)
    parallel_gripper_controller_name: str = "parallel_gripper_controller"
    # feedback rate of both gripper actions [Hz]
    gripper_feedback_rate_hz: float = ranged(20.0, *RATE_RANGE_HZ)


@dataclass
class _Grip:
    target: float
    motion_id: int
    canceled: bool = False
    last: tuple[float, float] | None = None    # (simulated time, finger) of the last check


class GripperController:
    """Both gripper actions on the goal plane; a goal queues one gripper move of the arm."""

    def __init__(self, goals: Plane, core: ArmCore, config: GripperConfig,
                 off_plane: Callable[[Callable[[], Any]], Awaitable[Any]]) -> None:
        self.core, self.off_plane = core, off_plane
        self.log = goals.owner.get_logger()
        self.watch = device_watch(goals, core.device, 1.0 / config.gripper_feedback_rate_hz)
        goals.goal_ends.append(self.watch)
        self._admitted: dict[int, _Grip] = {}
        cancel = accept_cancel(self.watch)
        self.servers = [
            action_server(goals, GripperCommand, f"{config.gripper_controller_name}/gripper_cmd",
                          self._execute_command, goal_callback=self._admit_command,
                          cancel_callback=cancel, callback_group=ReentrantCallbackGroup()),
            action_server(goals, ParallelGripperCommand,
                          f"{config.parallel_gripper_controller_name}/gripper_cmd",
                          self._execute_parallel, goal_callback=self._admit_parallel,
                          cancel_callback=cancel, callback_group=ReentrantCallbackGroup())]

    def finger(self) -> float:
        """The measured finger position (m from the centre)."""
        return self.core.get_feedback_pos_joint().values["pos"][-1] / 2000.0

    # --- goals ----------------------------------------------------------------------------------
    async def _admit_command(self, request: Any) -> GoalResponse:
        return await self._admit(request, request.command.position)

    async def _admit_parallel(self, request: Any) -> GoalResponse:
        names, positions = list(request.command.name), list(request.command.position)
        unknown = [n for n in names if n not in GRIPPER_JOINTS]
        if not names or unknown or len(positions) != len(names):
            return self._reject(f"the command must name gripper joints ({', '.join(GRIPPER_JOINTS)})"
                                f" with one position each: got {names} and {len(positions)} "
                                "position(s)")
        if max(positions) - min(positions) > 1e-9:
            return self._reject(f"the fingers mimic each other: {names} cannot go to different "
                                f"positions {positions}")
        return await self._admit(request, positions[0])

    async def _admit(self, request: Any, target: float) -> GoalResponse:
        top = self.core.finger_max
        if not (math.isfinite(target) and 0.0 <= target <= top + 1e-9):
            return self._reject(f"position {target:g} m is outside the finger's range "
                                f"[0, {top:g}] m")

        def queue() -> int | str:
            try:
                return self.core.queue_gripper_to(min(target, top), "gripper_cmd")["motion_id"]
            except Refused as e:
                return str(e)
        motion_id = await self.off_plane(queue)
        if isinstance(motion_id, str):
            return self._reject(motion_id)
        self._admitted[id(request)] = _Grip(target, motion_id)
        return GoalResponse.ACCEPT

    def _reject(self, why: str) -> GoalResponse:
        self.log.error(f"rejected a gripper goal: {why}")
        return GoalResponse.REJECT

    async def _execute_command(self, goal_handle: Any) -> Any:
        def result(kind: type, position: float, stalled: bool, reached: bool) -> Any:
            return kind(position=position, effort=0.0, stalled=stalled, reached_goal=reached)
        return await self._run(goal_handle, GripperCommand, result)

    async def _execute_parallel(self, goal_handle: Any) -> Any:
        def result(kind: type, position: float, stalled: bool, reached: bool) -> Any:
            state = JointState(name=list(GRIPPER_JOINTS), position=[position] * 2,
                               effort=[0.0, 0.0])
            if kind is ParallelGripperCommand.Feedback:
                return kind(state=state)
            return kind(state=state, stalled=stalled, reached_goal=reached)
        return await self._run(goal_handle, ParallelGripperCommand, result)

    async def _run(self, goal_handle: Any, action: type,
                   message: Callable[[type, float, bool, bool], Any]) -> Any:
        grip = self._admitted.pop(id(goal_handle.request))
        end = await self.watch.until(
            lambda: self._outcome(goal_handle, grip),
            lambda: goal_handle.publish_feedback(message(action.Feedback, self.finger(), False,
                                                         False)),
            closed=lambda why: "abort")
        position = self.finger()
        reached, stalled = grip_outcome(grip.target, position) if end == "succeed" \
            else (False, False)
        getattr(goal_handle, end)()
        return message(action.Result, position, stalled, reached)

    def _outcome(self, goal_handle: Any, grip: _Grip) -> str | None:
        """How the goal ends once the finger rests: succeed (reached, or stalled on an object),
        abort (its move was discarded: a stop, servo off, an alarm), canceled."""
        device = self.core.device
        over = device.is_over(grip.motion_id)
        if goal_handle.is_cancel_requested and not grip.canceled:
            grip.canceled = True
            if not over:
                self.core.stop_motion(reason="canceled by its client")
        if not over:
            return None
        if grip.canceled:
            return "canceled"
        if device.was_discarded(grip.motion_id):
            return "abort"
        t, finger = self.core.measured()[0], self.finger()
        if grip.last is None or t - grip.last[0] < AT_REST_WINDOW_S:
            grip.last = grip.last or (t, finger)
            return None
        moved = abs(finger - grip.last[1])
        grip.last = (t, finger)
        return None if moved > AT_REST_M else "succeed"
