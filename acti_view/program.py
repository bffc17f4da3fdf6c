"""The program panel of the live view: the RoboLine program that runs, around its current line,
with the breakpoints marked (▶ the line the program stands at, ● a breakpoint)."""
from __future__ import annotations

from typing import Callable, NamedTuple

from roboline import Program

AROUND = 8            # lines shown before and after the current one


class ProgramShown(NamedTuple):
    program: Program
    line: int
    breakpoints: list[int]
    state: str


ProgramSource = Callable[[], "ProgramShown | None"]


def program_markdown(shown: ProgramShown | None) -> str:
    if shown is None:
        return "*no RoboLine program runs*"
    source = shown.program.source
    lines = source.text.splitlines()
    current = shown.line or 1
    first, last = max(1, current - AROUND), min(len(lines), current + AROUND)
    width = len(str(last))
    rows = []
    for number in range(first, last + 1):
        mark = "▶" if number == shown.line else " "
        stop = "●" if number in shown.breakpoints else " "
        rows.append(f"{mark}{stop} {number:>{width}}  {lines[number - 1]}")
    head = f"**{source.name}**: {shown.state}, line {shown.line or '-'}"
    if shown.breakpoints:
        head += f"; breakpoints {', '.join(map(str, shown.breakpoints))}"
    return head + "\n\n```text\n" + "\n".join(rows) + "\n```"
