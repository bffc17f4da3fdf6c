"""Base paths without a world: the 1-D ramp from a moving start, exact curves, re-timing,
the straight move and the velocity drive."""
import math

import numpy as np
import pytest

from acti_motion.vehicle.paths import (ConstantTwist, Moved, Odometry, Pose2D, Ramp, Tail,
                                       TrackedBaseMotion, arc, line, straight_to, turn,
                                       velocity_path)

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



def _dense_peak(twist, t0, t1, dt=1e-4):
    """The largest |v| and |w| of twist(t) sampled every dt over [t0, t1)."""
    twists = np.abs([twist(t) for t in np.arange(t0, t1, dt)] or [(0.0, 0.0)])
    return tuple(twists.max(axis=0))


def _paths():
    start = Pose2D(0.3, -0.2, 0.4)
    chain = straight_to(start, Pose2D(1.5, 0.8, -1.0), LIMITS, True)
    drive = velocity_path(start, 0.1, -0.2, (0.45, 0.5), 1.5, (0.4, 1.0))
    return {"line": line(start, 1.2, LIMITS), "turn": turn(start, -2.0, LIMITS),
            "arc": arc(start, -0.4, 1.5, LIMITS), "chain": chain, "velocity drive": drive,
            "sampled": drive.paths[0], "re-timed chain": chain.retimed(2.0, LIMITS),
            "moved": Moved(chain, Pose2D(1.0, 1.0, 1.0)), "tail": Tail(drive, 0.7),
            "constant": ConstantTwist(start, (-0.3, 0.2), 1.0)}


@pytest.mark.parametrize("name", sorted(_paths()))
def test_peak_is_the_largest_speed_and_yaw_rate_over_the_span(name):
    """peak(t0, t1) is exact (a dense sampling comes within its step's change) over spans inside,
    across and outside the path; a point span is the twist there. The base's stop ramp takes
    it for the highest speed a path still reaching it reaches while it stops."""
    path = _paths()[name]
    d = path.duration
    for t0, t1 in ((0.0, d), (0.1 * d, 0.35 * d), (0.3 * d, 0.9 * d), (0.6 * d, d + 1.0),
                   (-1.0, 0.2 * d), (d, d + 1.0), (-2.0, -1.0)):
        got, dense = path.peak(t0, t1), _dense_peak(path.twist, t0, t1)
        assert got == pytest.approx(dense, abs=1e-3), (t0, t1)
        assert got[0] >= dense[0] - 1e-12 and got[1] >= dense[1] - 1e-12, (t0, t1)
    t = 0.4 * d
    assert path.peak(t, t) == pytest.approx(tuple(map(abs, path.twist(t))))


def test_a_motions_reference_peak_follows_each_segment_over_its_own_time():
    """Across a splice, each path counts only while it is the reference: the slow path spliced
    in hides the first one's speed from the splice on."""
    start = Pose2D(0.0, 0.0, 0.0)
    odometry = Odometry(0.1, 0.4, np.zeros(2))
    motion = TrackedBaseMotion(odometry, line(start, 3.0, LIMITS))
    motion.splice(1.0, ConstantTwist(start, (0.1, 0.0), 4.0))
    assert motion.reference_peak(0.0, 0.9) == pytest.approx(
        _dense_peak(motion.reference_twist, 0.0, 0.9), abs=1e-3)
    assert motion.reference_peak(1.0, 4.0) == pytest.approx((0.1, 0.0))
    assert motion.reference_peak(0.5, 2.0) == pytest.approx((0.4, 0.0))   # 0.4 m/s² for 1 s
