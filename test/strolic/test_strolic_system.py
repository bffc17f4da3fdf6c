"""The system functions (EE area) on the default host: clocks, warnings, I/O, files, interrupts."""
from __future__ import annotations

from datetime import datetime, timedelta

import pytest

from conftest import ClockHost, RecordingHost, execute, stack_of
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


def test_internal_clock_counts_milliseconds_from_clrclk() -> None:
    class Clock(Host):
        time = 100.0

        def now(self) -> float:
            return self.time

    host = Clock()
    host.time = 102.5
    vm, main = execute("CLOCK CLRCLK CLOCK", host=host)
    assert [item.value for item in main.stack] == [2500, 0]
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
