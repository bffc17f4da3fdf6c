"""The control loop at rest, without ROS: with no motion to command it wakes at most every
IDLE_WAKE_S and runs the steps that fell due back to back (the same physics, step by step), at
once when a device is given work, for every step of a listener that must be on time, and it keeps
real time on average. IDLE_WAKE_S is made long here, so that "at once" is told from "at the next
wake" on any machine."""
import time
from dataclasses import dataclass

import pytest

from acti_motion.executor import MotionExecutor
from acti_sim.world import World

LONG_WAKE_S = 5.0


@dataclass
class Hold:
    """A toy motion that commands nothing for `duration` s."""
    duration: float

    def at(self, t: float) -> float:
        return 0.0

    def apply(self, world, t: float, rate: float) -> None:
        pass


@pytest.fixture
def loop():
    """A real-time loop at 250 Hz with one device, started by the test; its wakes are counted
    (a wake is a step that follows a sleep of over 1 ms)."""
    world = World(time_step=0.004)
    ex = MotionExecutor(world, real_time_factor=1.0)
    ex.device = ex.add_device("toy", 4, 0.0)
    ex.stamps = []
    ex.after_step(lambda w: ex.stamps.append(time.monotonic()))
    yield ex
    ex.shutdown()
    world.close()


def wakes(stamps: list[float]) -> int:
    return 1 + sum(b - a > 1e-3 for a, b in zip(stamps, stamps[1:]))


def wait_for(predicate, seconds: float) -> bool:
    deadline = time.monotonic() + seconds
    while not predicate() and time.monotonic() < deadline:
        time.sleep(0.002)
    return predicate()


def test_an_idle_loop_steps_in_batches_and_keeps_real_time(loop):
    loop.IDLE_WAKE_S = 0.1
    t0 = time.monotonic()
    loop.start()
    time.sleep(1.0)
    steps, stamps, elapsed = loop.steps, list(loop.stamps), time.monotonic() - t0
    assert steps / wakes(stamps) >= 5           # 25 steps a wake when nothing is late
    assert abs(steps * loop.dt - elapsed) <= 2 * loop.IDLE_WAKE_S


def test_work_wakes_an_idle_loop_at_once(loop):
    loop.IDLE_WAKE_S = LONG_WAKE_S
    loop.start()
    assert wait_for(lambda: loop.steps > 0, 2.0)
    time.sleep(0.2)                             # asleep now, until LONG_WAKE_S
    given = time.monotonic()
    loop.device.submit(lambda start: Hold(1.0), "hold")
    assert wait_for(lambda: loop.device.current is not None, 2.0)
    assert time.monotonic() - given < 2.0
    before = loop.steps                         # moving: a step every period again
    time.sleep(0.5)
    assert loop.steps - before >= 60


def test_woken_by_work_the_loop_lets_the_giver_answer_before_it_steps(loop):
    """The steps an idle loop slept over run after a grace (`WORK_GRACE_S`): run at once,
    back to back, they held the core while the accept's answer went out. Made long here."""
    loop.IDLE_WAKE_S, loop.WORK_GRACE_S = LONG_WAKE_S, 2.0
    loop.start()
    assert wait_for(lambda: loop.steps > 0, 2.0)
    time.sleep(0.2)                             # asleep now, until LONG_WAKE_S
    before = loop.steps
    loop.device.submit(lambda start: Hold(1.0), "hold")
    time.sleep(0.1)                             # the giver answers (the GIL is free)
    assert loop.steps == before
    assert wait_for(lambda: loop.device.current is not None, 5.0)


def test_a_motion_over_at_once_leaves_an_idle_loop_asleep(loop):
    """A zero-length motion on an idle device is over when it is accepted: nothing for the loop
    to command, so it is not woken (woken, it stepped the steps it slept over back to back
    while the accept's answer went out)."""
    loop.IDLE_WAKE_S = LONG_WAKE_S
    loop.start()
    assert wait_for(lambda: loop.steps > 0, 2.0)
    time.sleep(0.2)                             # asleep now, until LONG_WAKE_S
    before = loop.steps
    motion_id = loop.device.submit(lambda start: Hold(0.0), "nothing")
    assert loop.device.retired_id == motion_id and loop.device.idle
    time.sleep(0.5)
    assert loop.steps == before


def test_a_listener_that_must_be_on_time_keeps_its_rate_while_idle(loop):
    loop.IDLE_WAKE_S = LONG_WAKE_S
    calls = []
    loop.after_step(lambda w: calls.append(time.monotonic()), every=loop.steps_per_period(25.0),
                    on_time=lambda: True)
    loop.start()
    assert wait_for(lambda: len(calls) >= 20, 3.0)      # 25 Hz, not one burst every 5 s
    assert max(b - a for a, b in zip(calls[1:], calls[2:])) < 1.0


def test_shutdown_wakes_an_idle_loop(loop):
    loop.IDLE_WAKE_S = LONG_WAKE_S
    loop.start()
    assert wait_for(lambda: loop.steps > 0, 2.0)
    time.sleep(0.1)
    t0 = time.monotonic()
    loop.shutdown()
    assert time.monotonic() - t0 < 2.0 and loop._thread is None


def test_a_loop_with_a_motion_steps_every_period(loop):
    loop.IDLE_WAKE_S = LONG_WAKE_S
    loop.device.submit(lambda start: Hold(10.0), "hold")
    loop.start()
    time.sleep(0.5)
    assert loop.steps >= 60 and wakes(loop.stamps) >= loop.steps / 3


def test_work_given_from_another_thread_while_it_decides_is_never_lost(loop):
    """Work given between the loop's look at its devices and its wait still wakes it."""
    loop.IDLE_WAKE_S = LONG_WAKE_S
    loop.start()
    for _ in range(20):
        loop.device.submit(lambda start: Hold(0.01), "short")
        assert wait_for(lambda: loop.device.idle and loop.device.retired_id == loop.device.last_id,
                        2.0)
