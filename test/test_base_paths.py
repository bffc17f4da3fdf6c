"""Base paths without a world: the 1-D ramp from a moving start, exact curves, re-timing,
the straight move and the velocity drive."""
import math

import numpy as np
import pytest

from acti_motion.vehicle.paths import Pose2D, Ramp, arc, line, straight_to, turn, velocity_path

LIMITS = (0.5, math.radians(45.0), 0.4, math.radians(90.0))


def sampled(ramp, dt=1e-3):
    ts = np.arange(0.0, ramp.duration + dt, dt)
    return np.array([ramp.sample(t) for t in ts])


@pytest.mark.parametrize("length, v0", [(2.0, 0.0), (0.1, 0.0), (2.0, 0.3), (2.0, 0.9), (0.05, 0.3)])
def test_ramp_reaches_the_end_at_rest_within_its_bounds(length, v0):
    r = Ramp(length, 0.5, 0.4, v0)
    s = sampled(r)
    assert s[0, 1] == pytest.approx(v0) and s[-1, 0] == pytest.approx(length)
    assert s[-1, 1] == 0.0 and np.all(np.diff(s[:, 0]) >= -1e-12)
    accel = np.abs(np.diff(s[:, 1])) / 1e-3
    stop = v0 * v0 / (2 * length)                      # harder only when it cannot stop in time
    assert accel.max() <= max(0.4, stop) * 1.01
    if v0 <= 0.5:
        assert s[:, 1].max() <= 0.5 + 1e-9


def test_curves_are_exact_rigid_motions():
    start = Pose2D(1.0, 2.0, math.radians(30.0))
    end = arc(start, 0.5, math.pi / 2, LIMITS)
    p = end.pose(end.duration)
    centre = start.compose(Pose2D(0.0, 0.5, 0.0))
    assert math.dist((p.x, p.y), (centre.x, centre.y)) == pytest.approx(0.5)
    assert p.theta == pytest.approx(start.theta + math.pi / 2)
    t = turn(start, -1.0, LIMITS)
    assert t.pose(t.duration) == Pose2D(start.x, start.y, start.theta - 1.0)
    v, w = arc(start, -0.5, 1.0, LIMITS).twist(0.5)
    assert v < 0 and w > 0 and v == pytest.approx(-0.5 * w)      # centre right, CCW: backwards


def test_retimed_keeps_the_geometry_and_starts_at_the_present_speed():
    path = line(Pose2D(0, 0, 0), 3.0, LIMITS)
    t = 2.0
    faster = path.retimed(t, (1.0,) + LIMITS[1:])
    assert faster.pose(0.0) == pytest.approx(path.pose(t))
    assert faster.twist(0.0)[0] == pytest.approx(path.twist(t)[0])
    assert faster.pose(faster.duration).x == pytest.approx(3.0)
    assert t + faster.duration < path.duration


def test_straight_to_turns_drives_and_turns_and_goes_backwards_to_a_goal_behind():
    start = Pose2D(0.0, 0.0, 0.0)
    ahead = straight_to(start, Pose2D(1.0, 1.0, math.pi), LIMITS, True)
    assert [type(p).__name__ for p in ahead.paths] == ["CurvePath"] * 3
    end = ahead.pose(ahead.duration)
    assert (end.x, end.y) == pytest.approx((1.0, 1.0)) and math.cos(end.theta) == pytest.approx(-1.0)
    behind = straight_to(start, Pose2D(-1.0, 0.0, 0.0), LIMITS, True)
    assert len(behind.paths) == 1 and behind.twist(1.0)[0] < 0          # no turn: backwards


def test_velocity_path_slews_holds_and_stops():
    p = velocity_path(Pose2D(0, 0, 0), 0.0, 0.0, (0.4, 0.2), 2.0, (0.4, 0.4))
    assert p.twist(1.5) == pytest.approx((0.4, 0.2), abs=1e-9)
    assert p.duration == pytest.approx(3.0, abs=0.01)                    # 2 s + 1 s to stop
    assert p.twist(p.duration) == (0.0, 0.0)
