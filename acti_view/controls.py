"""The page's buttons: the safe commands a person at the robot needs first.

Each button calls the same core method as the service of that name (`~/stop` → `ArmCore.stop`,
`/vehicle_node/stop` → `VehicleCore.stop`), so a press takes the very control path a service
call takes and answers the same way.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from acti_motion.replies import Reply


@dataclass(frozen=True)
class Control:
    device: str          # "arm" or "base": which core
    label: str           # on the button
    method: str          # the core method (= the service name)
    args: tuple = ()


CONTROLS = (
    Control("arm", "Servo on", "servo_on"),
    Control("arm", "Servo off", "servo_off"),
    Control("arm", "Pause", "pause"),
    Control("arm", "Resume", "resume"),
    Control("arm", "STOP arm", "stop"),
    Control("base", "Power on", "set_power", (True,)),
    Control("base", "Servo on", "set_servo", (True,)),
    Control("base", "Servo off", "set_servo", (False,)),
    Control("base", "Pause", "pause"),
    Control("base", "Resume", "resume"),
    Control("base", "STOP base", "stop"),
)


def press(control: Control, cores: dict[str, Any]) -> str:
    """Run the control on its core; what it answered, in words, for the page and the log."""
    reply: Reply = getattr(cores[control.device], control.method)(*control.args)
    name = f"{control.device} {control.method}{'(' + ', '.join(map(str, control.args)) + ')' if control.args else ''}"
    outcome = "OK" if reply.ok else f"refused ({reply.code.name})"
    return f"{name}: {outcome}" + (f": {reply.comment}" if reply.comment else "")
