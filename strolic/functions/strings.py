"""EF1C–EF1E: strings are byte strings (§10); positions count bytes from 1."""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..codes import Str, smallest_int
from ..process import Process
from .args import pop_count, pop_of

if TYPE_CHECKING:
    from ..vm import VM


def conc(vm: VM, proc: Process) -> None:
    b = pop_of(proc, Str, "a string")
    a = pop_of(proc, Str, "a string")
    vm.claim(len(a.data) + len(b.data))
    proc.push(Str(a.data + b.data))


def lng(vm: VM, proc: Process) -> None:
    """LNG: the length in the smallest integer type."""
    proc.push(smallest_int(len(pop_of(proc, Str, "a string").data)))


def mid(vm: VM, proc: Process) -> None:
    """MID: c bytes from byte b; b < 1 starts at the first byte, c < 1 gives ''."""
    count = pop_count(proc)
    start = pop_count(proc)
    text = pop_of(proc, Str, "a string").data
    first = max(start, 1) - 1
    proc.push(Str(text[first:first + count] if count >= 1 else b""))
