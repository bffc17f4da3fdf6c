"""The world's physics step without the GIL (`acti_sim.unlocked_step`): it moves the world
exactly as pybullet's `stepSimulation` does, other Python threads run while it steps, and no
other pybullet call of the world runs meanwhile (the client's lock)."""
import sys
import threading
import time

import numpy as np
import pybullet
import pytest

from acti_sim.unlocked_step import CLIENTS_TABLE, symbol_values
from acti_sim.world import World


def driven(world: World, step) -> list:
    """A drive of the arm and the wheels, stepped by `step`: the joints' states after it."""
    world.set_arm_targets(np.radians([30.0, 20.0, -10.0, -60.0, 15.0, 40.0, 5.0]))
    world.set_wheel_velocities(3.0, 2.0)
    for _ in range(240):
        step()
    return world.joint_states()


def test_it_moves_the_world_as_pybullets_step_does():
    ours, theirs = World(), World()
    try:
        assert driven(ours, ours.step) == driven(
            theirs, lambda: pybullet.stepSimulation(physicsClientId=theirs._p._id))
        assert ours.base_pose() == theirs.base_pose() and ours.base_pose()[0] > 0.1
    finally:
        ours.close()
        theirs.close()


def test_other_threads_run_while_it_steps():
    """With no forced switch of the GIL, another thread runs only where this one releases it.
    It watches for a step under way (the client's lock held, taken only around the step
    here), handing the GIL back between looks, while this one steps a moving arm: with
    pybullet's own step it never sees one."""
    world = World()
    world.set_arm_targets(np.radians([30.0, 20.0, -10.0, -60.0, 15.0, 40.0, 5.0]))
    seen, go, done = [], threading.Event(), threading.Event()

    def look() -> None:
        go.wait()
        while not done.is_set():
            if world._p.lock.locked():
                seen.append(True)
                return
            time.sleep(0)
        seen.append(False)
    interval = sys.getswitchinterval()
    sys.setswitchinterval(30.0)
    try:
        other = threading.Thread(target=look)
        other.start()
        go.set()
        for _ in range(480):
            world.step()
            if seen:
                break
        done.set()
        other.join()
    finally:
        sys.setswitchinterval(interval)
        world.close()
    assert seen == [True]


def test_a_step_after_close_is_pybullets_error_not_a_crash():
    world = World()
    world.close()
    with pytest.raises(pybullet.error, match="Not connected"):
        world.step()


def test_a_missing_symbol_is_said():
    with pytest.raises(RuntimeError, match="no symbol nowhere_at_all"):
        symbol_values(pybullet.__file__, (CLIENTS_TABLE, "nowhere_at_all"))
