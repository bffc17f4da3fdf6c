"""EF10–EF1A: complement, bitwise AND/OR/XOR, bit set/clear/test and the four shifts.

An operand of n bits is its n-bit two's complement pattern (n = 8, 16, 32 for I1, I2, I4).
"""
from __future__ import annotations

from typing import TYPE_CHECKING, Callable

from ..codes import INT_BITS, logical, wrap_int
from ..process import Process
from .args import pop_count, pop_int

if TYPE_CHECKING:
    from ..vm import VM


def cpl(vm: VM, proc: Process) -> None:
    a = pop_int(proc)
    proc.push(wrap_int(a.tag, ~a.value))


def bitwise(op: Callable[[int, int], int]):
    """AND, OR, XOR: operands sign-extended to the stronger type (Annex 1 §5)."""
    def handler(vm: VM, proc: Process) -> None:
        b = pop_int(proc)
        a = pop_int(proc)
        proc.push(wrap_int(max(a.tag, b.tag), op(a.value, b.value)))
    return handler


and_ = bitwise(lambda x, y: x & y)
or_ = bitwise(lambda x, y: x | y)
xor = bitwise(lambda x, y: x ^ y)


def _bit_operands(proc: Process):
    position = pop_count(proc)
    a = pop_int(proc)
    return a, position, 0 <= position < INT_BITS[a.tag]


def bset(vm: VM, proc: Process) -> None:
    a, position, inside = _bit_operands(proc)
    proc.push(wrap_int(a.tag, a.value | (1 << position)) if inside else a)


def bclr(vm: VM, proc: Process) -> None:
    a, position, inside = _bit_operands(proc)
    proc.push(wrap_int(a.tag, a.value & ~(1 << position)) if inside else a)


def btst(vm: VM, proc: Process) -> None:
    a, position, inside = _bit_operands(proc)
    proc.push(logical(inside and bool((a.value >> position) & 1)))


def _logical_shift(value: int, bits: int, count: int) -> int:
    """Shift the n-bit pattern left (count > 0) or right, zero filling; |count| ≥ n gives 0."""
    if abs(count) >= bits:
        return 0
    pattern = value & ((1 << bits) - 1)
    return pattern << count if count >= 0 else pattern >> -count


def _arithmetic_shift(value: int, bits: int, count: int) -> int:
    """Left: the sign bit stays, the other n−1 bits shift; right: sign filling."""
    if count < 0:
        return value >> min(-count, bits)
    sign = value & (1 << (bits - 1))
    magnitude = (value << min(count, bits)) & ((1 << (bits - 1)) - 1)
    return sign | magnitude


def shift(function: Callable[[int, int, int], int], direction: int):
    """LSH, RSH, LSHA, RSHA: a negative count shifts the other way; the type of a is kept."""
    def handler(vm: VM, proc: Process) -> None:
        count = pop_count(proc) * direction
        a = pop_int(proc)
        proc.push(wrap_int(a.tag, function(a.value, INT_BITS[a.tag], count)))
    return handler


lsh = shift(_logical_shift, 1)
rsh = shift(_logical_shift, -1)
lsha = shift(_arithmetic_shift, 1)
rsha = shift(_arithmetic_shift, -1)
