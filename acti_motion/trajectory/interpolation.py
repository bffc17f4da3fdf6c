"""joint_trajectory_controller's interpolation between trajectory points, as polynomials.

Between two knots each joint follows the lowest-order polynomial that matches what both knots
give: positions only, a line; with velocities, the cubic Hermite; with accelerations too, the
quintic. Coefficients are kept per segment and joint (powers of the time into the segment), so a
trajectory is sampled anywhere, many times at once, with its first two derivatives."""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Knot:
    """A trajectory point: time (s from the trajectory's start), positions, and the velocities
    and accelerations when given (None otherwise); one value per joint."""
    time: float
    positions: np.ndarray
    velocities: np.ndarray | None = None
    accelerations: np.ndarray | None = None

    @property
    def order(self) -> int:
        """How many derivatives, from the position on, this knot gives (1, 2 or 3)."""
        if self.velocities is None:
            return 1
        return 2 if self.accelerations is None else 3


@dataclass(frozen=True)
class State:
    """Positions, velocities and accelerations at one instant (one value per joint)."""
    positions: np.ndarray
    velocities: np.ndarray
    accelerations: np.ndarray


def segment_coefficients(a: Knot, b: Knot) -> np.ndarray:
    """Coefficients c[joint, k] of the polynomial sum c_k·τ^k (τ: seconds into the segment, six
    powers) from knot a to knot b, of the order both give."""
    T = b.time - a.time
    p0, p1 = a.positions, b.positions
    c = np.zeros((len(p0), 6))
    c[:, 0] = p0
    order = min(a.order, b.order)
    if order == 1:
        c[:, 1] = (p1 - p0) / T
    elif order == 2:
        v0, v1 = a.velocities, b.velocities
        c[:, 1] = v0
        c[:, 2] = (3 * (p1 - p0) - (2 * v0 + v1) * T) / T ** 2
        c[:, 3] = (2 * (p0 - p1) + (v0 + v1) * T) / T ** 3
    else:
        v0, v1, a0, a1 = a.velocities, b.velocities, a.accelerations, b.accelerations
        c[:, 1] = v0
        c[:, 2] = a0 / 2
        c[:, 3] = (20 * (p1 - p0) - (8 * v1 + 12 * v0) * T - (3 * a0 - a1) * T ** 2) / (2 * T ** 3)
        c[:, 4] = (30 * (p0 - p1) + (14 * v1 + 16 * v0) * T + (3 * a0 - 2 * a1) * T ** 2) \
            / (2 * T ** 4)
        c[:, 5] = (12 * (p1 - p0) - 6 * (v1 + v0) * T - (a0 - a1) * T ** 2) / (2 * T ** 5)
    return c


_D1 = np.arange(1, 6)                 # d/dτ of τ^k: k·τ^(k-1)
_D2 = _D1[1:] * np.arange(1, 5)      # d²/dτ²: k(k-1)·τ^(k-2)


class PiecewisePolynomial:
    """The interpolated trajectory through `knots` (strictly increasing times, the first at 0):
    before the first knot it holds the first, after the last it holds the last."""

    def __init__(self, knots: list[Knot]) -> None:
        self.knots = knots
        self.times = np.array([k.time for k in knots])
        self.coefficients = np.array([segment_coefficients(a, b)
                                      for a, b in zip(knots[:-1], knots[1:])])
        self.duration = float(self.times[-1])
        self._end = knots[-1].positions

    def sample_many(self, ts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Positions, velocities, accelerations at times ts (each N × joints)."""
        ts = np.clip(np.asarray(ts, float), 0.0, self.duration)
        if not len(self.coefficients):
            n = (len(ts), len(self._end))
            return np.broadcast_to(self._end, n).copy(), np.zeros(n), np.zeros(n)
        seg = np.clip(np.searchsorted(self.times, ts, side="right") - 1, 0,
                      len(self.coefficients) - 1)
        tau = (ts - self.times[seg])[:, None, None]
        c = self.coefficients[seg]                                   # N × joints × 6
        powers = tau ** np.arange(6)
        q = np.sum(c * powers, axis=2)
        qd = np.sum(c[:, :, 1:] * _D1 * powers[:, :, :5], axis=2)
        qdd = np.sum(c[:, :, 2:] * _D2 * powers[:, :, :4], axis=2)
        held = (np.asarray(ts) >= self.duration)[:, None]           # at rest past the end
        return q, np.where(held, 0.0, qd), np.where(held, 0.0, qdd)

    def state(self, t: float) -> State:
        q, qd, qdd = self.sample_many(np.array([t]))
        return State(q[0], qd[0], qdd[0])
