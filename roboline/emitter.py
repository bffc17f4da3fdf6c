"""What the compiler's parts share: the routine and body being compiled, errors at a place,
and emitting STROLIC codes (with the line each comes from) into a function body."""
from __future__ import annotations

from dataclasses import dataclass, field

from lark import Token, Tree

from strolic.codes import I2, TagHead, UserCode, make_number
from strolic.opcodes import BY_MNEMONIC
from strolic.values import encode_function_code, encode_item, encode_value

from .builtins import TYPES
from .program import Symbol
from .source import Source, SourceError

FIRST_KEY = 0x1000
LAST_KEY = 0xEAFE


@dataclass
class Routine:
    name: str
    key: int
    params: list[tuple[str, str]]
    result: str | None          # FUNCTION's type; None for a SUB
    tree: Tree | None = None


@dataclass
class Body:
    """One function body as it is emitted: its bytes, where each code starts and its line,
    its labels (byte offsets) and its branches (where the offset goes, the label, where the
    branch code ends)."""
    code: bytearray = field(default_factory=bytearray)
    starts: list[int] = field(default_factory=list)
    lines: list[int] = field(default_factory=list)
    labels: dict[str, int] = field(default_factory=dict)
    references: list[tuple[int, str, int]] = field(default_factory=list)
    label_lines: dict[str, Token] = field(default_factory=dict)


@dataclass
class Encoded:
    """A function body's bytes, and the byte offset and line of each of its codes."""
    code: bytes
    starts: list[int]
    lines: list[int]


# the bytes of the codes emitted most, made once (each code is encoded the first time it is
# emitted, not kept as an object to encode at the end)
OPS = {mnemonic: encode_function_code(op.code) for mnemonic, op in BY_MNEMONIC.items()}
BRANCH_PLACEHOLDER = encode_value(make_number(I2, 0))


def named(type_: str) -> str:
    """A type as an error message names it: "an INT", "a POSE"."""
    name = DISPLAY.get(type_, type_.upper())
    return f"{'an' if name[0] in 'AEIOU' else 'a'} {name}"


DISPLAY = {"flag": "INT", "num": "NUMBER", "real": "NUMBER", "poses": "POSE or PATH"}


def position(node) -> tuple[int, int]:
    """Line and column of the first token of a tree (or of a token)."""
    if isinstance(node, Token):
        return node.line, node.column
    for token in node.scan_values(lambda v: isinstance(v, Token)):
        return token.line, token.column
    return 0, 0


class Emitter:
    """Codes into `body`, each with the current source `line`."""

    source: Source
    body: Body
    line: int
    next_key: int
    serial: int
    globals: dict[str, Symbol]
    locals: dict[str, Symbol]
    routine: Routine | None

    def error(self, node, message: str) -> SourceError:
        line, column = position(node)
        return SourceError(self.source, line or self.line, column, message)

    def new_key(self, node) -> int:
        if self.next_key > LAST_KEY:
            raise self.error(node, "too many names for the user codes of STROLIC")
        key, self.next_key = self.next_key, self.next_key + 1
        return key

    def declare(self, name: Token, type_: str, table: dict[str, Symbol]) -> Symbol:
        upper = name.upper()
        if upper in table or (table is self.globals and upper in self.routines):
            raise self.error(name, f"{name} is declared twice")
        symbol = Symbol(str(name), type_, self.new_key(name),
                        self.routine.name if table is self.locals and self.routine else "")
        table[upper] = symbol
        return symbol

    def variable(self, name: Token) -> Symbol | None:
        upper = name.upper()
        return self.locals.get(upper) or self.globals.get(upper)

    def type_of(self, name: Token) -> str:
        if name.upper() not in TYPES:
            raise self.error(name, f"{name} is no type; expected one of: "
                             + ", ".join(sorted(TYPES)))
        return TYPES[name.upper()]

    def emit(self, code: bytes) -> None:
        """One code's bytes, kept with the current line."""
        body = self.body
        body.starts.append(len(body.code))
        body.lines.append(self.line)
        body.code += code

    def op(self, *mnemonics: str) -> None:
        for mnemonic in mnemonics:
            self.emit(OPS[mnemonic])

    def push(self, value) -> None:
        self.emit(encode_value(value))

    def suppressed(self, key: int) -> None:
        self.emit(encode_item(UserCode(key)))

    def suppressed_tag(self, head: TagHead) -> None:
        self.emit(encode_item(head))

    def evaluate(self, key: int) -> None:
        self.emit(encode_function_code(key))

    def new_label(self) -> str:
        self.serial += 1
        return f" {self.serial}"          # a blank: never a label of the source

    def place(self, label: str, node=None) -> None:
        if label in self.body.labels:
            raise self.error(node, f"label {label} is defined twice in this routine")
        self.body.labels[label] = len(self.body.code)

    def branch(self, label: str, mnemonic: str, node=None) -> None:
        """An I2 offset (to the label, from the end of the branch code) and the branch code."""
        if node is not None:
            self.body.label_lines.setdefault(label, node)
        at = len(self.body.code)
        self.emit(BRANCH_PLACEHOLDER)
        self.op(mnemonic)
        self.body.references.append((at, label, len(self.body.code)))

    def finish_body(self) -> Encoded:
        """The body's bytes (ending in END, the branch offsets filled in) and the places and
        lines of its codes."""
        self.op("END")
        body = self.body
        for at, label, end in body.references:
            if label not in body.labels:
                raise self.error(body.label_lines[label], f"label {label} is not defined "
                                 "in this routine")
            body.code[at:at + len(BRANCH_PLACEHOLDER)] = encode_value(
                make_number(I2, body.labels[label] - end))
        return Encoded(bytes(body.code), body.starts, body.lines)

    def check_count(self, args: list, count: int, node) -> None:
        if len(args) != count:
            raise self.error(node, f"{node} takes {count} argument{'s' * (count != 1)}, "
                             f"not {len(args)}")

    def number_value(self, token: Token) -> int | float:
        text = str(token)
        if text.upper().startswith("&H"):
            return int(text[2:], 16)
        if any(c in text for c in ".eE"):
            return float(text)
        return int(text)

    def written_number(self, node, message: str) -> int | float:
        """A number written out, with its signs (a FOR's STEP, POSE's values)."""
        sign = 1
        while isinstance(node, Tree) and node.data == "neg":
            sign, node = -sign, node.children[0]
        if isinstance(node, Tree) and node.data == "number":
            return sign * self.number_value(node.children[0])
        raise self.error(node, message)
