"""The coverage table: no function of the opcode table in EF00–EF8E may be silently missing."""
from __future__ import annotations

from strolic_cases import CASES, LISTED_EXCEPTIONS
from strolic import opcodes
from strolic.errors import ExceptionKind

EF_MNEMONICS = {row.mnemonic for row in opcodes.TABLE if 0xEF00 <= row.code <= 0xEF8E}


def test_opcode_table_has_all_143_vm_functions() -> None:
    assert [row.code for row in opcodes.VM_FUNCTIONS] == list(range(0xEF00, 0xEF8F))
    assert all(row.handler is not None for row in opcodes.VM_FUNCTIONS)


def test_every_ef_function_has_a_normal_case() -> None:
    missing = {m for m in EF_MNEMONICS
               if not any(not isinstance(expected, ExceptionKind) for _, expected in CASES.get(m, []))}
    assert not missing, f"functions without a normal case: {sorted(missing)}"
    assert set(CASES) <= EF_MNEMONICS, set(CASES) - EF_MNEMONICS


def test_every_listed_exception_has_a_case() -> None:
    for mnemonic, kind in LISTED_EXCEPTIONS.items():
        assert any(expected is kind for _, expected in CASES[mnemonic]), (mnemonic, kind)


def test_arithmetic_cases_cover_type_promotion() -> None:
    """Each mixed-arithmetic function has a case whose operands have different types."""
    for mnemonic in ("ADD", "SUB", "MUL", "DIV", "PWR", "MOD", "IDIV", "EQU", "LEQ", "GEQ",
                     "LT", "GT", "AND", "OR"):
        assert any(":" in program or "." in program for program, _ in CASES[mnemonic]), mnemonic


def test_system_and_robot_functions_are_rows_waiting_for_handlers() -> None:
    host_rows = [row for row in opcodes.TABLE if row.code < 0xEF00]
    assert [row.code for row in host_rows] == (list(range(0xEE00, 0xEE23))
                                               + list(range(0xED00, 0xED24)))
    assert all(row.handler is None and "--" in row.effect for row in host_rows)
    assert len(opcodes.BY_CODE) == len(opcodes.TABLE) == 143 + 71
