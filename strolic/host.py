"""What the VM asks of the world around it: output stream, console, clock, tasks, robot.

The robot and system functions (EE, ED areas) will act through a subclass of ``Host``; a table
row without a handler is dispatched to ``Host.call``.
"""
from __future__ import annotations

import sys
import time

from .errors import ExceptionKind as K, fail


class Host:
    """A host without robot or OS tasks; it keeps what the VM sends to the programming device."""

    def __init__(self) -> None:
        self.output: list[bytes] = []
        self.shared: dict[int, int] = {}

    # output stream and console (SYNC, RESULT, TRACE)
    def send(self, data: bytes) -> None:
        self.output.append(data)

    def console(self, text: str) -> None:
        print(text, file=sys.stderr)

    # clock (cyclic processes, in seconds)
    def now(self) -> float:
        return time.monotonic()

    def sleep(self, seconds: float) -> None:
        time.sleep(max(seconds, 0.0))

    def stop(self, error) -> None:
        """Program execution stopped on an exception (§4.5): robot motion must stop too."""

    # robot and system functions without a handler in the opcode table
    def call(self, vm, proc, opcode) -> object:
        raise fail(K.UNDEFINED_DATA, f"{opcode.mnemonic} is not provided by this host")

    # tasks (units of execution outside the STROLIC processor, Reference 1 §9)
    def start_task(self, number: int) -> int:
        """TXQT: 0 started, −1 already started, −2 cannot start (no OS tasks here)."""
        return -2

    def task_state(self, number: int) -> int:
        """0 finished, 1 executing, 2 waiting, 3 suspended."""
        return 0

    def set_task_priority(self, number: int, priority: int) -> None:
        """TPRECD."""

    def set_task_cycle(self, number: int, period: int) -> None:
        """TCYCLE (period in ms)."""

    def control_task(self, number: int, action: str) -> int:
        """TKILL, TSUSPEND, TRESUME ('kill', 'suspend', 'resume'): 0 done, 1 not applicable."""
        return 1

    def share(self, number: int, key: int) -> None:
        """SHARE: another task reaches user code ``key`` through shared-variable ``number``."""
        self.shared[number] = key
