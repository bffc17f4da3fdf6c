"""vehicle_node's completion path: ~/wait_motion waits for a motion a move service queued, with
feedback (progress, queue, pose) and cancel. Goals await on the goal plane without holding its
thread; at most `max_wait_goals` run at once, more are rejected (`acti_bringup.serving.waiting`)."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from acti_msgs.action import VehicleWaitMotion

from acti_bringup.serving.adapter import Plane, action_server
from acti_bringup.serving.conversions import fill
from acti_bringup.serving.waiting import GoalSlots, accept_cancel, device_watch, wait_for_motion
from acti_motion.vehicle.core import VehicleCore
from acti_motion.config_fields import GOALS_RANGE, RATE_RANGE_HZ, ranged


@dataclass
class WaitConfig:
    wait_feedback_rate_hz: float = ranged(10.0, *RATE_RANGE_HZ)  # ~/wait_motion feedback [Hz]
    max_wait_goals: int = ranged(16, *GOALS_RANGE)  # ~/wait_motion goals at once; more are rejected


class WaitMotionServer:
    def __init__(self, plane: Plane, core: VehicleCore, config: WaitConfig) -> None:
        self.core = core
        self.watch = device_watch(plane, core.device, 1.0 / config.wait_feedback_rate_hz)
        plane.goal_ends.append(self.watch)
        slots = GoalSlots(plane.owner, config.max_wait_goals, "max_wait_goals")
        self.server = action_server(plane, VehicleWaitMotion, plane.name("wait_motion"),
                                   slots.holding(self._wait), goal_callback=slots.admit,
                                   cancel_callback=accept_cancel(self.watch))

    async def _wait(self, goal_handle: Any) -> VehicleWaitMotion.Result:
        def feedback(motion_id: int, label: str, progress: float, queued: int) -> None:
            msg = VehicleWaitMotion.Feedback(current_motion_id=motion_id, current_label=label,
                                             progress=progress, queue_length=queued)
            fill(msg, self.core.get_position().values)
            goal_handle.publish_feedback(msg)
        out = await wait_for_motion(goal_handle, self.core.device, self.watch, feedback)
        result = VehicleWaitMotion.Result(motion_id=out.motion_id, completed=out.completed,
                                          success=not out.aborted, message=out.message)
        fill(result, self.core.get_position().values)
        out.finish(goal_handle)
        return result
