"""What keeps a controller process's control loop from being delayed by the machine or by the
process itself: the niceness of its threads, real-time scheduling of the control loop, and the
garbage collector's pauses.

Niceness: its threads (the simulation step, the serving planes, DDS's own) run before the
clients' on a busy machine.

On 2 cores under a storm of 8 client processes, the main job at the clients' priority let
/clock fall silent for 33 ms and a stopped arm came to rest 150 ms late: its threads waited for
the CPU behind the clients. A robot controller runs above its clients (ros2_control's
controller_manager asks for real-time scheduling for the same reason); here every thread of the
process gets a lower niceness, which needs CAP_SYS_NICE (root) below 0. Without it the process
keeps the niceness it has and says so once: it still runs, only without that margin.
"""
from __future__ import annotations

import gc
import os
from typing import Callable

NICE_RANGE = (-20, 19)


def thread_ids() -> list[int]:
    """The kernel ids of this process's threads."""
    return [int(t) for t in os.listdir("/proc/self/task")]


def set_niceness(nice: int, log: Callable[[str], None]) -> bool:
    """Give every thread of this process (and so every thread it makes later: a thread starts
    with its creator's) the niceness `nice`; False, after one log line, where it is refused."""
    lo, hi = NICE_RANGE
    if not lo <= nice <= hi:
        raise ValueError(f"nice must be {lo} … {hi}, got {nice}")
    refused = []
    for tid in thread_ids():
        try:
            os.setpriority(os.PRIO_PROCESS, tid, nice)
        except ProcessLookupError:          # the thread ended meanwhile
            continue
        except PermissionError:
            refused.append(tid)
    if refused:
        log(f"nice {nice} refused (it needs CAP_SYS_NICE or root): the threads keep niceness "
            f"{os.getpriority(os.PRIO_PROCESS, 0)}, so busy clients on this machine can delay "
            "the control loop")
        return False
    return True



FIFO_RANGE = (0, 99)


def check_fifo_priority(priority: int) -> int:
    """`priority` if it is a SCHED_FIFO priority or 0, else ValueError."""
    lo, hi = FIFO_RANGE
    if not lo <= priority <= hi:
        raise ValueError(f"the FIFO priority must be {lo} … {hi} (0: ordinary scheduling), "
                         f"got {priority}")
    return priority


def set_fifo(priority: int, log: Callable[[str], None]) -> bool:
    """Run the calling thread under SCHED_FIFO at `priority` (1 … 99; 0: leave it as it is);
    False, after one log line, where it is refused.

    The control loop then runs the moment its period starts, ahead of every ordinary thread:
    at niceness −10 alone, the base's planning and its clients still held the simulation step
    back by up to 10–19 ms (/clock silent 13.8 and 22.7 ms in two runs of the same case); under
    SCHED_FIFO 10, 5.8 ms. It is what ros2_control's controller_manager asks for (priority 50).
    Opt-in: a loop that falls behind steps without sleeping and then keeps a core from every
    ordinary thread (the kernel's real-time throttling leaves them 5 % of each second)."""
    if check_fifo_priority(priority) == 0:
        return True
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except PermissionError:
        log(f"real-time scheduling (SCHED_FIFO {priority}) refused (it needs CAP_SYS_NICE or "
            "root): the control loop runs at ordinary priority")
        return False
    return True


def freeze_heap() -> int:
    """Exempt every object made so far from garbage collection; how many there are.

    A full collection of the built main job (~185 000 objects: rclpy, Pinocchio, TOPP-RA,
    SciPy, viser) took ~95 ms, during which no thread ran Python: /clock fell silent for 72 ms
    under a storm of clients. Start-up objects live as long as the process, so after start-up
    they are frozen (gc.freeze) and a collection looks only at what serving makes."""
    gc.collect()
    gc.freeze()
    return gc.get_freeze_count()
