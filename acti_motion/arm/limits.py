"""The arm's soft limits as one snapshot, made when a limit is set, in every form they are read in.

A PTP accept checks its step and its target against them, a CP plan its joint spline, the watch
every moving step's set-point, each in another form (floats, bounds with a tolerance, arrays).
Made once per setting, each is one attribute read where it is used (a getter per form cost a
Python call, ~0.5 µs on the cold core of an accept), and all are one moment's limits together.
"""
from __future__ import annotations

import operator

import numpy as np

from acti_motion.replies import value_error

JOINT_TOLERANCE_DEG = 1e-9        # a joint target or step this far outside a limit is within
CARTESIAN_WATCH_TOLERANCE_MM = 0.1
JOINT_WATCH_TOLERANCE_DEG = 1e-6
NEAR_LIMIT_DEG = 0.01    # a CP path's joint spline this close to a joint soft limit: checked finer
_NEAR_JOINT_LIMIT = np.array([NEAR_LIMIT_DEG, -NEAR_LIMIT_DEG])


def _read_only(rows: np.ndarray) -> np.ndarray:
    rows.flags.writeable = False
    return rows


class SoftLimits:
    """The joint soft limits `joint` (degree) and the Cartesian ones `cartesian` (mm), rows
    (lower, upper), given the joints' hardware range `hard` (degree, rows); never changed once
    made (a setter makes a new one)."""

    __slots__ = ("joint", "cartesian", "hard", "hard_floats", "rows", "joint_floats",
                 "cartesian_floats", "target_lower", "target_upper", "step_lower", "step_upper",
                 "box_lower", "box_upper", "clear", "watch_bounds")

    def __init__(self, joint: np.ndarray, cartesian: np.ndarray, hard: np.ndarray) -> None:
        self.joint, self.cartesian, self.hard = joint, cartesian, hard
        self.hard_floats = hard.tolist()
        # J1 … J7 (degree), then x, y, z (mm): what the watch compares a set-point with, and
        # what a motion keeps as the limits its plan was checked with
        self.rows = _read_only(np.concatenate([joint, cartesian]))
        self.joint_floats, self.cartesian_floats = joint.tolist(), cartesian.tolist()
        lower, upper = zip(*self.joint_floats)
        hard_lower, hard_upper = zip(*self.hard_floats)
        tol = JOINT_TOLERANCE_DEG
        # a target within [lower − tol, upper + tol]; a step that takes some start within the
        # hardware range into the limits, within [lower − hard upper − tol, upper − hard lower
        # + tol] (the sums in this order: the floats the checks computed call by call)
        self.target_lower = [a - tol for a in lower]
        self.target_upper = [b + tol for b in upper]
        self.step_lower = [a - hb - tol for a, hb in zip(lower, hard_upper)]
        self.step_upper = [b - ha + tol for b, ha in zip(upper, hard_lower)]
        self.box_lower, self.box_upper = map(list, zip(*self.cartesian_floats))
        # (lower, upper) (rad) of the joints NEAR_LIMIT_DEG inside: what a CP spline keeps clear of
        clear = np.radians(joint + _NEAR_JOINT_LIMIT)
        self.clear = (clear[:, 0], clear[:, 1])
        # the limits widened by the watch's tolerances, as `rows` (lower, upper)
        self.watch_bounds = (np.concatenate([joint[:, 0] - JOINT_WATCH_TOLERANCE_DEG,
                                             cartesian[:, 0] - CARTESIAN_WATCH_TOLERANCE_MM]),
                             np.concatenate([joint[:, 1] + JOINT_WATCH_TOLERANCE_DEG,
                                             cartesian[:, 1] + CARTESIAN_WATCH_TOLERANCE_MM]))

    def with_joint(self, joint: np.ndarray) -> "SoftLimits":
        return SoftLimits(joint, self.cartesian, self.hard)

    def with_cartesian(self, cartesian: np.ndarray) -> "SoftLimits":
        return SoftLimits(self.joint, cartesian, self.hard)

    def check_target(self, goal_deg: list[float], name: str) -> None:
        """Every joint of a target (degree) within its soft limit, else VALUE_ERR (the first
        joint outside)."""
        if (all(map(operator.le, self.target_lower, goal_deg))
                and all(map(operator.le, goal_deg, self.target_upper))):
            return
        for i, (q, a, b, (lo, hi)) in enumerate(zip(goal_deg, self.target_lower,
                                                    self.target_upper, self.joint_floats)):
            if not a <= q <= b:
                raise value_error(f"{name}: J{i + 1} = {q:.10g}° is outside the soft limit "
                                  f"[{lo:g}, {hi:g}]°")

    def check_step(self, step_deg: list[float], name: str) -> None:
        """A relative step (degree) that takes no start within the hardware range into the soft
        limits is VALUE_ERR (the first joint so): the arm may rest outside soft limits set
        since, and a step back in is a move."""
        if (all(map(operator.le, self.step_lower, step_deg))
                and all(map(operator.le, step_deg, self.step_upper))):
            return
        for i, (d, a, b, (slo, shi), (hlo, hhi)) in enumerate(zip(
                step_deg, self.step_lower, self.step_upper, self.joint_floats, self.hard_floats)):
            if not a <= d <= b:
                raise value_error(f"{name}: J{i + 1} by {d:g}° leaves the soft limit "
                                  f"[{slo:g}, {shi:g}]° from any start within its "
                                  f"range [{hlo:g}, {hhi:g}]°")
