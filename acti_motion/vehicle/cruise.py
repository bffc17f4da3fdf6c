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

from acti_motion.vehicle.paths import (Chain, CurvePath, Odometry, Path, Pose2D, SampledPath,
                              TrackedBaseMotion, straight_to, turn, velocity_path, wrap_angle)

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
    A start faster than v_max (the velocity setting was lowered) is let down at a_max.
    The trajectory (callable t → [s, theta], and its derivatives), or None when infeasible."""
    ta = _toppra()
    v_max, w_max, a_max, alpha_max = limits
    keep = np.unique(np.linspace(0, len(s) - 1, min(len(s), 2000)).astype(int))
    path = ta.SplineInterpolator(s[keep], np.column_stack([s[keep], heading[keep]]))
    n = int(min(grid_max, max(20, math.ceil(s[-1] / grid_step))))
    if v0 > v_max:
        def bounds(si: float) -> np.ndarray:
            v = max(v_max, math.sqrt(max(0.0, v0 * v0 - 2.0 * a_max * si))) * (1 + 1e-6)
            w = w_max * v / v_max
            return np.array([[-v, v], [-w, w]])
        velocity = ta.constraint.JointVelocityConstraintVarying(bounds)
    else:
        velocity = ta.constraint.JointVelocityConstraint(np.array([[-v_max, v_max], [-w_max, w_max]]))
    constraints = [velocity, ta.constraint.JointAccelerationConstraint(
        np.array([[-a_max, a_max], [-alpha_max, alpha_max]]))]
    instance = ta.algorithm.TOPPRA(constraints, path, gridpoints=np.linspace(0.0, s[-1], n + 1),
                                   parametrizer="ParametrizeConstAccel")
    return instance.compute_trajectory(sd_start=v0, sd_end=0.0)


def spline_through(start: Pose2D, points: Sequence[tuple[float, float]]):
    """Dense samples of the cubic spline from the start position through `points`, leaving along
    the start heading: (arc length s, x, y, heading, arc length of each point); None if no point
    is farther than MIN_SEPARATION from the one before."""
    from scipy.interpolate import CubicSpline  # noqa: PLC0415 - lazy, like toppra (0.3 s)
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
    base passes every point without stopping and stops only at the last. From rest it first
    turns toward the first point."""

    def __init__(self, odometry: Odometry, start: Pose2D, point: tuple[float, float],
                 limits: tuple[float, float, float, float]) -> None:
        super().__init__(odometry, Chain([], start), "move_cruise_abs")
        self.points: list[tuple[float, float]] = []
        self.via_times: list[float] = []            # motion time from t0 of passing each point
        self.from_rest, self.curve_from = True, 0.0
        self.limits = limits
        if not self._replan(0.0, [point]):
            raise ValueError("no feasible timing for the cruise path")

    def add_point(self, point: tuple[float, float], t: float) -> bool:
        """Pass `point` after the others, re-planning from motion time t (the present, or 0 when
        still queued). False when the base is already stopping at its last point, or when no
        feasible path continues from its present speed (then the caller queues a new motion)."""
        return self._replan(t, [point])

    def retime(self, t: float, limits: tuple[float, float, float, float]) -> None:
        """New velocity or acceleration settings: the rest of the path re-planned from t."""
        self.limits = limits
        self._replan(t, [])

    def move_frame(self, frame: Pose2D) -> None:
        super().move_frame(frame)
        self.points = [(q.x, q.y) for q in (frame.compose(Pose2D(x, y, 0.0)) for x, y in self.points)]

    def _replan(self, t: float, extra: list[tuple[float, float]]) -> bool:
        local, here = t - self.t0, self.at(t)
        v0, w0 = self.reference_twist(t)
        if self.from_rest and local <= self.curve_from:        # turning toward the first point
            points = self.points + extra
            first = next((p for p in points if math.dist(p, (here.x, here.y)) > MIN_SEPARATION), None)
            off = 0.0 if first is None else wrap_angle(
                math.atan2(first[1] - here.y, first[0] - here.x) - here.theta)
            prefix: list[Path] = []
            if abs(off) > ALIGN_TOLERANCE or abs(w0) > 0.0:
                prefix.append(CurvePath(here, (0.0, math.copysign(1.0, off)), abs(off),
                                        self.limits, abs(w0)))
            plan = plan_curve(Pose2D(here.x, here.y, here.theta + off), points, self.limits)
            if plan is None and first is not None:
                return False
            parts = prefix + ([plan.path] if plan is not None else [])
            self.curve_from = sum(p.duration for p in prefix)
            self.via_times = [self.curve_from + v for v in (plan.via_times if plan else [0.0] * len(points))]
        else:
            points = [p for p, tp in zip(self.points, self.via_times) if tp > local + SAMPLE_DT] + extra
            if not points or v0 <= 1e-4:
                return False
            plan = plan_curve(here, points, self.limits, v0)
            if plan is None:
                return False
            parts, self.from_rest, self.curve_from = [plan.path], False, 0.0
            self.via_times = plan.via_times
        self.points = points
        self.splice(max(t, self.t0), Chain(parts, here))
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
