"""The base's states: table 7 of the VehicleService spec and which states accept which moves."""
from __future__ import annotations

from enum import IntEnum


class VehicleState(IntEnum):
    """Table 7 of the VehicleService spec: state code → the state string's stem."""
    READY = 0x010
    BUSY = 0x011
    WARNING = 0x012
    ALARM = 0x013
    STUCK = 0x014
    PAUSED = 0x015
    AVOID = 0x016
    LOCKED = 0x017
    POWERED = 0x018
    UNPOWERED = 0x019


STATE_STRINGS = {
    VehicleState.READY: "Ready", VehicleState.BUSY: "Busy", VehicleState.WARNING: "Warning",
    VehicleState.ALARM: "Alarm", VehicleState.STUCK: "Stuck", VehicleState.PAUSED: "Paused",
    VehicleState.AVOID: "Avoid", VehicleState.LOCKED: "Locked", VehicleState.POWERED: "Powered",
    VehicleState.UNPOWERED: "Unpowered",
}
# "Ready only" moves (moveForward, moveTurn, moveLinearRel, moveCircularRel) run from an idle base;
# Paused is idle too, and the pause operation says commands given then are kept for resume.
IDLE = (VehicleState.READY, VehicleState.WARNING, VehicleState.STUCK, VehicleState.PAUSED)
# "Servo on only" moves (moveLinearAbs, moveContinuousRel, moveCruiseAbs, moveJog) also queue
# behind a moving base; Alarm and Locked refuse every motion until clearAlarm / unlock.
SERVO_ON = IDLE + (VehicleState.BUSY, VehicleState.AVOID)
