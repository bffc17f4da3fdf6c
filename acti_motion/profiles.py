"""Time profiles: the synchronized trapezoid that PTP moves and straight base moves share."""
from __future__ import annotations

import math
import operator
from dataclasses import dataclass

import numpy as np

from acti_motion.replies import floats


@dataclass(frozen=True)
class Trapezoid:
    """Normalised progress s(t) in [0, 1] with equal accel and decel time `ramp`.

    `duration` = max(cruise_time, ramp) + ramp, so a short move becomes a triangle with the same
    ramp; every axis that scales this profile starts and stops together (the spec's PTP rule).
    """
    duration: float
    ramp: float

    @classmethod
    def for_axes(cls, distance: np.ndarray | list[float], max_speed: np.ndarray | list[float],
                 ramp: float) -> "Trapezoid":
        """Profile for axes moving `distance` at no more than `max_speed` each (same units; a
        speed of 0 for an axis that moves takes for ever). Plain floats: for a handful of axes
        numpy's per-call cost was most of a PTP accept's (lists of floats are taken as they are)."""
        d = distance if isinstance(distance, list) else floats(distance)    # (a PTP's lists:
        v = max_speed if isinstance(max_speed, list) else floats(max_speed)  # no call)
        if len(v) == 1:
            v = v * len(d)
        if not any(d):
            return cls(0.0, 0.0)
        if all(v):                  # the usual case, without a Python step per axis
            cruise = max(map(operator.truediv, map(abs, d), v))
        else:
            cruise = max(abs(a) / b if b else (math.inf if a else 0.0) for a, b in zip(d, v))
        return cls(max(cruise, ramp) + ramp, ramp)

    @property
    def peak(self) -> float:
        """Peak of ds/dt (1/s)."""
        return 1.0 / (self.duration - self.ramp) if self.duration > 0.0 else 0.0

    def sample_many(self, ts: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(s, ds/dt, d²s/dt²) at each time of ts (the acceleration of the phase each is in)."""
        T, ta, v = self.duration, self.ramp, self.peak
        t = np.clip(np.asarray(ts, float), 0.0, T)
        r = T - t
        rising, falling = t < ta, t > T - ta
        s = np.where(rising, v * t * t / (2 * ta),
                     np.where(falling, 1.0 - v * r * r / (2 * ta), v * (t - ta / 2)))
        sd = np.where(rising, v * t / ta, np.where(falling, v * r / ta, v))
        sdd = np.where(rising, v / ta, np.where(falling, -v / ta, 0.0))
        return s, sd, sdd

    def sample(self, t: float) -> tuple[float, float]:
        """(s, ds/dt) at time t, clamped to the profile's ends."""
        T, ta, v = self.duration, self.ramp, self.peak
        if T <= 0.0 or t >= T:
            return 1.0, 0.0
        if t <= 0.0:
            return 0.0, 0.0
        if t < ta:
            return v * t * t / (2 * ta), v * t / ta
        if t <= T - ta:
            return v * (t - ta / 2), v
        r = T - t
        return 1.0 - v * r * r / (2 * ta), v * r / ta
