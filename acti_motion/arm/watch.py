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

from acti_sim.world import World

ALARM_JOINT_SOFT_LIMIT = 0x4
ALARM_CARTESIAN_SOFT_LIMIT = 0x5

CARTESIAN_WATCH_TOLERANCE_MM = 0.1
JOINT_WATCH_TOLERANCE_DEG = 1e-6


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
    _inside: np.ndarray | None            # which limit rows the last set-point was within
    stop_motion: Callable[..., None]

    def _sample(self, world: World) -> None:
        """After every step (`MotionExecutor.after_step`): the feedback, then the watch."""
        self._feedback = world.arm_positions()
        self._measured = (world.time, self._feedback)     # one assignment: read together
        self._finger = world.gripper_position()
        self._watch()

    def _watch(self) -> None:
        """Stop and raise an alarm when the commanded set-point exceeds a soft limit while
        moving (5.4.8: 範囲を超える場合は、動作を停止してアラーム). Against the limits its plan was
        checked with, a motion can only leave them by a crossing, and one that starts outside
        them (a move back inside) may move; against a limit that changed since, it is stopped
        wherever it is outside it, also from its first step (it ran on outside a limit set while
        it waited in the queue).

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
        if self._alarms or inside.all():
            return
        checked = getattr(cur.motion, "limits_checked", None)
        changed = (np.ones(len(inside), bool) if checked is None
                   else np.any(checked != self._limit_rows(), axis=1))
        left = np.flatnonzero(~inside & (was | changed))
        if not len(left):
            return
        i = int(left[0])
        lj, lc = self.soft_limit_joint, self.soft_limit_cartesian
        when = "with a move paused there" if d.paused else "while moving"
        if i < self.axis_count:
            alarm = Alarm(ALARM_JOINT_SOFT_LIMIT, AlarmType.WARNING,
                          f"joint soft limit exceeded {when}: J{i + 1} = {values[i]:.3f}° "
                          f"left [{lj[i, 0]:g}, {lj[i, 1]:g}]°")
        else:
            axis = "xyz"[i - self.axis_count]
            lim = lc[i - self.axis_count]
            alarm = Alarm(ALARM_CARTESIAN_SOFT_LIMIT, AlarmType.WARNING,
                          f"Cartesian soft limit exceeded {when}: {axis} = {values[i]:.2f} mm "
                          f"left [{lim[0]:g}, {lim[1]:g}] mm")
        with self._alarm_lock:
            self._alarms.append(alarm)
        self.stop_motion(fastest=True, reason=f"alarm 0x{alarm.code:X} ({alarm.description})")

    def _limit_rows(self) -> np.ndarray:
        """The soft limits as rows (lower, upper): J1 … J7 (degree), then x, y, z (mm)."""
        return np.concatenate([self.soft_limit_joint, self.soft_limit_cartesian])

    def _within_watch_limits(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Joint values (degree) and control-point position (mm) of set-point q, and which of
        them lie within the soft limits widened by the watch tolerances."""
        p = self.frames.tool_of(self.kin.flange(q))[:3, 3] * 1000.0
        values = np.concatenate([np.degrees(q), p])
        lower, upper = self._watch_bounds()
        return values, (values >= lower) & (values <= upper)

    def _watch_bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """The soft limits widened by the watch tolerances (lower, upper), made again only when
        a limit was set (each setter assigns new arrays): the watch runs every moving step."""
        lj, lc = self.soft_limit_joint, self.soft_limit_cartesian
        made = getattr(self, "_bounds_made", None)
        if made is None or made[0] is not lj or made[1] is not lc:
            lower = np.concatenate([lj[:, 0] - JOINT_WATCH_TOLERANCE_DEG,
                                    lc[:, 0] - CARTESIAN_WATCH_TOLERANCE_MM])
            upper = np.concatenate([lj[:, 1] + JOINT_WATCH_TOLERANCE_DEG,
                                    lc[:, 1] + CARTESIAN_WATCH_TOLERANCE_MM])
            made = self._bounds_made = (lj, lc, lower, upper)
        return made[2], made[3]
