"""Every built-in function EF00–EF8E, run through the VM from the text form (cases.py)."""
from __future__ import annotations

import pytest

from strolic_cases import CASES
from conftest import error_of, stack_of
from strolic.errors import ExceptionKind

PARAMETERS = [pytest.param(program, expected, id=f"{mnemonic}-{i}")
              for mnemonic, cases in CASES.items() for i, (program, expected) in enumerate(cases)]


@pytest.mark.parametrize("program, expected", PARAMETERS)
def test_function(program: str, expected) -> None:
    if isinstance(expected, ExceptionKind):
        error = error_of(program)
        assert error.kind is expected, error.report()
        assert error.function is not None and error.offset is not None
    else:
        assert stack_of(program) == expected
