"""Velocity jogs of the arm's joints (control_msgs/JointJog) as trajectories: accelerate to the
commanded velocities, hold them for the jog's time, decelerate to rest. Each new jog replaces the
running one from where it is, so a stream of jogs moves the arm smoothly, and when the stream
stops the arm comes to rest after the last jog's time (the deadman). Bounded by the limits: the
velocities by the max speeds, the accelerations by the acceleration limits (the ramps lengthen),
and the travel by the soft limits (the hold shortens; a joint too near its limit for that goes
slower, and one with no room left does not move)."""
from __future__ import annotations

import numpy as np

from acti_motion.trajectory.interpolation import Knot, State
from acti_motion.trajectory.limits import FollowPlan, JointLimits
from acti_motion.trajectory.follow import PlanOf

SOFT_LIMIT_MARGIN_RAD = 1e-3     # a jog comes to rest this far inside a soft limit
QUINTIC_PEAK = 1.875             # peak/mean acceleration of a quintic velocity change


def jog_plan(velocities: np.ndarray, hold: float, ramp: float, limits: JointLimits) -> PlanOf:
    """Knots that jog every joint at `velocities` (rad/s, the controller's order) for `hold`
    seconds after ramping up in at least `ramp` seconds."""
    def plan_of(start: State, now: float) -> FollowPlan:
        v = np.clip(velocities, -limits.velocity, limits.velocity)
        q0, v0 = start.positions, start.velocities
        for _ in range(2):       # joints near a limit slow down; then the ramp and hold fit
            t_ramp = max(ramp, float(np.max(QUINTIC_PEAK * np.maximum(np.abs(v - v0), np.abs(v))
                                            / limits.acceleration)))
            base = (v0 + v) / 2 * t_ramp + v * t_ramp / 2          # the travel without holding
            room = np.where(v > 0, limits.upper - SOFT_LIMIT_MARGIN_RAD - q0,
                            limits.lower + SOFT_LIMIT_MARGIN_RAD - q0)
            with np.errstate(divide="ignore", invalid="ignore"):
                fits = np.where(v != 0, (room - base) / v, np.inf)
            slower = (room - v0 * t_ramp / 2) / t_ramp       # comes to rest at the limit
            v = np.where(fits >= 0, v, np.where(slower * v > 0, slower, 0.0))
        t_hold = max(0.0, min(hold, float(np.min(np.where(v != 0, fits, np.inf)))))
        zero = np.zeros_like(q0)
        p1 = q0 + (v0 + v) / 2 * t_ramp
        p2 = p1 + v * t_hold
        knots = [Knot(0.0, q0, v0, start.accelerations), Knot(t_ramp, p1, v, zero)]
        if t_hold > 0:
            knots.append(Knot(t_ramp + t_hold, p2, v, zero))
        knots.append(Knot(knots[-1].time + t_ramp, p2 + v * t_ramp / 2, zero, zero))
        return FollowPlan(knots, [-1] + [0] * (len(knots) - 1))
    return plan_of
