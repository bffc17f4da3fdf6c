"""Where a program comes from and how its errors are shown: `file:line:column`, the line, a
caret under the column, and what was wrong or expected."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Source:
    """A program's or a taught-data file's text and the name its errors give."""
    text: str
    name: str = "<program>"

    def line(self, number: int) -> str:
        lines = self.text.splitlines()
        return lines[number - 1] if 0 < number <= len(lines) else ""


class SourceError(Exception):
    """A program that does not compile: the place and what is wrong."""

    def __init__(self, source: Source, line: int, column: int, message: str) -> None:
        self.source, self.line, self.column, self.message = source, line, column, message
        super().__init__(self.report())

    def report(self) -> str:
        text = self.source.line(self.line)
        column = max(1, self.column)
        shown = text.expandtabs(1)
        return (f"{self.source.name}:{self.line}:{column}: error: {self.message}\n"
                f"    {shown}\n    {' ' * (column - 1)}^")
