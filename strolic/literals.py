"""Stack items in the text form (see README.md): used by the disassembler, TRACE and ``--stack``.

Formatting is exact: parsing the text gives back the same value, bit for bit.
"""
from __future__ import annotations

import numpy as np

from . import opcodes
from .codes import (ARRAY, LENGTH_TAGS, R4, R8, TAG_NAMES, Array, Function, FunctionCode, Num,
                    Pose, Record, Str, TagHead, Trn, UserCode, Vec, smallest_int)
from .values import array_elements

PRINTABLE = set(range(0x20, 0x7F)) - {ord('"'), ord("\\")}
ESCAPES = {b: f"\\x{b:02x}" for b in range(256) if b not in PRINTABLE}   # str.translate table
ELEMENTS_AT_ONCE = 4096      # array elements formatted together (a huge array is no huge list)


EXACT_INTEGERS_BELOW = 2.0 ** 53    # integral reals of this size print every digit as it is


def format_real32(value: float) -> str:
    """The shortest decimal that reads back as the same single-precision value, except for an
    integral value whose shortest form names another integer: I4 33554437 × R4 2.5 is R4
    83886088 (Annex 1 §5), whose shortest form 8.388609e+07 read as 83886090."""
    text = str(np.float32(value))
    if value.is_integer() and abs(value) < EXACT_INTEGERS_BELOW and float(text) != value:
        return f"{int(value)}.0"
    return text


def format_number(num: Num, typed: bool = True) -> str:
    """Integers bare when their type is the smallest that holds them, reals bare when R8."""
    if num.tag == R8:
        text = repr(float(num.value))
    elif num.tag == R4:
        text = format_real32(num.value)
    else:
        text = str(num.value)
    bare = num.tag == R8 or (num.tag != R4 and smallest_int(num.value).tag == num.tag)
    return text if bare or not typed else f"{TAG_NAMES[num.tag]}:{text}"


def format_string(data: bytes) -> str:
    """Escaped through a translate table: a string of megabytes costs its text, not a string
    object per byte."""
    return '"' + data.decode("latin-1").translate(ESCAPES) + '"'


def format_head(head: TagHead) -> str:
    """``St(3)``, ``Ar(6, I2)``; a length in a longer form than its smallest is typed:
    ``St(I4:200)``."""
    name = TAG_NAMES[head.tag]
    length = format_number(Num(head.length_tag, head.length)) if head.length_tag else head.length
    if head.tag == ARRAY:
        return f"{name}({length}, {format_head(head.element)})"
    if head.tag in LENGTH_TAGS:
        return f"{name}({length})"
    return name


def format_user_code(code: int) -> str:
    return f"%{code:04X}" if code <= 0xFFFF else f"%{code:08X}"


def format_element(value) -> str:
    """An array element: numbers without type (the array head gives it)."""
    if isinstance(value, Num):
        return format_number(value, typed=False)
    return format_value(value)


def format_elements(array: Array) -> str:
    """The elements of an array, ELEMENTS_AT_ONCE at a time: 16 MiB of I1 would otherwise be
    16 M numbers and their texts at once (gigabytes)."""
    step = array.element.element_size() * ELEMENTS_AT_ONCE or 1
    return " ".join(" ".join(map(format_element, array_elements(Array(array.element, part))))
                    for part in (array.data[i:i + step] for i in range(0, len(array.data), step)))


def format_value(value) -> str:
    """Any stack item in the text form."""
    if isinstance(value, Num):
        return format_number(value)
    if isinstance(value, Str):
        return format_string(value.data)
    if isinstance(value, Record):
        return f"Rd<{value.data.hex()}>"
    if isinstance(value, Function):
        return f"Fn<{value.body.hex()}>"
    if isinstance(value, Vec):
        return "Vec(" + " ".join(format_real32(v) for v in value.xyz) + ")"
    if isinstance(value, Trn):
        return "Trn(" + " ".join(format_real32(v) for v in value.values) + ")"
    if isinstance(value, Pose):
        return "Pm(" + " ".join(format_number(e) for e in value.elements) + ")"
    if isinstance(value, Array):
        elements = format_elements(value)
        return f"Ar[{format_head(value.element)}{' ' if elements else ''}{elements}]"
    if isinstance(value, UserCode):
        return "#" + format_user_code(value.code)
    if isinstance(value, FunctionCode):
        return "#" + opcodes.BY_CODE[value.code].mnemonic
    if isinstance(value, TagHead):
        return "#" + format_head(value)
    raise TypeError(f"not a STROLIC item: {value!r}")
