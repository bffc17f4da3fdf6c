"""The coverage table: no function of EF00–EF8E, EE00–EE22 or ED00–ED23 may be silently missing."""
from __future__ import annotations

import strolic_robot_cases as robot
from strolic_cases import CASES, LISTED_EXCEPTIONS, LISTED_WARNINGS, Warns
from strolic import opcodes
from strolic.errors import ExceptionKind

EF_MNEMONICS = {row.mnemonic for row in opcodes.TABLE if 0xEF00 <= row.code <= 0xEF8E}
EE_MNEMONICS = {row.mnemonic for row in opcodes.TABLE if 0xEE00 <= row.code <= 0xEE22}
COVERED = EF_MNEMONICS | EE_MNEMONICS


def test_opcode_table_has_all_143_vm_functions() -> None:
    assert [row.code for row in opcodes.VM_FUNCTIONS] == list(range(0xEF00, 0xEF8F))
    assert all(row.handler is not None for row in opcodes.VM_FUNCTIONS)


def test_every_function_has_a_normal_case() -> None:
    missing = {m for m in COVERED
               if not any(not isinstance(expected, ExceptionKind) for _, expected in CASES.get(m, []))}
    assert not missing, f"functions without a normal case: {sorted(missing)}"
    assert set(CASES) <= COVERED, set(CASES) - COVERED


def test_every_listed_exception_has_a_case() -> None:
    for mnemonic, kind in LISTED_EXCEPTIONS.items():
        assert any(expected is kind for _, expected in CASES[mnemonic]), (mnemonic, kind)


def test_every_listed_warning_has_a_case() -> None:
    """STIME, SDATE, CNFG, DOUT, DIN: the exception is a console warning, the program goes on."""
    for mnemonic in LISTED_WARNINGS:
        assert any(isinstance(expected, Warns) for _, expected in CASES[mnemonic]), mnemonic


def test_arithmetic_cases_cover_type_promotion() -> None:
    """Each mixed-arithmetic function has a case whose operands have different types."""
    for mnemonic in ("ADD", "SUB", "MUL", "DIV", "PWR", "MOD", "IDIV", "EQU", "LEQ", "GEQ",
                     "LT", "GT", "AND", "OR"):
        assert any(":" in program or "." in program for program, _ in CASES[mnemonic]), mnemonic


def test_every_robot_function_has_a_normal_case_and_its_listed_exceptions() -> None:
    """ED00–ED23 (strolic_robot_cases.py): a case that ends normally without an error flag,
    and a case for every exception the standard lists (reported by the function's flag)."""
    ed = {row.mnemonic for row in opcodes.TABLE if 0xED00 <= row.code <= 0xED23}
    assert set(robot.CASES) == ed, ed ^ set(robot.CASES)
    for mnemonic, cases in robot.CASES.items():
        flags = {robot.NOT_READY, *robot.LISTED_FLAGS.get(mnemonic, ())}
        assert any(isinstance(case[1], robot.Check) or isinstance(case[1], list)
                   and not flags & set(case[1]) for case in cases), mnemonic
    for mnemonic, listed in robot.LISTED_FLAGS.items():
        for flag in listed:
            assert any(isinstance(case[1], list) and flag in case[1]
                       for case in robot.CASES[mnemonic]), (mnemonic, flag)


def test_system_and_robot_function_rows() -> None:
    """EE rows have handlers that use the host's hooks; ED rows are the host's (the robot
    binding, acti_motion/programs/robot.py, dispatches them by mnemonic)."""
    host_rows = [row for row in opcodes.TABLE if row.code < 0xEF00]
    assert [row.code for row in host_rows] == (list(range(0xEE00, 0xEE23))
                                               + list(range(0xED00, 0xED24)))
    assert all("--" in row.effect for row in host_rows)
    assert all((row.handler is None) == (row.code < 0xEE00) for row in host_rows)
    assert len(opcodes.BY_CODE) == len(opcodes.TABLE) == 143 + 71
