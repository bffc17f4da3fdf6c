"""EF00–EF0F, EF1B, EF27–EF35: arithmetic, comparison, NOT, sign, conversion, ε, π, angles.

Mixed arithmetic (Annex 1 §5): both operands are first converted to the stronger representation
I1 < I2 < I4 < R4 < R8 (an I4 going to R4 is rounded to single precision), the operation is done
in it and the result has it; DIV converts its operands the same way and gives R8 (its table).
LEQ/GEQ/LT/GT compare in the stronger representation too. An integer result that does not fit
its type is numeric overflow (only INC/DEC wrap, as their remarks say; NEG is two's complement,
so it wraps too).
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING, Callable

from ..codes import (I2, I4, INT_RANGE, R4, R8, Num, converted, logical, make_int, make_number,
                     make_real, smallest_int, to_float32, wrap_int)
from ..errors import ExceptionKind as K, fail
from ..process import Process
from .args import pop_int, pop_num, pop_real

if TYPE_CHECKING:
    from ..vm import VM

Handler = Callable[[object, object], None]


def _pop_pair(proc: Process, pop=pop_num) -> tuple[Num, Num]:
    b = pop(proc)
    a = pop(proc)
    return a, b


def _promoted(proc: Process, pop=pop_num) -> tuple[int, int | float, int | float]:
    """a b: the stronger representation of the two and both values converted to it (§5)."""
    a, b = _pop_pair(proc, pop)
    tag = max(a.tag, b.tag)
    if tag == R4:              # the one conversion that can round: an I4 to single precision
        return tag, converted(a, tag), converted(b, tag)
    return tag, a.value, b.value   # exact: Python's int/float arithmetic converts the same way


def _checked_real(tag: int, value: float, *operands: float) -> Num:
    """A real result; 0 computed from non-zero ``operands`` (of ×, ÷, ^) is underflow (§9)."""
    if value == 0.0 and operands and all(operands):
        raise fail(K.NUMERIC_UNDERFLOW, "real result underflows to 0")
    return make_real(tag, value)


def binary_arithmetic(int_op: Callable[[int, int], int], real_op: Callable[[float, float], float],
                      underflow_check: bool = False) -> Handler:
    """ADD, SUB, MUL: done in the stronger representation. Single precision + − × are exact
    in double, so one rounding of the double result gives the single precision result."""
    def handler(vm: VM, proc: Process) -> None:
        tag, a, b = _promoted(proc)
        if tag <= I4:
            proc.push(make_int(tag, int_op(a, b)))
        else:
            operands = (a, b) if underflow_check else ()
            proc.push(_checked_real(tag, real_op(a, b), *operands))
    return handler


add = binary_arithmetic(lambda x, y: x + y, lambda x, y: x + y)
sub = binary_arithmetic(lambda x, y: x - y, lambda x, y: x - y)
mul = binary_arithmetic(lambda x, y: x * y, lambda x, y: x * y, underflow_check=True)


def div(vm: VM, proc: Process) -> None:
    """DIV: the operands converted to the stronger representation (§5), the quotient in R8 (the
    output its table gives: a ÷ b, not an integer division)."""
    _, a, b = _promoted(proc)
    if b == 0:
        raise fail(K.DIVISION_BY_ZERO, "DIV by 0")
    proc.push(_checked_real(R8, a / b, a, b))


def pwr(vm: VM, proc: Process) -> None:
    """PWR: a^b in the stronger type; b < 0 is handled as division by 0."""
    tag, a, b = _promoted(proc)
    if b < 0:
        raise fail(K.DIVISION_BY_ZERO, "PWR with a negative exponent")
    if tag <= I4:
        if abs(a) > 1 and b > 64:
            raise fail(K.NUMERIC_OVERFLOW, "PWR result too large")
        proc.push(make_int(tag, a ** b))
        return
    if a < 0 and not float(b).is_integer():
        raise fail(K.UNDEFINED_DATA, "negative base with a fractional exponent")
    try:
        value = math.pow(a, b)
    except OverflowError:
        raise fail(K.NUMERIC_OVERFLOW, "PWR result too large") from None
    proc.push(_checked_real(tag, value, a))


def _integer_division(vm: VM, proc: Process) -> tuple[int, Num, Num]:
    a, b = _pop_pair(proc, pop_int)
    if b.value == 0:
        raise fail(K.DIVISION_BY_ZERO, "divisor is 0")
    return max(a.tag, b.tag), a, b


def mod(vm: VM, proc: Process) -> None:
    """MOD: c = SGN(a)·(|a| − INT(|a|/|b|)·|b|): the sign of the dividend."""
    tag, a, b = _integer_division(vm, proc)
    remainder = abs(a.value) % abs(b.value)
    proc.push(make_int(tag, remainder if a.value >= 0 else -remainder))


def idiv(vm: VM, proc: Process) -> None:
    """IDIV: c = SGN(a·b)·INT(|a|/|b|): truncation toward 0."""
    tag, a, b = _integer_division(vm, proc)
    quotient = abs(a.value) // abs(b.value)
    proc.push(make_int(tag, quotient if (a.value < 0) == (b.value < 0) else -quotient))


def step(delta: int) -> Handler:
    """INC, DEC: same type, wrapping from the positive maximum to the negative maximum."""
    def handler(vm: VM, proc: Process) -> None:
        a = pop_int(proc)
        proc.push(wrap_int(a.tag, a.value + delta))
    return handler


inc, dec = step(1), step(-1)


# ---- comparison ---------------------------------------------------------------------------------
def _equal(a: Num, b: Num) -> bool:
    """EQU remarks: integers compare by value; reals only with the same type; int ≠ real."""
    if a.is_integer and b.is_integer:
        return a.value == b.value
    return a.tag == b.tag and a.value == b.value


def equality(equal: bool) -> Handler:
    """EQU, NEQ: by their remarks, not by conversion."""
    def handler(vm: VM, proc: Process) -> None:
        a, b = _pop_pair(proc)
        proc.push(logical(_equal(a, b) == equal))
    return handler


def ordering(test: Callable[[int | float, int | float], bool]) -> Handler:
    """LEQ, GEQ, LT, GT: in the stronger representation, as the arithmetic (§5), so that
    ``a b LT`` agrees with the sign of ``a b SUB``."""
    def handler(vm: VM, proc: Process) -> None:
        _, a, b = _promoted(proc)
        proc.push(logical(test(a, b)))
    return handler


equ, neq = equality(True), equality(False)
leq = ordering(lambda a, b: a <= b)
geq = ordering(lambda a, b: a >= b)
lt = ordering(lambda a, b: a < b)
gt = ordering(lambda a, b: a > b)


def aeq(vm: VM, proc: Process) -> None:
    """AEQ: |a − b| < ε (ε set by SEPS)."""
    _, a, b = _promoted(proc, pop_real)
    proc.push(logical(abs(a - b) < vm.eps))


def not_(vm: VM, proc: Process) -> None:
    proc.push(logical(pop_num(proc).value == 0))


# ---- sign and absolute value --------------------------------------------------------------------
def neg(vm: VM, proc: Process) -> None:
    """NEG: two's complement (the most negative value maps to itself)."""
    a = pop_int(proc)
    proc.push(wrap_int(a.tag, -a.value))


