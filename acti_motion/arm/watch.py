"""The soft-limit watch of the arm: what the simulation thread runs after every step.

It samples the sensed joints and gripper (the feedback the getters answer with) and compares the
set-point the device commands with the soft limits: one that leaves them raises an alarm and stops
the arm (5.4.8). It runs on the simulation thread because only there is every control period's
set-point seen, and the stop begins at the step that crossed. It never waits for a plan under way
(planning holds no lock it takes; the alarms' and the device's locks are held for moments), and at
rest it computes nothing. A part of `ArmCore` (mixed in; uses its attributes).
"""
from __future__ import annotations

import threading
from dataclasses import dataclass
from enum import IntEnum
from typing import Callable

import numpy as np

from acti_motion.arm.limits import SoftLimits
from acti_motion.executor import MotionExecutor
from acti_sim.world import World

ALARM_JOINT_SOFT_LIMIT = 0x4
ALARM_CARTESIAN_SOFT_LIMIT = 0x5

# Joints measured faster than this still move (the state word's 0x02): a stop's tail decays from
# ~0.3°/s to this in ~5 control periods; the base driving shakes the arm's joints by < 0.004°/s.
SETTLED_DEG_S = 0.05
SETTLED_RAD_S = np.radians(SETTLED_DEG_S)
ANTICIPATE_SAMPLES = 8       # along a look-ahead, to find the first crossing of a limit
ANTICIPATE_BISECTIONS = 16   # then to put the rest at it (the clock to ~1e-5 of the look-ahead)


class AlarmType(IntEnum):
    FAULT = 0
    WARNING = 1
    UNKNOWN = 2


@dataclass(frozen=True)
class Alarm:
    code: int
    type: AlarmType
    description: str

    def as_tuple(self) -> tuple[int, int, str]:
        return (self.code, int(self.type), self.description)


