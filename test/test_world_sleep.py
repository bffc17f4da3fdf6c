"""Bullet's sleeping (acti_sim.world): a robot at rest stops being integrated, and every
set-point wakes it, so no motion is lost however slowly it runs after a rest."""
import numpy as np

from arm_fixtures import WORK, arm, rest  # noqa: F401
from sim_fixtures import executor  # noqa: F401
from vehicle_fixtures import assert_at, base, ready, settle, steps  # noqa: F401

REST_S = 3.0            # longer than Bullet's 2 s at rest before a body sleeps


def test_a_robot_at_rest_sleeps(executor):  # noqa: F811
    """Asleep, the world does not integrate: the joints do not move by a bit (awake, PyBullet's
    solver moves a resting joint by ~1e-12 each step)."""
    steps(executor, REST_S)
    before = executor.world.joint_states()[1]
    steps(executor, 0.4)
    assert executor.world.joint_states()[1] == before


def test_a_slow_drive_after_a_rest_reaches_its_target(executor, base):  # noqa: F811
    """10 mm/s turns the wheels at 0.1 rad/s, below Bullet's threshold: without a wake each step
    the base fell asleep 2 s into the drive and stopped after 20 of 50 mm."""
    ready(base)
    assert base.set_velocity((10.0, 10.0)).ok
    steps(executor, REST_S)
    assert base.move_forward(50.0).ok
    settle(executor, base)
    assert_at(base, 50.0, 0.0, 0.0, mm=2.0)


def test_a_slow_joint_move_after_a_rest_reaches_its_target(executor, arm):  # noqa: F811
    """1 % of the joint speed: J1 turns at ~0.02 rad/s, well below Bullet's threshold."""
    rest(executor, arm)
    steps(executor, REST_S)
    target = [WORK[0] + 3.0, *WORK[1:]]
    assert arm.set_speed_joint(1).ok
    assert arm.move_ptp_joint_abs(target).ok
    rest(executor, arm, max_seconds=60.0)
    assert np.allclose(arm.get_feedback_pos_joint().values["pos"][:7], target, atol=0.01)


def test_a_box_put_on_a_sleeping_robot_falls_on_it(executor):  # noqa: F811
    """A body that falls on the sleeping robot wakes it (Bullet wakes what an active body
    touches): the box comes to rest on the arm, not in it."""
    world = executor.world
    steps(executor, REST_S)
    box = world.add_box((0.0, 0.0, 0.45), (0.05, 0.05, 0.05), mass=1.0)
    steps(executor, 1.0)
    assert world._p.getBasePositionAndOrientation(box)[0][2] < 0.44
