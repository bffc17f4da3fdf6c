"""wait_for_motion on a real Device, awaited on the test client's executor (rclpy): bad goals,
completion (announced by the device from another thread), discard, timeout and cancel.

The goal handle here is a plain recorder of what the server would be told; the ROS path of both
~/wait_motion servers is tested over DDS in test_arm_ros.py, test_vehicle_ros.py and
test_control_plane_ros.py."""
import math
import threading
from dataclasses import dataclass

import pytest

from acti_bringup.serving.waiting import device_watch, wait_for_motion
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


@pytest.fixture
def wait(ros):
    def run(device, goal, cancel=False, feedback=None, period=0.01):
        watch = device_watch(ros.node, device, period)
        task = ros.executor.create_task(wait_for_motion(
            Handle(goal, cancel), device, watch, feedback or (lambda *status: None)))
        assert ros.wait(task, 10.0), "the wait never ended"
        return task.result()
    return run


@pytest.mark.parametrize("timeout", [-1.0, math.nan, math.inf, -math.inf])
def test_a_timeout_that_is_not_a_finite_number_of_seconds_is_a_bad_goal(wait, timeout):
    out = wait(device_with(1), Goal(1, timeout=timeout))
    assert out.bad_goal and out.aborted and "finite number of seconds >= 0" in out.message


def test_a_motion_never_queued_is_a_bad_goal(wait):
    out = wait(device_with(1), Goal(5))
    assert out.bad_goal and out.aborted and "never queued" in out.message


def test_timeout_aborts_with_feedback_meanwhile(wait):
    seen = []
    out = wait(device_with(2), Goal(2, timeout=0.05), feedback=lambda *s: seen.append(s))
    assert out.aborted and not out.bad_goal and "timed out" in out.message
    assert seen and seen[-1] == (0, "", 0.0, 2)


def test_cancel_ends_the_wait_only(wait):
    d = device_with(1)
    out = wait(d, Goal(1), cancel=True)
    assert out.end == "canceled" and d.queue_length == 1


def test_discarded_motion_is_reported_not_completed_with_why(wait):
    d = device_with(2)
    d.stop(0.1)
    out = wait(d, Goal(0))
    assert out.end == "succeed" and out.motion_id == 2
    assert not out.completed and out.message == "discarded: stop"
    d = device_with(2)
    d.stop(0.1, "servo off")
    assert wait(d, Goal(2)).message == "discarded: servo off"


def test_completed_motion_is_announced_by_the_device_at_once(wait):
    d = device_with(1)
    # the device retires the motion on another thread; no tick of the watch is needed (period 10 s)
    threading.Timer(0.05, lambda: [d.tick(None, 0.6) for _ in range(3)]).start()
    out = wait(d, Goal(1, timeout=5.0), period=10.0)
    assert out.end == "succeed" and out.completed and out.message == ""


def test_goal_slots_reject_beyond_the_limit_and_free_a_slot_however_a_goal_ends(ros):
    from rclpy.action import GoalResponse

    from acti_bringup.serving.waiting import GoalSlots
    with pytest.raises(ValueError, match="max_goals must be >= 1"):
        GoalSlots(ros.node, 0, "max_goals")
    slots = GoalSlots(ros.node, 1, "max_goals")
    assert slots.admit(None) == GoalResponse.ACCEPT
    assert slots.admit(None) == GoalResponse.REJECT

    async def failing(_handle):
        raise RuntimeError("goal failed")
    task = ros.executor.create_task(slots.holding(failing)(None))
    with pytest.raises(RuntimeError, match="goal failed"):
        ros.wait(task, 5.0)
    assert slots.admit(None) == GoalResponse.ACCEPT


def test_a_stop_ends_the_wait_on_the_current_motion_only_once_it_is_at_rest(wait):
    d = device_with(2)
    d.tick(None, 0.1)                     # motion 1 runs, motion 2 waits behind it
    d.stop(0.5)                           # 2 is discarded at once; 1 decelerates for 0.5 s
    assert d.is_over(2) and not d.is_over(1)
    threading.Timer(0.05, lambda: [d.tick(None, 0.1) for _ in range(10)]).start()
    out = wait(d, Goal(1, timeout=5.0), period=10.0)
    assert out.end == "succeed" and not out.completed and d.current is None


def test_a_timeout_is_answered_at_its_deadline_not_at_the_next_tick(wait):
    """The deadline was checked on the feedback tick only: a 0.01 s timeout was answered after
    0.106 s. Here the tick is 30 s away: the deadline itself must end the wait."""
    d = device_with(1)
    out = wait(d, Goal(1, timeout=0.05), period=30.0)
    assert out.end == "abort" and "timed out after 0.05 s" in out.message


def test_a_timeout_longer_than_a_timer_can_wait_is_waited_without_error(wait, monkeypatch):
    """A goal with timeout 1e300 s (finite, so accepted) killed the deadline's timer thread with
    OverflowError (a traceback in the job's log) before this was fixed."""
    errors = []
    monkeypatch.setattr(threading, "excepthook", errors.append)
    d = device_with(1)
    threading.Timer(0.05, lambda: [d.tick(None, 0.6) for _ in range(3)]).start()
    out = wait(d, Goal(1, timeout=1e300), period=10.0)
    assert out.end == "succeed" and out.completed
    assert [e.exc_type for e in errors] == []


def test_closing_the_watch_ends_a_pending_wait_aborted_with_why(ros):
    """What the process does to the goals it holds when it stops (`end_goals`)."""
    d = device_with(1)
    watch = device_watch(ros.node, d, 10.0)
    task = ros.executor.create_task(wait_for_motion(Handle(Goal(1)), d, watch,
                                                    lambda *status: None))
    threading.Timer(0.05, watch.close, ["the node shuts down"]).start()
    assert ros.wait(task, 5.0), "the wait never ended"
    out = task.result()
    assert out.aborted and not out.completed and out.message == "the node shuts down"
    assert watch.idle


class Instant(Still):
    """A motion that takes no time: retired as it is accepted."""
    duration = 0.0


def test_a_retire_while_nothing_waits_wakes_no_executor(ros):
    """Nothing waits: a retire triggers no guard condition. Each trigger woke the goals'
    executor beside the answer of a 0° move's accept on an idle arm (it retires at once)."""
    device = Device("test", 8, 0.0)
    watch = device_watch(ros.node, device, 0.01)
    triggered = []

    class Counted:
        def __init__(self, guard):
            self.guard = guard

        def trigger(self):
            triggered.append(True)
            self.guard.trigger()
    watch._guard = Counted(watch._guard)
    assert device.submit(lambda start: Instant(), "instant") == 1 and device.retired_id == 1
    assert not triggered
