"""The arm's completion paths: ~/wait_motion (wait for any queued motion) and ~/move (one move,
answered when it is over). Both report progress as feedback and can be canceled.

Waiting blocks an executor thread (rclpy coroutines that await would spin the executor), so the
number of goals running at once is bounded (`max_action_goals`); more are rejected.
"""
from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import Any

from acti_msgs.action import Move, WaitMotion
from acti_msgs.msg import ReturnId
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.node import Node

from acti_bringup.conversions import fill, to_core
from acti_motion.arm import ArmCore
from acti_motion.replies import Reply, ReturnCode

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
    feedback_rate_hz: float = 10.0   # feedback of ~/wait_motion and ~/move [Hz]
    max_action_goals: int = 4        # goals of both actions running at once; more are rejected


def return_id(reply: Reply) -> ReturnId:
    return ReturnId(id=int(reply.code), comment=reply.comment)


class MotionActions:
    """~/wait_motion and ~/move of one ArmCore."""

    def __init__(self, node: Node, core: ArmCore, group: Any, config: ActionConfig) -> None:
        self.node, self.core, self.config = node, core, config
        self.period = 1.0 / config.feedback_rate_hz
        self._running = 0
        self._lock = threading.Lock()
        accept_cancel = (lambda _goal: CancelResponse.ACCEPT)
        self.servers = [
            ActionServer(node, WaitMotion, "~/wait_motion", self._wait, callback_group=group,
                         goal_callback=self._admit, cancel_callback=accept_cancel),
            ActionServer(node, Move, "~/move", self._move, callback_group=group,
                         goal_callback=self._admit, cancel_callback=accept_cancel),
        ]

    def _admit(self, _goal: Any) -> GoalResponse:
        with self._lock:
            if self._running >= self.config.max_action_goals:
                self.node.get_logger().warning(
                    f"rejected an action goal: {self._running} running (max_action_goals)")
                return GoalResponse.REJECT
            self._running += 1
            return GoalResponse.ACCEPT

    def _release(self) -> None:
        with self._lock:
            self._running -= 1

    # --- ~/wait_motion ----------------------------------------------------------------------------
    def _wait(self, goal_handle: Any) -> WaitMotion.Result:
        try:
            return self._wait_goal(goal_handle)
        finally:
            self._release()

    def _wait_goal(self, goal_handle: Any) -> WaitMotion.Result:
        goal = goal_handle.request
        device = self.core.device
        target = goal.motion_id or device.last_id
        result = WaitMotion.Result(motion_id=target)
        if goal.motion_id > device.last_id or goal.timeout < 0:
            why = (f"timeout {goal.timeout:g} s is negative" if goal.timeout < 0
                   else f"no motion {goal.motion_id} has been queued yet (last id {device.last_id})")
            result.return_id = return_id(Reply(ReturnCode.VALUE_ERR, why))
            goal_handle.abort()
            return result
        deadline = time.monotonic() + goal.timeout if goal.timeout > 0 else None
        while not device.wait(target, self.period):
            if goal_handle.is_cancel_requested:
                goal_handle.canceled()
                result.return_id = return_id(Reply(ReturnCode.OK, "canceled: still queued"))
                return result
            if deadline is not None and time.monotonic() > deadline:
                goal_handle.abort()
                result.return_id = return_id(Reply(ReturnCode.NG,
                                                   f"timed out after {goal.timeout:g} s"))
                return result
            motion_id, label, progress, queued = self.core.motion_status()
            goal_handle.publish_feedback(WaitMotion.Feedback(
                current_motion_id=motion_id, current_label=label, progress=progress,
                queue_length=queued))
        result.completed = not device.was_discarded(target)
        result.return_id = return_id(Reply(comment="" if result.completed else
                                           "discarded by stop, servo off or an alarm"))
        goal_handle.succeed()
        return result

    # --- ~/move -------------------------------------------------------------------------------------
    def _move(self, goal_handle: Any) -> Move.Result:
        try:
            return self._move_goal(goal_handle)
        finally:
            self._release()

    def _move_goal(self, goal_handle: Any) -> Move.Result:
        goal = goal_handle.request
        result = Move.Result()
        fields = MOVE_KINDS.get(goal.kind)
        if fields is None:
            reply = Reply(ReturnCode.VALUE_ERR, f"unknown kind {goal.kind!r}: one of "
                                                + ", ".join(MOVE_KINDS))
        else:
            kwargs = {name: to_core(getattr(goal, field)) for name, field in fields}
            reply = getattr(self.core, goal.kind)(**kwargs)
        result.return_id = return_id(reply)
        if not reply.ok:
            goal_handle.abort()
            self._where(result)
            return result
        motion_id = result.motion_id = reply.values["motion_id"]
        device = self.core.device
        canceled = False
        while not device.wait(motion_id, self.period):
            if goal_handle.is_cancel_requested and not canceled:
                self.core.stop()
                canceled = True
            current, _, progress, queued = self.core.motion_status()
            goal_handle.publish_feedback(Move.Feedback(
                motion_id=current, progress=progress if current == motion_id else 0.0,
                queue_length=queued))
        result.completed = not device.was_discarded(motion_id)
        self._where(result)
        if canceled:
            goal_handle.canceled()
        else:
            goal_handle.succeed()
        return result

    def _where(self, result: Move.Result) -> None:
        fill(result, {"joint_pos": self.core.get_feedback_pos_joint().values["pos"],
                      "pos": self.core.get_feedback_pos_cartesian().values["pos"]})
