"""Helpers shared by the STROLIC tests: run a text program, get its stack or its exception."""
from __future__ import annotations

import sys
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
    """A host that keeps console lines and uses a settable clock."""

    def __init__(self) -> None:
        super().__init__()
        self.lines: list[str] = []

    def console(self, text: str) -> None:
        self.lines.append(text)


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
