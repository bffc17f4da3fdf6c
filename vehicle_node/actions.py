"""vehicle_node's completion path: ~/wait_motion waits for a motion a move service queued, with
feedback (progress, queue, pose) and cancel. A goal holds an executor thread while it waits, so
at most `max_wait_goals` run at once; more are rejected."""
from __future__ import annotations

import threading
import time
from dataclasses import dataclass
from typing import Any

from acti_msgs.action import VehicleWaitMotion
from rclpy.action import ActionServer, CancelResponse, GoalResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from acti_bringup.conversions import fill
from acti_motion.vehicle import VehicleCore


@dataclass
class WaitConfig:
    wait_feedback_rate_hz: float = 10.0   # ~/wait_motion feedback [Hz]
    max_wait_goals: int = 1               # ~/wait_motion goals at once (each holds a thread)


class WaitMotionServer:
    def __init__(self, node: Node, core: VehicleCore, config: WaitConfig) -> None:
        if config.wait_feedback_rate_hz <= 0 or config.max_wait_goals < 1:
            raise ValueError("wait_feedback_rate_hz must be > 0 and max_wait_goals >= 1")
        self.node, self.core, self.config = node, core, config
        self._slots = threading.BoundedSemaphore(config.max_wait_goals)
        self.server = ActionServer(node, VehicleWaitMotion, "~/wait_motion", self._execute,
                                   callback_group=ReentrantCallbackGroup(), goal_callback=self._admit,
                                   cancel_callback=lambda _goal: CancelResponse.ACCEPT)

    def _admit(self, _goal: Any) -> GoalResponse:
        if self._slots.acquire(blocking=False):
            return GoalResponse.ACCEPT
        self.node.get_logger().warning("~/wait_motion: goal rejected (max_wait_goals running)")
        return GoalResponse.REJECT

    def _execute(self, goal_handle: Any) -> VehicleWaitMotion.Result:
        try:
            return self._wait(goal_handle)
        finally:
            self._slots.release()

    def _wait(self, goal_handle: Any) -> VehicleWaitMotion.Result:
        goal, device, period = goal_handle.request, self.core.device, 1.0 / self.config.wait_feedback_rate_hz
        target = goal.motion_id or device.last_id
        result = VehicleWaitMotion.Result(motion_id=target)
        refusal = (f"timeout is {goal.timeout:g} s: it must be >= 0" if goal.timeout < 0 else
                   f"motion {goal.motion_id} was never queued (the last is {device.last_id})"
                   if goal.motion_id > device.last_id else "")
        if refusal:
            return self._end(goal_handle.abort, result, False, refusal)
        deadline = time.monotonic() + goal.timeout if goal.timeout > 0 else None
        while not device.wait(target, period):
            if goal_handle.is_cancel_requested:
                return self._end(goal_handle.canceled, result, True, "canceled: the motion goes on")
            if deadline is not None and time.monotonic() > deadline:
                return self._end(goal_handle.abort, result, False, f"timed out after {goal.timeout:g} s")
            current = device.current
            motion_id, progress = device.progress()
            feedback = VehicleWaitMotion.Feedback(
                current_motion_id=motion_id, current_label=current.label if current else "",
                progress=progress, queue_length=device.queue_length)
            fill(feedback, self.core.get_position().values)
            goal_handle.publish_feedback(feedback)
        result.completed = not device.was_discarded(target)
        return self._end(goal_handle.succeed, result, True,
                         "" if result.completed else "discarded (stop, servo or power off, contact, blockage, fault)")

    def _end(self, finish: Any, result: Any, success: bool, message: str) -> Any:
        result.success, result.message = success, message
        fill(result, self.core.get_position().values)
        finish()
        return result
