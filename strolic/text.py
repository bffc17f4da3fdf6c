"""The text form: assembler (text → codes → bytes) and disassembler (bytes → text).

One code per token group; see README.md for the grammar. ``assemble(disassemble(b)) == b``
for every program ``b`` that decodes.
"""
from __future__ import annotations

import re

from . import opcodes
from .codec import Code, CodeKind, decode, decode_function, encode, encode_code, written
from .codes import (ARRAY, FUNCTION, I2, INDIRECT, LENGTH_TAGS, NUMERIC_TAGS, R8, REAL_TAGS,
                    SUPPRESS, TAGS_BY_NAME, Array, Function, FunctionCode, Num, Pose, Record, Str,
                    TagHead, Trn, UserCode, Vec, is_user_code, make_number, smallest_int,
                    to_float32)
from .errors import ExceptionKind as K, StrolicError
from .literals import format_head, format_user_code, format_value
from .values import MAX_NESTING, data_of, head_of, length_tag_of, value_from_data

TOKEN = re.compile(r'''(?P<skip>[\s,]+|;[^\n]*)
                     |(?P<string>"(?:[^"\\]|\\.)*")
                     |(?P<hex><[0-9A-Fa-f\s]*>)
                     |(?P<punct>[()\[\]{}])
                     |(?P<word>[^\s,;()\[\]{}"<]+)''', re.VERBOSE)
INTEGER = re.compile(r"[+-]?(0[xX][0-9A-Fa-f]+|\d+)$")
REAL = re.compile(r"[+-]?(\d+\.\d*|\.\d+|\d+)([eE][+-]?\d+)?$")
ESCAPES = {"n": 10, "t": 9, "r": 13, "0": 0, '"': 34, "\\": 92}


class AsmError(StrolicError):
    """A text that is not a program; ``offset`` is the line number."""

    def __init__(self, detail: str, line: int) -> None:
        super().__init__(K.INVALID_CODE, detail, function=f"line {line}")


def tokenize(text: str) -> list[tuple[str, str, int]]:
    tokens, line, pos = [], 1, 0
    while pos < len(text):
        match = TOKEN.match(text, pos)
        if match is None:
            raise AsmError(f"cannot read {text[pos:pos + 10]!r}", line)
        if match.lastgroup != "skip":
            tokens.append((match.lastgroup, match.group(), line))
        line += match.group().count("\n")
        pos = match.end()
    return tokens


