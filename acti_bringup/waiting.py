"""Waiting for a queued motion, shared by both nodes' action servers.

A waiting goal blocks an executor thread (an rclpy coroutine that awaits would spin the
executor), so `GoalSlots` bounds how many run at once. `wait_for_motion` is the ~/wait_motion
loop of either device; each node writes the outcome in its own reply style.
"""
from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import Any, Callable

from rclpy.action import GoalResponse
from rclpy.node import Node

from acti_motion.executor import Device


class GoalSlots:
    """At most `limit` goals of the servers that share it run at once; more are rejected."""

    def __init__(self, node: Node, limit: int, parameter: str) -> None:
        if limit < 1:
            raise ValueError(f"{parameter} must be >= 1")
        self._node, self._parameter = node, parameter
        self._slots = threading.BoundedSemaphore(limit)

    def admit(self, _goal: Any) -> GoalResponse:
        if self._slots.acquire(blocking=False):
            return GoalResponse.ACCEPT
        self._node.get_logger().warning(f"rejected an action goal: {self._parameter} running")
        return GoalResponse.REJECT

    def holding(self, execute: Callable[[Any], Any]) -> Callable[[Any], Any]:
        """`execute` that gives its slot back however it ends."""
        def run(goal_handle: Any) -> Any:
            try:
                return execute(goal_handle)
            finally:
                self._slots.release()
        return run


@dataclass(frozen=True)
class WaitOutcome:
    """How a wait ended: `end` names the goal handle's method that ends the goal (succeed,
    abort, canceled); `bad_goal` marks a goal refused before waiting; `message` says why."""
    motion_id: int
    end: str
    completed: bool = False
    bad_goal: bool = False
    message: str = ""

    @property
    def aborted(self) -> bool:
        return self.end == "abort"

    def finish(self, goal_handle: Any) -> None:
        getattr(goal_handle, self.end)()


Feedback = Callable[[int, str, float, int], None]


def wait_for_motion(goal_handle: Any, device: Device, period: float, discarded_by: str,
                    feedback: Feedback) -> WaitOutcome:
    """Wait for goal.motion_id (0: everything queued now) with goal.timeout (0: no limit),
    calling feedback(current id, label, progress, queue length) every `period` seconds."""
    goal = goal_handle.request
    target = goal.motion_id or device.last_id
    if goal.timeout < 0:
        return WaitOutcome(target, "abort", bad_goal=True,
                           message=f"timeout is {goal.timeout:g} s: it must be >= 0")
    if goal.motion_id > device.last_id:
        return WaitOutcome(target, "abort", bad_goal=True,
                           message=f"motion {goal.motion_id} was never queued "
                                   f"(the last is {device.last_id})")
    deadline = time.monotonic() + goal.timeout if goal.timeout > 0 else None
    while not device.wait(target, period):
        if goal_handle.is_cancel_requested:
            return WaitOutcome(target, "canceled", message="canceled: the motion goes on")
        if deadline is not None and time.monotonic() > deadline:
            return WaitOutcome(target, "abort",
                               message=f"timed out after {goal.timeout:g} s")
        feedback(*device.status())
    completed = not device.was_discarded(target)
    return WaitOutcome(target, "succeed", completed,
                       message="" if completed else f"discarded by {discarded_by}")
