"""ROS-free fixtures: a real PyBullet world and executor, stepped by the test itself."""
from __future__ import annotations

import threading

import pytest

from acti_motion.executor import MotionExecutor
from acti_sim.world import World


def run_until(executor: MotionExecutor, predicate, max_seconds: float) -> float:
    """Step the simulation until predicate() holds; simulated seconds it took."""
    t0 = executor.world.time
    while not predicate():
        if executor.world.time - t0 > max_seconds:
            raise AssertionError(f"condition not reached in {max_seconds} simulated s")
        executor.step()
    return executor.world.time - t0


class Announced:
    """A lock that says (`waits`) when a thread comes to wait for it (a try is no wait)."""

    def __init__(self, lock) -> None:
        self.lock, self.waits = lock, threading.Event()

    def acquire(self, blocking: bool = True) -> bool:
        if blocking:
            self.waits.set()
        return self.lock.acquire(blocking)

    def release(self) -> None:
        self.lock.release()

    def __enter__(self):
        return self.acquire()

    def __exit__(self, *exc):
        self.release()


@pytest.fixture
def executor():
    world = World()
    ex = MotionExecutor(world, real_time_factor=0.0)
    yield ex
    world.close()
