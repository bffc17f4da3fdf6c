"""wait_for_motion on a real Device: bad goals, completion, discard, timeout and cancel.

The goal handle here is a plain recorder of what the server would be told; the ROS path of both
~/wait_motion servers is tested over DDS in test_arm_ros.py and test_vehicle_ros.py."""
import threading
from dataclasses import dataclass

from acti_bringup.waiting import wait_for_motion
from acti_motion.executor import Device


@dataclass
class Goal:
    motion_id: int = 0
    timeout: float = 0.0


class Handle:
    def __init__(self, goal: Goal, cancel: bool = False) -> None:
        self.request, self.is_cancel_requested = goal, cancel


class Still:
    """A motion that takes one second and rests at 0."""
    duration = 1.0

    def at(self, t):
        return 0.0

    def apply(self, world, t, rate):
        pass


def device_with(n: int) -> Device:
    d = Device("test", 8, 0.0)
    for _ in range(n):
        assert d.submit(lambda start: Still(), "still") is not None
    return d


def wait(device, goal, cancel=False, feedback=None):
    return wait_for_motion(Handle(goal, cancel), device, 0.01, "stop",
                           feedback or (lambda *status: None))


def test_negative_timeout_is_a_bad_goal():
    out = wait(device_with(1), Goal(1, timeout=-1.0))
    assert out.bad_goal and out.aborted and ">= 0" in out.message


def test_a_motion_never_queued_is_a_bad_goal():
    out = wait(device_with(1), Goal(5))
    assert out.bad_goal and out.aborted and "never queued" in out.message


def test_timeout_aborts_with_feedback_meanwhile():
    seen = []
    out = wait(device_with(2), Goal(2, timeout=0.05), feedback=lambda *s: seen.append(s))
    assert out.aborted and not out.bad_goal and "timed out" in out.message
    assert seen and seen[-1] == (0, "", 0.0, 2)


def test_cancel_ends_the_wait_only():
    d = device_with(1)
    out = wait(d, Goal(1), cancel=True)
    assert out.end == "canceled" and d.queue_length == 1


def test_discarded_motion_is_reported_not_completed():
    d = device_with(2)
    d.stop(0.1)
    out = wait(d, Goal(0))
    assert out.end == "succeed" and out.motion_id == 2
    assert not out.completed and out.message == "discarded by stop"


def test_completed_motion():
    d = device_with(1)
    threading.Timer(0.05, lambda: [d.tick(None, 0.6) for _ in range(3)]).start()
    out = wait(d, Goal(1, timeout=5.0))
    assert out.end == "succeed" and out.completed and out.message == ""


def test_goal_slots_reject_beyond_the_limit_and_free_a_slot_however_a_goal_ends(ros):
    import pytest
    from rclpy.action import GoalResponse

    from acti_bringup.waiting import GoalSlots
    with pytest.raises(ValueError, match="max_goals must be >= 1"):
        GoalSlots(ros.node, 0, "max_goals")
    slots = GoalSlots(ros.node, 1, "max_goals")
    assert slots.admit(None) == GoalResponse.ACCEPT
    assert slots.admit(None) == GoalResponse.REJECT

    def failing(_handle):
        raise RuntimeError("goal failed")
    with pytest.raises(RuntimeError):
        slots.holding(failing)(None)
    assert slots.admit(None) == GoalResponse.ACCEPT