class Assembler:
    """Recursive descent over the tokens; produces codes (their offsets come from decoding)."""

    def __init__(self, text: str) -> None:
        self.tokens = tokenize(text)
        self.pos = 0
        self.names: dict[str, int] = {}
        self.depth = 0
        self.array_depth = 0

    # ---- token access --------------------------------------------------------------------
    def peek(self) -> tuple[str, str, int] | None:
        return self.tokens[self.pos] if self.pos < len(self.tokens) else None

    def next(self) -> tuple[str, str, int]:
        token = self.peek()
        if token is None:
            line = self.tokens[-1][2] if self.tokens else 1
            raise AsmError("unexpected end of text", line)
        self.pos += 1
        return token

    def expect(self, text: str) -> None:
        kind, value, line = self.next()
        if value != text:
            raise AsmError(f"{text!r} expected, found {value!r}", line)

    def error(self, detail: str) -> AsmError:
        token = self.tokens[self.pos - 1] if self.pos else (None, None, 1)
        return AsmError(detail, token[2])

    # ---- programs ------------------------------------------------------------------------------
    def program(self, closing: str | None = None) -> list[Code]:
        """Codes up to ``closing``; labels (``name:``) and references (``>name``) are local."""
        codes: list[Code] = []
        labels: dict[str, int] = {}
        references: list[tuple[int, str, int]] = []
        while True:
            token = self.peek()
            if token is None and closing is not None:
                raise self.error(f"{closing!r} missing")
            if token is None or token[1] == closing:
                self.pos += token is not None
                return resolve_labels(codes, labels, references)
            self.pos += 1
            kind, word, line = token
            if word == ".name":
                self.define_name()
            elif kind == "word" and word.endswith(":") and len(word) > 1:
                if word[:-1] in labels:
                    raise self.error(f"label {word[:-1]!r} is defined twice")
                labels[word[:-1]] = len(codes)
            elif kind == "word" and word.startswith(">") and len(word) > 1:
                references.append((len(codes), word[1:], line))
                codes.append(Code(CodeKind.DATA, Num(I2, 0), 0, 0))
            else:
                codes.append(self.code(kind, word, line))

    def define_name(self) -> None:
        _, name, line = self.next()
        if name in opcodes.BY_MNEMONIC or name in TAGS_BY_NAME or not name.isidentifier():
            raise AsmError(f"{name!r} cannot name a user code", line)
        self.names[name] = self.user_code(self.next()[1])

    def code(self, kind: str, word: str, line: int) -> Code:
        try:
            return self.code_from(kind, word)
        except StrolicError as error:
            if isinstance(error, AsmError):
                raise
            raise AsmError(error.detail, line) from None

    def code_from(self, kind: str, word: str) -> Code:
        if kind == "word" and word.startswith("#") and len(word) > 1:
            item = self.suppressed(word[1:])
            if isinstance(item, TagHead):
                return Code(CodeKind.SUPPRESSED, item.canonical(), 0, 0, written(item))
            return Code(CodeKind.SUPPRESSED, item, 0, 0)
        if kind == "word" and word.startswith("=") and len(word) > 1:
            return self.written_datum(self.head(word[1:]))
        if kind == "word" and word.startswith("@"):
            return Code(CodeKind.INDIRECT, self.user_code(word[1:]), 0, 0)
        if kind == "word" and word == "Fn" and self.peek() and self.peek()[1] == "{":
            self.pos += 1
            self.depth += 1
            if self.depth > MAX_NESTING:
                raise self.error(f"function data nested deeper than {MAX_NESTING}")
            body = encode(self.program("}"))
            self.depth -= 1
            return Code(CodeKind.DATA, Function(body), 0, 0)
        if kind == "word" and (word in opcodes.BY_MNEMONIC or word in self.names
                               or word.startswith("%")):
            code = (opcodes.BY_MNEMONIC[word].code if word in opcodes.BY_MNEMONIC
                    else self.user_code(word))
            return Code(CodeKind.CALL, code, 0, 0)
        return Code(CodeKind.DATA, self.literal(kind, word), 0, 0)

    def written_datum(self, head: TagHead) -> Code:
        """``=St(I4:200) "…"``: the datum that follows, written with ``head`` (its lengths in
        the forms given)."""
        if written(head) is None:
            raise self.error(f"={format_head(head)} has no length in a longer form: leave it out")
        kind, word, line = self.next()
        code = self.code(kind, word, line)
        if code.kind is not CodeKind.DATA or head_of(code.value) != head.canonical():
            raise AsmError(f"the head ={format_head(head)} does not describe {word!r}", line)
        return Code(CodeKind.DATA, code.value, 0, 0, head)

    def user_code(self, word: str) -> int:
        if word in self.names:
            return self.names[word]
        if not word.startswith("%"):
            raise self.error(f"unknown name {word!r}")
        try:
            code = int(word[1:], 16)
        except ValueError:
            raise self.error(f"{word!r} is not a user code number") from None
        if not is_user_code(code) or (code > 0xFFFF) != (len(word) > 5):
            raise self.error(f"{word!r} is not a user code (1000–EAFF, EB000000–EBFFFFFF)")
        return code

    def suppressed(self, word: str):
        if word == "#":
            return TagHead(SUPPRESS)
        if word in opcodes.BY_MNEMONIC:
            return FunctionCode(opcodes.BY_MNEMONIC[word].code)
        if word in TAGS_BY_NAME:
            return self.head(word)
        return UserCode(self.user_code(word))

    # ---- data ------------------------------------------------------------------------------------
    def head(self, name: str, depth: int = 0) -> TagHead:
        tag = TAGS_BY_NAME.get(name)
        if depth > MAX_NESTING:
            raise self.error(f"arrays nested deeper than {MAX_NESTING}")
        if tag is None:
            raise self.error(f"{name!r} is not a tag")
        if tag == ARRAY:
            self.expect("(")
            length, length_tag = self.length(self.next()[1])
            element = self.head(self.next()[1], depth + 1)
            self.expect(")")
            if element.tag in (SUPPRESS, INDIRECT):
                raise self.error("array elements must be data")
            return TagHead(tag, length, element, length_tag)
        if tag in LENGTH_TAGS:
            self.expect("(")
            length, length_tag = self.length(self.next()[1])
            self.expect(")")
            return TagHead(tag, length, length_tag=length_tag)
        return TagHead(tag)

    def length(self, word: str) -> tuple[int, int | None]:
        """A length in a head: ``200`` (the smallest form) or typed, ``I4:200`` (§6.2)."""
        num = self.number(word)
        if not num.is_integer or num.value < 0:
            raise self.error(f"{word!r} is not a length")
        return num.value, length_tag_of(num.tag, num.value)

    def integer(self, word: str) -> int:
        if not INTEGER.match(word):
            raise self.error(f"{word!r} is not an integer")
        return int(word, 0) if "x" in word.lower() else int(word)

    def number(self, word: str, tag: int | None = None) -> Num:
        """A numeric literal; ``tag`` forces the type (typed literals and array elements)."""
        element = tag is not None
        if ":" in word:
            name, word = word.split(":", 1)
            if TAGS_BY_NAME.get(name) not in NUMERIC_TAGS:
                raise self.error(f"{name!r} is not a numeric type")
            tag = TAGS_BY_NAME[name]
        if INTEGER.match(word):
            value = self.integer(word)
            return smallest_int(value) if tag is None else make_number(tag, value)
        if REAL.match(word) and (tag is None or tag in REAL_TAGS):
            return make_number(tag or R8, float(word))
        if element and not NUMBER_START.match(word):
            raise self.error(f"{word!r} where a number of the array was expected (is its ] "
                             "missing?)")
        raise self.error(f"{word!r} is not a number{' of that type' if tag else ''}")

    def reals(self, count: int) -> tuple[float, ...]:
        self.expect("(")
        values = tuple(to_float32(float(self.number(self.next()[1]).value)) for _ in range(count))
        self.expect(")")
        return values

    def blob(self) -> bytes:
        kind, word, _ = self.next()
        if kind != "hex":
            raise self.error("<hex bytes> expected")
        try:
            return bytes.fromhex("".join(word[1:-1].split()))
        except ValueError:
            raise self.error(f"{word!r}: hex bytes are pairs of hex digits") from None

    def literal(self, kind: str, word: str):
        if kind == "string":
            return Str(unescape(word[1:-1], self))
        if kind != "word":
            raise self.error(f"{word!r} is not a code")
        if word == "Vec":
            return Vec(self.reals(3))
        if word == "Trn":
            return Trn(self.reals(12))
        if word == "Rd":
            return Record(self.blob())
        if word == "Fn":
            return value_from_data(TagHead(FUNCTION, 0), self.blob())
        if word == "Pm":
            self.expect("(")
            elements = []
            while self.peek() and self.peek()[1] != ")":
                elements.append(self.number(self.next()[1]))
            self.expect(")")
            return Pose(tuple(elements))
        if word == "Ar":
            return self.array()
        if ":" not in word and not NUMBER_START.match(word):
            raise self.error(f"{word!r} is no function, name or number (a misspelt function, "
                             "or a name without .name?)")
        return self.number(word)

    def array(self) -> Array:
        """``Ar[head elements…]``; array literals in array literals are counted, as heads are,
        so that a deep nest is an error and not a Python recursion error."""
        self.expect("[")
        self.array_depth += 1
        if self.array_depth > MAX_NESTING:
            raise self.error(f"arrays nested deeper than {MAX_NESTING}")
        element = self.head(self.next()[1])
        if element.tag in (SUPPRESS, INDIRECT):
            raise self.error("array elements must be data")
        if written(element):
            raise self.error("a longer length form in an element head goes in the =Ar(…) head")
        data = []
        while self.peek() and self.peek()[1] != "]":
            kind, word, _ = self.next()
            value = (self.number(word, element.tag) if element.tag in NUMERIC_TAGS
                     else self.literal(kind, word))
            if head_of(value) != element:
                raise self.error(f"element {word!r} is not of the element type")
            data.append(data_of(value))
        self.expect("]")
        self.array_depth -= 1
        return Array(element, b"".join(data))


