"""Program bytes ⇄ codes: the decoder and encoder of §5–§18.

A program is a list of ``Code``: a datum to push, a suppressed item (``#…``), an indirect
reference (``F7 u``) or a function code (built-in or user). Function data bodies are decoded
too, so a program that decodes is syntactically valid all the way down. A length written in
the longer form §6.2 allows is kept in ``Code.head``, so decoding and encoding again gives the
same bytes (branch offsets in function bodies stay right through the text form too).
"""
from __future__ import annotations

import enum
from dataclasses import dataclass

from . import opcodes
from .codes import (END_CODE, FUNCTION, INDIRECT, SUPPRESS, Function, FunctionCode, TagHead,
                    UserCode, is_user_code)
from .errors import read_at
from .values import (MAX_NESTING, Reader, data_of, encode_function_code, encode_head, encode_item,
                     encode_value, invalid, value_from_data)


class CodeKind(enum.Enum):
    DATA = "data"              # push the value
    SUPPRESSED = "suppressed"  # push UserCode / FunctionCode / TagHead unevaluated
    INDIRECT = "indirect"      # evaluate the user code held by a user code
    CALL = "call"              # evaluate a built-in function or a user code


@dataclass(frozen=True, slots=True)
class Code:
    kind: CodeKind
    value: object
    offset: int
    size: int
    head: TagHead | None = None   # a datum's or #tag's head as written, when not canonical


def written(head: TagHead) -> TagHead | None:
    """The ``Code.head`` to keep for ``head``: None when its lengths are in the smallest form."""
    return None if head == head.canonical() else head


EXTENDED_PREFIX = 0xEB   # first byte of the 4-byte user codes decoded here (EA… is 2-byte)
FIRST_TAG = SUPPRESS     # bytes F0–FF start data, lower bytes start function codes (§A.19)


def code_width(first: int) -> int:
    return 4 if first == EXTENDED_PREFIX else 2


def read_function_code(reader: Reader, first: int) -> int:
    start = reader.offset - 1
    code = int.from_bytes(bytes([first]) + reader.take(code_width(first) - 1), "big")
    if not (is_user_code(code) or code in opcodes.BY_CODE):
        raise invalid(f"0x{code:04X} is neither a STROLIC function nor a user code", start)
    return code


def read_code(reader: Reader, depth: int) -> Code:
    start = reader.offset
    first = reader.byte()
    if first == SUPPRESS:
        second = reader.byte()
        if second >= FIRST_TAG:
            head = reader.head(second)
            return Code(CodeKind.SUPPRESSED, head.canonical(), start, reader.offset - start,
                        written(head))
        code = read_function_code(reader, second)
        item = UserCode(code) if is_user_code(code) else FunctionCode(code)
        return Code(CodeKind.SUPPRESSED, item, start, reader.offset - start)
    if first == INDIRECT:
        second = reader.byte()
        code = read_function_code(reader, second)
        if not is_user_code(code):
            raise invalid("an indirect reference needs a user code", start)
        return Code(CodeKind.INDIRECT, code, start, reader.offset - start)
    if first >= FIRST_TAG:
        head = reader.head(first)
        if head.tag == INDIRECT:
            raise invalid("indirect reference without user code", start)
        data_offset = reader.offset
        value = value_from_data(head.canonical(), reader.take(head.element_size()), data_offset)
        if head.tag == FUNCTION:
            if depth >= MAX_NESTING:
                raise invalid(f"function data nested deeper than {MAX_NESTING}", start)
            decode(value.body, data_offset, function_body=True, depth=depth + 1)
        return Code(CodeKind.DATA, value, start, reader.offset - start, written(head))
    return Code(CodeKind.CALL, read_function_code(reader, first), start, reader.offset - start)


def decode(data: bytes, base: int = 0, *, function_body: bool = False,
           depth: int = 0) -> list[Code]:
    """All codes of ``data``; offsets are counted from ``base``. Raises StrolicError only."""
    reader = Reader(bytes(data), base)
    codes = []
    while not reader.at_end():
        codes.append(read_code(reader, depth))
    if function_body and (not codes or codes[-1].kind is not CodeKind.CALL
                          or codes[-1].value != END_CODE):
        raise invalid("function data must end with END", base)
    return codes


def decode_function(function: Function) -> list[Code]:
    """The codes of a function body, offsets relative to where it was read (or to its start:
    a body made at run time has no place in the program, see ``read_at``)."""
    with read_at(function.origin):
        return decode(function.body, function.origin or 0, function_body=True)


def encode_code(code: Code) -> bytes:
    if code.head is not None:
        head = encode_head(code.head)
        if code.kind is CodeKind.DATA:
            return head + data_of(code.value)
        return bytes([SUPPRESS]) + head
    if code.kind is CodeKind.DATA:
        return encode_value(code.value)
    if code.kind is CodeKind.CALL:
        return encode_function_code(code.value)
    if code.kind is CodeKind.INDIRECT:
        return bytes([INDIRECT]) + encode_function_code(code.value)
    return encode_item(code.value)


def encode(codes: list[Code]) -> bytes:
    return b"".join(encode_code(code) for code in codes)
