"""Differential-drive base: wheel odometry and pose-tracking motions (SI units: m, rad, s)."""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from acti_motion.profiles import Trapezoid
from acti_sim.world import World


@dataclass(frozen=True)
class Pose2D:
    x: float
    y: float
    theta: float

    def forward(self, distance: float) -> "Pose2D":
        return Pose2D(self.x + distance * math.cos(self.theta),
                      self.y + distance * math.sin(self.theta), self.theta)


def wrap_angle(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


class Odometry:
    """Dead reckoning from wheel rotation, as a real base would have it (not the ground truth).

    `origin` redefines where the odometry frame is (setPosition).
    """

    def __init__(self, wheel_radius: float, wheel_separation: float, wheels: np.ndarray) -> None:
        self.r, self.b = wheel_radius, wheel_separation
        self._last = wheels.copy()
        self.pose = Pose2D(0.0, 0.0, 0.0)
        self.v = 0.0
        self.w = 0.0

    def update(self, wheels: np.ndarray, dt: float) -> None:
        dl, dr = (wheels - self._last) * self.r
        self._last = wheels.copy()
        ds, dth = (dl + dr) / 2, (dr - dl) / self.b
        p = self.pose
        mid = p.theta + dth / 2
        self.pose = Pose2D(p.x + ds * math.cos(mid), p.y + ds * math.sin(mid),
                           wrap_angle(p.theta + dth))
        self.v, self.w = ds / dt, dth / dt

    def reset(self, pose: Pose2D) -> None:
        self.pose = pose


class TrackedBaseMotion:
    """A base motion along a reference path: feed-forward twist plus feedback on the odometry
    error (Kanayama's tracking law), then a short settle so the base ends on the target."""

    SETTLE = 0.4
    K_X, K_Y, K_TH = 3.0, 30.0, 6.0

    def __init__(self, odometry: Odometry, reference: "LinePath") -> None:
        self.odometry = odometry
        self.reference = reference
        self.duration = reference.duration + self.SETTLE

    def at(self, t: float) -> Pose2D:
        return self.reference.pose(min(t, self.reference.duration))

    def apply(self, world: World, t: float, rate: float) -> None:
        if t >= self.duration:
            world.set_wheel_velocities(0.0, 0.0)
            return
        ref = self.at(t)
        v_d, w_d = self.reference.twist(t) if t < self.reference.duration else (0.0, 0.0)
        v_d, w_d = v_d * rate, w_d * rate
        p = self.odometry.pose
        dx, dy = ref.x - p.x, ref.y - p.y
        ex = math.cos(p.theta) * dx + math.sin(p.theta) * dy
        ey = -math.sin(p.theta) * dx + math.cos(p.theta) * dy
        eth = wrap_angle(ref.theta - p.theta)
        v = v_d * math.cos(eth) + self.K_X * ex
        w = w_d + v_d * self.K_Y * ey + self.K_TH * math.sin(eth)
        r, b = self.odometry.r, self.odometry.b
        world.set_wheel_velocities((v - w * b / 2) / r, (v + w * b / 2) / r)


class LinePath:
    """Straight line from `start` by `distance` (m; negative drives backwards), trapezoid-timed."""

    def __init__(self, start: Pose2D, distance: float, speed: float, accel: float) -> None:
        self.start, self.distance = start, distance
        self.profile = Trapezoid.for_axes(np.array([distance]), np.array([speed]), speed / accel)
        self.duration = self.profile.duration

    def pose(self, t: float) -> Pose2D:
        s, _ = self.profile.sample(t)
        return self.start.forward(s * self.distance)

    def twist(self, t: float) -> tuple[float, float]:
        _, ds = self.profile.sample(t)
        return ds * self.distance, 0.0
