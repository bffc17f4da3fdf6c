"""STROLIC data: tags (Tables 2–3), tag heads, the value types that live on the stack, numbers.

Values are immutable, so the stack, variables and DUP can share them. A value is described by
its *head* (tag, length, element tag: the `data-tag-part` of §6.1) and its *data part* (the
bytes after the head); the codec, arrays, EXTB/EMBB and the heap areas all use that split.
"""
from __future__ import annotations

import math
import struct
from dataclasses import dataclass, field

from .errors import ExceptionKind as K, fail

# ---- tags (Table 2, Table 3) --------------------------------------------------------------------
SUPPRESS, I1, I2, I4, R4, R8, INDIRECT = 0xF0, 0xF1, 0xF2, 0xF4, 0xF5, 0xF6, 0xF7
ARRAY, STRING, RECORD, FUNCTION = 0xF9, 0xFA, 0xFB, 0xFD
VECTOR, TRANSFORM, POSE = 0xFF01, 0xFF02, 0xFF04

INTEGER_TAGS = (I1, I2, I4)
REAL_TAGS = (R4, R8)
NUMERIC_TAGS = INTEGER_TAGS + REAL_TAGS
LENGTH_TAGS = (STRING, RECORD, FUNCTION, POSE)          # tag, length
FIXED_SIZE = {I1: 1, I2: 2, I4: 4, R4: 4, R8: 8, VECTOR: 12, TRANSFORM: 48}
TAG_NAMES = {I1: "I1", I2: "I2", I4: "I4", R4: "R4", R8: "R8", ARRAY: "Ar", STRING: "St",
             RECORD: "Rd", FUNCTION: "Fn", VECTOR: "Vec", TRANSFORM: "Trn", POSE: "Pm",
             SUPPRESS: "#", INDIRECT: "Rf"}
TAGS_BY_NAME = {name: tag for tag, name in TAG_NAMES.items()}

INT_RANGE = {I1: (-0x80, 0x7F), I2: (-0x8000, 0x7FFF), I4: (-0x8000_0000, 0x7FFF_FFFF)}
INT_BITS = {I1: 8, I2: 16, I4: 32}
INT_FORMAT = {I1: ">b", I2: ">h", I4: ">i"}
REAL_FORMAT = {R4: ">f", R8: ">d"}

# ---- code areas (§16, §17, Annex 1 §2) ----------------------------------------------------------
END_CODE = 0xEF5C
VAR_CODE = 0xEF63
ACK_CODE = 0xEF73
USER_MIN, USER_MAX = 0x1000, 0xEAFF
EXT_USER_MIN, EXT_USER_MAX = 0xEB00_0000, 0xEBFF_FFFF
EXT_ALIAS_MIN, EXT_ALIAS_MAX = 0xEB00_1000, 0xEB00_EAFF


def is_user_code(code: int) -> bool:
    """2-byte user codes 1000–EAFF and the EB-prefixed extended codes (the ones decoded here)."""
    return USER_MIN <= code <= USER_MAX or EXT_USER_MIN <= code <= EXT_USER_MAX


def user_code_of(num: Num) -> int:
    """CONSU's reading of a number as a code: I2/I4 bit patterns, reals rounded (§6)."""
    if num.is_integer:
        value = num.value & (0xFFFF if num.tag <= I2 else 0xFFFF_FFFF)
    else:
        value = round_half_away(num.value)
    if not is_user_code(value):
        shown = f"{value:#x}" if abs(value) <= 0xFFFF_FFFF else f"{num.value:g}"
        raise fail(K.TYPE_MISMATCH, f"{shown} is not a user code number")
    return value


def user_key(code: int) -> int:
    """The variable-table key: EB00xxxx and xxxx name the same variable (§17.2)."""
    return code & 0xFFFF if EXT_ALIAS_MIN <= code <= EXT_ALIAS_MAX else code


# ---- numbers ------------------------------------------------------------------------------------
class Num:
    """A tagged number: ``tag`` is I1, I2, I4, R4 or R8 (their order is the §5 strength order)."""

    __slots__ = ("tag", "value")

    def __init__(self, tag: int, value: int | float) -> None:
        self.tag = tag
        self.value = value

    def __eq__(self, other: object) -> bool:
        return (isinstance(other, Num) and self.tag == other.tag
                and (self.value == other.value
                     and math.copysign(1, self.value) == math.copysign(1, other.value)))

    def __hash__(self) -> int:
        return hash((self.tag, self.value))

    def __repr__(self) -> str:
        return f"Num({TAG_NAMES[self.tag]}, {self.value!r})"

    @property
    def is_integer(self) -> bool:
        return self.tag <= I4


def to_float32(value: float) -> float:
    """Round a double to single precision, reporting overflow and underflow (§9)."""
    try:
        rounded = struct.unpack(">f", struct.pack(">f", value))[0]
    except OverflowError:
        raise fail(K.NUMERIC_OVERFLOW, f"{value!r} does not fit R4") from None
    if math.isinf(rounded) and not math.isinf(value):
        raise fail(K.NUMERIC_OVERFLOW, f"{value!r} does not fit R4")
    if rounded == 0.0 and value != 0.0:
        raise fail(K.NUMERIC_UNDERFLOW, f"{value!r} underflows R4")
    return rounded


def make_int(tag: int, value: int) -> Num:
    """An integer of a fixed type; out of range is numeric overflow (no silent wrap)."""
    low, high = INT_RANGE[tag]
    if not low <= value <= high:
        raise fail(K.NUMERIC_OVERFLOW, f"{value} does not fit {TAG_NAMES[tag]}")
    return Num(tag, value)


