"""Where a new velocity setting reaches the moving base: after set_velocity has answered.

1.4.32 makes the answer the value's check alone (真：引数で指定した値が正常に設定された; 偽：引数で
指定した値が不正のため設定が拒否された) and the speed change the motion's business (移動中に実行
すると，移動速度を連続かつ動的に変化させて設定値に一致させます). The re-plan of a running cruise is a
TOPP-RA timing of tens of milliseconds (hundreds on a busy machine); answering only once it was
committed kept the caller, and the node's motion plane, waiting that long (280 ms seen while
cruising). So the node's set_velocity answers once the value is set, and a thread of the core's
own re-times the running and queued moves to it (`start()`): requests that come while it plans
are served by one re-plan with the latest settings. Without `start()` (the ROS-free core in
tests and benches) the re-plan runs on the caller's thread before it returns, as before.
"""
from __future__ import annotations

import logging
import threading
from typing import Callable

_log = logging.getLogger("acti_motion")


class Retimer:
    """Runs `retime()` (re-time the motions to the settings as they are then) after each
    `request()`: on a thread of its own once started, else on the caller's thread."""

    def __init__(self, retime: Callable[[], None]) -> None:
        self._retime = retime
        self._thread: threading.Thread | None = None
        self._changed = threading.Condition()
        self._requested = 0          # requests so far
        self._done = 0               # the requests the last finished re-plan served

    def start(self) -> None:
        if self._thread is None:
            self._thread = threading.Thread(target=self._loop, name="base-retime", daemon=True)
            self._thread.start()

    def request(self) -> None:
        """Re-time to the settings as they are now: at once here, or soon on the thread."""
        if self._thread is None:
            self._run()
            return
        with self._changed:
            self._requested += 1
            self._changed.notify_all()

    def wait_done(self, timeout: float) -> bool:
        """Until every request so far is served (what a caller that must see the new timing
        waits for); False after `timeout` s."""
        with self._changed:
            target = self._requested
            return self._changed.wait_for(lambda: self._done >= target, timeout)

    def _loop(self) -> None:
        while True:
            with self._changed:
                self._changed.wait_for(lambda: self._requested > self._done)
                serving = self._requested
            self._run()
            with self._changed:
                self._done = serving
                self._changed.notify_all()

    def _run(self) -> None:
        try:
            self._retime()
        except Exception as e:      # the settings stay set; the moves keep their old timing
            _log.error(f"the base's moves could not be re-timed to the new settings "
                       f"({type(e).__name__}: {e}): they keep their old timing")
