"""Debugging a RoboLine program by its source lines: breakpoints, stepping one line, continuing.

`Debugger` holds what the operator asked for (from any thread); `LineVM` runs process 0 code by
code while breakpoints or a step are pending, and at the start of a line that should stop it
waits, first for the program's motions so far to end, then for a step or continue. Nothing of
the STROLIC machine changes: the program's codes are standard; the VM only pauses between them.
"""
from __future__ import annotations

import threading
from typing import Iterable

from roboline import Program
from strolic.process import State
from strolic.vm import VM

HELD = "at breakpoint"


class Debugger:
    """Breakpoints (source lines with code) and the step/continue commands."""

    def __init__(self, program: Program, breakpoints: Iterable[int] = (),
                 step: bool = False) -> None:
        self.program = program
        self.breakpoints: set[int] = set()
        self.stepping = step
        self.line = 0                   # the line process 0 stands at (0: none yet)
        self.held = False
        self._go = threading.Event()
        self._lock = threading.Lock()
        self.set(breakpoints)

    @property
    def active(self) -> bool:
        return bool(self.breakpoints) or self.stepping

    def set(self, lines: Iterable[int]) -> str:
        """Add breakpoints; a line without code is refused (its message names it)."""
        lines = set(lines)
        bad = sorted(lines - self.program.code_lines)
        with self._lock:
            self.breakpoints |= lines - set(bad)
        return f"no code on line{'s' * (len(bad) > 1)} {', '.join(map(str, bad))}" if bad else ""

    def clear(self, lines: Iterable[int] = ()) -> None:
        lines = set(lines)
        with self._lock:
            self.breakpoints = self.breakpoints - lines if lines else set()

    def step(self) -> None:
        """Run to the start of the next line, and stop there."""
        self.stepping = True
        self._go.set()

    def resume(self) -> None:
        """Run to the next breakpoint."""
        self.stepping = False
        self._go.set()

    @property
    def waiting(self) -> bool:
        """Held at a line, and not yet told to go on."""
        return self.held and not self._go.is_set()

    def stops_at(self, line: int) -> bool:
        return self.stepping or line in self.breakpoints

    def wait_for_go(self, poll: float) -> bool:
        return self._go.wait(poll)

    def arrive(self) -> None:
        self._go.clear()
        self.held = True

    def leave(self) -> None:
        self.held = False


class LineVM(VM):
    """The VM of a RoboLine run: between two codes of process 0 it notes the source line, and
    holds the program where the debugger says (the host waits: `hold`)."""

    def __init__(self, host, debugger: Debugger) -> None:
        super().__init__(host)
        self.debugger = debugger

    def current_line(self) -> int:
        main = self.main
        frame = main.frame
        if frame.pc >= len(frame.codes):
            return 0
        offset = self.program_offset(main, frame, frame.codes[frame.pc][2])
        return self.debugger.program.lines.get(offset, 0)

    def _execute(self, proc, limit: int) -> None:
        debugger = self.debugger
        if proc is not self.main or not debugger.active:
            super()._execute(proc, limit)
            if proc is self.main:
                debugger.line = self.current_line() or debugger.line
            return
        for _ in range(limit):
            if proc.state is not State.RUNNING:
                return
            line = self.current_line()
            if line and line != debugger.line:
                debugger.line = line
                if debugger.stops_at(line):
                    self.host.hold(self, debugger)
            super()._execute(proc, 1)
