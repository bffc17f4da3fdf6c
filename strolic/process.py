"""Processes and frames of the intermediate-code machine (Reference 1 §2, §9).

Each process has a data stack, a return stack and a chain of nested scopes whose outermost
(level 0, the global variables) is shared by all processes.
"""
from __future__ import annotations

import enum

from .codes import Function
from .errors import ExceptionKind as K, fail
from .variables import Scope

PUSH, BUILTIN, USER, INDIRECT = range(4)
WAIT = object()          # returned by a handler that must wait; the VM retries it later
DEFAULT_PRIORITY = 100
RETRY = -1               # ``blocked_at`` of a process that should look at its condition again
CYCLE_WAIT = -2          # ``blocked_at`` of a cyclic process waiting for its next start


class State(enum.IntEnum):
    """The state codes of FDONE (EF7C)."""
    DONE = 0
    RUNNING = 1
    WAITING = 2
    SUSPENDED = 3


class Frame:
    """Executing code: a function body (``function`` set) or the program itself; ``origin``
    is where the body stands in the program (None for one made at run time)."""

    __slots__ = ("codes", "pc", "origin", "function", "name", "_positions")

    def __init__(self, codes: list, origin: int | None, function: Function | None,
                 name: str) -> None:
        self.codes = codes
        self.pc = 0
        self.origin = origin
        self.function = function
        self.name = name
        self._positions: dict[int, int] | None = None

    def jump(self, offset: int, index: int) -> None:
        """Move ``offset`` bytes from the end of instruction ``index`` (§ BRA, BRF, BRT, BAL)."""
        _, _, start, size = self.codes[index]
        target = start + size + offset
        if self._positions is None:
            self._positions = {code[2]: i for i, code in enumerate(self.codes)}
        if target not in self._positions:
            raise fail(K.BRANCH_OUT_OF_FUNCTION,
                       f"target {target} is not a code of this function body")
        self.pc = self._positions[target]


class Process:
    """A unit of execution inside the VM; number 0 is the program from the input stream, an
    interrupt process has a label (``timer interrupt``) in place of a number."""

    def __init__(self, number: int | str, frame: Frame, scopes: list[Scope]) -> None:
        self.number = number
        self.stack: list = []
        self.returns: list = []            # ('call', caller frame) or ('bal', pc)
        self.frame = frame
        self.root = frame
        self.scopes = scopes
        self.state = State.RUNNING
        self.suspended_from = State.RUNNING
        self.priority = DEFAULT_PRIORITY
        self.period = 0.0                  # cyclic start interval in seconds (0: none)
        self.next_start = 0.0
        self.blocked_at = RETRY            # VM generation when it last had to wait
        self.last_run = 0
        self.event_buffer: list[int] = []
        self.wake_at: float | None = None  # a waiting process looks again at this host time
        self.timed: tuple | None = None    # ((frame, pc), end) of the timed wait it is in
        self.push = self.stack.append

    @property
    def name(self) -> str:
        """How reports name it: ``process 3``, or an interrupt process by its label."""
        return f"process {self.number}" if isinstance(self.number, int) else str(self.number)

    def pop(self):
        try:
            return self.stack.pop()
        except IndexError:
            raise fail(K.STACK_UNDERFLOW, "the data stack is empty") from None

    def peek(self, depth: int = 0):
        if depth >= len(self.stack):
            raise fail(K.STACK_UNDERFLOW, "the data stack is too short")
        return self.stack[-1 - depth]

    def restart(self) -> None:
        """Back to the start of the root function (cyclic start)."""
        self.frame = self.root
        self.root.pc = 0
        self.returns.clear()
        self.stack.clear()
        del self.scopes[1:]
        self.state = State.RUNNING
