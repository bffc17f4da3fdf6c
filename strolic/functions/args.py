"""Taking typed arguments off a process's data stack.

Rule for reals where an integer is meant (Annex 1 §6): counts, positions, offsets, numbers of
processes/flags/levels accept reals and round them half away from zero; operands whose *type*
decides the result (MOD, AND, INC …) must be integers, a real there is a type mismatch.
"""
from __future__ import annotations

from ..codes import (REAL_TAGS, Function, Num, TagHead, UserCode, round_half_away, type_name,
                     user_key)
from ..errors import ExceptionKind as K, fail
from ..process import Process
from ..variables import find


def expect(value: object, cls: type | tuple, what: str) -> object:
    if not isinstance(value, cls):
        raise fail(K.TYPE_MISMATCH, f"{what} expected, got {type_name(value)}")
    return value


def pop_of(proc: Process, cls: type | tuple, what: str):
    return expect(proc.pop(), cls, what)


def pop_num(proc: Process) -> Num:
    """Any of I1, I2, I4, R4, R8."""
    return pop_of(proc, Num, "a number")


def pop_int(proc: Process) -> Num:
    """An integer operand (I1, I2, I4); reals are a type mismatch."""
    num = pop_of(proc, Num, "an integer")
    if not num.is_integer:
        raise fail(K.TYPE_MISMATCH, f"an integer expected, got {type_name(num)}")
    return num


def pop_real(proc: Process) -> Num:
    """A real operand (R4, R8)."""
    num = pop_of(proc, Num, "a real")
    if num.tag not in REAL_TAGS:
        raise fail(K.TYPE_MISMATCH, f"a real expected, got {type_name(num)}")
    return num


def integer_value(num: Num) -> int:
    """The integer meant by a number argument (reals rounded, Annex 1 §6)."""
    return num.value if num.is_integer else round_half_away(num.value)


def pop_count(proc: Process) -> int:
    """A count, position, offset or identifying number, as a Python int."""
    return integer_value(pop_num(proc))


def pop_user(proc: Process) -> UserCode:
    return pop_of(proc, UserCode, "a suppressed user code (#u)")


def pop_head(proc: Process) -> TagHead:
    return pop_of(proc, TagHead, "a suppressed tag (#t)")


def pop_many(proc: Process, count: int) -> list:
    """The ``count`` items under the count argument, deepest first."""
    if count < 0:
        raise fail(K.TYPE_MISMATCH, f"negative count {count}")
    if count > len(proc.stack):
        raise fail(K.STACK_UNDERFLOW, f"{count} items wanted, {len(proc.stack)} on the stack")
    items = proc.stack[len(proc.stack) - count:]
    del proc.stack[len(proc.stack) - count:]
    return items


def function_of(proc: Process, item) -> Function | None:
    """A function given as the datum or as ``#u`` of a user code holding one (FXQT, ACTION …);
    None when it is neither."""
    if isinstance(item, UserCode):
        binding = find(proc.scopes, user_key(item.code))
        item = binding.value() if binding.defined else None
    return item if isinstance(item, Function) else None
