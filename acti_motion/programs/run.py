"""One run of a STROLIC program on the arm, without ROS: load (text form or code), run on the
calling thread or a thread of its own, progress while it runs, cancel, and the result.

A run ends when the program has ended *and* the motions it commanded are over (its end waits
for them as `$WAIT` would); an exception (the program's, a motion error, a cancel) stops the
program and the arm (`RobotHost.stop`).
"""
from __future__ import annotations

import enum
import threading
from typing import Any, Callable, Iterable
from dataclasses import dataclass, field

from acti_motion.arm.core import ArmCore
from acti_motion.programs.debugger import Debugger, LineVM
from acti_motion.programs.robot import CANCELED, ProgramDefaults, RobotHost
from roboline import Program
from strolic.codec import decode
from strolic.errors import ExceptionKind as K, StrolicError, fail
from strolic.host import MemoryIO
from strolic.literals import format_value
from strolic.process import State
from strolic.text import assemble, format_code
from strolic.variables import visible_scopes
from strolic.vm import VM


class Status(enum.IntEnum):
    """How a run ended (the RunProgram action's result status)."""
    FINISHED = 0
    EXCEPTION = 1
    CANCELED = 2
    INVALID = 3          # the program did not load (assembly or code error)


@dataclass
class Progress:
    program_counter: int = -1     # byte offset of the program's next code (process 0)
    line: int = 0                 # RoboLine: its source line, and the breakpoints
    breakpoints: list[int] = field(default_factory=list)
    instructions: int = 0
    state: str = "starting"
    message: str = ""             # PAUSE's message while paused
    motion_id: int = 0            # the arm's current motion (any source), its label and progress
    motion_label: str = ""
    progress: float = 0.0
    queue_length: int = 0


@dataclass
class ProgramResult:
    status: Status
    error: StrolicError | None = None
    stack: list[str] = field(default_factory=list)     # final data stack, bottom first
    output: list[str] = field(default_factory=list)    # what the program sent (SYNC, RESULT)
    console: list[str] = field(default_factory=list)   # TRACE, warnings, flags, PAUSE messages
    instructions: int = 0
    duration: float = 0.0                              # simulated seconds
    line: int = 0                                      # RoboLine: the exception's source line
    explained: str = ""                                # … and the report that names it

    @property
    def report(self) -> str:
        if self.explained:
            return self.explained
        return self.error.report() if self.error is not None else ""


MAX_PROGRAM = 1 << 20      # bytes (code) or characters (text) of a program
RESULT_ITEM = 65536        # characters of a stack item shown in the result …
RESULT_ITEMS = 1000        # … the top-most stack items shown …
RESULT_CHARS = 1 << 20     # … and the characters formatted for all of them
CHARS_PER_BYTE = 6         # the most a datum's byte takes as text (\\xNN; "-128 " in an I1 array)


def load(program: bytes | str | Program) -> list:
    """Decoded codes of a program in the text form (str) or as code (bytes); StrolicError when
    it does not assemble or decode, or is longer than MAX_PROGRAM (a 2 MB text takes seconds
    to assemble). Any other failure of the assembler or decoder is invalid code too: a flaw
    there must not look like a fault of the controller."""
    if not isinstance(program, Program) and len(program) > MAX_PROGRAM:
        raise StrolicError(K.INVALID_CODE, f"the program is {len(program)} "
                           f"{'characters' if isinstance(program, str) else 'bytes'} long: at most "
                           f"{MAX_PROGRAM} (1 MiB)")
    if isinstance(program, Program):
        return decode(program.code)
    try:
        return decode(assemble(program) if isinstance(program, str) else bytes(program))
    except StrolicError:
        raise
    except Exception as e:
        raise StrolicError(K.INVALID_CODE, f"the program does not load ({type(e).__name__}: "
                           f"{e})") from None


def _bounded(entries: Iterable, size_of: Callable[[Any], int], text_of: Callable[[Any], str],
             note_of: Callable[[Any], str]) -> list[str]:
    """Each entry's text while the texts keep within RESULT_ITEM characters each and about
    RESULT_CHARS in all, else its note. DUP shares a datum and a byte can take four characters
    (\\xNN): 13 copies of an 8 MB string made 436 MB of result text, 1000 of 64 KiB 262 MB,
    and RESULT in a loop 120 MB of output. An entry is formatted only when even its longest text
    (CHARS_PER_BYTE a byte) would fit, so the work stays bounded too, and only the text kept is
    charged; a number is always shown."""
    budget, shown = RESULT_CHARS, []
    for entry in entries:
        size = size_of(entry)
        text = ""
        if size == 0 or CHARS_PER_BYTE * size <= min(RESULT_ITEM, budget):
            text = text_of(entry)            # a number always: a few characters
        if size and (not text or len(text) > min(RESULT_ITEM, budget)):
            text = note_of(entry)
        budget -= len(text)
        shown.append(text)
    return shown


def shown_stack(stack: list) -> list[str]:
    """The final stack in the text form, bottom first: its top RESULT_ITEMS items, bounded
    (`_bounded`) from the top down, the others by their size only."""
    def data(item: Any) -> bytes:
        return getattr(item, "data", None) or getattr(item, "body", b"")
    shown = _bounded(reversed(stack[-RESULT_ITEMS:]), lambda item: len(data(item)), format_value,
                     lambda item: f"{type(item).__name__}<{len(data(item))} bytes, not shown>")
    if len(stack) > RESULT_ITEMS:
        shown.append(f"… {len(stack) - RESULT_ITEMS} items below not shown")
    return shown[::-1]