def abs_(vm: VM, proc: Process) -> None:
    a = pop_num(proc)
    proc.push(make_number(a.tag, abs(a.value)))


def sgn(vm: VM, proc: Process) -> None:
    a = pop_num(proc).value
    proc.push(Num(I2, (a > 0) - (a < 0)))


# ---- type conversion ----------------------------------------------------------------------------
def _floor(a: Num) -> int:
    return a.value if a.is_integer else math.floor(a.value)


def int_(vm: VM, proc: Process) -> None:
    """INT: floor, in the smallest integer type; overflow gives ±I4 maximum."""
    low, high = INT_RANGE[I4]
    proc.push(smallest_int(min(max(_floor(pop_num(proc)), low), high)))


def int_of(tag: int) -> Handler:
    """INT1, INT2, INT4: floor, then the low-order bytes."""
    def handler(vm: VM, proc: Process) -> None:
        proc.push(wrap_int(tag, _floor(pop_num(proc))))
    return handler


def real(vm: VM, proc: Process) -> None:
    """REAL: integers become R4, reals stay as they are."""
    a = pop_num(proc)
    proc.push(Num(R4, to_float32(float(a.value))) if a.is_integer else a)


def real_of(tag: int) -> Handler:
    """REAL4, REAL8 (R8 → R4 may overflow: numeric overflow)."""
    def handler(vm: VM, proc: Process) -> None:
        proc.push(make_real(tag, float(pop_num(proc).value)))
    return handler


# ---- ε, π, angles, elementary functions ---------------------------------------------------------
def seps(vm: VM, proc: Process) -> None:
    vm.eps = abs(float(pop_real(proc).value))


def eps(vm: VM, proc: Process) -> None:
    proc.push(Num(R8, vm.eps))


def pi(vm: VM, proc: Process) -> None:
    proc.push(Num(R8, math.pi))


def real_function(function: Callable[[float], float],
                  domain: Callable[[float], bool] = lambda x: True) -> Handler:
    """A real function of one R4/R8 argument; the result keeps the type. Outside ``domain``
    the standard asks for 'the same processing as division by 0'."""
    def handler(vm: VM, proc: Process) -> None:
        a = pop_real(proc)
        if not domain(a.value):
            raise fail(K.DIVISION_BY_ZERO, f"argument {a.value!r} outside the domain")
        try:
            value = function(a.value)
        except OverflowError:
            raise fail(K.NUMERIC_OVERFLOW, "result too large") from None
        proc.push(make_real(a.tag, value))
    return handler


def _exp(x: float) -> float:
    value = math.exp(x)
    if value == 0.0:
        raise fail(K.NUMERIC_UNDERFLOW, "EXP result underflows")
    return value


sin, cos, tan, atan = (real_function(f) for f in (math.sin, math.cos, math.tan, math.atan))
ln = real_function(math.log, lambda x: x > 0)
exp = real_function(_exp)
sqrt = real_function(math.sqrt, lambda x: x >= 0)
degrad = real_function(math.radians)
raddeg = real_function(math.degrees)


def atan2(vm: VM, proc: Process) -> None:
    """ATAN2: a is y, b is x; the usual quadrant rule (atan2(0, x<0) = π)."""
    tag, a, b = _promoted(proc, pop_real)
    proc.push(make_real(tag, math.atan2(a, b)))
