"""Device.edit_planned: a plan made under no lock is committed only if the device did not change
meanwhile (else planned again, at most `tries` times), and Device.discard_queue."""
import threading

from acti_motion.executor import STALE, Device
from test_executor_edit import Ramp1D


def device_with(*deltas: float) -> Device:
    device = Device("d", 8, 0.0)
    for delta in deltas:
        device.submit(lambda start, d=delta: Ramp1D(start, d, 1.0), "ramp")
    return device


def retarget(delta: float, planned: list):
    """look: the last queued motion; plan: a new one from its start; commit: replace it."""
    def look(device, attempt):
        return device.queue[-1]

    def plan(last):
        planned.append(last.id)
        motion = Ramp1D(last.motion.start, delta, 1.0)

        def commit(device):
            last.motion = motion
            return last.id
        return commit
    return look, plan


def test_commits_when_nothing_changed_and_the_queued_end_follows():
    device, planned = device_with(1.0, 2.0), []
    revision = device.revision
    assert device.edit_planned(*retarget(5.0, planned)) == 2
    assert planned == [2] and device.queued_end == 6.0 and device.revision == revision + 1


def test_plans_again_when_the_device_changed_while_planning():
    device, planned = device_with(1.0), []
    look, plan = retarget(5.0, planned)
    changed = threading.Event()

    def plan_while_another_edit_comes_in(last):
        commit = plan(last)
        if not changed.is_set():
            changed.set()
            device.submit(lambda start: Ramp1D(start, 1.0, 1.0), "ramp")     # meanwhile
        return commit
    assert device.edit_planned(look, plan_while_another_edit_comes_in) == 2
    assert planned == [1, 2]                     # planned again, for the motion now last
    assert device.queued_end == 6.0


def test_a_commit_that_comes_too_late_plans_again_then_gives_up():
    device, attempts = device_with(1.0), []

    def look(device, attempt):
        attempts.append(attempt)

    def plan(seen):
        return lambda device: STALE
    assert device.edit_planned(look, plan, tries=3) is STALE
    assert attempts == [0, 1, 2]


def test_discard_queue_keeps_the_current_motion():
    device = device_with(1.0, 2.0, 3.0)
    device.current = device.queue.popleft()
    generation = device.generation
    device.edit(Device.discard_queue)
    assert device.queue_length == 0 and device.current is not None
    assert device.retired_id == 3 and device.generation == generation + 1
    assert device.queued_end == 1.0