def shown_output(output: list[bytes]) -> list[str]:
    """What the program sent (SYNC, RESULT) in the text form, first first, bounded
    (`_bounded`); the rest by size only."""
    return _bounded(output, len, lambda data: " ".join(map(format_code, decode(data))),
                    lambda data: f"<{len(data)} bytes sent, not shown>")


class ProgramRun:
    """A program run on `arm`; `step` (tests) advances the simulation while the program waits.
    A RoboLine `Program` runs with its source map: progress and exceptions name source lines,
    and `debugger` (breakpoints, step) and `variable` work."""

    def __init__(self, arm: ArmCore, program: bytes | str | Program, *,
                 io: MemoryIO | None = None, step: Callable[[], None] | None = None,
                 defaults: ProgramDefaults | None = None, budget: int | None = None,
                 echo: bool = False, breakpoints: Iterable[int] = (), stepping: bool = False,
                 host: RobotHost | None = None) -> None:
        self.arm = arm
        self.program = program
        self.host = host or RobotHost(arm, io, step=step, defaults=defaults, echo=echo)
        self.source = program if isinstance(program, Program) else None
        self.debugger = (Debugger(program, breakpoints, stepping) if self.source is not None
                         else None)
        self.vm = LineVM(self.host, self.debugger) if self.debugger else VM(self.host)
        self.budget = budget
        self.result: ProgramResult | None = None
        self._thread: threading.Thread | None = None

    def run(self) -> ProgramResult:
        """Load and run to the end on this thread (loading a big program takes a while: not on
        the caller's, which may serve others)."""
        vm, host = self.vm, self.host
        start = host.now()
        try:
            codes = load(self.program)
        except StrolicError as e:
            host.state = "invalid"
            self.result = ProgramResult(Status.INVALID, e)
            return self.result
        try:
            try:
                vm.run(codes, budget=self.budget)
                host.wait_motions(vm)
            except StrolicError:
                raise
            except Exception as e:      # a fault outside the VM's own: it stops the arm too
                raise StrolicError(K.CONTROLLER_ERROR, f"{type(e).__name__}: {e}") from e
            status, error = Status.FINISHED, None
        except StrolicError as e:
            if host.state != "stopping":
                host.stop(e)
            host.wait_at_rest()
            status = Status.CANCELED if e.kind is K.STOPPED else Status.EXCEPTION
            error = e
        host.state = status.name.lower()
        dropped = [f"… {host.lines_dropped} more console lines not kept"] \
            if host.lines_dropped else []
        self.result = ProgramResult(
            status, error, shown_stack(vm.main.stack) if vm.main else [],
            shown_output(host.output),
            host.lines + dropped, vm.executed, host.now() - start)
        if self.source is not None and error is not None:
            self.result.line = self.source.line_at(error.offset)
            self.result.explained = self.source.explain(error)
        return self.result

    def start(self) -> None:
        """Run on a thread of its own (`join`, `result`)."""
        self._thread = threading.Thread(target=self._run_guarded, name="strolic-program",
                                        daemon=True)
        self._thread.start()

    def _run_guarded(self) -> None:
        try:
            self.run()
        except Exception as e:  # the world went away (shutdown) or a bug: no traceback, a result
            self.result = ProgramResult(
                Status.EXCEPTION, StrolicError(K.CONTROLLER_ERROR, f"{type(e).__name__}: {e}"),
                console=self.host.lines[:], instructions=self.vm.executed)

    def join(self, timeout: float | None = None) -> bool:
        if self._thread is not None:
            self._thread.join(timeout)
            return not self._thread.is_alive()
        return self.result is not None

    def cancel(self) -> None:
        """Stop the program and the arm; the run ends with CANCELED. The arm starts to
        decelerate here, on the canceling thread: a cancel is a stop, and the program's thread,
        which stopped it before, ran only when the machine let it (the arm then ran on for up
        to a few control periods more under load)."""
        host = self.host
        host.cancel_event.set()
        if self.result is None and host.state != "stopping":
            host.stop(fail(K.STOPPED, CANCELED))

    def progress(self) -> Progress:
        vm, host = self.vm, self.host
        out = Progress(instructions=vm.executed + vm.in_slice, state=host.state,
                       message=host.message)
        main = vm.main
        if main is not None:
            frame = main.frame
            codes = frame.codes
            offset = (codes[frame.pc][2] if frame.pc < len(codes)
                      else codes[-1][2] + codes[-1][3] if codes else 0)
            out.program_counter = vm.program_offset(main, frame, offset)
            if host.state == "running" and main.state is State.WAITING:
                out.state = "waiting"
        if self.debugger is not None:
            out.line = self.debugger.line
            out.breakpoints = sorted(self.debugger.breakpoints)
        out.motion_id, out.motion_label, out.progress, out.queue_length = self.arm.motion_status()
        return out

    def variable(self, name: str) -> tuple[str, str]:
        """A RoboLine variable's type and value (text form), the innermost binding visible to
        the program where it stands; KeyError with the reason when there is none."""
        if self.source is None:
            raise KeyError("the program is not a RoboLine program: it has no variable names")
        candidates = [s for s in self.source.symbols.values() if s.name.upper() == name.upper()]
        if not candidates:
            raise KeyError(f"{name} is no variable of the program")
        main = self.vm.main
        for scope in visible_scopes(main.scopes if main is not None else [self.vm.globals]):
            for symbol in candidates:
                registrations = scope.table.get(symbol.key)
                if registrations:
                    try:
                        return symbol.type, format_value(registrations[-1].value())
                    except StrolicError:
                        raise KeyError(f"{name} has no value yet") from None
        raise KeyError(f"{name} is not in scope where the program stands")
