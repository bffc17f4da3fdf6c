"""The command line and the example programs, run as a user would run them."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from conftest import ROOT

EXAMPLES = ROOT / "examples" / "strolic"
EXPECTED_STACKS = {
    "loop.sasm": ["I2:55"],
    "function_call.sasm": ["3628800", "49"],
    "vectors_transforms.sasm": [
        "R4:5.0", "Vec(0.0 0.0 1.0)", "Vec(-40.0 110.0 30.0)",
        "Trn(0.0 0.0 0.0 1.0 0.0 0.0 0.0 1.0 0.0 0.0 0.0 1.0)", "Vec(-20.0 110.0 30.0)", "1.0"],
    "processes.sasm": ["1", "2", "3", "I2:0"],
    "io_interrupts.sasm": ["I2:4", '"parts=3 time-out=0"', "I2:0"],
}


def strolic(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "strolic", *args], cwd=ROOT, capture_output=True,
                          text=True, timeout=60)


def test_every_example_is_checked() -> None:
    """robot_*.sasm move the arm: test_program_ros.py runs them through ~/run_program."""
    assert sorted(p.name for p in EXAMPLES.glob("*.sasm")
                  if not p.name.startswith("robot_")) == sorted(EXPECTED_STACKS)


@pytest.mark.parametrize("name", sorted(EXPECTED_STACKS))
def test_examples_run_from_text_and_from_raw_code(name: str, tmp_path: Path) -> None:
    result = strolic("run", str(EXAMPLES / name), "--stack")
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines() == EXPECTED_STACKS[name]

    raw = tmp_path / "program.stl"
    assert strolic("asm", str(EXAMPLES / name), str(raw)).returncode == 0
    result = strolic("run", str(raw), "--stack")
    assert result.stdout.splitlines() == EXPECTED_STACKS[name]

    text = tmp_path / "again.sasm"
    dis = strolic("dis", str(raw))
    assert dis.returncode == 0
    text.write_text(dis.stdout)
    assert strolic("asm", str(text), str(tmp_path / "again.stl")).returncode == 0
    assert (tmp_path / "again.stl").read_bytes() == raw.read_bytes()


def test_exception_exits_non_zero_with_the_report(tmp_path: Path) -> None:
    program = tmp_path / "bad.sasm"
    program.write_text("1 2 ADD 0 DIV\n")
    result = strolic("run", str(program), "--stack")
    assert result.returncode != 0
    assert "division by zero in DIV at byte 8" in result.stderr
    assert result.stdout == ""


def test_budget_and_output_stream(tmp_path: Path) -> None:
    program = tmp_path / "loop.sasm"
    program.write_text(".name f %1000 VAR #f DCL 7 RESULT #f FDEF Fn{ a: >a BRA END } f\n")
    result = strolic("run", str(program), "--budget", "500")
    assert result.returncode != 0
    assert "instruction budget exhausted" in result.stderr
    assert "output: 7" in result.stderr


def test_dis_offsets_match_exception_reports(tmp_path: Path) -> None:
    (tmp_path / "p.sasm").write_text(".name f %1000 VAR #f DCL #f FDEF Fn{ 1 0 IDIV END } f\n")
    strolic("asm", str(tmp_path / "p.sasm"), str(tmp_path / "p.stl"))
    report = strolic("run", str(tmp_path / "p.stl")).stderr
    listing = strolic("dis", str(tmp_path / "p.stl"), "--offsets").stdout
    offset = report.split("at byte ")[1].split()[0]
    assert f"IDIV  ; @{offset}" in listing
    (tmp_path / "again.sasm").write_text(listing)
    strolic("asm", str(tmp_path / "again.sasm"), str(tmp_path / "again.stl"))
    assert (tmp_path / "again.stl").read_bytes() == (tmp_path / "p.stl").read_bytes()


def test_asm_and_dis_report_bad_input(tmp_path: Path) -> None:
    (tmp_path / "bad.sasm").write_text("1 NOSUCH\n")
    assert strolic("asm", str(tmp_path / "bad.sasm"), str(tmp_path / "x.stl")).returncode != 0
    (tmp_path / "bad.stl").write_bytes(b"\xf3")
    result = strolic("dis", str(tmp_path / "bad.stl"))
    assert result.returncode != 0 and "invalid code" in result.stderr


def test_missing_file_is_reported_without_a_traceback(tmp_path: Path) -> None:
    result = strolic("run", str(tmp_path / "missing.sasm"))
    assert result.returncode == 2 and "Traceback" not in result.stderr


@pytest.mark.parametrize("command", [("strolic", "run"), ("acti_middle_node.run_program",)])
@pytest.mark.parametrize("name, content", [("missing.sasm", None), ("latin1.sasm", b"\xff\xfe 1 2 ADD")])
def test_a_program_file_that_cannot_be_read_is_one_line_and_status_2(tmp_path: Path, command,
                                                                     name, content) -> None:
    """Was: a UnicodeDecodeError traceback (both), a FileNotFoundError traceback (run_program).
    Neither needs a node: the file is read before any ROS."""
    path = tmp_path / name
    if content is not None:
        path.write_bytes(content)
    result = subprocess.run([sys.executable, "-m", *command, str(path)], capture_output=True,
                            text=True, timeout=60, cwd=ROOT)
    assert result.returncode == 2 and "Traceback" not in result.stderr, result.stderr
    assert result.stderr.strip().count("\n") == 0 and result.stderr.strip(), result.stderr


def test_run_uses_the_directory_of_the_program_for_files(tmp_path: Path) -> None:
    (tmp_path / "file2.txt").write_text("41\n")
    program = tmp_path / "files.sasm"
    program.write_text("2 1 FOPEN 3 2 FOPEN 3 2 INPUT INC LOUTPUT\n")
    result = strolic("run", str(program))
    assert result.returncode == 0, result.stderr
    assert (tmp_path / "file3.txt").read_text() == "42\n"
