"""EE00–EE09: time of day, date and the internal clock (through the host).

The time representation is ``HH:MM:SS`` (24-hour clock) and the date representation
``YYYY/MM/DD`` (years 1900–2100), the forms the standard recommends; every field has exactly
that many digits. The internal clock counts milliseconds and wraps to 0 after 2³¹ − 1.
"""
from __future__ import annotations

from datetime import date, datetime, time
from typing import TYPE_CHECKING

from ..codes import I2, I4, Num, Str
from ..process import Process
from .args import integer_value, pop_num, pop_of

if TYPE_CHECKING:
    from ..vm import VM

# (digits, lowest, highest) of each field; out of range a field is its lowest value (PACKDT,
# UNPKDT use the lower limit; PACKTM, UNPKTM use 0, which is the lower limit of theirs)
TIME_FIELDS = ((2, 0, 23), (2, 0, 59), (2, 0, 59))
DATE_FIELDS = ((4, 1900, 2100), (2, 1, 12), (2, 1, 31))
CLOCK_MODULUS = 1 << 31


def _format(values: list[int], fields, separator: str) -> Str:
    return Str(separator.join(f"{v:0{digits}d}" for v, (digits, _, _) in zip(values, fields))
               .encode("ascii"))


def _in_range(value: int, field) -> int:
    _, low, high = field
    return value if low <= value <= high else low


def _parse(text: bytes, fields, separator: bytes) -> tuple[list[int], bool]:
    """Field by field: a field with the wrong digit count or out of range is its lowest value;
    ``exact`` says whether the whole text was the representation."""
    parts = text.split(separator)
    values, exact = [], len(parts) == len(fields)
    for i, field in enumerate(fields):
        part = parts[i] if i < len(parts) else b""
        digits, low, high = field
        good = len(part) == digits and part.isdigit() and low <= int(part) <= high
        values.append(int(part) if good else low)
        exact = exact and good
    return values, exact


def _pop_fields(proc: Process, fields) -> list[int]:
    """Three numbers a b c (reals rounded), each replaced by its lower limit out of range."""
    values = [integer_value(pop_num(proc)) for _ in fields][::-1]
    return [_in_range(v, field) for v, field in zip(values, fields)]


def _pop_text(proc: Process) -> bytes:
    return pop_of(proc, Str, "a string").data


# ---- reading the clocks -------------------------------------------------------------------------
def time_(vm: VM, proc: Process) -> None:
    now = vm.host.wall_clock()
    proc.push(_format([now.hour, now.minute, now.second], TIME_FIELDS, ":"))


def date_(vm: VM, proc: Process) -> None:
    now = vm.host.wall_clock()
    proc.push(_format([now.year, now.month, now.day], DATE_FIELDS, "/"))


def clock(vm: VM, proc: Process) -> None:
    proc.push(Num(I4, vm.host.clock_ms() % CLOCK_MODULUS))


def clrclk(vm: VM, proc: Process) -> None:
    vm.host.clear_clock()


# ---- setting the time of day --------------------------------------------------------------------
def stime(vm: VM, proc: Process) -> None:
    """STIME: a string that is not HH:MM:SS gives a console warning; the time is kept."""
    text = _pop_text(proc)
    (hour, minute, second), exact = _parse(text, TIME_FIELDS, b":")
    if not exact:
        vm.host.warn(f"STIME: {text!r} is not a time HH:MM:SS; the time is not set")
        return
    now = vm.host.wall_clock()
    vm.host.set_wall_clock(datetime.combine(now.date(), time(hour, minute, second)))


def sdate(vm: VM, proc: Process) -> None:
    """SDATE: a string that is not a calendar date YYYY/MM/DD gives a warning; the date is kept."""
    text = _pop_text(proc)
    (year, month, day), exact = _parse(text, DATE_FIELDS, b"/")
    try:
        new_date = date(year, month, day) if exact else None
    except ValueError:                      # 2023/02/30: the representation, but no such day
        new_date = None
    if new_date is None:
        vm.host.warn(f"SDATE: {text!r} is not a date YYYY/MM/DD; the date is not set")
        return
    vm.host.set_wall_clock(datetime.combine(new_date, vm.host.wall_clock().time()))


# ---- packing and unpacking ----------------------------------------------------------------------
def packer(fields, separator: str):
    """PACKTM, PACKDT: a b c → the representation (a value out of range is its lower limit)."""
    def handler(vm: VM, proc: Process) -> None:
        proc.push(_format(_pop_fields(proc, fields), fields, separator))
    return handler


def unpacker(fields, separator: bytes):
    """UNPKTM, UNPKDT: the representation → three I2 (a bad field is its lower limit)."""
    def handler(vm: VM, proc: Process) -> None:
        for value in _parse(_pop_text(proc), fields, separator)[0]:
            proc.push(Num(I2, value))
    return handler


packtm, packdt = packer(TIME_FIELDS, ":"), packer(DATE_FIELDS, "/")
unpktm, unpkdt = unpacker(TIME_FIELDS, b":"), unpacker(DATE_FIELDS, b"/")
