"""Service responses that DDS could not deliver yet are sent again, off the serving thread.

A client that calls as soon as it has discovered the server can be answered before the server has
discovered the client's response reader. Fast DDS then waits 100 ms for that reader and gives up;
rclpy turns the failure into a RuntimeWarning and the response is lost: the client waits forever
(ros2/ros2#1253). A late client is therefore answered again, a few times over a few seconds, by a
thread of its own, and the log says so once per service when it never could be. A response
that cannot be sent at all is one log line: raised, it would end the executor's serving."""
from __future__ import annotations

import heapq
import threading
import time
import warnings
from typing import Any, Callable, Iterable

from rclpy.node import Node

UNDELIVERED = "failed to send response"     # the start of rclpy's warning on a timeout
RETRY_AFTER_S = (0.05, 0.2, 0.5, 1.0, 2.0, 4.0)   # each retry may block up to 100 ms in rmw

_failed = threading.local()


def _note_undelivered(show: Callable[..., None]) -> Callable[..., None]:
    """warnings.showwarning that marks the calling thread instead of printing rclpy's warning."""
    def showwarning(message: Any, category: type, *args: Any, **kwargs: Any) -> None:
        if category is RuntimeWarning and str(message).startswith(UNDELIVERED):
            _failed.flag = True
        else:
            show(message, category, *args, **kwargs)
    return showwarning


def _install_warning_hook() -> None:
    if getattr(warnings.showwarning, "_acti_responses", False):
        return
    warnings.filterwarnings("always", message=UNDELIVERED, category=RuntimeWarning)
    hook = _note_undelivered(warnings.showwarning)
    hook._acti_responses = True   # type: ignore[attr-defined]
    warnings.showwarning = hook


def delivered(send: Callable[[Any, Any], None], response: Any, header: Any) -> bool:
    """Send once; False when DDS could not deliver it (the client is not discovered yet)."""
    _failed.flag = False
    send(response, header)
    return not _failed.flag


class LateResponses:
    """Sends again, on its own thread, the responses that DDS could not deliver at once."""

    def __init__(self, log: Callable[[str], None]) -> None:
        self._log = log
        self._due: list[tuple[float, int, int, Callable, Any, Any, str]] = []
        self._count = 0
        self._wake = threading.Condition()
        self._given_up: set[str] = set()
        threading.Thread(target=self._run, name="late-responses", daemon=True).start()

    def serve(self, nodes: Iterable[Node]) -> None:
        """Every service of these nodes (theirs and rclpy's parameter services) retries a
        response that could not be delivered."""
        _install_warning_hook()
        for node in nodes:
            for service in node.services:
                service.send_response = self._sender(service.send_response, service.service_name)

    def _sender(self, send: Callable[[Any, Any], None], name: str) -> Callable[[Any, Any], None]:
        def send_response(response: Any, header: Any) -> None:
            try:
                if not delivered(send, response, header):
                    self._later(0, send, response, header, name)
            except Exception as e:   # raised out of the executor, it would end the serving
                self._log(f"a response to {name} could not be sent: {type(e).__name__}: {e}")
        return send_response

    def _later(self, attempt: int, send: Callable, response: Any, header: Any, name: str) -> None:
        with self._wake:
            self._count += 1
            due = time.monotonic() + RETRY_AFTER_S[attempt]
            heapq.heappush(self._due, (due, self._count, attempt, send, response, header, name))
            self._wake.notify()

    def _run(self) -> None:
        while True:
            with self._wake:
                while not self._due or self._due[0][0] > time.monotonic():
                    self._wake.wait(None if not self._due else self._due[0][0] - time.monotonic())
                _, _, attempt, send, response, header, name = heapq.heappop(self._due)
            try:
                if delivered(send, response, header):
                    continue
            except Exception as e:   # the service was destroyed, the process ends
                self._log(f"response to {name} not sent again: {e}")
                continue
            if attempt + 1 < len(RETRY_AFTER_S):
                self._later(attempt + 1, send, response, header, name)
            elif name not in self._given_up:
                self._given_up.add(name)
                self._log(f"a response to {name} was never delivered: its client was not "
                          f"discovered within {sum(RETRY_AFTER_S):.0f} s")
