"""Bytes of data values: head (tag, length, element tag) and data part, both ways.

Used by the program codec, by arrays (elements are data parts under one element head), by the
heap areas and by EXTB/EMBB, so the byte layout of §6–§15 is written down once, here.
"""
from __future__ import annotations

import math
import struct

import numpy as np

from .codes import (ARRAY, FIXED_SIZE, FUNCTION, I1, INDIRECT, INT_FORMAT, INTEGER_TAGS,
                    LENGTH_TAGS, NUMERIC_TAGS, POSE, R4, R8, REAL_FORMAT, RECORD, STRING,
                    SUPPRESS, TAG_NAMES, TRANSFORM, VECTOR, Array, Function, FunctionCode, Num,
                    Pose, Record, Str, TagHead, Trn, UserCode, Vec, smallest_int)
from .errors import ExceptionKind as K, fail, read_at


# Bytes counted for a registration without an area, and for an event flag that is on: what
# the interpreter's objects for one take (DCL in a loop grew to 1.1 GB with nothing counted).
ENTRY_BYTES = 256


def invalid(detail: str, offset: int | None = None) -> Exception:
    error = fail(K.INVALID_CODE, detail)
    error.offset = offset
    return error


# ---- lengths and numbers ------------------------------------------------------------------------
def encode_length(length: int, tag: int | None = None) -> bytes:
    """§6.2: a length is a tagged integer; written in the smallest form unless ``tag`` (a
    head's ``length_tag``) names the longer one it was read in."""
    tag = tag or smallest_int(length).tag
    return bytes([tag]) + struct.pack(INT_FORMAT[tag], length)


def length_tag_of(tag: int, length: int, offset: int | None = None) -> int | None:
    """The ``length_tag`` of a length written with the integer tag ``tag``: None for its
    smallest form, ``tag`` for the other form §6.2 allows ("127以下の値ならタグ付きの1バイトの
    整数を用い,それ以上なら2バイト又は4バイトの整数を用いる": an I4 for 128–32767); a length of
    127 or less in I2 or I4 is invalid code."""
    smallest = smallest_int(length).tag
    if tag == smallest:
        return None
    if smallest == I1:
        raise invalid(f"length {length} must be an I1 (127 or less)", offset)
    return tag


def encode_number_data(num: Num) -> bytes:
    fmt = INT_FORMAT.get(num.tag) or REAL_FORMAT[num.tag]
    return struct.pack(fmt, num.value)


def decode_number_data(tag: int, data: bytes, offset: int = 0) -> Num:
    """Big-endian two's complement integers and IEEE 754 reals (Reference 2: no NaN, no ∞)."""
    if tag in INT_FORMAT:
        return Num(tag, struct.unpack(INT_FORMAT[tag], data)[0])
    value = struct.unpack(REAL_FORMAT[tag], data)[0]
    if math.isnan(value) or math.isinf(value):
        raise invalid(f"{TAG_NAMES[tag]} bit pattern is not a number", offset)
    return Num(tag, value)


MAX_NESTING = 64     # array heads in array heads, function data in function data
MAX_DATUM = 1 << 24  # bytes of the data part of one datum made at run time (the default heap)


def check_datum_size(size: int) -> None:
    """A function is about to make a datum of ``size`` bytes (CONC, CONSA, ENCODE1 …): one
    longer than the whole heap is refused before it is made, so doubling a string cannot
    take the machine's memory."""
    if size > MAX_DATUM:
        raise fail(K.MEMORY_EXHAUSTED, f"a datum of {size} bytes (at most {MAX_DATUM})")


class Reader:
    """A cursor over code bytes; ``base`` turns positions into offsets of the whole program."""

    def __init__(self, data: bytes, base: int = 0) -> None:
        self.data = data
        self.pos = 0
        self.base = base

    @property
    def offset(self) -> int:
        return self.base + self.pos

    def at_end(self) -> bool:
        return self.pos >= len(self.data)

    def take(self, count: int) -> bytes:
        if count < 0 or self.pos + count > len(self.data):
            raise invalid(f"code ends inside a datum (needs {count} bytes)", self.offset)
        chunk = self.data[self.pos:self.pos + count]
        self.pos += count
        return chunk

    def byte(self) -> int:
        return self.take(1)[0]

    def number(self) -> Num:
        start = self.offset
        tag = self.byte()
        if tag not in NUMERIC_TAGS:
            raise invalid(f"0x{tag:02X} is not a numeric tag", start)
        return decode_number_data(tag, self.take(FIXED_SIZE[tag]), start)

    def length(self) -> tuple[int, int | None]:
        """A length, non-negative, in a form §6.2 allows: the value and its ``length_tag``."""
        start = self.offset
        tag = self.byte()
        if tag not in INTEGER_TAGS:
            raise invalid("a length must be a tagged integer", start)
        value = decode_number_data(tag, self.take(FIXED_SIZE[tag])).value
        if value < 0:
            raise invalid(f"negative length {value}", start)
        return value, length_tag_of(tag, value, start)

    def head(self, first: int, depth: int = 0) -> TagHead:
        """The data-tag-part after its first byte ``first`` (§6.1)."""
        start = self.offset - 1
        if depth > MAX_NESTING:
            raise invalid(f"arrays nested deeper than {MAX_NESTING}", start)
        tag = first
        if first == 0xFF:
            tag = 0xFF00 | self.byte()
        if tag in FIXED_SIZE or tag in (SUPPRESS, INDIRECT):
            return TagHead(tag)
        if tag == ARRAY:
            length, length_tag = self.length()
            element_first = self.byte()
            element = self.head(element_first, depth + 1)
            if element.tag in (SUPPRESS, INDIRECT):
                raise invalid("array elements must be data", start)
            return TagHead(tag, length, element, length_tag)
        if tag in LENGTH_TAGS:
            length, length_tag = self.length()
            return TagHead(tag, length, length_tag=length_tag)
        raise invalid(f"reserved or undefined tag 0x{tag:X}", start)


