"""EE0E–EE15: interrupts and the timer interrupt (the mechanism is in ``interrupts.py``).

Interrupt codes and levels are integers (I1, I2, I4: a real is a type mismatch, as the
standard lists); levels are positive (0 means "every level" for ACTRS only). Procedures are
function data, given as the datum or as ``#u`` of a user code that holds one.
"""
from __future__ import annotations

from typing import TYPE_CHECKING

from ..codes import Function
from ..errors import ExceptionKind as K, fail
from ..process import Process
from .args import function_of, pop_int, pop_num

if TYPE_CHECKING:
    from ..vm import VM


def _level(proc: Process, allow_all: bool = False) -> int:
    level = pop_int(proc).value
    if level < 0 or (level == 0 and not allow_all):
        raise fail(K.UNDEFINED_DATA, f"interrupt level {level} (levels are positive)")
    return level


def _procedure(proc: Process) -> Function:
    function = function_of(proc, proc.pop())
    if function is None:
        raise fail(K.TYPE_MISMATCH, "a function (Fn, or #u holding one) expected")
    return function


def act(vm: VM, proc: Process) -> None:
    vm.interrupts.enabled.add(_level(proc))


def actrs(vm: VM, proc: Process) -> None:
    """ACTRS a: level a (every level for 0) no longer accepted; REACT undoes it once."""
    vm.interrupts.disable(_level(proc, allow_all=True))


def react(vm: VM, proc: Process) -> None:
    """REACT: the levels the last ACTRS (or the last accepted interrupt) disabled, once."""
    interrupts = vm.interrupts
    interrupts.enabled |= interrupts.react
    interrupts.react = set()


def actcode(vm: VM, proc: Process) -> None:
    """ACTCODE a b c: interrupt code a of level b, detected when procedure c gives true."""
    detect = _procedure(proc)
    level = _level(proc)
    entry = vm.interrupts.code(pop_int(proc).value)
    entry.level, entry.detect = level, detect


def action(vm: VM, proc: Process) -> None:
    """ACTION a b: procedure b runs when interrupt code a occurs."""
    handler = _procedure(proc)
    vm.interrupts.code(pop_int(proc).value).action = handler


def timer(vm: VM, proc: Process) -> None:
    """TIMER a: the timer interrupt in a ms (once); a ≤ 0 disarms it."""
    milliseconds = pop_num(proc).value
    vm.interrupts.timer_due = (vm.host.now() + milliseconds / 1000.0 if milliseconds > 0
                               else None)


def rtimer(vm: VM, proc: Process) -> None:
    """RTIMER: the levels the last timer interrupt disabled are accepted again (once); the
    timer is not started again."""
    interrupts = vm.interrupts
    interrupts.enabled |= interrupts.rtimer
    interrupts.rtimer = set()


def taction(vm: VM, proc: Process) -> None:
    vm.interrupts.timer_action = _procedure(proc)
