"""Every built-in function EF00–EF8E and EE00–EE22, run through the VM from the text form
(strolic_cases.py), each case on a fresh recording host."""
from __future__ import annotations

from pathlib import Path

import pytest

from strolic_cases import CASES, Warns
from conftest import case_host, error_of, stack_of
from strolic.errors import ExceptionKind

PARAMETERS = [pytest.param(program, expected, id=f"{mnemonic}-{i}")
              for mnemonic, cases in CASES.items() for i, (program, expected) in enumerate(cases)]


@pytest.mark.parametrize("program, expected", PARAMETERS)
def test_function(program: str, expected, tmp_path: Path) -> None:
    host = case_host(tmp_path)
    if isinstance(expected, ExceptionKind):
        error = error_of(program, host=host)
        assert error.kind is expected, error.report()
        assert error.function is not None and error.offset is not None
    else:
        assert stack_of(program, host=host) == expected
        warnings = [line for line in host.lines if line.startswith("STROLIC warning")]
        assert bool(warnings) == isinstance(expected, Warns), warnings
