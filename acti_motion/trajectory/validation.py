"""Whether a requested joint trajectory can be followed: joint_trajectory_controller's (ROS 2
Jazzy) acceptance rules, each refusal saying what was wrong, and the accepted request turned into
knots in the controller's joint order."""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

from acti_motion.trajectory.interpolation import Knot


@dataclass(frozen=True)
class RequestedPoint:
    """One trajectory_msgs/JointTrajectoryPoint, as given (one value per requested joint)."""
    time_from_start: float
    positions: Sequence[float]
    velocities: Sequence[float] = ()
    accelerations: Sequence[float] = ()
    effort: Sequence[float] = ()


@dataclass(frozen=True)
class RequestedTrajectory:
    """A trajectory_msgs/JointTrajectory: `start_time` is its header stamp (s on the
    controller's clock), 0 for "start now"."""
    joint_names: Sequence[str]
    points: Sequence[RequestedPoint]
    start_time: float = 0.0


class InvalidTrajectory(ValueError):
    """A trajectory the controller refuses; `code` is FollowJointTrajectory's error code
    (INVALID_GOAL -1, INVALID_JOINTS -2, OLD_HEADER_TIMESTAMP -3)."""

    def __init__(self, code: int, message: str) -> None:
        super().__init__(message)
        self.code = code


INVALID_GOAL, INVALID_JOINTS, OLD_HEADER_TIMESTAMP = -1, -2, -3


@dataclass(frozen=True)
class ValidTrajectory:
    """An accepted trajectory: knots in the controller's joint order (joints the request left
    out are None in `given`: they hold where they are), and when it starts."""
    knots: list[Knot]
    given: np.ndarray = field(repr=False)       # which controller joints the request names
    start_time: float = 0.0


def validate(request: RequestedTrajectory, joints: Sequence[str], now: float,
             allow_partial_joints_goal: bool = False) -> ValidTrajectory:
    """The request checked against the controller's `joints` at time `now`; InvalidTrajectory
    names the first rule it breaks."""
    names = list(request.joint_names)
    if not names:
        raise InvalidTrajectory(INVALID_JOINTS, "the trajectory names no joints")
    unknown = [n for n in names if n not in joints]
    if unknown:
        raise InvalidTrajectory(INVALID_JOINTS, f"unknown joint(s) {', '.join(unknown)}: this "
                                f"controller has {', '.join(joints)}")
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise InvalidTrajectory(INVALID_JOINTS, f"joint(s) named twice: {', '.join(twice)}")
    missing = [j for j in joints if j not in names]
    if missing and not allow_partial_joints_goal:
        raise InvalidTrajectory(INVALID_JOINTS, f"joint(s) missing: {', '.join(missing)} (every "
                                "joint of the controller is needed: allow_partial_joints_goal "
                                "is false)")
    points = list(request.points)
    if not points:
        raise InvalidTrajectory(INVALID_GOAL, "the trajectory has no points")
    end = request.start_time + points[-1].time_from_start
    if request.start_time > 0 and end < now:
        raise InvalidTrajectory(OLD_HEADER_TIMESTAMP,
                                f"the trajectory ends in the past: it starts at "
                                f"{request.start_time:.3f} s and ends at {end:.3f} s, now is "
                                f"{now:.3f} s")
    for i, p in enumerate(points):
        _check_point(i, p, len(names))
        if i and p.time_from_start <= points[i - 1].time_from_start:
            raise InvalidTrajectory(INVALID_GOAL, f"time_from_start is not strictly increasing: "
                                    f"point {i - 1} at {points[i - 1].time_from_start:g} s, point "
                                    f"{i} at {p.time_from_start:g} s")
    last = points[-1]
    moving = [(n, v) for n, v in zip(names, last.velocities) if v != 0.0]
    if moving:
        raise InvalidTrajectory(INVALID_GOAL, f"the last point's velocity is not zero: "
                                f"{moving[0][0]} at {moving[0][1]:g}")
    order = [names.index(j) if j in names else -1 for j in joints]
    given = np.array([k >= 0 for k in order])
    return ValidTrajectory([_knot(p, order) for p in points], given, request.start_time)


def _check_point(i: int, p: RequestedPoint, count: int) -> None:
    if p.time_from_start < 0 or not math.isfinite(p.time_from_start):
        raise InvalidTrajectory(INVALID_GOAL, f"point {i}: time_from_start {p.time_from_start:g}"
                                " s is negative or not finite")
    for what, values, needed in (("positions", p.positions, True),
                                 ("velocities", p.velocities, False),
                                 ("accelerations", p.accelerations, False)):
        if (needed or len(values)) and len(values) != count:
            raise InvalidTrajectory(INVALID_GOAL, f"point {i}: {len(values)} {what} for "
                                    f"{count} joint names")
        if not all(math.isfinite(x) for x in values):
            raise InvalidTrajectory(INVALID_GOAL, f"point {i}: {what} has a value that is not "
                                    "finite")
    if len(p.accelerations) and not len(p.velocities):
        raise InvalidTrajectory(INVALID_GOAL, f"point {i}: accelerations without velocities "
                                "(the interpolation needs velocities too)")
    if len(p.effort):
        raise InvalidTrajectory(INVALID_GOAL, f"point {i}: effort is given: trajectories with "
                                "effort are not supported (positions are followed)")


def _knot(p: RequestedPoint, order: list[int]) -> Knot:
    """The point in the controller's joint order; joints it leaves out are NaN (filled in by
    the caller with where they are) and move with zero velocity and acceleration."""
    def pick(values: Sequence[float], missing: float) -> np.ndarray | None:
        if not len(values):
            return None
        return np.array([values[k] if k >= 0 else missing for k in order], float)
    return Knot(p.time_from_start, pick(p.positions, math.nan), pick(p.velocities, 0.0),
                pick(p.accelerations, 0.0))
