"""The exceptions of JIS B 8440 Annex 1 §9 and the one error class that reports them.

Every failure of the package (decoding, assembling, executing) is a ``StrolicError`` so that a
caller can catch one class; ``kind`` says which exception of §9 it is, ``function`` and ``offset``
say where execution stopped (§4.5: the program stops and the exception is reported).
"""
from __future__ import annotations

import contextlib
import enum
from typing import Iterator


class ExceptionKind(enum.Enum):
    """Annex 1 §9 exception kinds, plus the 'other computer errors' this implementation names."""

    # general computer-language exceptions (§9)
    DIVISION_BY_ZERO = "division by zero"
    NUMERIC_OVERFLOW = "numeric overflow"
    NUMERIC_UNDERFLOW = "numeric underflow"
    STACK_OVERFLOW = "stack overflow"
    STACK_UNDERFLOW = "stack underflow"
    TYPE_MISMATCH = "data type mismatch"
    UNDEFINED_DATA = "undefined data"
    # 'other computer errors', named so that a report says what went wrong
    INVALID_CODE = "invalid code"
    BRANCH_OUT_OF_FUNCTION = "branch target outside the function"
    NO_RETURN_DESTINATION = "return without a return destination"
    AREA_ERROR = "access outside the allocated area"
    SINGULAR_TRANSFORM = "transform has no inverse"
    DEADLOCK = "every process is waiting"
    INSTRUCTION_BUDGET = "instruction budget exhausted"
    FILE_ERROR = "file input/output error"
    FILE_OUTSIDE = "file outside the program directory"
    CONVERSION_ERROR = "conversion error"
    DETECTION_WAITED = "an interrupt detection procedure waited"
    MEMORY_EXHAUSTED = "not enough memory for the data"
    COMPUTER_ERROR = "other computer error"
    # robot-language exceptions (§9)
    OUT_OF_OPERATING_REGION = "outside the operating region"
    EXCESSIVE_SPEED = "excessive speed"
    ROBOT_ERROR = "other robot error"
    # controller exceptions (§9)
    EMERGENCY_STOP = "emergency stop"
    SERVO_ERROR = "servo error"
    COMMUNICATION_ERROR = "communication error"
    CONTROLLER_ERROR = "other controller error"
    STOPPED = "stopped by the operator"    # the run was canceled (robot binding)


DETAIL_CHARS = 1000     # of an exception's detail: it quotes the program (a 1 MB token)


def _cut(detail: str) -> str:
    """At most DETAIL_CHARS characters: the head and the tail (where the reason usually is)
    around the length; cutting again changes nothing."""
    if len(detail) <= DETAIL_CHARS:
        return detail
    note = f" … ({len(detail)} characters) … "
    keep = DETAIL_CHARS - len(note)
    head = keep * 2 // 3
    return detail[:head] + note + detail[len(detail) - (keep - head):]


class StrolicError(Exception):
    """An exception state: what happened, in which function, at which byte offset. The detail
    is cut to DETAIL_CHARS characters: it goes into results and log lines, and quotes what the
    program holds (a 1 MB bad token was echoed whole into both)."""

    def __init__(self, kind: ExceptionKind, detail: str = "", *,
                 function: str | None = None, offset: int | None = None) -> None:
        detail = _cut(detail)
        super().__init__(detail)
        self.kind = kind
        self.detail = detail
        self.function = function
        self.offset = offset

    def located(self, function: str | None, offset: int | None) -> "StrolicError":
        """Fill in the place of the failure unless an inner frame already did."""
        if self.function is None:
            self.function = function
        if self.offset is None:
            self.offset = offset
        return self

    def report(self) -> str:
        """One line for a person: kind, function, offset, detail."""
        where = []
        if self.function is not None:
            where.append(f"in {self.function}")
        if self.offset is not None:
            where.append(f"at byte {self.offset} (0x{self.offset:X})")
        text = f"STROLIC exception: {self.kind.value}"
        if where:
            text += " " + " ".join(where)
        return text + (f": {self.detail}" if self.detail else "")

    def __str__(self) -> str:
        return self.report()


def fail(kind: ExceptionKind, detail: str = "") -> StrolicError:
    """Build the error to raise; short to write at every check."""
    return StrolicError(kind, detail)


@contextlib.contextmanager
def read_at(origin: int | None) -> Iterator[None]:
    """Decoding a datum read at ``origin`` of the program: its errors carry program offsets.
    A datum made at run time (EXTB, EMBB into an area, DECODE1) has no place in the program:
    its errors lose the offset, and the VM puts the one of the code that used the datum."""
    try:
        yield
    except StrolicError as error:
        if origin is None:
            error.offset = None
        raise
