"""The knots an accepted trajectory is followed through (from where the arm is), and the check of
its interpolation against the joint limits, naming the joint, the point and the limit broken."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Sequence

import numpy as np

from acti_motion.trajectory.interpolation import Knot, PiecewisePolynomial, State
from acti_motion.trajectory.validation import INVALID_GOAL, InvalidTrajectory, ValidTrajectory

# A first point at time 0 must be where the arm is (MoveIt's first point is the start state)
START_TOLERANCE_RAD = 0.01
CHECK_STEP_S = 0.002            # the interpolation is checked at least this densely
VELOCITY_SLACK = 1e-6           # relative: rounding of a trajectory timed exactly at a limit
ACCELERATION_SLACK = 1e-3


@dataclass(frozen=True)
class JointLimits:
    """Per joint (the controller's order): names, position range (rad), speed (rad/s) and
    acceleration (rad/s²) limits."""
    names: Sequence[str]
    lower: np.ndarray
    upper: np.ndarray
    velocity: np.ndarray
    acceleration: np.ndarray


@dataclass(frozen=True)
class FollowPlan:
    """The knots to follow from the arm's state at the trajectory's time 0, and which requested
    point each knot is (-1: where the arm was)."""
    knots: list[Knot]
    points: list[int]

    def polynomial(self) -> PiecewisePolynomial:
        return PiecewisePolynomial(self.knots)


def follow_plan(valid: ValidTrajectory, start: State, now: float,
                names: Sequence[str]) -> FollowPlan:
    """Knots from `start` (the arm's set-point when the trajectory begins, at `now`) through
    the requested points: a trajectory stamped in the future holds the start until then; one
    stamped in the past joins its remaining points from where the arm is, as the controller
    does. Joints the request left out hold their start position."""
    elapsed = now - valid.start_time if valid.start_time > 0 else 0.0
    delay = max(-elapsed, 0.0)
    knots, points = [Knot(0.0, start.positions, start.velocities, start.accelerations)], [-1]
    if delay > 0:
        rest = np.zeros_like(start.positions)
        knots.append(Knot(delay, start.positions, rest, rest))
        points.append(-1)
    for i, k in enumerate(valid.knots):
        t = k.time - elapsed
        if t <= 0 and elapsed > 0:
            continue
        q = np.where(np.isnan(k.positions), start.positions, k.positions)
        if t == knots[-1].time:         # a point where the trajectory begins: the arm must be there
            _check_start(q, start.positions, i, names)
            continue
        knots.append(Knot(t, q, k.velocities, k.accelerations))
        points.append(i)
    if len(knots) == 1:
        if elapsed > 0:
            raise InvalidTrajectory(INVALID_GOAL, "the trajectory ends now: nothing is left to "
                                    "follow")
        rest = np.zeros_like(start.positions)   # a single point where the arm is: hold it
        knots.append(Knot(CHECK_STEP_S, start.positions, rest, rest))
        points.append(0)
    return FollowPlan(knots, points)


def _check_start(q: np.ndarray, at: np.ndarray, point: int, names: Sequence[str]) -> None:
    off = np.abs(q - at)
    j = int(np.argmax(off))
    if off[j] > START_TOLERANCE_RAD:
        raise InvalidTrajectory(
            INVALID_GOAL, f"point {point} is where the trajectory begins, but {names[j]} is "
            f"{off[j]:.4f} rad from where the arm is ({at[j]:.4f} rad; at most "
            f"{START_TOLERANCE_RAD:g} rad): start the trajectory from the current state")


def check_limits(plan: FollowPlan, limits: JointLimits) -> PiecewisePolynomial:
    """The plan's interpolation, if it keeps every limit; else InvalidTrajectory naming the
    first joint to break one, the points it breaks it between, and the limit."""
    poly = plan.polynomial()
    steps = max(2, math.ceil(poly.duration / CHECK_STEP_S) + 1)
    ts = np.union1d(np.linspace(0.0, poly.duration, steps), poly.times)
    q, qd, qdd = poly.sample_many(ts)
    slack_v, slack_a = 1 + VELOCITY_SLACK, 1 + ACCELERATION_SLACK
    checks = (
        ("position", q, limits.lower, limits.upper, "its soft limit",
         lambda j: f"[{limits.lower[j]:.4f}, {limits.upper[j]:.4f}] rad"),
        ("velocity", qd, -limits.velocity * slack_v, limits.velocity * slack_v, "its max speed",
         lambda j: f"±{limits.velocity[j]:.4f} rad/s"),
        ("acceleration", qdd, -limits.acceleration * slack_a, limits.acceleration * slack_a,
         "its acceleration limit", lambda j: f"±{limits.acceleration[j]:.4f} rad/s²"))
    for what, values, lo, hi, limit, bound in checks:
        bad = (values < lo - 1e-12) | (values > hi + 1e-12)
        if not bad.any():
            continue
        k, j = (int(x) for x in np.argwhere(bad)[0])
        seg = min(int(np.searchsorted(poly.times, ts[k], side="left")), len(plan.points) - 1)
        where = (f"at {_name(plan.points[seg])}" if ts[k] == poly.times[seg] else
                 f"between {_name(plan.points[seg - 1])} and {_name(plan.points[seg])}")
        raise InvalidTrajectory(
            INVALID_GOAL, f"{limits.names[j]} breaks {limit} {where} (t = {ts[k]:.3f} s): "
            f"{what} {values[k, j]:.4f}, limit {bound(j)}")
    return poly


def _name(point: int) -> str:
    return "where the arm is" if point < 0 else f"point {point}"
