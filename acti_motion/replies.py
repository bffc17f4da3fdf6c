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


def answers(fn: Callable[..., dict[str, Any] | Reply | None]) -> Callable[..., Reply]:
    """Wrap a core operation: its out-values dict becomes an OK reply, `Refused` a refusal, and
    any other exception (a bug, or input no check foresaw) NG with a comment that says what
    failed: a request never ends the process and never leaves a traceback in the log."""
    @functools.wraps(fn)
    def wrapper(*args: Any, **kwargs: Any) -> Reply:
        try:
            out = fn(*args, **kwargs)
        except Refused as r:
            return Reply(r.code, r.comment)
        except Exception as e:
            comment = f"{fn.__name__} failed: {type(e).__name__}: {e}"
            _log.error(comment)
            return Reply(ReturnCode.NG, comment)
        if isinstance(out, Reply):
            return out
        return Reply(values=out or {})
    return wrapper


def returns(*codes: ReturnCode) -> Callable[[Callable[..., Any]], Callable[..., Reply]]:
    """`answers`, for an operation whose spec lists exactly OK, NG and `codes`: a refusal with
    any other id becomes NG ("failed for another reason"), comment kept. The allowed ids are
    the wrapper's `return_codes`, for tests and documentation."""
    allowed = frozenset((ReturnCode.OK, ReturnCode.NG, *codes))

    def decorate(fn: Callable[..., Any]) -> Callable[..., Reply]:
        inner = answers(fn)

        @functools.wraps(fn)
        def wrapper(*args: Any, **kwargs: Any) -> Reply:
            reply = inner(*args, **kwargs)
            if reply.code not in allowed:
                return Reply(ReturnCode.NG, reply.comment, reply.values)
            return reply
        wrapper.return_codes = allowed  # type: ignore[attr-defined]
        return wrapper
    return decorate


def value_error(what: str) -> Refused:
    return Refused(ReturnCode.VALUE_ERR, what)


def finite_vector(values: Iterable[float], length: int | tuple[int, ...], name: str) -> np.ndarray:
    """`values` as a float vector of an allowed length with only finite numbers, else VALUE_ERR."""
    v = np.asarray(values if isinstance(values, list) else list(values), dtype=float).reshape(-1)
    allowed = (length,) if isinstance(length, int) else length
    if len(v) not in allowed:
        want = " or ".join(str(n) for n in allowed)
        raise value_error(f"{name} needs {want} values, got {len(v)}")
    floats = v.tolist()      # numpy's scalars one by one cost more than the rest of the check
    if not all(map(math.isfinite, floats)):
        bad = [i for i, x in enumerate(floats) if not math.isfinite(x)]
        raise value_error(f"{name}[{bad[0]}] is {v[bad[0]]}: every value must be a finite number")
    return v


def finite_number(x: float, name: str) -> float:
    if not math.isfinite(x):
        raise value_error(f"{name} is {x}: it must be a finite number")
    return float(x)


def ratio_percent(x: int, name: str) -> int:
    """A percentage 0 … 100 (the spec's ULONG ratios), else VALUE_ERR."""
    if not 0 <= x <= 100:
        raise value_error(f"{name} is {x} %: it must be within 0 … 100 %")
    return int(x)
