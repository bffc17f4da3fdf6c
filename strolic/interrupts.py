"""Interrupts and the timer interrupt (EE0E–EE15) on the cooperative scheduler.

Between two slices the scheduler *polls*: the timer interrupt fires when its time has come, and
the detection procedure of every interrupt code whose level is enabled (and that has an action,
and whose action is not still running) is run to its end; a true result (a number not 0) is an
interrupt. An accepted interrupt starts its action as an *interrupt process*: empty stacks, the
global variables, and precedence over every process, so the interrupted ones stand still until
it ends or waits. Accepting an interrupt of level L disables level L (REACT enables it again);
the timer interrupt is one-shot and disables every level (RTIMER enables them again).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from .codes import Function

if TYPE_CHECKING:
    from .vm import VM

POLL = 0.001                 # seconds between two polls while every process waits
TIMER = "timer interrupt"


@dataclass
class InterruptCode:
    level: int = 0
    detect: Function | None = None
    action: Function | None = None


class Interrupts:
    """The interrupt state of a VM (INIT makes a new one)."""

    def __init__(self) -> None:
        self.codes: dict[int, InterruptCode] = {}
        self.enabled: set[int] = set()
        self.react: set[int] = set()          # what REACT enables: the last ACTRS / accepted level
        self.timer_due: float | None = None   # host time at which the timer interrupt fires
        self.timer_action: Function | None = None
        self.rtimer: set[int] = set()         # what RTIMER enables: levels the timer disabled

    # ---- the functions ------------------------------------------------------------------------
    def disable(self, level: int) -> None:
        """ACTRS: one level, or every level (0)."""
        self.react = set(self.enabled) if level == 0 else self.enabled & {level}
        self.enabled -= self.react

    def code(self, number: int) -> InterruptCode:
        return self.codes.setdefault(number, InterruptCode())

    # ---- polling ------------------------------------------------------------------------------
    def _watched(self, vm: VM):
        return [(number, entry) for number, entry in self.codes.items()
                if entry.level in self.enabled and entry.detect is not None
                and entry.action is not None and not vm.handler_running(f"interrupt {number}")]

    def due(self, vm: VM, now: float) -> list[float]:
        """When the next poll could find an interrupt (for a VM with nothing to run)."""
        due = ([self.timer_due] if self.timer_due is not None
               and not vm.handler_running(TIMER) else [])
        if self._watched(vm):
            due.append(now + POLL)
        return due

    def poll(self, vm: VM) -> None:
        if self.timer_due is not None and vm.host.now() >= self.timer_due \
                and not vm.handler_running(TIMER):
            self.timer_due = None
            if self.timer_action is not None:
                self.rtimer = set(self.enabled)
                self.enabled.clear()
                vm.start_handler(TIMER, self.timer_action)
        for number, entry in self._watched(vm):
            if entry.level in self.enabled and vm.detect(entry.detect, f"interrupt {number}"):
                self.enabled.discard(entry.level)
                self.react = {entry.level}
                vm.start_handler(f"interrupt {number}", entry.action)
