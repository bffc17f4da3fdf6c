"""EE1F–EE22: format conversion (Annex 2), BASIC style (DECODE1, ENCODE1) and C style (DECODE2,
ENCODE2); the text of data that OUTPUT writes and INPUT, LINPUT read.

A conversion that fails is the exception *conversion error*: the program stops.
"""
from __future__ import annotations

import re
from typing import TYPE_CHECKING

from ..codes import (ARRAY, I2, INT_RANGE, NUMERIC_TAGS, POSE, R4, R8, RECORD, STRING, TAG_NAMES,
                     TRANSFORM, VECTOR, Array, Function, Num, Pose, Record, Str, TagHead, Trn,
                     UserCode, Vec, make_number, round_half_away, type_name, user_key)
from ..errors import ExceptionKind as K, StrolicError, fail
from ..formatting import assignments, basic_encode, c_decode, c_encode, conversion_error
from ..literals import format_head
from ..process import Process
from ..values import array_elements, data_of, head_of
from ..variables import find
from .args import expect, pop_count, pop_head, pop_many, pop_of

if TYPE_CHECKING:
    from ..vm import VM

NUMBER = re.compile(rb"[+-]?(\d+\.?\d*|\.\d+)([eE][+-]?\d+)?")
INTEGER = re.compile(rb"[+-]?\d+")
SEPARATORS = re.compile(rb"[\s,]+")
COUNTS = {VECTOR: 3, TRANSFORM: 12, POSE: 14}


# ---- text → data (DECODE1, LINPUT, INPUT) -------------------------------------------------------
def text_datum(text: bytes):
    """A datum in the text form (``12``, ``2.5``, ``"a b"``, ``Vec(1 2 3)`` …), or None."""
    from ..codec import CodeKind, decode       # here: text.py imports the opcode table
    from ..text import assemble
    try:
        codes = decode(assemble(text.decode("utf-8")))
    except (StrolicError, UnicodeDecodeError):
        return None
    if len(codes) == 1 and codes[0].kind is CodeKind.DATA:
        value = codes[0].value      # a function read from text has no place in the program
        return Function(value.body) if isinstance(value, Function) else value
    return None


def number_from_text(text: bytes, tag: int) -> Num:
    """A BASIC numeric constant converted to type ``tag`` (reals rounded for integer types)."""
    if not NUMBER.fullmatch(text):
        raise conversion_error(f"{text!r} is not a number")
    value = int(text) if INTEGER.fullmatch(text) else float(text)
    if tag not in (R4, R8) and isinstance(value, float):
        value = round_half_away(value)
    try:
        return make_number(tag, value)
    except StrolicError:
        raise conversion_error(f"{text.decode()} does not fit {TAG_NAMES[tag]}") \
            from None


def _same_type(value, head: TagHead) -> bool:
    """The text form gave a datum of the wanted type (array lengths may differ)."""
    if head.tag == ARRAY:
        return isinstance(value, Array) and value.element == head.element
    return head_of(value).tag == head.tag


def decode_text(text: bytes, head: TagHead):
    """DECODE1's conversion: St and Rd take the text as it is; a number is a BASIC numeric
    constant (blanks around it ignored); Vec, Trn, Pm and arrays of numbers are numbers
    separated by blanks or commas, or any datum in the text form (``Vec(1 2 3)``)."""
    tag = head.tag
    if tag == STRING:
        return Str(bytes(text))
    if tag == RECORD:
        return Record(bytes(text))
    text = text.strip()
    if tag in NUMERIC_TAGS:
        return number_from_text(text, tag)
    datum = text_datum(text) if text[:1].isalpha() else None
    if datum is not None and _same_type(datum, head):
        return datum
    words = [word for word in SEPARATORS.split(text) if word]
    if tag in COUNTS and len(words) != COUNTS[tag]:
        raise conversion_error(f"{format_head(head)} needs {COUNTS[tag]} numbers, "
                               f"{text!r} has {len(words)}")
    if tag in (VECTOR, TRANSFORM):
        values = tuple(number_from_text(word, R4).value for word in words)
        return Vec(values) if tag == VECTOR else Trn(values)
    if tag == POSE:
        return Pose(tuple(number_from_text(word, I2 if i == 12 else R8)
                          for i, word in enumerate(words)))
    if tag == ARRAY and head.element.tag in NUMERIC_TAGS:
        return Array(head.element, b"".join(data_of(number_from_text(word, head.element.tag))
                                            for word in words))
    raise conversion_error(f"cannot convert {text!r} to {format_head(head)}")


def decode1(vm: VM, proc: Process) -> None:
    """DECODE1 a #b: string a converted to the type of tag b."""
    head = pop_head(proc)
    proc.push(decode_text(pop_of(proc, Str, "a string").data, head))


# ---- data → text (ENCODE1, ENCODE2), text → variables (DECODE2) ----------------------------------
def scalars(items: list, limit: int) -> list:
    """The data as numbers and strings: Vec, Trn, Pm and arrays give their elements in order;
    at most ``limit`` of them (the data stack's), counted before an array is expanded, so that
    an array of millions of bytes does not become millions of numbers."""
    out = []
    for item in items:
        if isinstance(item, Array) and len(out) + len(item.data) // (
                item.element.element_size() or 1) > limit:
            raise fail(K.STACK_OVERFLOW, f"the data give more than {limit} numbers and strings")
        if isinstance(item, (Num, Str)):
            out.append(item)
        elif isinstance(item, (Vec, Trn)):
            out.extend(Num(R4, v) for v in (item.xyz if isinstance(item, Vec) else item.values))
        elif isinstance(item, Pose):
            out.extend(item.elements)
        elif isinstance(item, Array):
            out.extend(scalars(array_elements(item), limit - len(out)))
        else:
            raise conversion_error(f"{type_name(item)} cannot be converted to text")
    return out


def _pop_data(vm: VM, proc: Process) -> tuple[bytes, list]:
    """a b1 … bn n: the format string and the data (numbers and strings)."""
    items = pop_many(proc, pop_count(proc))
    template = pop_of(proc, Str, "a format string").data
    return template, scalars(items, vm.max_stack)


def encoder(convert):
    """ENCODE1 (BASIC image), ENCODE2 (C format): a b1 … bn n → the string."""
    def handler(vm: VM, proc: Process) -> None:
        text = convert(*_pop_data(vm, proc))
        vm.claim(len(text))
        proc.push(Str(text))
    return handler


encode1, encode2 = encoder(basic_encode), encoder(c_encode)


def decode2(vm: VM, proc: Process) -> None:
    """DECODE2 a b #c1 … #cn n: sscanf of string b with format a; the values go to c1, c2 …
    (as STORE), the count of values (−1: b ended before the first conversion) is pushed."""
    targets = [expect(item, UserCode, "a suppressed user code (#u)")
               for item in pop_many(proc, pop_count(proc))]
    data = pop_of(proc, Str, "a string").data
    template = pop_of(proc, Str, "a format string").data
    stored = assignments(template)
    if stored > len(targets):
        raise conversion_error(f"the format stores {stored} values, "
                               f"{len(targets)} user codes are given")
    if stored > INT_RANGE[I2][1]:
        raise conversion_error(f"the format stores {stored} values; the count is an I2 "
                               f"(at most {INT_RANGE[I2][1]})")
    values, count = c_decode(template, data)
    for target, value in zip(targets, values):
        find(proc.scopes, user_key(target.code)).assign(value)
    proc.push(Num(I2, count))
