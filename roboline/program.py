"""A compiled program: its STROLIC code with the source map (code offset → source line), the
variables by name, and how to read an exception report back into the source."""
from __future__ import annotations

import bisect
import json
from dataclasses import dataclass, field
from pathlib import Path

from strolic.errors import StrolicError

from .source import Source

FAIL_CODE = 0xEAFF      # never declared: evaluating it stops the program (a refused command)
MAP_SUFFIX = ".map.json"


@dataclass(frozen=True)
class Symbol:
    """A variable: its name as written, type, user code and the routine it is local to."""
    name: str
    type: str
    key: int
    routine: str = ""


@dataclass
class Program:
    code: bytes
    source: Source
    lines: dict[int, int]                       # offset of every code → its line (0: none)
    symbols: dict[str, Symbol] = field(default_factory=dict)   # NAME or ROUTINE.NAME

    def __post_init__(self) -> None:
        self._offsets = sorted(self.lines)

    @property
    def code_lines(self) -> set[int]:
        """The lines that have code (where a breakpoint can stop)."""
        return {line for line in self.lines.values() if line}

    def line_at(self, offset: int | None) -> int:
        """The source line of the code at (or last before) `offset`; 0 when none."""
        if offset is None:
            return 0
        index = bisect.bisect_right(self._offsets, offset) - 1
        return self.lines[self._offsets[index]] if index >= 0 else 0

    def symbol(self, name: str, routine: str = "") -> Symbol | None:
        """A variable by name: the routine's own first, then the program's."""
        upper = name.upper()
        return (self.symbols.get(f"{routine.upper()}.{upper}") if routine else None) \
            or self.symbols.get(upper)

    def explain(self, error: StrolicError) -> str:
        """The exception report with the source line it happened on."""
        line = self.line_at(error.offset)
        if not line:
            return error.report()
        where = f"{self.source.name}:{line}: {self.source.line(line).strip()}"
        if error.function and error.function.startswith(f"%{FAIL_CODE:04X}"):
            return f"{where}: the command was refused (its error flag is in ERR; see the console)"
        return f"{where}: {error.report()}"

    # ---- the source map kept with the code --------------------------------------------------
    def map_json(self) -> str:
        return json.dumps({"source": self.source.name, "text": self.source.text,
                           "lines": sorted(self.lines.items()),
                           "symbols": [vars(s) for s in self.symbols.values()]}, indent=0)

    def save(self, path: Path) -> Path:
        """The code at `path`, the source map beside it (`path` + .map.json)."""
        path.write_bytes(self.code)
        map_path = path.with_name(path.name + MAP_SUFFIX)
        map_path.write_text(self.map_json())
        return map_path

    @classmethod
    def load(cls, path: Path) -> "Program":
        data = json.loads(path.with_name(path.name + MAP_SUFFIX).read_text())
        symbols = [Symbol(**s) for s in data["symbols"]]
        return cls(path.read_bytes(), Source(data["text"], data["source"]),
                   {int(o): int(line) for o, line in data["lines"]},
                   {(f"{s.routine.upper()}.{s.name.upper()}" if s.routine else s.name.upper()): s
                    for s in symbols})