def resolve_labels(codes: list[Code], labels: dict[str, int],
                   references: list[tuple[int, str, int]]) -> list[Code]:
    """A reference ``>name`` is an I2 branch offset from the end of the code after it."""
    starts = [0]
    for code in codes:
        starts.append(starts[-1] + len(encode_code(code)))
    for index, name, line in references:
        if name not in labels:
            raise AsmError(f"label {name!r} is not defined here", line)
        if index + 1 >= len(codes):
            raise AsmError(f"a branch code must follow >{name}", line)
        offset = starts[labels[name]] - starts[index + 2]
        codes[index] = Code(CodeKind.DATA, make_number(I2, offset), 0, 0)
    return codes


HEX_ESCAPE = re.compile(r"[0-9A-Fa-f]{1,2}")
NUMBER_START = re.compile(r"[+-]?(\d|\.\d|inf|nan)", re.IGNORECASE)   # what a number can begin with

def unescape(body: str, assembler: Assembler) -> bytes:
    out, i = bytearray(), 0
    while i < len(body):
        char = body[i]
        if char != "\\":
            if "\ud800" <= char <= "\udfff":
                raise assembler.error(f"a lone surrogate (U+{ord(char):04X}) in a string: not "
                                      "a character UTF-8 can hold")
            out += char.encode("utf-8")
            i += 1
        elif body[i + 1:i + 2] == "x":
            digits = HEX_ESCAPE.match(body, i + 2)
            if digits is None:
                raise assembler.error(f"{body[i:i + 4]!r}: \\x takes one or two hex digits")
            out.append(int(digits.group(), 16))
            i = digits.end()
        elif body[i + 1:i + 2] in ESCAPES:
            out.append(ESCAPES[body[i + 1]])
            i += 2
        else:
            raise assembler.error(f"unknown escape in string: {body[i:i + 2]!r}")
    return bytes(out)


