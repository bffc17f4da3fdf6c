"""The executor without ROS: Device.edit and Device.halt (in-place changes keep the queued end
right; a halt discards everything at once and rests where it is told), sequences queued whole,
what was discarded, step listeners at their rates, and a step that fails."""
import random
import time
from dataclasses import dataclass

import numpy as np

from acti_motion.executor import Device, DiscardLog, MotionExecutor
from acti_sim.world import World
from sim_fixtures import executor  # noqa: F401


@dataclass
class Ramp1D:
    """A toy motion: from `start` by `delta` over `duration` s."""
    start: float
    delta: float
    duration: float

    def at(self, t: float) -> float:
        return self.start + self.delta * min(1.0, max(0.0, t / self.duration))

    def apply(self, world, t: float, rate: float) -> None:
        pass


def test_edit_changes_a_queued_motion_and_the_queued_end_follows():
    d = Device("toy", 4, 0.0)
    d.submit(lambda s: Ramp1D(s, 1.0, 1.0), "a")
    d.submit(lambda s: Ramp1D(s, 1.0, 1.0), "b")
    assert d.queued_end == 2.0

    def longer(device):
        device.queue[-1].motion.delta = 5.0
        return device.queue[-1].id
    assert d.edit(longer) == 2
    assert d.queued_end == 6.0
    assert d.submit(lambda s: Ramp1D(s, 1.0, 1.0), "c") == 3 and d.queued_end == 7.0


def test_edit_of_an_idle_device_moves_its_rest_point():
    d = Device("toy", 4, 0.0)

    def move(device):
        device.hold = 3.0
    d.edit(move)
    assert d.queued_end == 3.0


def test_halt_discards_the_current_and_queued_motions_at_once():
    d = Device("toy", 4, 0.0)
    for label in "abc":
        d.submit(lambda s: Ramp1D(s, 1.0, 1.0), label)
    d.tick(None, 0.5)                                       # "a" runs
    assert d.moving and d.queue_length == 2
    generation = d.generation
    d.halt(0.42, "blocked")
    assert not d.busy and d.retired_id == 3 and d.discarded == 3
    assert d.hold == d.queued_end == 0.42 and d.generation == generation + 1
    assert d.submit(lambda s: Ramp1D(s, 1.0, 1.0), "d") == 4 and d.queued_end == 1.42


def test_submit_all_queues_a_sequence_whole_or_not_at_all():
    d = Device("toy", 4, 0.0)
    d.submit(lambda s: Ramp1D(s, 1.0, 1.0), "a")
    starts = []

    def ramp(s):
        starts.append(s)
        return Ramp1D(s, 1.0, 1.0)
    assert d.submit_all([(ramp, "b"), (ramp, "c")]) == [2, 3]
    assert starts == [1.0, 2.0] and d.queued_end == 3.0           # each from the one before
    assert d.submit_all([(ramp, "d"), (ramp, "e")]) is None        # room for one only
    assert d.queue_length == 3 and d.last_id == 3

    def refused(s):
        raise ValueError("no")
    try:
        d.submit_all([(ramp, "d"), (refused, "e")])
    except ValueError:
        pass
    assert d.queue_length == 3 and d.last_id == 3 and d.queued_end == 3.0


def test_a_discarded_motion_stays_discarded_after_many_more_discards():
    """The reasons of the last 256 discards are kept; whether a motion was discarded, always
    (an old discarded motion's wait said completed once 256 more discards had come)."""
    d = Device("toy", 4, 0.0)
    first = d.submit(lambda s: Ramp1D(s, 1.0, 1.0), "a")
    d.stop(0.1, "stop")                                        # at rest: discarded at once
    done = d.submit(lambda s: Ramp1D(s, 1.0, 1.0), "b")
    while d.busy:
        d.tick(None, 0.5)
    for _ in range(300):
        d.submit(lambda s: Ramp1D(s, 1.0, 1.0), "c")
        d.stop(0.1, "servo off")
        while d.busy:
            d.tick(None, 0.5)
    assert d.discard_reason(first) == DiscardLog.FORGOTTEN and d.was_discarded(first)
    assert not d.was_discarded(done) and d.discard_reason(d.last_id) == "servo off"
    assert not d.was_discarded(d.last_id + 1) and not d.was_discarded(10 ** 9)


def test_a_listener_keeps_a_rate_that_is_no_whole_number_of_steps():
    """100 Hz at 250 Hz is every 2.5 steps: it alternates 2 and 3 (rounding to 2 gave 125 Hz)."""
    world = World(time_step=0.004)
    try:
        ex, calls = MotionExecutor(world, real_time_factor=0.0), []
        ex.after_step(lambda w: calls.append(ex.steps), every=ex.steps_per_period(100.0))
        ex.after_step(lambda w: calls.append(-ex.steps), every=ex.steps_per_period(50.0))
        for _ in range(250):
            ex.step()
    finally:
        world.close()
    fractional = np.array([c for c in calls if c > 0])
    assert len(fractional) == 100 and set(np.diff(fractional).tolist()) == {2, 3}
    assert [-c for c in calls if c < 0] == list(range(5, 251, 5))


def test_the_discard_log_marks_exactly_the_ranges_it_is_given():
    """Ranges of every length and alignment (whole bytes are set at once) against a plain set."""
    rng = random.Random(7)
    log, expected, next_id = DiscardLog(), set(), 1
    for _ in range(300):
        first = next_id + rng.randrange(0, 20)
        last = first + rng.choice([0, 1, 6, 7, 8, 9, 15, 16, 17, rng.randrange(0, 3000)])
        log.add(first, last, "stop")
        expected.update(range(first, last + 1))
        next_id = last + 1
    assert {i for i in range(next_id + 50) if log.reason(i) is not None} == expected


def test_a_step_that_fails_ends_the_loop_and_says_so(executor, caplog):  # noqa: F811
    """A bug in a step (here a listener) ends the loop with `failed` and the error, so that the
    host ends too instead of answering calls while nothing moves."""
    steps = []

    def listener(_world) -> None:
        steps.append(1)
        if len(steps) == 5:
            raise ZeroDivisionError("a listener's bug")
    executor.after_step(listener)
    executor.start()
    deadline = time.monotonic() + 10.0
    while not executor.failed and time.monotonic() < deadline:
        time.sleep(0.01)
    assert executor.failed and isinstance(executor.error, ZeroDivisionError)
    executor._thread.join(timeout=5.0)
    assert not executor._thread.is_alive() and len(steps) == 5
    assert "the control loop stopped: ZeroDivisionError: a listener's bug" in caplog.text
    executor.shutdown()
