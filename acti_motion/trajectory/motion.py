"""The arm motion that follows an interpolated trajectory: what the motion queue runs.

The executor scales its time for pause, resume and stop like any motion's, so the arm slows down
along the trajectory's own path. A trajectory that replaces a running one (preemption, the
streaming topics) takes over at a splice time a little ahead of the arm: before it the motion is
the old one, after it the new one, so the set-point stays continuous."""
from __future__ import annotations

import numpy as np

from acti_motion.arm.trajectories import ArmSetpoint
from acti_motion.trajectory.interpolation import PiecewisePolynomial, State
from acti_sim.world import World


class TrajectoryMotion:
    """Follows `poly` from motion time `t0` on (before it, `before`); the finger stays put.
    `ramp` is the accel time pause and stop use for it."""
    kind = "trajectory"

    def __init__(self, poly: PiecewisePolynomial, finger: float, ramp: float,
                 before: "TrajectoryMotion | None" = None, t0: float = 0.0) -> None:
        self.poly, self.finger, self.ramp = poly, finger, ramp
        self.before, self.t0 = before, t0
        self.duration = t0 + poly.duration
        self.limits_checked: np.ndarray | None = None   # the soft limits its plan was checked with
        self._state: tuple[float, State] | None = None

    @property
    def end(self) -> np.ndarray:
        """Where it ends (the joints, rad)."""
        return self.poly.knots[-1].positions

    def state(self, t: float) -> State:
        """The reference at motion time t: positions, velocities, accelerations."""
        cached = self._state
        if cached is not None and cached[0] == t:
            return cached[1]
        s = self.before.state(t) if self.before is not None and t < self.t0 \
            else self.poly.state(t - self.t0)
        self._state = (t, s)
        return s

    def at(self, t: float) -> ArmSetpoint:
        return ArmSetpoint(self.state(t).positions, self.finger)

    def apply(self, world: World, t: float, rate: float) -> None:
        s = self.state(t)
        world.set_arm_targets(s.positions, rate * s.velocities)

    def handover(self, t: float, poly: PiecewisePolynomial, now: float) -> "TrajectoryMotion":
        """This motion until motion time t, then `poly` (which starts where this one is at t).
        What lies before `now` (the device's time) is no longer needed and is dropped, so that
        a stream of replacements does not pile up."""
        return TrajectoryMotion(poly, self.finger, self.ramp, self._trimmed(now), t)

    def _trimmed(self, now: float) -> "TrajectoryMotion":
        """This motion without the parts before `now`."""
        if self.before is None:
            return self
        before = self.before._trimmed(now) if now < self.t0 else None
        trimmed = TrajectoryMotion(self.poly, self.finger, self.ramp, before, self.t0)
        trimmed.limits_checked = self.limits_checked
        return trimmed
