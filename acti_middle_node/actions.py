"""The arm's completion paths: ~/wait_motion (wait for any queued motion) and ~/move (one move,
answered when it is over). Both report progress as feedback and can be canceled.

Goals await on the goal plane without holding its thread (`acti_bringup.serving.waiting`); the goals of
both running at once are bounded (`max_action_goals`) and more are rejected.
"""
from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Any, Callable, TypeVar

from acti_msgs.action import Move, WaitMotion
from acti_msgs.msg import ReturnId

from acti_bringup.serving.adapter import Plane, action_server
from acti_bringup.serving.conversions import fill, to_core
from acti_bringup.serving.waiting import GoalSlots, accept_cancel, device_watch, wait_for_motion
from acti_motion.arm.core import ArmCore
from acti_motion.replies import Reply, ReturnCode
from acti_motion.config_fields import GOALS_RANGE, RATE_RANGE_HZ, ranged

T = TypeVar("T")

# Move.Goal.kind → the core operation and the goal fields it takes (core name ← goal field).
MOVE_KINDS: dict[str, tuple[tuple[str, str], ...]] = {
    "move_ptp_joint_abs": (("joint_points", "joint_points"),),
    "move_ptp_joint_rel": (("joint_points", "joint_points"),),
    "move_ptp_cartesian_abs": (("car_point", "car_point"),),
    "move_ptp_cartesian_rel": (("car_point", "car_point"),),
    "move_linear_cartesian_abs": (("car_point", "car_point"),),
    "move_linear_cartesian_rel": (("car_point", "car_point"),),
    "move_circular_cartesian_abs": (("car_point_r", "car_point_r"), ("car_point_t", "car_point")),
    "move_circular_cartesian_rel": (("car_point_r", "car_point_r"), ("car_point_t", "car_point")),
    "move_gripper": (("angle_ratio", "angle_ratio"),),
    "open_gripper": (),
    "close_gripper": (),
    "go_home": (),
}


@dataclass
class ActionConfig:
    # feedback of ~/wait_motion and ~/move [Hz]
    feedback_rate_hz: float = ranged(10.0, *RATE_RANGE_HZ)
    # goals of both actions running at once; more are rejected
    max_action_goals: int = ranged(16, *GOALS_RANGE)


def return_id(reply: Reply) -> ReturnId:
    return ReturnId(id=int(reply.code), comment=reply.comment)


class MotionActions:
    """~/wait_motion and ~/move of one ArmCore."""

    def __init__(self, plane: Plane, core: ArmCore, config: ActionConfig) -> None:
        self.core, self.config = core, config
        self.watch = device_watch(plane, core.device, 1.0 / config.feedback_rate_hz)
        self._planner = ThreadPoolExecutor(1, thread_name_prefix="acti-move-goals")
        plane.goal_ends.append(self.watch)
        slots = GoalSlots(plane.owner, config.max_action_goals, "max_action_goals")
        cancel = accept_cancel(self.watch)
        self.servers = [
            action_server(plane, WaitMotion, plane.name("wait_motion"), slots.holding(self._wait),
                         goal_callback=slots.admit, cancel_callback=cancel),
            action_server(plane, Move, plane.name("move"), slots.holding(self._move),
                         goal_callback=slots.admit, cancel_callback=cancel),
        ]

    # --- ~/wait_motion ----------------------------------------------------------------------------
    async def _wait(self, goal_handle: Any) -> WaitMotion.Result:
        def feedback(motion_id: int, label: str, progress: float, queued: int) -> None:
            goal_handle.publish_feedback(WaitMotion.Feedback(
                current_motion_id=motion_id, current_label=label, progress=progress,
                queue_length=queued))
        out = await wait_for_motion(goal_handle, self.core.device, self.watch, feedback)
        code = (ReturnCode.VALUE_ERR if out.bad_goal else
                ReturnCode.NG if out.aborted else ReturnCode.OK)
        result = WaitMotion.Result(motion_id=out.motion_id, completed=out.completed,
                                   return_id=return_id(Reply(code, out.message)))
        out.finish(goal_handle)
        return result

    # --- ~/move -------------------------------------------------------------------------------------
    async def _move(self, goal_handle: Any) -> Move.Result:
        goal = goal_handle.request
        result = Move.Result()
        fields = MOVE_KINDS.get(goal.kind)
        if fields is None:
            reply = Reply(ReturnCode.VALUE_ERR, f"unknown kind {goal.kind!r}: one of "
                                                + ", ".join(MOVE_KINDS))
        else:
            kwargs = {name: to_core(getattr(goal, field)) for name, field in fields}
            reply = await self.off_plane(lambda: getattr(self.core, goal.kind)(**kwargs))
        result.return_id = return_id(reply)
        if not reply.ok:
            goal_handle.abort()
            self._where(result)
            return result
        motion_id = result.motion_id = reply.values["motion_id"]
        device = self.core.device
        canceled = False

        def over() -> str | None:
            """"" once the move retired; a cancel stops the arm (and is then waited out)."""
            nonlocal canceled
            if goal_handle.is_cancel_requested and not canceled:
                self.core.stop()
                canceled = True
            return "" if device.is_over(motion_id) else None

        def feedback() -> None:
            """This goal's move: its progress once it runs (0 while queued)."""
            current, _, progress, queued = device.status()
            goal_handle.publish_feedback(Move.Feedback(
                motion_id=motion_id, progress=progress if current == motion_id else 0.0,
                queue_length=queued))
        shutdown = await self.watch.until(over, feedback, closed=lambda why: why)
        why = shutdown or device.discard_reason(motion_id)
        result.completed = why is None
        if shutdown:
            result.return_id = return_id(Reply(ReturnCode.NG, shutdown))
        elif why is not None:
            result.return_id.comment = f"discarded: {why}"
        self._where(result)
        # a move that did not run to its end is not a success, whatever discarded it
        if canceled:
            goal_handle.canceled()
        elif result.completed:
            goal_handle.succeed()
        else:
            goal_handle.abort()
        return result

    async def off_plane(self, move: Callable[[], T]) -> T:
        """move() (a core operation, or anything that answers and never raises) on the goals'
        planning thread (the trajectory and gripper goals use it too),
        awaited without holding the goal plane's one thread: a move plans for milliseconds and
        waits for any plan under way (the accept lock) for as long as that takes, and every
        other goal's acceptance, feedback, cancel and result waited with it. One thread, so
        that the moves of goals are queued in the order the goals came."""
        planned = self._planner.submit(move)
        planned.add_done_callback(lambda _: self.watch.poke())
        return await self.watch.until(lambda: planned.result() if planned.done() else None,
                                      lambda: None)

    def _where(self, result: Move.Result) -> None:
        fill(result, {"joint_pos": self.core.get_feedback_pos_joint().values["pos"],
                      "pos": self.core.get_feedback_pos_cartesian().values["pos"]})
