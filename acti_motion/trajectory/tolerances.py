"""Path and goal tolerances of a FollowJointTrajectory goal, as joint_trajectory_controller reads
them: per joint, a value > 0 is the tolerance, 0 takes the controller's default, < 0 none."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np

from acti_motion.trajectory.validation import INVALID_GOAL, InvalidTrajectory


@dataclass(frozen=True)
class RequestedTolerance:
    """One control_msgs/JointTolerance."""
    name: str
    position: float = 0.0
    velocity: float = 0.0
    acceleration: float = 0.0


@dataclass(frozen=True)
class Tolerances:
    """Per joint of the controller (its order): position (rad) and velocity (rad/s) bounds on
    the error; inf where there is none. Accelerations are not measured, so not checked."""
    position: np.ndarray
    velocity: np.ndarray

    @classmethod
    def uniform(cls, count: int, position: float, velocity: float) -> "Tolerances":
        """The same bounds for every joint; 0 (as in the controller's parameters): none."""
        def bound(x: float) -> float:
            return x if x > 0 else np.inf
        return cls(np.full(count, bound(position)), np.full(count, bound(velocity)))

    def with_requested(self, requested: Sequence[RequestedTolerance], joints: Sequence[str],
                       what: str) -> "Tolerances":
        """These defaults, overridden by a goal's `what` (path_tolerance, goal_tolerance)."""
        position, velocity = self.position.copy(), self.velocity.copy()
        for r in requested:
            if r.name not in joints:
                raise InvalidTrajectory(INVALID_GOAL, f"{what} names {r.name!r}, not a joint of "
                                        f"this controller ({', '.join(joints)})")
            j = list(joints).index(r.name)
            for bounds, value in ((position, r.position), (velocity, r.velocity)):
                if value > 0:
                    bounds[j] = value
                elif value < 0:
                    bounds[j] = np.inf
        return Tolerances(position, velocity)

    def violation(self, names: Sequence[str], reference: np.ndarray, actual: np.ndarray,
                  reference_velocity: np.ndarray, actual_velocity: np.ndarray) -> str | None:
        """What breaks these tolerances first, said; None when nothing does."""
        for what, unit, error, bound in (
                ("position", "rad", actual - reference, self.position),
                ("velocity", "rad/s", actual_velocity - reference_velocity, self.velocity)):
            over = np.flatnonzero(np.abs(error) > bound)
            if len(over):
                j = int(over[0])
                return (f"{names[j]} {what} error {error[j]:+.4f} {unit} exceeds the tolerance "
                        f"{bound[j]:g} {unit}")
        return None
