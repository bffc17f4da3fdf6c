"""Blending of consecutive arm moves (STROLIC SACC): the next move starts before the previous one
has stopped, so a via point is passed without stopping.

The previous move A is cut at T_A − τ (`Truncated`) and the next move B becomes `Blend`: for its
first τ seconds it adds A's tail, relative to A's end (which is B's start), to its own joint
set-points and velocities. Position and velocity are continuous at both seams; while the two
overlap, the path leaves the corner by no more than A's remaining and B's covered distance.

τ is the longest overlap that keeps the control point within the approach radius of the via
point at both seams (A still has at most `radius` to go, B has covered at most `radius`) and fits
in A's decelerating and B's accelerating ramp, so every joint's speed stays below the larger of
the two moves' speeds (in the overlap each joint's speed is between A's and B's there).

The device's queue does the rest: A retires at the seam (a `$WAIT` on it returns there) and B
starts at the next control cycle. A stop while A's cut tail is running decelerates along A's
whole path (`unblended`), never at the seam.
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Callable, Protocol

import numpy as np

from acti_motion.executor import Device
from acti_motion.arm.trajectories import ArmSetpoint

if TYPE_CHECKING:
    from acti_sim.world import World

ARM_MOVES = ("joint", "cartesian")
SEAM_MARGIN = 0.02         # s: a running move is not cut closer than this to where it is now
OVERLAP_STEPS = 24         # candidate overlaps tried, longest first


class ArmMove(Protocol):
    """An arm move the device runs: an `ArmMotion` as planned, or one cut (`Truncated`) or
    blended (`Blend`) here."""
    duration: float
    ramp: float
    kind: str
    limits_checked: np.ndarray | None

    def at(self, t: float) -> ArmSetpoint: ...

    def apply(self, world: World, t: float, rate: float) -> None: ...


def joint_velocity(motion: ArmMove, t: float) -> np.ndarray:
    """dq/dt (rad/s) of a motion at time t."""
    velocity = getattr(motion, "velocity", None)
    if velocity is not None:
        return velocity(t)
    s, ds = motion.timing.sample(t)
    return ds * motion.path.dq(s)


class Truncated:
    """A move cut short at `duration` (it hands over to the next one there)."""

    def __init__(self, whole: ArmMove, duration: float) -> None:
        self.unblended = whole
        self.duration = duration
        self.ramp, self.kind = whole.ramp, whole.kind
        self.limits_checked = whole.limits_checked

    def at(self, t: float) -> ArmSetpoint:
        return self.unblended.at(min(t, self.duration))

    def velocity(self, t: float) -> np.ndarray:
        return joint_velocity(self.unblended, min(t, self.duration))

    def apply(self, world: World, t: float, rate: float) -> None:
        self.unblended.apply(world, min(t, self.duration), rate)


class Blend:
    """Move `nxt` started `head` seconds before the end of `prev`: for t < head the set-point is
    nxt(t) + prev(T − head + t) − prev(T), the velocities add."""

    def __init__(self, prev: ArmMove, head: float, nxt: ArmMove) -> None:
        self.prev, self.head, self.next = prev, head, nxt
        self.t0 = prev.duration - head
        self._seam = prev.at(prev.duration).joints
        self.duration = nxt.duration
        self.ramp = max(prev.ramp, nxt.ramp)
        self.kind = nxt.kind
        # the rows both were checked with; NaN where they differ (the watch is strict there),
        # so that a limit set between the two plans does not make every other row strict too
        a, b = prev.limits_checked, nxt.limits_checked
        self.limits_checked = None if a is None or b is None else np.where(a == b, a, np.nan)

    def at(self, t: float) -> ArmSetpoint:
        b = self.next.at(t)
        if t >= self.head:
            return b
        return ArmSetpoint(b.joints + self.prev.at(self.t0 + t).joints - self._seam, b.finger)

    def velocity(self, t: float) -> np.ndarray:
        v = joint_velocity(self.next, t)
        return v + joint_velocity(self.prev, self.t0 + t) if t < self.head else v

    def apply(self, world: World, t: float, rate: float) -> None:
        if t >= self.head:
            self.next.apply(world, t, rate)
        else:
            world.set_arm_targets(self.at(t).joints, rate * self.velocity(t))


def overlap(prev: ArmMove, nxt: ArmMove, radius: float,
            position: Callable[[np.ndarray], np.ndarray], earliest: float = 0.0) -> float:
    """The blend time τ (s) of `nxt` after `prev` for the approach radius `radius` (m); 0 when
    they cannot overlap. `earliest`: prev may not be cut before this time (where it is now)."""
    room = prev.duration - getattr(prev, "head", 0.0)
    limit = min(prev.ramp, nxt.ramp, room, nxt.duration / 2, prev.duration - earliest)
    if radius <= 0.0 or limit <= 0.0:
        return 0.0
    seam = position(prev.at(prev.duration).joints)
    for tau in np.linspace(limit, 0.0, OVERLAP_STEPS, endpoint=False):
        if (np.linalg.norm(position(prev.at(prev.duration - tau).joints) - seam) <= radius
                and np.linalg.norm(position(nxt.at(tau).joints) - seam) <= radius):
            return float(tau)
    return 0.0


def blend_with_previous(device: Device, motion_id: int, previous_id: int, radius: float,
                        position: Callable[[np.ndarray], np.ndarray]) -> float:
    """Overlap queued move `motion_id` with move `previous_id` just before it in the queue (or
    running) for the approach radius `radius` (m) of the point `position(q)`; the overlap (s),
    0 when there is none (another motion between them, a gripper motion, a stop, too late)."""
    def edit(d: Device) -> float:
        entries = ([d.current] if d.current is not None else []) + list(d.queue)
        ids = [e.id for e in entries]
        if motion_id not in ids or ids.index(motion_id) == 0:
            return 0.0
        i = ids.index(motion_id)
        prev, nxt = entries[i - 1], entries[i]
        if prev.id != previous_id or prev.motion.kind not in ARM_MOVES \
                or nxt.motion.kind not in ARM_MOVES:
            return 0.0
        running = prev is d.current
        if running and d.stopping:
            return 0.0
        earliest = d.t + SEAM_MARGIN if running else 0.0
        tau = overlap(prev.motion, nxt.motion, radius, position, earliest)
        if tau > 0.0:
            whole = prev.motion
            prev.motion = Truncated(whole, whole.duration - tau)
            nxt.motion = Blend(whole, tau, nxt.motion)
        return tau
    return device.edit(edit)
