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
