"""The base's TOPP-RA plans in a process of their own (acti_motion.vehicle.planner): the same
plans as in the calling process, made there and not here, and back here once it is stopped."""
import numpy as np
import pytest

from acti_motion.vehicle import cruise, planner
from acti_motion.vehicle.paths import Pose2D
from sim_fixtures import executor, run_until  # noqa: F401
from vehicle_fixtures import base, ready, settle  # noqa: F401

POINTS = [(0.8, 0.3), (1.6, 0.0), (2.4, 0.4)]
LIMITS = (0.6, 1.0, 0.5, 1.6)


@pytest.fixture
def planning_process():
    planner.start()
    assert planner.wait_ready()
    yield
    planner.stop()


def here_only(*_args, **_kwargs):
    raise AssertionError("TOPP-RA ran in the calling process")


def test_the_planning_process_plans_what_this_process_would(planning_process, monkeypatch):
    there = cruise.plan_curve(Pose2D(0.0, 0.0, 0.3), POINTS, LIMITS, 0.2, 0.1)
    planner.stop()
    here = cruise.plan_curve(Pose2D(0.0, 0.0, 0.3), POINTS, LIMITS, 0.2, 0.1)
    assert there.via_times == here.via_times
    for field in ("t", "x", "y", "theta", "v", "w"):
        assert np.array_equal(getattr(there.path, field), getattr(here.path, field)), field


def test_cruise_points_and_set_velocity_replans_run_in_the_planning_process(
        base, executor, planning_process, monkeypatch):  # noqa: F811
    monkeypatch.setattr(cruise, "time_optimal", here_only)   # this process's TOPP-RA is never used
    ready(base)
    for x, y in POINTS:
        assert base.move_cruise_abs((1000.0 * x, 1000.0 * y)).ok
    run_until(executor, lambda: base.odometry.v > 0.1, 5.0)
    assert base.set_velocity((150.0, 30.0)).ok                # the running cruise, re-timed
    settle(executor, base)
    assert base.device.completed == 1


def test_without_the_planning_process_plans_run_here(monkeypatch):
    planner.start()
    assert planner.wait_ready()
    planner.stop()
    monkeypatch.setattr(cruise, "time_optimal", here_only)
    with pytest.raises(AssertionError, match="calling process"):
        cruise.plan_curve(Pose2D(0.0, 0.0, 0.0), POINTS, LIMITS)
