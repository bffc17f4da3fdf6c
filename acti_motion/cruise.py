"""Smooth paths through points for a differential drive, timed by TOPP-RA (SI units).

The geometric path is a cubic spline through the points that leaves along the base's heading;
the base follows its tangent, so the path in TOPP-RA's terms has two coordinates, the arc length
s and the heading theta(s). Their bounds are exactly the drive's: |ds/dt| = forward speed,
|dtheta/dt| = yaw rate, and their second derivatives the accelerations. ParametrizeConstAccel
turns the time-optimal velocity profile into a trajectory, sampled for tracking.
"""
from __future__ import annotations

import functools
import logging
import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np
from scipy.interpolate import CubicSpline

from acti_motion.base import (Chain, Odometry, Path, Pose2D, SampledPath, TrackedBaseMotion,
                              straight_to, turn, velocity_path, wrap_angle)

SAMPLE_DT = 0.005            # s between samples of the timed path
DENSE_STEP = 0.002           # m between samples of the geometric path
GRID_STEP = 0.01             # m between TOPP-RA grid points …
GRID_MAX = 600               # … at most this many
MIN_SEPARATION = 1e-3        # m: closer points are one point


@dataclass
class CurvePlan:
    """A timed path and the times (s from its start) at which it passes each point."""
    path: SampledPath
    via_times: list[float]


@functools.cache
def _toppra():
    import toppra  # noqa: PLC0415 - lazy: importing toppra takes about a second
    import toppra.algorithm  # noqa: PLC0415
    import toppra.constraint  # noqa: PLC0415
    logging.getLogger("toppra").setLevel(logging.ERROR)   # an infeasible start is handled here
    return toppra


def time_optimal(s: np.ndarray, heading: np.ndarray, limits: tuple[float, float, float, float],
                 v0: float = 0.0, grid_step: float = GRID_STEP, grid_max: int = GRID_MAX):
    """TOPP-RA over the path (s, theta(s)) with the drive's bounds, from speed v0 to rest.
    The trajectory (callable t → [s, theta], and its derivatives), or None when infeasible."""
    ta = _toppra()
    v_max, w_max, a_max, alpha_max = limits
    keep = np.unique(np.linspace(0, len(s) - 1, min(len(s), 2000)).astype(int))
    path = ta.SplineInterpolator(s[keep], np.column_stack([s[keep], heading[keep]]))
    n = int(min(grid_max, max(20, math.ceil(s[-1] / grid_step))))
    constraints = [
        ta.constraint.JointVelocityConstraint(np.array([[-v_max, v_max], [-w_max, w_max]])),
        ta.constraint.JointAccelerationConstraint(np.array([[-a_max, a_max],
                                                            [-alpha_max, alpha_max]])),
    ]
    instance = ta.algorithm.TOPPRA(constraints, path, gridpoints=np.linspace(0.0, s[-1], n + 1),
                                   parametrizer="ParametrizeConstAccel")
    return instance.compute_trajectory(sd_start=v0, sd_end=0.0)


def spline_through(start: Pose2D, points: Sequence[tuple[float, float]]):
    """Dense samples of the cubic spline from the start position through `points`, leaving along
    the start heading: (arc length s, x, y, heading, arc length of each point); None if no point
    is farther than MIN_SEPARATION from the one before."""
    xy = [(start.x, start.y)]
    index = []                                   # per given point: its row in xy
    for p in points:
        if math.dist(p, xy[-1]) > MIN_SEPARATION:
            xy.append(tuple(p))
        index.append(len(xy) - 1)
    if len(xy) < 2:
        return None
    xy_arr = np.array(xy)
    u = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy_arr, axis=0), axis=1))])
    tangent = [math.cos(start.theta), math.sin(start.theta)]
    spline = CubicSpline(u, xy_arr, bc_type=((1, tangent), (2, [0.0, 0.0])), axis=0)
    uu = np.linspace(0.0, u[-1], int(min(20000, max(200, u[-1] / DENSE_STEP))))
    pos, d = spline(uu), spline(uu, 1)
    speed = np.linalg.norm(d, axis=1)
    s = np.concatenate([[0.0], np.cumsum((speed[1:] + speed[:-1]) / 2 * np.diff(uu))])
    heading = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    heading += start.theta - heading[0]          # the spline leaves along the heading exactly
    s_points = [float(np.interp(u[i], uu, s)) for i in index]
    return s, pos[:, 0], pos[:, 1], heading, s_points


