"""Smooth paths through points for a differential drive, timed by TOPP-RA (SI units).

The geometric path is a cubic spline through the points that leaves along the base's heading;
the base follows its tangent, so the path in TOPP-RA's terms has two coordinates, the arc length
s and the heading theta(s). Their bounds are exactly the drive's: |ds/dt| = forward speed,
|dtheta/dt| = yaw rate, and their second derivatives the accelerations. ParametrizeConstAccel
turns the time-optimal velocity profile into a trajectory, sampled for tracking.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass, replace
from typing import Callable, Sequence

import numpy as np
import toppra
import toppra.algorithm
import toppra.constraint
from scipy.interpolate import make_interp_spline

from acti_motion.vehicle.paths import (Chain, CurvePath, Odometry, Path, Pose2D, SampledPath,
                                       TrackedBaseMotion, straight_to, turn, velocity_path,
                                       wrap_angle)
from acti_motion.vehicle.planner import planned

# Every plan's cost is bounded by these caps, whatever the path's length or the speed settings.
SAMPLE_DT = 0.005            # s between samples of the timed path …
SAMPLES_MAX = 8000           # … at most this many (a slower path is sampled coarser)
DENSE_STEP = 0.002           # m between samples of the geometric path …
DENSE_MAX = 10000            # … at most this many
SPLINE_KEEP = 2000           # samples of it handed to TOPP-RA's interpolator
GRID_STEP = 0.01             # m between TOPP-RA grid points …
GRID_MAX = 600               # … at most this many
MIN_SEPARATION = 1e-3        # m: closer points are one point
CUSP_TURN = math.radians(30.0)   # heading change between two dense samples: the path doubles back
WINDOW = 2                   # points before a new cruise point that are planned again with it
LET_DOWN = 0.8               # a start above v_max is let down at this share of a_max (slack for TOPP-RA)
RETIME_SAMPLES = 400         # samples of the rest of a cruise path timed again (more: a noisier heading)

logging.getLogger("toppra").setLevel(logging.ERROR)   # an infeasible start is handled here


@dataclass
class CurvePlan:
    """A timed path and the times (s from its start) at which it passes each point."""
    path: SampledPath
    via_times: list[float]


# a geometric path's dense samples (arc length s, x, y, heading) and the arc length of each point
CurveGeometry = tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, list[float]]


def time_optimal(s: np.ndarray, heading: np.ndarray, limits: tuple[float, float, float, float],
                 v0: float = 0.0, grid_step: float = GRID_STEP,
                 grid_max: int = GRID_MAX) -> toppra.interpolator.AbstractGeometricPath | None:
    """TOPP-RA over the path (s, theta(s)) with the drive's bounds, from speed v0 to rest.
    A start faster than v_max (the velocity setting was lowered) is let down at LET_DOWN · a_max.
    The trajectory (callable t → [s, theta], and its derivatives), or None when infeasible."""
    ta = toppra
    v_max, w_max, a_max, alpha_max = limits
    keep = np.unique(np.linspace(0, len(s) - 1, min(len(s), SPLINE_KEEP)).astype(int))
    path = ta.SplineInterpolator(s[keep], np.column_stack([s[keep], heading[keep]]))
    n = int(min(grid_max, max(20, math.ceil(s[-1] / grid_step))))
    if v0 > v_max:
        def bounds(si: float) -> np.ndarray:
            v = max(v_max, math.sqrt(max(0.0, v0 * v0 - 2.0 * LET_DOWN * a_max * si))) * (1 + 1e-6)
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


def spline_through(start: Pose2D, points: Sequence[tuple[float, float]],
                   curvature: float = 0.0) -> CurveGeometry | None:
    """Dense samples of the quintic spline from the start position through `points`, leaving
    along the start heading with the given curvature (1/m; so the yaw rate goes on without a
    jump where it takes over from a running path) and ending straight: (arc length s, x, y,
    heading, arc length of each point); None if no point is farther than MIN_SEPARATION from
    the one before, or where the path doubles back on itself (a point that reverses the
    direction: a cusp no differential drive passes without stopping; the caller then stops
    there and starts a new path)."""
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
    bend = [-curvature * math.sin(start.theta), curvature * math.cos(start.theta)]
    spline = make_interp_spline(u, xy_arr, k=5, axis=0, bc_type=(
        [(1, tangent), (2, bend)], [(2, [0.0, 0.0]), (3, [0.0, 0.0])]))
    uu = np.linspace(0.0, u[-1], int(min(DENSE_MAX, max(200, u[-1] / DENSE_STEP))))
    pos, d = spline(uu), spline(uu, 1)
    speed = np.linalg.norm(d, axis=1)
    s = np.concatenate([[0.0], np.cumsum((speed[1:] + speed[:-1]) / 2 * np.diff(uu))])
    heading = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    if len(heading) > 1 and np.max(np.abs(np.diff(heading))) > CUSP_TURN:
        return None
    heading += start.theta - heading[0]          # the spline leaves along the heading exactly
    s_points = [float(np.interp(u[i], uu, s)) for i in index]
    return s, pos[:, 0], pos[:, 1], heading, s_points


def plan_curve(start: Pose2D, points: Sequence[tuple[float, float]],
               limits: tuple[float, float, float, float], v0: float = 0.0,
               w0: float = 0.0) -> CurvePlan | None:
    """The timed smooth path from `start` (moving forward at v0, turning at w0) through
    `points` to rest at the last; None when there is nothing to do or TOPP-RA finds no
    feasible timing. The path starts with the curvature of (v0, w0) where a timing exists,
    else straight (the yaw rate then changes at once, as little as the geometry allows)."""
    w0 = min(max(w0, -0.999 * limits[1]), 0.999 * limits[1])
    plan = _plan_curve(start, points, limits, v0, w0 / v0 if v0 > 1e-6 else 0.0)
    if plan is None and w0 != 0.0 and v0 > 1e-6:
        plan = _plan_curve(start, points, limits, v0, 0.0)
    return plan


def warm_up(limits: tuple[float, float, float, float] = (0.3, 0.8, 0.5, 1.6)) -> None:
    """Plan one short cruise, so that the first request does not pay for first-use costs."""
    plan_curve(Pose2D(0.0, 0.0, 0.0), [(0.5, 0.2), (1.0, 0.0)], limits)


@planned
def _plan_curve(start: Pose2D, points: Sequence[tuple[float, float]],
                limits: tuple[float, float, float, float], v0: float,
                curvature: float) -> CurvePlan | None:
    geometry = spline_through(start, points, curvature)
    return None if geometry is None else timed_path(*geometry, limits, v0)


@planned
def timed_path(s: np.ndarray, x: np.ndarray, y: np.ndarray, heading: np.ndarray,
               s_points: Sequence[float], limits: tuple[float, float, float, float],
               v0: float) -> CurvePlan | None:
    """The geometric path (arc length s, x, y, heading) timed by TOPP-RA from speed v0 to rest,
    with the times at which it passes the arc lengths `s_points`."""
    trajectory = time_optimal(s, heading, limits, v0)
    if trajectory is None:
        return None
    duration = float(trajectory.duration)
    ts = np.append(np.arange(0.0, duration, max(SAMPLE_DT, duration / SAMPLES_MAX)), duration)
    q, qd = trajectory(ts), trajectory(ts, 1)
    st = np.clip(q[:, 0], 0.0, s[-1])
    st = np.maximum.accumulate(st)               # never backwards along the path
    path = SampledPath(ts, np.interp(st, s, x), np.interp(st, s, y), q[:, 1],
                       np.maximum(qd[:, 0], 0.0), qd[:, 1])
    path.x[-1], path.y[-1], path.v[-1], path.w[-1] = x[-1], y[-1], 0.0, 0.0
    via = [float(np.interp(sp, st, ts)) for sp in s_points]
    return CurvePlan(path, via)


@planned
def retimed_rest(path: Path, local: float, via: Sequence[float],
                 limits: tuple[float, float, float, float], v0: float) -> CurvePlan | None:
    """The rest of `path` from its time `local` on (its geometry, sampled), timed by TOPP-RA
    for `limits` from speed v0 to rest, with the times at which it passes the path times `via`."""
    times = np.linspace(local, path.duration, RETIME_SAMPLES)
    poses = [path.pose(float(tau)) for tau in times]
    xy = np.array([(p.x, p.y) for p in poses])
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(xy, axis=0), axis=1))])
    keep = np.concatenate([[True], np.diff(s) > 1e-7])
    heading = np.array([p.theta for p in poses])
    s_points = [float(np.interp(tp, times, s)) for tp in via]
    return timed_path(s[keep], xy[keep, 0], xy[keep, 1], heading[keep], s_points, limits, v0)


ALIGN_TOLERANCE = math.radians(1.0)   # from rest, turn toward the first point when off by more


@dataclass(frozen=True)
class CruiseState:
    """What a cruise re-plan changes: its points still ahead, when it passes them (path time),
    whether it started from rest and when its curve begins (after the turn toward the first
    point), its limits, and the new reference (`path` from motion time `at`)."""
    points: tuple[tuple[float, float], ...]
    via_times: tuple[float, ...]
    from_rest: bool
    curve_from: float
    limits: tuple[float, float, float, float]
    at: float = 0.0
    path: Path | None = None


class CruiseMotion(TrackedBaseMotion):
    """moveCruiseAbs: one smooth motion through the points given so far. A point added while it
    runs re-plans the rest of the path (speed continuous), so the base passes every point
    without stopping and stops only at the last. From rest it first turns toward the first
    point. Planning (`plan`) only reads the motion; `commit` installs a plan under the device's
    lock. A point is added in constant time: only the path after the point WINDOW before the
    last is planned again."""

    def __init__(self, odometry: Odometry, start: Pose2D, point: tuple[float, float],
                 limits: tuple[float, float, float, float]) -> None:
        super().__init__(odometry, Chain([], start), "move_cruise_abs")
        self.state = CruiseState((), (), True, 0.0, limits)
        plan = self.plan(0.0, [point], limits)
        if plan is None:
            raise ValueError("no feasible timing for the cruise path")
        self.commit(plan)

    @property
    def limits(self) -> tuple[float, float, float, float]:
        return self.state.limits

    def plan(self, t: float, extra: list[tuple[float, float]],
             limits: tuple[float, float, float, float]) -> CruiseState | None:
        """The motion with `extra` points after the others and `limits`, re-planned from motion
        time t (ahead of the device, or 0 when still queued); None when no feasible path
        continues from the speed there (then the caller queues a new motion)."""
        return self._plan_window(t, extra, limits) or self._plan_from(t, extra, limits)

    def commit(self, plan: CruiseState) -> None:
        self.state = replace(plan, path=None)
        self.splice(plan.at, plan.path)

    def replan(self, t: float, limits: tuple[float, float, float, float]) -> Callable[[], None] | None:
        """New velocity or acceleration settings: the rest of the path timed again from t (its
        geometry kept), or planned again while the base still turns toward the first point."""
        plan = self._retimed(t, limits) or self.plan(t, [], limits)
        return None if plan is None else (lambda: self.commit(plan))

    def _retimed(self, t: float, limits: tuple[float, float, float, float]) -> CruiseState | None:
        st, path = self.state, self.path
        t = max(t, self.t0)
        local = t - self.t0
        ahead = self._ahead(local)
        v0 = self.reference_twist(t)[0]
        if (st.from_rest and local <= st.curve_from) or not ahead or v0 <= 1e-4:
            return None
        plan = retimed_rest(path, local, [tp for _, tp in ahead], limits, v0)
        if plan is None:
            return None
        return CruiseState(tuple(p for p, _ in ahead), tuple(plan.via_times), False, 0.0, limits, t,
                           Chain([plan.path], path.pose(local)))

    def move_frame(self, frame: Pose2D) -> None:
        super().move_frame(frame)
        moved = tuple((q.x, q.y) for q in (frame.compose(Pose2D(x, y, 0.0)) for x, y in self.state.points))
        self.state = replace(self.state, points=moved)

    def _ahead(self, local: float) -> list[tuple[tuple[float, float], float]]:
        st = self.state
        return [(p, tp) for p, tp in zip(st.points, st.via_times) if tp > local + SAMPLE_DT]

    def _plan_window(self, t: float, extra: list[tuple[float, float]],
                     limits: tuple[float, float, float, float]) -> CruiseState | None:
        """Points added with unchanged limits: keep the path up to the point WINDOW before the
        last and plan only from there (through the last WINDOW points and the new ones): far
        enough back that the old stop at the last point barely slows the base there."""
        st, t0, path = self.state, self.t0, self.path
        ahead = self._ahead(t - t0)
        if not extra or limits != st.limits or len(ahead) <= WINDOW or not isinstance(path, Chain):
            return None
        cut = ahead[-WINDOW - 1][1]
        head = path.head(cut)
        v0, w0 = path.twist(cut)
        if head is None or v0 <= 1e-4:
            return None
        again = [p for p, _ in ahead[-WINDOW:]]
        plan = plan_curve(path.pose(cut), again + list(extra), limits, v0, w0)
        if plan is None:
            return None
        return CruiseState(tuple(p for p, _ in ahead) + tuple(extra),
                           tuple(tp for _, tp in ahead[:-WINDOW]) + tuple(cut + v for v in plan.via_times),
                           st.from_rest, st.curve_from, limits, t0, Chain(head + [plan.path], path.start))

    def _plan_from(self, t: float, extra: list[tuple[float, float]],
                   limits: tuple[float, float, float, float]) -> CruiseState | None:
        """The whole rest of the path planned again from motion time t."""
        st = self.state
        t = max(t, self.t0)
        local, here = t - self.t0, self.at(t)
        v0, w0 = self.reference_twist(t)
        if st.from_rest and local <= st.curve_from:        # turning toward the first point
            points = list(st.points) + list(extra)
            first = next((p for p in points if math.dist(p, (here.x, here.y)) > MIN_SEPARATION), None)
            off = 0.0 if first is None else wrap_angle(
                math.atan2(first[1] - here.y, first[0] - here.x) - here.theta)
            prefix: list[Path] = []
            if abs(off) > ALIGN_TOLERANCE or abs(w0) > 0.0:
                prefix.append(CurvePath(here, (0.0, math.copysign(1.0, off)), abs(off), limits, abs(w0)))
            plan = plan_curve(Pose2D(here.x, here.y, here.theta + off), points, limits)
            if plan is None and first is not None:
                return None
            curve_from = sum(p.duration for p in prefix)
            parts = prefix + ([plan.path] if plan is not None else [])
            via = [curve_from + v for v in (plan.via_times if plan else [0.0] * len(points))]
            return CruiseState(tuple(points), tuple(via), True, curve_from, limits, t, Chain(parts, here))
        points = [p for p, _ in self._ahead(local)] + list(extra)
        if not points or v0 <= 1e-4:
            return None
        plan = plan_curve(here, points, limits, v0, w0)
        if plan is None:
            return None
        return CruiseState(tuple(points), tuple(plan.via_times), False, 0.0, limits, t,
                           Chain([plan.path], here))


AHEAD = math.radians(60.0)            # a new goal within this bearing is reached on a curve


def transition_to(start: Pose2D, v0: float, w0: float, goal: Pose2D,
                  limits: tuple[float, float, float, float]) -> Path:
    """moveContinuousRel's path from the reference state (start, v0, w0) to `goal`, speed
    continuous: from rest the straight move; moving forward toward a goal ahead, a smooth curve
    onto it (TOPP-RA from v0) and a turn to its heading; otherwise brake, then the straight move.
    Every way the heading change is the one given (goal.theta is unwrapped, as the curve's
    heading is): a 270° target turns 270°, as from rest, not 90° the other way."""
    if abs(v0) < 1e-3 and abs(w0) < 1e-3:
        return straight_to(start, goal, limits, False)
    bearing = wrap_angle(math.atan2(goal.y - start.y, goal.x - start.x) - start.theta)
    if v0 > 0.0 and abs(bearing) < AHEAD and abs(w0) < limits[1]:
        plan = plan_curve(start, [(goal.x, goal.y)], limits, v0, w0)
        if plan is not None:
            end = plan.path.pose(plan.path.duration)
            final = turn(end, goal.theta - end.theta, limits)
            return Chain([plan.path, final], start)
    brake = velocity_path(start, v0, w0, (0.0, 0.0), 0.0, (limits[2], limits[3]))
    rest = brake.pose(brake.duration)
    return Chain([brake, straight_to(rest, goal, limits, False)], start)
