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
# "Ready only" moves (moveForward, moveTurn, moveLinearRel, moveCircularRel): 1.4.14, 1.4.20
# "Ready 状態でのみ実行可能です。それ以外の場合は設定値を無視し，偽を返します" (1.4.17, 1.4.21 alike), so
# Warning-### and Stuck refuse them too (clear_alarm or stop first). Paused takes them as the one
# other state: 1.4.22 "一時停止状態で入力された動作指令は内部に蓄積され…resume()実行後に実行されます".
READY_ONLY = (VehicleState.READY, VehicleState.PAUSED)
# "Servo on only" moves (moveLinearAbs, moveContinuousRel, moveCruiseAbs, moveJog) also run from
# Warning and Stuck and queue behind a moving base; Alarm and Locked refuse every motion until
# clearAlarm / unlock.
SERVO_ON = READY_ONLY + (VehicleState.WARNING, VehicleState.STUCK, VehicleState.BUSY,
                         VehicleState.AVOID)
