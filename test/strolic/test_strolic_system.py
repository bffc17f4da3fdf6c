"""The system functions (EE area) on the default host: clocks, warnings, I/O, files, interrupts."""
from __future__ import annotations

import io
from datetime import datetime, timedelta
from pathlib import Path

import pytest

from conftest import ClockHost, RecordingHost, error_of, execute, stack_of
from strolic.errors import ExceptionKind
from strolic.host import Host, PortSettings


class ConsoleHost(RecordingHost):
    """The default host's time of day, with the console recorded."""

    wall_clock = Host.wall_clock
    set_wall_clock = Host.set_wall_clock


# ---- time of day and internal clock -------------------------------------------------------------
def test_default_host_time_of_day_follows_the_system_clock() -> None:
    before = datetime.now()
    time_text, date_text = (item.strip('"') for item in stack_of("TIME DATE", host=Host()))
    after = datetime.now()
    assert before.strftime("%Y/%m/%d") <= date_text <= after.strftime("%Y/%m/%d")
    read = datetime.strptime(f"{date_text} {time_text}", "%Y/%m/%d %H:%M:%S")
    assert before - timedelta(seconds=1) <= read <= after


def test_stime_and_sdate_move_the_controller_clock_not_the_system_clock() -> None:
    host = ConsoleHost()
    assert stack_of('"2001/02/03" SDATE "04:05:06" STIME DATE TIME', host=host) == \
        ['"2001/02/03"', '"04:05:06"']
    assert abs(host.wall_clock() - datetime(2001, 2, 3, 4, 5, 6)) < timedelta(seconds=2)
    assert abs(Host().wall_clock() - datetime.now()) < timedelta(seconds=2)


def test_a_bad_time_or_date_is_a_warning_on_the_console() -> None:
    host = RecordingHost()
    execute('"25:00:00" STIME "2001/02/30" SDATE 1', host=host)
    assert host.lines == [
        "STROLIC warning: STIME: b'25:00:00' is not a time HH:MM:SS; the time is not set",
        "STROLIC warning: SDATE: b'2001/02/30' is not a date YYYY/MM/DD; the date is not set"]
    assert host.wall == datetime(2024, 5, 6, 7, 8, 9)


def test_internal_clock_counts_milliseconds_of_the_host_clock_from_clrclk() -> None:
    class Clock(Host):
        time = 100.0

        def now(self) -> float:
            return self.time

    host = Clock()
    host.time = 102.5
    vm, main = execute("CLOCK CLRCLK CLOCK", host=host)
    assert [item.value for item in main.stack] == [102500, 0]
    host.time += 2**31 / 1000 + 1.0               # the I4 clock wraps to 0 after 2³¹ − 1 ms
    assert vm.run(b"\xee\x02").stack[0].value in (999, 1000)


# ---- communication ports and digital I/O --------------------------------------------------------
def test_cnfg_records_the_port_settings_in_the_host() -> None:
    host = RecordingHost()
    execute("1 3 6 0x2F CNFG 2 0 1 0x0A CNFG 2 0 9 1 CNFG", host=host)
    assert host.port_settings[1] == PortSettings(flow_control=True, rs_control=True,
                                                 speed=19200, data_bits=8, parity="even",
                                                 stop_bits=2)
    assert host.port_settings[2] == PortSettings(speed=300, data_bits=7, parity="odd",
                                                 stop_bits=1.5)
    assert host.lines == ["STROLIC warning: CNFG: invalid setting for port 2 (b=0, c=9, d=1); "
                          "nothing is set"]


def test_iowait_times_out_after_its_milliseconds() -> None:
    host = ClockHost()
    _, main = execute("1 1 1 250 IOWAIT", host=host)
    assert [item.value for item in main.stack] == [0, 1]
    assert host.time == pytest.approx(0.25)


def test_iowait_sees_an_input_set_outside_the_vm() -> None:
    class Sensor(ClockHost):
        def read_io(self, port: int) -> int:
            return 0b100 if self.time >= 0.1 else 0

    host = Sensor()
    _, main = execute("3 4 1 1000 IOWAIT", host=host)
    assert [item.value for item in main.stack] == [4, 0]
    assert 0.1 <= host.time < 0.11


