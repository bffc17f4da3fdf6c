"""What a core operation answers: the arm's RETURN_ID and the vehicle's boolean + message.

Cores raise `Refused` where an operation is refused; `answers` turns that into the port's reply,
so every check reads as one line and every refusal carries a comment for a person.
"""
from __future__ import annotations

import functools
import logging
import math
from dataclasses import dataclass, field
from enum import IntEnum
from typing import Any, Callable, Iterable

import numpy as np


_log = logging.getLogger("acti_motion")


class ReturnCode(IntEnum):
    """RETURN_ID.id of the ACT ports (middle-level spec table 3; NOT_IMPLEMENTED from 2014)."""
    OK = 0
    NG = -1
    STATUS_ERR = -2
    VALUE_ERR = -3
    NOT_SV_ON_ERR = -4
    FULL_MOTION_QUEUE_ERR = -5
    NOT_IMPLEMENTED = -6


class Refused(Exception):
    """An operation refused with `code` (a ReturnCode; the vehicle maps every code to false)."""

    def __init__(self, code: ReturnCode, comment: str) -> None:
        super().__init__(comment)
        self.code = code
        self.comment = comment


@dataclass
class Reply:
    """The outcome of one operation: code, comment and the out parameters by IDL name."""
    code: ReturnCode = ReturnCode.OK
    comment: str = ""
    values: dict[str, Any] = field(default_factory=dict)

    @property
    def ok(self) -> bool:
        return self.code == ReturnCode.OK


def plans(fn: Callable[..., Any]) -> Callable[..., Any]:
    """Mark an operation that plans motion or waits for a plan under way: its node serves it on
    the device's motion plane, so that the control plane (stop, pause, the getters) never waits
    behind it. The mark survives `answers` and `returns` (functools.wraps copies it)."""
    fn.plans = True
    return fn


def answers(fn: Callable[..., dict[str, Any] | Reply | None],
            allowed: frozenset[ReturnCode] | None = None) -> Callable[..., Reply]:
    """Wrap a core operation: its out-values dict becomes an OK reply, `Refused` a refusal, and
    any other exception (a bug, or input no check foresaw) NG with a comment that says what
    failed: a request never ends the process and never leaves a traceback in the log. Given
    `allowed` (`returns`), a refusal with another id becomes NG, comment kept."""
    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Reply:
        try:
            out = fn(*args, **kwargs)
        except Refused as r:
            if allowed is not None and r.code not in allowed:
                return Reply(ReturnCode.NG, r.comment)
            return Reply(r.code, r.comment)
        except Exception as e:
            comment = f"{fn.__name__} failed: {type(e).__name__}: {e}"
            _log.error(comment)
            return Reply(ReturnCode.NG, comment)
        if isinstance(out, Reply):
            if allowed is not None and out.code not in allowed:
                return Reply(ReturnCode.NG, out.comment, out.values)
            return out
        return Reply(values=out or {})
    return wrapper


def returns(*codes: ReturnCode) -> Callable[[Callable[..., Any]], Callable[..., Reply]]:
    """`answers`, for an operation whose spec lists exactly OK, NG and `codes`: a refusal with
    any other id becomes NG ("failed for another reason"), comment kept. The allowed ids are
    the wrapper's `return_codes`, for tests and documentation. One wrapper, not two: every
    call of an operation (a move's accept, a getter) goes through it."""
    allowed = frozenset((ReturnCode.OK, ReturnCode.NG, *codes))

    def decorate(fn: Callable[..., Any]) -> Callable[..., Reply]:
        wrapper = answers(fn, allowed)
        wrapper.return_codes = allowed  # type: ignore[attr-defined]
        return wrapper
    return decorate


def value_error(what: str) -> Refused:
    return Refused(ReturnCode.VALUE_ERR, what)


def floats(values: np.ndarray | list[float]) -> list[float]:
    """A list as it is; an array (or a number) flattened into floats. For a handful of values
    plain floats cost less than numpy's calls (1 … 3 µs each on a cold core)."""
    return values if isinstance(values, list) else np.asarray(values, float).reshape(-1).tolist()


_ONLY_FLOATS = {float}


def finite_floats(values: Iterable[float], length: int | tuple[int, ...], name: str) -> list[float]:
    """`values` as a list of floats of an allowed length, all finite, else VALUE_ERR. A list of
    floats (what a ROS request's array is read as) is checked as it is, without numpy."""
    if type(values) is list and {*map(type, values)} == _ONLY_FLOATS:
        got = list(values)
    else:
        got = np.asarray(values if isinstance(values, list) else list(values),
                         dtype=float).reshape(-1).tolist()
    allowed = (length,) if isinstance(length, int) else length
    if len(got) not in allowed:
        want = " or ".join(str(n) for n in allowed)
        raise value_error(f"{name} needs {want} values, got {len(got)}")
    if not all(map(math.isfinite, got)):
        bad = [i for i, x in enumerate(got) if not math.isfinite(x)]
        raise value_error(f"{name}[{bad[0]}] is {got[bad[0]]}: every value must be a finite number")
    return got


def finite_vector(values: Iterable[float], length: int | tuple[int, ...], name: str) -> np.ndarray:
    """`values` as a float vector of an allowed length with only finite numbers, else VALUE_ERR."""
    return np.array(finite_floats(values, length, name))


def finite_number(x: float, name: str) -> float:
    if not math.isfinite(x):
        raise value_error(f"{name} is {x}: it must be a finite number")
    return float(x)


def ratio_percent(x: int, name: str) -> int:
    """A percentage 0 … 100 (the spec's ULONG ratios), else VALUE_ERR."""
    if not 0 <= x <= 100:
        raise value_error(f"{name} is {x} %: it must be within 0 … 100 %")
    return int(x)
