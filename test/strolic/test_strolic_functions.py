"""Every built-in function EF00–EF8E and EE00–EE22, run through the VM from the text form
(strolic_cases.py), each case on a fresh recording host; mixed I4/R4 arithmetic against numpy."""
from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

from strolic_cases import CASES, Warns
from conftest import case_host, error_of, execute, stack_of
from strolic.codes import R4, Num
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


# ---- Annex 1 §5: mixed I4/R4 operands are converted to R4 first, the operation done in R4 -------
R4_OPERANDS = st.floats(width=32, allow_nan=False, allow_infinity=False, min_value=-2.0**90,
                        max_value=2.0**90)


@settings(max_examples=150, deadline=None)
@given(st.integers(-2**31, 2**31 - 1), R4_OPERANDS)
def test_mixed_i4_r4_arithmetic_is_single_precision_arithmetic(a: int, b: float) -> None:
    """numpy's float32 arithmetic is the oracle: a is rounded to R4, then a ∘ b rounded once."""
    x, y = np.float32(a), np.float32(b)
    program = f"I4:{a} R4:{b!r} ADD I4:{a} R4:{b!r} SUB I4:{a} R4:{b!r} MUL"
    _, main = execute(program)
    assert main.stack == [Num(R4, float(x + y)), Num(R4, float(x - y)), Num(R4, float(x * y))]


@settings(max_examples=150, deadline=None)
@given(st.integers(-2**31, 2**31 - 1), R4_OPERANDS)
def test_mixed_i4_r4_ordering_agrees_with_the_difference(a: int, b: float) -> None:
    """Choice 10: LT/GT compare in R4, so `a b LT` is `a b SUB 0 LT` (and `b a GT`)."""
    operands = f"I4:{a} R4:{b!r}"
    program = f"{operands} LT {operands} SUB 0 LT R4:{b!r} I4:{a} GT"
    expected = "I2:1" if np.float32(a) < np.float32(b) else "I2:0"
    assert stack_of(program) == [expected] * 3