def test_each_iowait_gets_its_own_timeout() -> None:
    host = ClockHost()
    program = "#f Fn{ >body BAL >body BAL RET body: 1 1 1 100 IOWAIT RET END } STORE f"
    _, main = execute(program, host=host)
    assert [item.value for item in main.stack] == [0, 1, 0, 1]
    assert host.time == pytest.approx(0.2)


def test_a_host_with_its_own_ports() -> None:
    class Robot(RecordingHost):
        def __init__(self) -> None:
            super().__init__()
            self.written: list[tuple[int, int]] = []

        def io_port_bits(self, port: int, output: bool) -> int | None:
            return 8 if (port == 1) == output else None      # 1 is an output, 2 an input

        def write_io(self, port: int, value: int) -> None:
            self.written.append((port, value))

        def read_io(self, port: int) -> int:
            return 0x5A

    host = Robot()
    assert stack_of("1 I2:0x1A5 DOUT 2 DIN 1 DIN", host=host) == ["I2:90", "I2:0"]
    assert host.written == [(1, 0xA5)]
    assert host.lines == ["STROLIC warning: DIN: input port 1 does not exist"]


# ---- files: inside the program directory only ---------------------------------------------------
def file_host(root: Path, **files: str) -> RecordingHost:
    host = RecordingHost()
    host.file_root = root
    host.files.update({int(number[1:]): name for number, name in files.items()})
    return host


def test_files_are_written_and_read_in_the_program_directory(tmp_path: Path) -> None:
    (tmp_path / "points.txt").write_bytes(b"10 -2.5 Vec(1.0 2.0 3.0)\n# a note\n")
    host = file_host(tmp_path, n3="points.txt", n4="log/run.txt")
    (tmp_path / "log").mkdir()
    program = ('3 1 FOPEN 3 INPUT 3 INPUT 3 INPUT 3 #St(0) LINPUT 3 #St(0) LINPUT 3 FSTAT '
               '4 2 FOPEN 4 "x" OUTPUT 4 I2:7 OUTPUT 4 R4:0.5 LOUTPUT 4 65 PUTC')
    assert stack_of(program, host=host) == ["10", "-2.5", "Vec(1.0 2.0 3.0)", '""', '"# a note"',
                                            "I2:1"]
    assert (tmp_path / "log" / "run.txt").read_bytes() == b"x 7 0.5\nA"   # closed at the end
    assert (tmp_path / "file1.txt").exists() is False


def test_a_symbolic_link_inside_the_directory_may_be_used(tmp_path: Path) -> None:
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "real.txt").write_bytes(b"42\n")
    (tmp_path / "alias.txt").symlink_to(tmp_path / "data" / "real.txt")
    assert stack_of("1 1 FOPEN 1 INPUT", host=file_host(tmp_path, n1="alias.txt")) == ["42"]


@pytest.mark.parametrize("name", ["../escape.txt", "sub/../../escape.txt", "/tmp/escape.txt",
                                  "link/escape.txt", "secret.txt", "", "a\0b"])
@pytest.mark.parametrize("mode", [1, 2, 4])
def test_a_path_out_of_the_program_directory_is_refused_and_never_opened(
        tmp_path: Path, name: str, mode: int) -> None:
    root, outside = tmp_path / "program", tmp_path / "outside"
    (root / "sub").mkdir(parents=True)
    outside.mkdir()
    (root / "link").symlink_to(outside, target_is_directory=True)
    (outside / "secret.txt").write_bytes(b"secret")
    (root / "secret.txt").symlink_to(outside / "secret.txt")
    if name.startswith("/tmp/"):
        name = str(outside / "escape.txt")
    error = error_of(f"1 {mode} FOPEN 1 INPUT", host=file_host(root, n1=name))
    assert (error.kind, error.function) == (ExceptionKind.FILE_OUTSIDE, "FOPEN")
    assert sorted(p.name for p in outside.iterdir()) == ["secret.txt"]
    assert (outside / "secret.txt").read_bytes() == b"secret"
    assert not (tmp_path / "escape.txt").exists()


