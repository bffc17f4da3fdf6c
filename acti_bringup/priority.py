"""What keeps a controller process's control loop from being delayed by the machine or by the
process itself: the niceness of its threads, and the garbage collector's pauses.

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



def freeze_heap() -> int:
    """Exempt every object made so far from garbage collection; how many there are.

    A full collection of the built main job (~185 000 objects: rclpy, Pinocchio, TOPP-RA,
    SciPy, viser) took ~95 ms, during which no thread ran Python: /clock fell silent for 72 ms
    under a storm of clients. Start-up objects live as long as the process, so after start-up
    they are frozen (gc.freeze) and a collection looks only at what serving makes."""
    gc.collect()
    gc.freeze()
    return gc.get_freeze_count()