class SoftLimitWatch:
    """The simulation-thread part of ArmCore: feedback snapshot and soft-limit watch (mixed in:
    it reads ArmCore's kinematics, frames, soft limits and device)."""

    _alarms: list[Alarm]
    _alarm_lock: threading.Lock
    limits: SoftLimits                    # the soft limits in force
    _inside: np.ndarray | None            # which limit rows the last set-point was within
    _settling: bool                       # the measured joints still move (SETTLED_DEG_S)
    stop_motion: Callable[..., None]
    executor: MotionExecutor

    def _sample(self, world: World) -> None:
        """After every step (`MotionExecutor.after_step`): the feedback, then the watch."""
        self._feedback = world.arm_positions()
        self._measured = (world.time, self._feedback)     # one assignment: read together
        self._finger = world.gripper_position()
        self._settling = bool(np.any(np.abs(world.arm_velocities()) > SETTLED_RAD_S))
        self._watch()

    @property
    def settling(self) -> bool:
        """The joints, as the last control period measured them, still move onto a set-point
        (faster than SETTLED_DEG_S): the state word says moving meanwhile."""
        return self._settling

    def _watch(self) -> None:
        """Stop and raise an alarm where the commanded set-point would exceed a soft limit while
        moving (5.4.8: 範囲を超える場合は、動作を停止してアラーム): the watch looks ahead to where a
        fastest stop begun at the next step would rest and, when that is past a limit the
        set-point is within now, stops now so that the arm rests at the limit (`_anticipate`),
        not a braking distance past it. Against the limits its plan was checked with, a motion
        never gets there, and one that starts outside them (a move back inside) may move;
        against a limit that changed since (one set while the move was paused or queued, a
        Cartesian one set while moving) it is stopped at it, and wherever it is outside it,
        also from its first step.

        At rest nothing is computed (the FK is most of a step's Python work): the first moving
        step compares against the rest point, under the limits in force then."""
        d = self.device
        cur = d.current
        if cur is None:
            self._inside = None
            return
        if self._inside is None:
            self._inside = self._within_watch_limits(d.hold.joints)[1]
        values, inside = self._within_watch_limits(cur.motion.at(d.t).joints)
        was, self._inside = self._inside, inside
        if self._alarms:
            return
        if not inside.all():
            checked = getattr(cur.motion, "limits_checked", None)
            changed = (np.ones(len(inside), bool) if checked is None
                       else np.any(checked != self.limits.rows, axis=1))
            left = np.flatnonzero(~inside & (was | changed))
            if len(left):
                alarm = self._limit_alarm(int(left[0]), values, "exceeded")
                self.stop_motion(fastest=True, reason=self._raise(alarm))
                return
        self._anticipate(values)

    def _anticipate(self, values: np.ndarray) -> None:
        """Stop at a soft limit that the set-point is within now and that a fastest stop begun
        at the next step would rest beyond: the rest is put where the path reaches the limit
        (bisected along the motion's clock), by a stop over a ramp at least the fastest."""
        d = self.device
        cur = d.current
        fastest = self._fastest_ramp(cur)
        t_rest = d.rest_time_after_next_step(fastest, self.executor.dt)
        if t_rest <= d.t:
            return                                   # held at rest (paused, stopped)
        lower, upper = self.limits.rows.T
        within_now = (values >= lower) & (values <= upper)
        if not within_now.any():
            return

        def leaves(t: float) -> np.ndarray:
            v = self._watched_values(cur.motion.at(t).joints)
            return within_now & ((v < lower) | (v > upper))
        if not leaves(t_rest).any():     # the look-ahead slides by a step's travel each step
            return
        inside_t, outside_t = d.t, None
        for t in np.linspace(d.t, t_rest, ANTICIPATE_SAMPLES + 1)[1:].tolist():
            if leaves(t).any():
                outside_t = t
                break
            inside_t = t
        if outside_t is None:
            return
        for _ in range(ANTICIPATE_BISECTIONS):
            mid = (inside_t + outside_t) / 2
            if leaves(mid).any():
                outside_t = mid
            else:
                inside_t = mid
        row = int(np.flatnonzero(leaves(outside_t))[0])
        at_limit = self._watched_values(cur.motion.at(inside_t).joints)
        alarm = self._limit_alarm(row, at_limit, "reached")
        d.stop_at(inside_t, fastest, self._raise(alarm))

    def _fastest_ramp(self, cur) -> float:
        """The shortest stop the settings allow for the current motion (the alarm's stop)."""
        return (self.min_accel_time_cartesian if cur is not None and cur.motion.kind == "cartesian"
                else self.min_accel_time_joint)

    def _limit_alarm(self, i: int, values: np.ndarray, what: str) -> Alarm:
        """The alarm of limit row i (a joint, then x, y, z), with the set-point's value there."""
        lj, lc = self.soft_limit_joint, self.soft_limit_cartesian
        when = "with a move paused there" if self.device.paused else "while moving"
        if i < self.axis_count:
            return Alarm(ALARM_JOINT_SOFT_LIMIT, AlarmType.WARNING,
                         f"joint soft limit {what} {when}: J{i + 1} = {values[i]:.3f}° "
                         f"left [{lj[i, 0]:g}, {lj[i, 1]:g}]°" if what == "exceeded" else
                         f"joint soft limit {what} {when}: J{i + 1} = {values[i]:.3f}° at the "
                         f"edge of [{lj[i, 0]:g}, {lj[i, 1]:g}]°, stopped there")
        axis, lim = "xyz"[i - self.axis_count], lc[i - self.axis_count]
        return Alarm(ALARM_CARTESIAN_SOFT_LIMIT, AlarmType.WARNING,
                     f"Cartesian soft limit {what} {when}: {axis} = {values[i]:.2f} mm "
                     f"left [{lim[0]:g}, {lim[1]:g}] mm" if what == "exceeded" else
                     f"Cartesian soft limit {what} {when}: {axis} = {values[i]:.2f} mm at the "
                     f"edge of [{lim[0]:g}, {lim[1]:g}] mm, stopped there")

    def _raise(self, alarm: Alarm) -> str:
        """Make `alarm` active; the reason its stop gives a discarded motion."""
        with self._alarm_lock:
            self._alarms.append(alarm)
        return f"alarm 0x{alarm.code:X} ({alarm.description})"

    def _watched_values(self, q: np.ndarray) -> np.ndarray:
        """Joint values (degree) and control-point position (mm) of set-point q: the rows of
        `limits.rows`."""
        p = self.frames.tool_of(self.kin.flange(q))[:3, 3] * 1000.0
        return np.concatenate([np.degrees(q), p])

    def _within_watch_limits(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The watched values of set-point q, and which of them lie within the soft limits
        widened by the watch tolerances."""
        values = self._watched_values(q)
        lower, upper = self.limits.watch_bounds
        return values, (values >= lower) & (values <= upper)