# ---- heads --------------------------------------------------------------------------------------
def encode_head(head: TagHead) -> bytes:
    tag = head.tag.to_bytes(2 if head.tag > 0xFF else 1, "big")
    if head.tag == ARRAY:
        return tag + encode_length(head.length, head.length_tag) + encode_head(head.element)
    if head.tag in LENGTH_TAGS:
        return tag + encode_length(head.length, head.length_tag)
    return tag


def head_of(value: object) -> TagHead:
    """The head a value is written with."""
    if isinstance(value, Num):
        return TagHead(value.tag)
    if isinstance(value, Array):
        return TagHead(ARRAY, len(value.data), value.element)
    if isinstance(value, (Vec, Trn)):
        return TagHead(VECTOR if isinstance(value, Vec) else TRANSFORM)
    tag = {Str: STRING, Record: RECORD, Function: FUNCTION, Pose: POSE}.get(type(value))
    if tag is None:
        raise fail(K.TYPE_MISMATCH, f"{type(value).__name__} is not data")
    return TagHead(tag, len(data_of(value)))


def data_of(value: object) -> bytes:
    """The data part: the bytes after the head."""
    if isinstance(value, Num):
        return encode_number_data(value)
    if isinstance(value, (Str, Record, Array)):
        return value.data
    if isinstance(value, Function):
        return value.body
    if isinstance(value, Vec):
        return struct.pack(">3f", *value.xyz)
    if isinstance(value, Trn):
        return struct.pack(">12f", *value.values)
    if isinstance(value, Pose):
        return b"".join(bytes([e.tag]) + encode_number_data(e) for e in value.elements)
    raise fail(K.TYPE_MISMATCH, f"{type(value).__name__} is not data")


def encode_value(value: object) -> bytes:
    """A tagged data code."""
    return encode_head(head_of(value)) + data_of(value)


def encode_item(item: object) -> bytes:
    """Any stack item as code: data, or a suppressed user code, function code or tag (#…)."""
    if isinstance(item, TagHead):
        return bytes([SUPPRESS]) + encode_head(item)
    if isinstance(item, (UserCode, FunctionCode)):
        return bytes([SUPPRESS]) + encode_function_code(item.code)
    return encode_value(item)


def encode_function_code(code: int) -> bytes:
    """2-byte codes, 4-byte extended user codes."""
    return code.to_bytes(4 if code > 0xFFFF else 2, "big")


def value_from_data(head: TagHead, data: bytes, offset: int | None = None) -> object:
    """The value that ``head`` and its data part ``data`` describe (data of the exact size).
    ``offset`` is where the data part stands in the program; data made at run time (EXTB, EXTE,
    an area after EMBB) has none, so that an error is located at the code that reads it."""
    if head.tag == FUNCTION:
        return Function(bytes(data), offset)
    with read_at(offset):
        return _value_from_data(head, data, offset or 0)


def _value_from_data(head: TagHead, data: bytes, offset: int) -> object:
    tag = head.tag
    if tag in NUMERIC_TAGS:
        return decode_number_data(tag, data, offset)
    if tag == STRING:
        return Str(bytes(data))
    if tag == RECORD:
        return Record(bytes(data))
    if tag in (VECTOR, TRANSFORM):
        count = 3 if tag == VECTOR else 12
        values = struct.unpack(f">{count}f", data)
        if any(math.isnan(v) or math.isinf(v) for v in values):
            raise invalid("vector or transform element is not a number", offset)
        return Vec(values) if tag == VECTOR else Trn(values)
    if tag == ARRAY:
        size = head.element.element_size()
        if (size == 0 and data) or (size and len(data) % size):
            raise invalid(f"array length {len(data)} is not a multiple of element size {size}",
                          offset)
        _check_elements(head.element, data, size, offset)
        return Array(head.element, bytes(data))
    if tag == POSE:
        reader = Reader(bytes(data), offset)
        elements = []
        while not reader.at_end():
            elements.append(reader.number())
        return Pose(tuple(elements))
    raise invalid(f"{TAG_NAMES.get(tag, hex(tag))} has no data", offset)


# elements checked at once: every bit pattern is valid data, or a real's must be finite
_ANY_BITS = (*INTEGER_TAGS, STRING, RECORD, FUNCTION)
_REAL_DTYPES = {R4: ">f4", R8: ">f8", VECTOR: ">f4", TRANSFORM: ">f4"}


def _check_elements(element: TagHead, data: bytes, size: int, offset: int) -> None:
    """Every element of an array's data part must be valid data. Flat elements are checked at
    once (element by element, a 16 MiB area took 4.5 s to read back); nested ones one by one."""
    if element.tag in _ANY_BITS:
        return
    if element.tag in _REAL_DTYPES:
        reals = np.frombuffer(data, dtype=_REAL_DTYPES[element.tag])
        bad = np.flatnonzero(~np.isfinite(reals))
        if len(bad):
            at = int(bad[0]) * reals.itemsize // size * size
            _value_from_data(element, data[at:at + size], offset + at)    # says what is wrong
        return
    for start in range(0, len(data), size or 1):
        _value_from_data(element, data[start:start + size], offset + start)


def array_elements(array: Array) -> list:
    """The elements of an array as values (smallest subscript first)."""
    size = array.element.element_size()
    return [value_from_data(array.element, array.data[i:i + size])
            for i in range(0, len(array.data), size)] if size else []

