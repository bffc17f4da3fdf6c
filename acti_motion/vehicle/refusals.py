"""How the base's operations answer: a refusal raises its warning and becomes false with a
comment; a move given during a stop is discarded (true, with a comment); any other failure is a
refusal too, never an exception. Also the checks of the settings' values."""
from __future__ import annotations

import functools
import math
from typing import TYPE_CHECKING, Any, Callable

from acti_motion.replies import Refused, ReturnCode, answers, finite_number, plans
from acti_motion.vehicle.alarms import AlarmCode, Kind
from acti_motion.vehicle.paths import Pose2D

if TYPE_CHECKING:
    from acti_motion.vehicle.core import VehicleCore


class VehicleRefused(Refused):
    """A refusal with the warning code it raises."""

    def __init__(self, alarm: AlarmCode, comment: str) -> None:
        super().__init__(ReturnCode.NG, comment)
        self.alarm = alarm


class Discarded(Refused):
    """A move accepted while a stop decelerates: true, and discarded (stop: 停止後は全ての動作指令を廃棄)."""

    def __init__(self, operation: str) -> None:
        super().__init__(ReturnCode.OK, f"discarded: the base is stopping ({operation} given during "
                                        "the stop's deceleration; stop discards every motion command)")


WARNING_FOR = {ReturnCode.VALUE_ERR: AlarmCode.INVALID_VALUE,
               ReturnCode.STATUS_ERR: AlarmCode.WRONG_STATE,
               ReturnCode.FULL_MOTION_QUEUE_ERR: AlarmCode.QUEUE_FULL}


def invalid(message: str) -> VehicleRefused:
    return VehicleRefused(AlarmCode.INVALID_VALUE, message)


def _operation(clears_warnings: bool, planning: bool = False) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """An IDL operation: a refusal raises its warning, success clears the command warnings, and
    any other failure is a refusal with a comment, never an exception. Control operations hold
    the short state lock; planning operations (`planning`) hold only the planning lock, so that
    stop, pause, the getters and the simulation never wait for a plan, and are marked `plans`
    (their node serves them on the motion plane: one waits there for another's plan)."""
    def decorate(fn: Callable[..., Any]) -> Callable[..., Any]:
        name = fn.__name__.lstrip("_")      # the checking half of an operation (_set_velocity) names it

        @functools.wraps(fn)
        def recorded(self: "VehicleCore", *args: Any, **kwargs: Any) -> Any:
            with (self.planning_operation() if planning else self.lock):
                try:
                    out = fn(self, *args, **kwargs)
                except Refused as r:
                    if r.code != ReturnCode.OK:
                        code = getattr(r, "alarm", None) or WARNING_FOR.get(r.code, AlarmCode.INVALID_VALUE)
                        self.alarms.raise_(code, f"{name}: {r.comment}", Kind.COMMAND)
                    raise
                except (ArithmeticError, ValueError, TypeError, IndexError) as e:
                    comment = f"{name} could not be carried out ({type(e).__name__}: {e})"
                    self.alarms.raise_(AlarmCode.INVALID_VALUE, comment, Kind.COMMAND)
                    raise invalid(comment) from None
                if clears_warnings:
                    self.alarms.clear(Kind.COMMAND)
                return out
        return answers(plans(recorded) if planning else recorded)
    return decorate


command = _operation(clears_warnings=True)    # changes something: success clears command warnings
query = _operation(clears_warnings=False)     # reads: a refusal (unknown id) still warns
planned = _operation(clears_warnings=True, planning=True)   # plans a motion or a new timing


def bounded_pair(values: Any, lower: tuple[float, float], limits: tuple[float, float], name: str,
                 unit: tuple[str, str]) -> tuple[float, float]:
    """(translation, rotation), each finite and within [lower, limit]."""
    out = []
    for value, low, limit, part, u in zip(values, lower, limits, ("translation", "rotation"), unit):
        v = finite_number(value, f"{name}.{part}")
        if not low <= v <= limit:
            raise invalid(f"{name}.{part} is {v:.10g} {u}: it must be within {low:g} … {limit:g} {u}")
        out.append(v)
    return out[0], out[1]


def si_pair(pair: tuple[float, float]) -> tuple[float, float]:
    """A (translation, rotation) pair of the spec's units (mm…, degree…) in SI (m…, rad…)."""
    return pair[0] / 1000.0, math.radians(pair[1])


def finite_pose(pos: Any, name: str = "pos") -> Pose2D:
    """A Position (mm, mm, degree) as a Pose2D (m, m, rad)."""
    x, y, theta = (finite_number(v, f"{name}.{f}") for v, f in zip(pos, ("x", "y", "theta")))
    return Pose2D(x / 1000.0, y / 1000.0, math.radians(theta))
