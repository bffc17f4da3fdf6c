"""Helpers shared by the STROLIC tests: run a text program, get its stack or its exception."""
from __future__ import annotations

import os
import sys
from datetime import datetime
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from strolic.errors import StrolicError  # noqa: E402
from strolic.host import Host  # noqa: E402
from strolic.literals import format_value  # noqa: E402
from strolic.text import assemble  # noqa: E402
from strolic.vm import VM  # noqa: E402

# names every case may use; x, y, f, g are declared at level 0 before the case runs
PRELUDE = """
.name x %1000 .name y %1001 .name f %1002 .name g %1003 .name h %1004
VAR #x #y #f #g #h DCL
"""


class RecordingHost(Host):
    """A host that keeps console lines; its time of day stands still at 2024/05/06 07:08:09."""

    def __init__(self) -> None:
        super().__init__()
        self.lines: list[str] = []
        self.wall = datetime(2024, 5, 6, 7, 8, 9)

    def console(self, text: str) -> None:
        self.lines.append(text)

    def wall_clock(self) -> datetime:
        return self.wall

    def set_wall_clock(self, value: datetime) -> None:
        self.wall = value


class ClockHost(RecordingHost):
    """A recording host whose clock moves only when the VM sleeps (exact timings)."""

    time = 0.0

    def now(self) -> float:
        return self.time

    def sleep(self, seconds: float) -> None:
        self.time += max(seconds, 0.0)


def case_host(directory: Path) -> RecordingHost:
    """The host of the case table (strolic_cases.py). Its program directory is
    ``directory/program`` (file N is ``fileN.txt``), with a subdirectory ``sub``; a symbolic link
    ``out`` leads to ``directory/outside``. File 7 is named ``../outside.txt``, 8 an absolute
    path, 9 ``out/x.txt`` (through the link), 10 ``sub/data.txt``, 11 ``sub`` (a directory),
    12 ``fifo`` (a named pipe nobody writes to)."""
    host = RecordingHost()
    host.file_root = directory / "program"
    (host.file_root / "sub").mkdir(parents=True)
    (directory / "outside").mkdir()
    (host.file_root / "out").symlink_to(directory / "outside", target_is_directory=True)
    os.mkfifo(host.file_root / "fifo")
    host.files.update({7: "../outside.txt", 8: str(directory / "outside" / "abs.txt"),
                       9: "out/x.txt", 10: "sub/data.txt", 11: "sub", 12: "fifo"})
    return host


def execute(text: str, budget: int | None = 200_000, host: Host | None = None, **vm_options):
    """Run PRELUDE + text; returns (vm, main process)."""
    vm = VM(host or RecordingHost(), **vm_options)
    main = vm.run(assemble(PRELUDE + text), budget=budget)
    return vm, main


def stack_of(text: str, **options) -> list[str]:
    """The final stack in the text form, bottom first."""
    _, main = execute(text, **options)
    return [format_value(item) for item in main.stack]


def error_of(text: str, **options) -> StrolicError:
    with pytest.raises(StrolicError) as caught:
        execute(text, **options)
    return caught.value