def wrap_int(tag: int, value: int) -> Num:
    """An integer reduced to the low-order bytes of its type (INC/DEC/INTn, two's complement)."""
    bits = INT_BITS[tag]
    value &= (1 << bits) - 1
    if value >> (bits - 1):
        value -= 1 << bits
    return Num(tag, value)


def make_real(tag: int, value: float) -> Num:
    """A real of a fixed type; infinities and NaN are not STROLIC numbers (Reference 2)."""
    if math.isnan(value):
        raise fail(K.UNDEFINED_DATA, "result is not a number")
    if math.isinf(value):
        raise fail(K.NUMERIC_OVERFLOW, "real result overflows")
    return Num(tag, to_float32(value) if tag == R4 else value)


def make_number(tag: int, value: int | float) -> Num:
    """A number of type ``tag`` with an overflow check."""
    return make_int(tag, int(value)) if tag <= I4 else make_real(tag, float(value))


def converted(num: Num, tag: int) -> int | float:
    """Annex 1 §5: the value of ``num`` in the stronger representation ``tag`` (I1 < I2 < I4 <
    R4 < R8), where mixed arithmetic is done: an integer going to R4 is rounded to single
    precision (I4 33554433 becomes 33554432), every other conversion is exact."""
    if tag <= I4:
        return num.value
    return to_float32(float(num.value)) if tag == R4 else float(num.value)


def smallest_int(value: int) -> Num:
    """The minimal integer type holding ``value`` (INT, LNG, lengths, bare literals)."""
    for tag in INTEGER_TAGS:
        low, high = INT_RANGE[tag]
        if low <= value <= high:
            return Num(tag, value)
    raise fail(K.NUMERIC_OVERFLOW, f"{value} does not fit I4")


def round_half_away(value: float) -> int:
    """Annex 1 §6 rounding of a real where an integer is meant: half away from zero."""
    if math.isnan(value) or math.isinf(value):
        raise fail(K.UNDEFINED_DATA, "cannot round a non-number")
    whole = math.floor(abs(value))
    return int(math.copysign(whole + (abs(value) - whole >= 0.5), value))


TRUE, FALSE = Num(I2, 1), Num(I2, 0)


def logical(flag: bool) -> Num:
    """Annex 1 §7: a logical value is the standard integer 1 or 0."""
    return TRUE if flag else FALSE


# ---- tag heads (the `data-tag-part` of §6.1) ----------------------------------------------------
@dataclass(frozen=True, slots=True)
class TagHead:
    """A tag with its length (St, Rd, Fn, Pm, Ar) and, for Ar, the element head.

    Pushed on the stack by ``#tag`` (§6.2); also the element type of arrays. ``length_tag`` is
    the integer tag a length was written with when that is not its smallest form (§6.2 allows a
    2- or 4-byte integer above 127: I4 for a length that fits I2); the codec keeps it so that
    code re-encodes as it was read. Stack items and values hold ``canonical`` heads only.
    """

    tag: int
    length: int | None = None
    element: "TagHead | None" = None
    length_tag: int | None = None

    def canonical(self) -> "TagHead":
        """The same head with every length in its smallest form."""
        element = self.element.canonical() if self.element is not None else None
        return TagHead(self.tag, self.length, element)

    def element_size(self) -> int:
        """Bytes one value of this head takes without its head (array elements, EXTB)."""
        if self.tag in FIXED_SIZE:
            return FIXED_SIZE[self.tag]
        if self.length is not None:
            return self.length
        raise fail(K.TYPE_MISMATCH, f"{TAG_NAMES[self.tag]} is not a data type")


# ---- values -------------------------------------------------------------------------------------
@dataclass(frozen=True, slots=True)
class Str:
    data: bytes


@dataclass(frozen=True, slots=True)
class Record:
    data: bytes


@dataclass(frozen=True, slots=True)
class Array:
    element: TagHead
    data: bytes


@dataclass(frozen=True, slots=True)
class Function:
    """Function data (§12): the body bytes, END included; ``origin`` is where they were read."""

    body: bytes
    origin: int | None = field(default=None, compare=False)


@dataclass(frozen=True, slots=True)
class Vec:
    xyz: tuple[float, float, float]


@dataclass(frozen=True, slots=True)
class Trn:
    """Homogeneous transform, 12 reals in storage order Px Py Pz Nx Ny Nz Ox Oy Oz Ax Ay Az."""

    values: tuple[float, ...]


@dataclass(frozen=True, slots=True)
class Pose:
    """Pose data (§15): a sequence of tagged numbers (this VM's layout: functions/geometry.py)."""

    elements: tuple[Num, ...]


@dataclass(frozen=True, slots=True)
class UserCode:
    """A user code pushed without evaluation (``#u``)."""

    code: int


@dataclass(frozen=True, slots=True)
class FunctionCode:
    """A built-in function code pushed without evaluation (``#ADD``; VAR pushes itself)."""

    code: int


DATA_TYPES = (Num, Str, Record, Array, Function, Vec, Trn, Pose)
Value = Num | Str | Record | Array | Function | Vec | Trn | Pose | UserCode | FunctionCode | TagHead


def type_name(value: object) -> str:
    """The notation of Tables 2–3 for error messages."""
    if isinstance(value, Num):
        return TAG_NAMES[value.tag]
    return {Str: "St", Record: "Rd", Array: "Ar", Function: "Fn", Vec: "Vec", Trn: "Trn",
            Pose: "Pm", UserCode: "#user code", FunctionCode: "#function code",
            TagHead: "#tag"}.get(type(value), type(value).__name__)
