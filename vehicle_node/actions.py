"""vehicle_node's completion path: ~/wait_motion waits for a motion a move service queued, with
feedback (progress, queue, pose) and cancel; at most `max_wait_goals` goals run at once
(`acti_bringup.waiting`)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from acti_msgs.action import VehicleWaitMotion
from rclpy.action import ActionServer, CancelResponse
from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from acti_bringup.conversions import fill
from acti_bringup.waiting import GoalSlots, wait_for_motion
from acti_motion.vehicle.core import VehicleCore


@dataclass
class WaitConfig:
    wait_feedback_rate_hz: float = 10.0   # ~/wait_motion feedback [Hz]
    max_wait_goals: int = 1               # ~/wait_motion goals at once (each holds a thread)


class WaitMotionServer:
    def __init__(self, node: Node, core: VehicleCore, config: WaitConfig) -> None:
        if config.wait_feedback_rate_hz <= 0:
            raise ValueError("wait_feedback_rate_hz must be > 0")
        self.core, self.period = core, 1.0 / config.wait_feedback_rate_hz
        slots = GoalSlots(node, config.max_wait_goals, "max_wait_goals")
        self.server = ActionServer(node, VehicleWaitMotion, "~/wait_motion",
                                   slots.holding(self._wait),
                                   callback_group=ReentrantCallbackGroup(), goal_callback=slots.admit,
                                   cancel_callback=lambda _goal: CancelResponse.ACCEPT)

    def _wait(self, goal_handle: Any) -> VehicleWaitMotion.Result:
        def feedback(motion_id: int, label: str, progress: float, queued: int) -> None:
            msg = VehicleWaitMotion.Feedback(current_motion_id=motion_id, current_label=label,
                                             progress=progress, queue_length=queued)
            fill(msg, self.core.get_position().values)
            goal_handle.publish_feedback(msg)
        out = wait_for_motion(goal_handle, self.core.device, self.period,
                              "stop, servo or power off, contact, blockage or fault", feedback)
        result = VehicleWaitMotion.Result(motion_id=out.motion_id, completed=out.completed,
                                          success=not out.aborted, message=out.message)
        fill(result, self.core.get_position().values)
        out.finish(goal_handle)
        return result
