"""What the VM asks of the world around it: output stream, console, clocks, digital I/O,
communication ports, files, tasks, robot.

The system functions (EE area) use the small hooks below, whose defaults need no hardware
(in-memory I/O, files in a program directory); the robot binding overrides them in a subclass.
A table row without a handler (the ED area, for now) is dispatched to ``Host.call``.
"""
from __future__ import annotations

import errno
import io
import os
import stat
import sys
import time
from dataclasses import dataclass
from datetime import datetime, timedelta
from pathlib import Path, PurePath
from typing import BinaryIO

from .errors import ExceptionKind as K, fail


@dataclass(frozen=True)
class PortSettings:
    """CNFG: the settings of a communication port."""

    flow_control: bool = False
    rs_control: bool = False
    speed: int = 9600                      # bps
    data_bits: int = 8
    parity: str = "none"                   # "none", "odd", "even"
    stop_bits: float = 1


class MemoryIO:
    """Digital I/O in memory: ports 1–8 are 8 bits wide, 9–16 are 16 bits; each port holds one
    value, written by DOUT and read by DIN (outputs wired back to the inputs of the same
    number), and a test or simulation may set it directly."""

    def __init__(self, widths: dict[int, int] | None = None) -> None:
        self.widths = widths if widths is not None else {p: 8 if p <= 8 else 16
                                                         for p in range(1, 17)}
        self.values = dict.fromkeys(self.widths, 0)


class Loopback(io.RawIOBase):
    """A communication port with a loopback plug: what is written can be read back."""

    def __init__(self, buffer: bytearray) -> None:
        super().__init__()
        self.buffer = buffer

    def readable(self) -> bool:
        return True

    def writable(self) -> bool:
        return True

    def readinto(self, target) -> int:
        count = min(len(target), len(self.buffer))
        target[:count] = self.buffer[:count]
        del self.buffer[:count]
        return count

    def write(self, data) -> int:
        self.buffer.extend(data)
        return len(data)


OPEN_FLAGS = {"r": os.O_RDONLY, "w": os.O_WRONLY | os.O_CREAT | os.O_TRUNC,
              "a": os.O_WRONLY | os.O_CREAT | os.O_APPEND}


def open_regular(path: Path, mode: str) -> BinaryIO:
    """A binary stream on the regular file `path` ('r', 'w' or 'a'). Opened without blocking
    and refused unless a regular file: a FIFO in the program directory made FOPEN wait for
    ever, and a device would be read without end."""
    fd = os.open(path, OPEN_FLAGS[mode] | os.O_NONBLOCK, 0o666)
    try:
        if not stat.S_ISREG(os.fstat(fd).st_mode):
            raise OSError(errno.EINVAL, "not a regular file")
        os.set_blocking(fd, True)
        return os.fdopen(fd, mode + "b")
    except BaseException:
        os.close(fd)
        raise


def inside(root: Path | None, name: str) -> Path:
    """The path of file ``name`` in the directory ``root``; a name that could leave it (absolute,
    with a ``..`` part) or that leads out of it through a symbolic link is refused, and nothing
    is opened."""
    if root is None:
        raise fail(K.FILE_ERROR, "this host has no program directory for files")
    relative = PurePath(name)
    if not name or "\0" in name or relative.is_absolute() or relative.drive \
            or ".." in relative.parts:
        raise fail(K.FILE_OUTSIDE, f"{name!r} is not a name inside the program directory")
    base = Path(root).resolve()
    target = (base / relative).resolve()
    if target != base and base not in target.parents:
        raise fail(K.FILE_OUTSIDE, f"{name!r} leads out of the program directory")
    return target


OUTPUT_ENTRY = 64     # bytes an entry of the output stream takes besides its data (SYNC's 2)


class Host:
    """A host without robot or OS tasks; it keeps what the VM sends to the programming device,
    has digital I/O and communication ports in memory, and files in a program directory."""

    def __init__(self) -> None:
        self.output: list[bytes] = []
        self.shared: dict[int, int] = {}
        self.time_offset = timedelta(0)        # STIME/SDATE: set time of day − system time
        self.clock_origin = 0.0                # CLRCLK: when (host time) the clock read 0
        self.io = MemoryIO()
        self.port_settings = {1: PortSettings(), 2: PortSettings()}   # communication ports
        self.port_files = {101: 1, 102: 2}     # file number → communication port
        self.port_buffers = {port: bytearray() for port in self.port_settings}
        self.file_root: Path | None = None     # the program directory (None: no files)
        self.files: dict[int, str] = {}        # file number → name in the program directory

    # output stream and console (SYNC, RESULT, TRACE)
    def send(self, data: bytes) -> None:
        self.output.append(data)

    def memory_in_use(self) -> int:
        """Bytes the host keeps for the program (output stream, port buffers): counted against
        the VM's ``memory_limit``."""
        return (sum(len(data) + OUTPUT_ENTRY for data in self.output)
                + sum(map(len, self.port_buffers.values())))

    def console(self, text: str) -> None:
        print(text, file=sys.stderr)

    def warn(self, text: str) -> None:
        """A warning on the console (STIME, SDATE, CNFG, DOUT, DIN: the program continues)."""
        self.console(f"STROLIC warning: {text}")

    # clock (cyclic processes, in seconds)
    def now(self) -> float:
        return time.monotonic()

    def sleep(self, seconds: float) -> None:
        time.sleep(max(seconds, 0.0))

    # time of day (TIME, DATE, STIME, SDATE) and the internal clock (CLOCK, CLRCLK)
    def wall_clock(self) -> datetime:
        """The controller's time of day: the system time plus what STIME/SDATE set."""
        return datetime.now() + self.time_offset

    def set_wall_clock(self, value: datetime) -> None:
        """STIME/SDATE: the controller's time of day only; the system clock is not touched."""
        self.time_offset = value - datetime.now()

    def clock_ms(self) -> int:
        """The internal clock: milliseconds of ``now()`` since its zero, or since CLRCLK."""
        return int((self.now() - self.clock_origin) * 1000)

    def clear_clock(self) -> None:
        self.clock_origin = self.now()

    def check(self, vm) -> None:
        """Called by the scheduler between slices and waits: raise a StrolicError to stop the
        program for what happened outside it (a motion error, an operator's stop)."""

    def stop(self, error) -> None:
        """Program execution stopped on an exception (§4.5): robot motion must stop too."""

    # digital I/O ports (DOUT, DIN, IOWAIT); values are unsigned, within the port's width
    def io_port_bits(self, port: int, output: bool) -> int | None:
        """The width of an output (``output``) or input port in bits, None if there is none."""
        return self.io.widths.get(port)

    def write_io(self, port: int, value: int) -> None:
        self.io.values[port] = value

    def read_io(self, port: int) -> int:
        return self.io.values[port]

    # communication ports (CNFG)
    def configure_port(self, port: int, settings: PortSettings) -> bool:
        """CNFG: False when there is no such port."""
        if port not in self.port_settings:
            return False
        self.port_settings[port] = settings
        return True

    # files (FOPEN … GETC)
    def file_name(self, number: int) -> str:
        """The name of file ``number`` in the program directory."""
        return self.files.get(number, f"file{number}.txt")

    def open_file(self, number: int, mode: str) -> BinaryIO:
        """FOPEN: a binary stream for file ``number``, mode 'r', 'w' (truncate) or 'a'; the
        files of communication ports are loopbacks; OSError or StrolicError when it fails."""
        if number in self.port_files:
            return Loopback(self.port_buffers[self.port_files[number]])
        return open_regular(inside(self.file_root, self.file_name(number)), mode)

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