def plan_curve(start: Pose2D, points: Sequence[tuple[float, float]],
               limits: tuple[float, float, float, float], v0: float = 0.0) -> CurvePlan | None:
    """The timed smooth path from `start` (moving forward at v0) through `points` to rest at the
    last; None when there is nothing to do or TOPP-RA finds no feasible timing."""
    geometry = spline_through(start, points)
    if geometry is None:
        return None
    s, x, y, heading, s_points = geometry
    trajectory = time_optimal(s, heading, limits, v0)
    if trajectory is None:
        return None
    duration = float(trajectory.duration)
    ts = np.append(np.arange(0.0, duration, SAMPLE_DT), duration)
    q, qd = trajectory(ts), trajectory(ts, 1)
    st = np.clip(q[:, 0], 0.0, s[-1])
    st = np.maximum.accumulate(st)               # never backwards along the path
    path = SampledPath(ts, np.interp(st, s, x), np.interp(st, s, y), q[:, 1],
                       np.maximum(qd[:, 0], 0.0), qd[:, 1])
    path.x[-1], path.y[-1], path.v[-1], path.w[-1] = x[-1], y[-1], 0.0, 0.0
    via = [float(np.interp(sp, st, ts)) for sp in s_points]
    return CurvePlan(path, via)


ALIGN_TOLERANCE = math.radians(1.0)   # from rest, turn toward the first point when off by more


class CruiseMotion(TrackedBaseMotion):
    """moveCruiseAbs: one smooth motion through the points given so far. A point added while it
    runs re-plans the rest of the path from the reference state then (speed continuous), so the
    base passes every point without stopping and stops only at the last."""

    def __init__(self, odometry: Odometry, start: Pose2D, point: tuple[float, float],
                 limits: tuple[float, float, float, float]) -> None:
        self.start, self.points, self.limits = start, [point], limits
        self.via_times: list[float] = []
        self.from_rest = True
        super().__init__(odometry, self._plan_from_rest(), "move_cruise_abs")

    def _plan_from_rest(self) -> Path:
        """Turn in place toward the first point if needed, then the curve through all of them."""
        start = self.start
        first = next((p for p in self.points if math.dist(p, (start.x, start.y)) > MIN_SEPARATION), None)
        if first is None:
            self.via_times = [0.0] * len(self.points)
            self.curve_from = 0.0
            return Chain([], start)
        off = wrap_angle(math.atan2(first[1] - start.y, first[0] - start.x) - start.theta)
        prefix: list[Path] = []
        if abs(off) > ALIGN_TOLERANCE:
            prefix.append(turn(start, off, self.limits))
            start = Pose2D(start.x, start.y, start.theta + off)
        plan = plan_curve(start, self.points, self.limits)
        if plan is None:
            raise ValueError("no feasible timing for the cruise path")
        self.curve_from = sum(p.duration for p in prefix)
        self.via_times = [self.curve_from + t for t in plan.via_times]
        return Chain(prefix + [plan.path], self.start)

    def add_point(self, point: tuple[float, float], t: float) -> bool:
        """Pass `point` after the others, re-planning from motion time t (the present, or 0 when
        still queued). False when the base is already stopping at its last point, or when no
        feasible path continues from its present speed (then the caller queues a new motion)."""
        if self.from_rest and t <= self.t0 + self.curve_from:   # not on the curve yet: plan again
            self.points.append(point)
            self.path = self._plan_from_rest()
            return True
        local = t - self.t0
        ahead = [p for p, tp in zip(self.points, self.via_times) if tp > local + SAMPLE_DT]
        v0, _ = self.reference_twist(t)
        if not ahead or v0 <= 1e-4:
            return False
        plan = plan_curve(self.at(t), ahead + [point], self.limits, v0)
        if plan is None:
            return False
        self.points = ahead + [point]
        self.splice(t, plan.path)
        self.from_rest, self.curve_from = False, 0.0
        self.via_times = plan.via_times
        return True


AHEAD = math.radians(60.0)            # a new goal within this bearing is reached on a curve


def transition_to(start: Pose2D, v0: float, w0: float, goal: Pose2D,
                  limits: tuple[float, float, float, float]) -> Path:
    """moveContinuousRel's path from the reference state (start, v0, w0) to `goal`, speed
    continuous: from rest the straight move; moving forward toward a goal ahead, a smooth curve
    onto it (TOPP-RA from v0) and a turn to its heading; otherwise brake, then the straight move."""
    if abs(v0) < 1e-3 and abs(w0) < 1e-3:
        return straight_to(start, goal, limits, False)
    bearing = wrap_angle(math.atan2(goal.y - start.y, goal.x - start.x) - start.theta)
    if v0 > 0.0 and abs(bearing) < AHEAD and abs(w0) < limits[1]:
        plan = plan_curve(start, [(goal.x, goal.y)], limits, v0)
        if plan is not None:
            end = plan.path.pose(plan.path.duration)
            final = turn(end, wrap_angle(goal.theta - end.theta), limits)
            return Chain([plan.path, final], start)
    brake = velocity_path(start, v0, w0, (0.0, 0.0), 0.0, (limits[2], limits[3]))
    rest = brake.pose(brake.duration)
    return Chain([brake, straight_to(rest, goal, limits, False)], start)
