"""Where the base's heavy plans run: in a process of their own, once `start()` was called.

The simulation step runs on a thread of the node's process. A plan on another thread of that
process (a TOPP-RA timing: a cruise point, a set_velocity re-plan of a running cruise) shares
its GIL, and TOPP-RA's loops hold it long and often: each time the step gave the GIL up (a
sleep, a publish), it waited for the planner to hand it back, and /clock fell silent for up to
75 ms during one re-plan. A `planned` function therefore runs in a worker process when one is
ready: the calling thread waits for the answer without the GIL, and the step never waits for a
plan. Without `start()` (the ROS-free core in tests and benches), before the worker has warmed
up, or once it is gone, it runs on the caller's thread, as before; the numbers are the same.
"""
from __future__ import annotations

import functools
import logging
import multiprocessing
import os
import signal
import threading
import time
from multiprocessing.connection import Connection
from typing import Any, Callable, TypeVar

_log = logging.getLogger("acti_motion")
F = TypeVar("F", bound=Callable[..., Any])

WORKER_NICENESS = 10        # above the node's: on a busy machine the step runs before a plan
_PLANS: dict[str, Callable[..., Any]] = {}        # name → the plain function (in both processes)
READY = "ready"             # what the worker says once it has warmed up


class _Worker:
    """One spawned process (not forked: the node's threads and DDS stay out of it) and the pipe
    to it; one call at a time."""

    def __init__(self) -> None:
        context = multiprocessing.get_context("spawn")
        self._conn, child = context.Pipe()
        self.process = context.Process(target=_serve, args=(child, os.getpid()), daemon=True,
                                       name="acti-base-planner")
        self.process.start()         # daemonic: multiprocessing ends it when the node exits
        child.close()
        self._lock = threading.Lock()
        self._ready = False

    def ready(self, timeout: float = 0.0) -> bool:
        """Warmed up (waiting up to `timeout` s for it)."""
        if not self._ready:
            with self._lock:
                if not self._ready and self._conn.poll(timeout):
                    self._ready = self._conn.recv() == READY
        return self._ready

    def call(self, name: str, args: tuple) -> Any:
        """Run plan `name` there; its exception is raised here. EOFError/OSError: the worker is
        gone."""
        with self._lock:
            self._conn.send((name, args))
            ok, value = self._conn.recv()
        if not ok:
            raise value
        return value

    def close(self) -> None:
        self._conn.close()
        self.process.kill()
        self.process.join(5.0)


_worker: _Worker | None = None


def planned(fn: F) -> F:
    """Run `fn` (a module-level function of picklable arguments and result) in the worker
    process when it is ready, else here."""
    name = f"{fn.__module__}.{fn.__qualname__}"
    _PLANS[name] = fn

    @functools.wraps(fn)
    def elsewhere(*args: Any) -> Any:
        worker = _worker
        if worker is None or not worker.ready():
            return fn(*args)
        try:
            return worker.call(name, args)
        except (EOFError, OSError):
            _lost(worker)
            return fn(*args)
    return elsewhere  # type: ignore[return-value]


def start() -> None:
    """Start the worker process; it warms up in the background, and plans run here until then."""
    global _worker
    if _worker is None:
        _worker = _Worker()


def wait_ready(timeout: float = 60.0) -> bool:
    """Until the worker has warmed up; False if there is none or it did not in time."""
    return _worker is not None and _worker.ready(timeout)


def stop() -> None:
    global _worker
    worker, _worker = _worker, None
    if worker is not None:
        worker.close()


def _lost(worker: _Worker) -> None:
    """The worker died (killed, out of memory): plan here from now on, and say so once."""
    global _worker
    if _worker is worker:
        _log.error("the base's planning process ended: plans run in the node's process from now "
                   "on (the simulation step may wait for them)")
        _worker = None


def _serve(conn: Connection, node: int) -> None:
    """The worker: Ctrl-C goes to the node (which ends the worker as it exits), a node that ends
    without (killed) ends it too; it yields the CPU to the node's threads when both want it."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    os.nice(WORKER_NICENESS)

    def orphaned() -> None:
        while os.getppid() == node:
            time.sleep(1.0)
        os._exit(0)
    threading.Thread(target=orphaned, name="node-watch", daemon=True).start()
    from acti_motion.vehicle.cruise import warm_up      # fills _PLANS here
    warm_up()
    conn.send(READY)
    while True:
        try:
            name, args = conn.recv()
        except (EOFError, OSError):
            return
        try:
            answer = (True, _PLANS[name](*args))
        except Exception as e:      # a refusal or a failure of the plan: raised in the node
            answer = (False, e)
        conn.send(answer)