def assemble_codes(text: str) -> list[Code]:
    return Assembler(text).program()


def assemble(text: str) -> bytes:
    """Text form → program bytes (validated by decoding them again)."""
    program = encode(assemble_codes(text))
    decode(program)
    return program


# ---- disassembler -------------------------------------------------------------------------------
def format_code(code: Code) -> str:
    if code.kind is CodeKind.CALL:
        row = opcodes.BY_CODE.get(code.value)
        return row.mnemonic if row else format_user_code(code.value)
    if code.kind is CodeKind.INDIRECT:
        return "@" + format_user_code(code.value)
    if code.kind is CodeKind.SUPPRESSED and code.head is not None:
        return "#" + format_head(code.head)
    return written_prefix(code) + format_value(code.value)


def written_prefix(code: Code) -> str:
    """``=head `` before a datum whose head was written with a longer length form."""
    return f"={format_head(code.head)} " if code.head is not None else ""


def disassemble_codes(codes: list[Code], indent: int = 0, offsets: bool = False) -> list[str]:
    """Lines of text; with ``offsets`` each ends in a comment giving the code's byte offset."""
    lines = []
    pad = "  " * indent
    for code in codes:
        note = f"  ; @{code.offset}" if offsets else ""
        if code.kind is CodeKind.DATA and isinstance(code.value, Function):
            lines.append(pad + written_prefix(code) + "Fn{" + note)
            lines.extend(disassemble_codes(decode_function(code.value), indent + 1, offsets))
            lines.append(pad + "}")
        else:
            lines.append(pad + format_code(code) + note)
    return lines


def disassemble(program: bytes, offsets: bool = False) -> str:
    """Program bytes → text form, one code per line, function bodies indented."""
    return "\n".join(disassemble_codes(decode(program), offsets=offsets)) + "\n"