def test_a_host_without_a_program_directory_has_no_files() -> None:
    error = error_of("1 2 FOPEN", host=RecordingHost())
    assert error.kind is ExceptionKind.FILE_ERROR
    assert error.detail == "this host has no program directory for files"


def test_files_are_closed_when_the_program_stops_and_at_init(tmp_path: Path) -> None:
    host = file_host(tmp_path)
    error_of('1 2 FOPEN 1 "kept" OUTPUT 1 0 DIV', host=host)
    assert (tmp_path / "file1.txt").read_bytes() == b"kept "
    assert stack_of('2 2 FOPEN 2 "a" OUTPUT INIT 2 FSTAT', host=host) == ["I2:2"]
    assert (tmp_path / "file2.txt").read_bytes() == b"a "


# ---- interrupts -----------------------------------------------------------------------------
def test_an_interrupt_is_detected_between_slices_of_a_busy_program() -> None:
    program = ("#x I4:0 STORE 5 1 Fn{ x 1000 GT END } ACTCODE 5 Fn{ #y x STORE #g 1 STORE END } "
               "ACTION 1 ACT #g 0 STORE #f Fn{ top: #x x INC STORE g 0 EQU >top BRT END } STORE "
               "f y 1000 GT y 1500 LT")
    assert stack_of(program)[-2:] == ["I2:1", "I2:1"]       # at most a slice late


def test_the_interrupted_processes_stand_still_while_the_action_runs() -> None:
    action = ("Fn{ #y x STORE #h I2:0 STORE top: #h h INC STORE h I2:600 LT >top BRT "
              "#y y x EQU STORE #g 1 STORE END }")
    program = (f"#x I4:0 STORE #g 0 STORE 5 1 Fn{{ x 100 GT END }} ACTCODE 5 {action} ACTION "
               "1 ACT #f Fn{ top: #x x INC STORE g 0 EQU >top BRT END } STORE f y")
    assert stack_of(program)[-1] == "I2:1"


def test_an_exception_in_an_action_names_the_interrupt() -> None:
    error = error_of("5 1 Fn{ 1 END } ACTCODE 5 Fn{ 1 0 DIV END } ACTION 1 ACT 9 EWAIT")
    assert error.kind is ExceptionKind.DIVISION_BY_ZERO
    assert error.function == "DIV (in function interrupt 5) (interrupt 5)"


def test_init_forgets_the_interrupts() -> None:
    error = error_of("5 1 Fn{ 1 END } ACTCODE 5 Fn{ 9 ESIG END } ACTION 1 ACT INIT 9 EWAIT")
    assert error.kind is ExceptionKind.DEADLOCK


def test_the_timer_interrupt_fires_after_its_milliseconds() -> None:
    host = ClockHost()
    _, main = execute("Fn{ 9 ESIG END } TACTION 250 TIMER 9 EWAIT 1", host=host)
    assert [item.value for item in main.stack] == [1]
    assert host.time == pytest.approx(0.25)


def test_a_file_that_fails_to_close_at_the_end_is_reported() -> None:
    class Full(io.BytesIO):
        def close(self) -> None:
            raise OSError(28, "No space left on device")

    class DiskFull(RecordingHost):
        def open_file(self, number: int, mode: str):
            return Full()

    error = error_of('1 2 FOPEN 1 "x" OUTPUT', host=DiskFull())
    assert error.kind is ExceptionKind.FILE_ERROR and "No space left" in error.detail


@pytest.mark.parametrize("count, expected", [(32767, ["32767"]), (32768, None)])
def test_decode2_stores_at_most_what_its_i2_count_can_say(count: int, expected) -> None:
    """EE21 DECODE2 pushes the number of values stored as I2: a format of 32768 conversions
    pushed an I2 no I2 holds, and RESULT of it stopped with a Python struct error. It is a
    conversion error now, found before anything is stored."""
    program = (f'"{"%d" * count}" "{"1 " * count}" {"#x " * count} I4:{count} DECODE2 DUP '
               "RESULT")
    if expected is None:
        assert error_of(program, budget=None).kind is ExceptionKind.CONVERSION_ERROR
    else:
        assert stack_of(program, budget=None) == expected
