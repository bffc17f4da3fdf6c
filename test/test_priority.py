"""The job's threads run at the configured niceness (acti_bringup.priority); without the right
to lower it the process keeps its own and says so, and runs on. Start-up objects are exempt from
garbage collection, so that a collection no longer pauses every thread for ~0.1 s. The control
loop's thread alone can run under SCHED_FIFO, with the same fallback."""
import gc
import os
import subprocess
import sys
import textwrap

import pytest

from acti_bringup.priority import freeze_heap, set_fifo, set_niceness

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCRIPT = textwrap.dedent("""
    import os, sys, threading
    from acti_bringup.priority import set_niceness
    def nice(tid):
        with open(f"/proc/{tid}/stat") as f:
            return int(f.read().rsplit(")", 1)[1].split()[16])
    before = threading.Thread(target=threading.Event().wait, args=(5,), daemon=True)
    before.start()
    ok = set_niceness(int(sys.argv[1]), print)
    later = []
    after = threading.Thread(target=lambda: later.append(nice(threading.get_native_id())))
    after.start(); after.join()
    print(ok, nice(threading.get_native_id()), nice(before.native_id), later[0])
""")


FIFO_SCRIPT = textwrap.dedent("""
    import os, sys, threading
    from acti_bringup.priority import set_fifo
    said = []
    def loop():
        said.append(set_fifo(int(sys.argv[1]), print))
        said.append(os.sched_getscheduler(0) == os.SCHED_FIFO and os.sched_getparam(0).sched_priority)
    t = threading.Thread(target=loop); t.start(); t.join()
    print(*said, os.sched_getscheduler(0) == os.SCHED_FIFO)   # the other threads: unchanged
""")


def run(arg: int, without_cap_sys_nice: bool = False, script: str = SCRIPT) -> list[str]:
    # root keeps the right to lower a niceness unless its bounding set loses CAP_SYS_NICE
    drop = ["setpriv", "--bounding-set", "-sys_nice"] if without_cap_sys_nice \
        and os.geteuid() == 0 else []
    out = subprocess.run([*drop, sys.executable, "-c", script, str(arg)], cwd=ROOT,
                         env={**os.environ, "PYTHONPATH": ROOT}, capture_output=True, text=True,
                         timeout=60, check=True).stdout
    return out.splitlines()


@pytest.mark.skipif(os.geteuid() != 0, reason="lowering the niceness needs root")
def test_every_thread_and_every_later_one_gets_the_niceness():
    assert run(-7) == ["True -7 -7 -7"]


def test_a_refused_niceness_is_said_once_and_the_process_runs_on():
    *said, last = run(-7, without_cap_sys_nice=True)
    assert len(said) == 1 and "nice -7 refused" in said[0] and "CAP_SYS_NICE" in said[0]
    assert last == "False 0 0 0"


def test_a_niceness_outside_minus_20_to_19_is_refused():
    with pytest.raises(ValueError, match="-20 … 19"):
        set_niceness(20, print)


def test_after_the_freeze_a_collection_no_longer_walks_the_start_up_objects():
    made = [[i] for i in range(1000)]               # long-lived, like a built job's objects
    try:
        assert freeze_heap() >= len(made)
        tracked = {id(o) for o in gc.get_objects()}  # what a collection walks
        assert id(made) not in tracked and id(made[0]) not in tracked
    finally:
        gc.unfreeze()


@pytest.mark.skipif(os.geteuid() != 0, reason="real-time scheduling needs root")
def test_the_calling_thread_alone_runs_under_sched_fifo():
    assert run(10, script=FIFO_SCRIPT) == ["True 10 False"]


def test_refused_real_time_scheduling_is_said_once_and_the_thread_runs_on():
    *said, last = run(10, without_cap_sys_nice=True, script=FIFO_SCRIPT)
    assert len(said) == 1 and "SCHED_FIFO 10" in said[0] and "refused" in said[0]
    assert last == "False False False"


def test_fifo_priority_0_leaves_the_scheduling_and_out_of_range_is_refused():
    assert set_fifo(0, print)
    with pytest.raises(ValueError, match="0 … 99"):
        set_fifo(100, print)
