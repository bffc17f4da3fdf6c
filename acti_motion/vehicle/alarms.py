"""Alarms of the base: codes, the IDL's AlarmType, and the table of active ones.

An alarm is a FAULT (the unit refuses motion until clearAlarm: state Alarm-###) or a WARNING
(state Warning-###; motion is still accepted). Each has a kind that says what clears it.
"""
from __future__ import annotations

import threading
from dataclasses import dataclass
from enum import Enum, IntEnum


class AlarmType(IntEnum):
    """The IDL appendix's order (it wins over the text's FAULT, WARNING, UNKNOWN)."""
    UNKNOWN = 0
    FAULT = 1
    WARNING = 2


class Kind(Enum):
    """What raised an alarm, hence what clears it."""
    COMMAND = "command"        # a refused command: cleared by clearAlarm or the next accepted command
    CONDITION = "condition"    # a sensed condition (battery): clearAlarm clears it if the cause is gone
    STUCK = "stuck"            # the base was blocked: clearAlarm or the next accepted command
    CONTACT = "contact"        # the contact sensor locked the base: unlock only


class AlarmCode(IntEnum):
    """Codes reported by getActiveAlarm and in the state strings (Warning-101, Alarm-201 …)."""
    INVALID_VALUE = 101         # NaN, inf, zero/negative or over-limit value
    WRONG_STATE = 102           # the command is not accepted in the unit's state
    QUEUE_FULL = 103            # the motion queue is full
    UNKNOWN_ID = 104            # unknown or reserved I/O id, unknown axis id
    NOT_HOLONOMIC = 105         # impossible for a differential drive (y velocity, centre off the axle)
    BATTERY_LOW = 110           # battery below the low-voltage warning level
    STUCK = 120                 # the base could not follow its path and stopped
    OBSTACLE = 121              # an obstacle in the stop zone: the base stopped (Stuck)
    BATTERY_EMPTY = 201         # battery below the cut-off voltage: power and servo off
    CONTACT = 301               # the contact sensor touched something: Locked until unlock


TYPES = {
    AlarmCode.BATTERY_EMPTY: AlarmType.FAULT,
    AlarmCode.CONTACT: AlarmType.FAULT,
}


@dataclass(frozen=True)
class Alarm:
    code: int
    type: AlarmType
    source: str
    kind: Kind


class Alarms:
    """The active alarms, oldest first, one per code (a repeat updates the source)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._active: dict[int, Alarm] = {}

    def raise_(self, code: AlarmCode, source: str, kind: Kind) -> None:
        alarm = Alarm(int(code), TYPES.get(code, AlarmType.WARNING), source, kind)
        with self._lock:
            self._active.pop(int(code), None)
            self._active[int(code)] = alarm

    def clear(self, *kinds: Kind, code: AlarmCode | None = None) -> None:
        """Remove the alarms of these kinds (or the one code)."""
        with self._lock:
            for c, a in list(self._active.items()):
                if a.kind in kinds or c == code:
                    del self._active[c]

    def active(self) -> list[Alarm]:
        """Faults first, then warnings; each group oldest first."""
        with self._lock:
            alarms = list(self._active.values())
        return sorted(alarms, key=lambda a: a.type != AlarmType.FAULT)

    def has(self, code: AlarmCode) -> bool:
        return int(code) in self._active

    def first(self, type_: AlarmType, *exclude: Kind) -> Alarm | None:
        for a in self.active():
            if a.type == type_ and a.kind not in exclude:
                return a
        return None
