"""The system functions (EE area) on the default host: clocks, warnings, I/O, files, interrupts."""
from __future__ import annotations

from datetime import datetime, timedelta

from conftest import RecordingHost, execute, stack_of
from strolic.host import Host


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
