"""The synchronized trapezoid: every axis starts and stops together, limits hold."""
import numpy as np
import pytest

from acti_motion.profiles import Trapezoid


def test_long_move_cruises_at_the_slowest_axis_limit():
    p = Trapezoid.for_axes(np.array([1.0, 0.5]), np.array([0.5, 1.0]), ramp=0.2)
    assert p.duration == pytest.approx(2.0 + 0.2)
    assert p.peak * 1.0 == pytest.approx(0.5)          # axis 0 at its limit
    assert p.peak * 0.5 <= 1.0                          # axis 1 below its limit


def test_short_move_is_a_triangle_with_the_same_ramp():
    p = Trapezoid.for_axes(np.array([0.01]), np.array([1.0]), ramp=0.3)
    assert p.duration == pytest.approx(0.6)
    assert p.sample(0.3)[0] == pytest.approx(0.5)


def test_profile_is_continuous_and_ends_at_one():
    p = Trapezoid.for_axes(np.array([2.0]), np.array([1.0]), ramp=0.5)
    ts = np.linspace(0, p.duration, 2001)
    s = np.array([p.sample(t)[0] for t in ts])
    assert s[0] == 0.0 and s[-1] == pytest.approx(1.0)
    assert np.all(np.diff(s) >= -1e-12)
    assert np.max(np.abs(np.diff(s))) < 2e-3


def test_zero_move_takes_no_time():
    p = Trapezoid.for_axes(np.zeros(3), np.ones(3), ramp=0.3)
    assert p.duration == 0.0 and p.sample(0.0) == (1.0, 0.0)


@pytest.mark.parametrize("distance, ramp", [(2.0, 0.5), (0.01, 0.3)])
def test_sample_many_matches_sample_and_gives_the_phase_acceleration(distance, ramp):
    p = Trapezoid.for_axes(np.array([distance]), np.array([1.0]), ramp=ramp)
    ts = np.linspace(-0.1, p.duration + 0.1, 501)
    s, sd, sdd = p.sample_many(ts)
    assert np.allclose(np.array([p.sample(t) for t in ts]), np.stack([s, sd], axis=1), atol=1e-12)
    corners = np.array([0.0, ramp, p.duration - ramp, p.duration])
    smooth = ((np.min(np.abs(ts[:, None] - corners), axis=1) > 2 * (ts[1] - ts[0]))
              & (ts > 0.0) & (ts < p.duration))
    assert np.allclose(np.gradient(sd, ts)[smooth], sdd[smooth], atol=1e-9)
