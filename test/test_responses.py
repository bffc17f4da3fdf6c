"""A response that DDS could not deliver at once (rclpy's "failed to send response (timeout)"
warning: the client's reader is not discovered yet) is sent again off the serving thread, and
given up with one log line when the client never appears. Here through rclpy's send (a stand-in
service, `RclpySender`); the GIL-free send over real DDS is in test_unlocked and test_spinning.
Every first send leaves from the outbox's thread, never from the serving thread."""
from __future__ import annotations

import threading
import time
import warnings

from acti_bringup.serving import responses
from acti_bringup.serving.outbox import Outbox
from acti_bringup.serving.responses import LateResponses, RclpySender


class Service:
    """rclpy's Service as far as LateResponses uses it; the send warns as rclpy does on a DDS
    timeout until `reachable_after` sends."""

    def __init__(self, reachable_after: int) -> None:
        self.service_name = "/node/op"
        self.reachable_after = reachable_after
        self.sends: list[tuple[str, str]] = []

    def send_response(self, response: str, header: str) -> None:
        self.sends.append((response, threading.current_thread().name))
        if len(self.sends) <= self.reachable_after:
            warnings.warn("failed to send response (timeout): client will not receive response",
                          RuntimeWarning)


class Node:
    def __init__(self, *services: Service) -> None:
        self.services = services


def late(log) -> LateResponses:
    return LateResponses(log, Outbox(print), RclpySender)


def wait_for(predicate, timeout: float = 10.0) -> bool:
    deadline = time.monotonic() + timeout
    while not predicate() and time.monotonic() < deadline:
        time.sleep(0.01)
    return predicate()


def test_a_response_to_an_undiscovered_client_is_sent_again_until_delivered():
    log: list[str] = []
    service = Service(reachable_after=2)
    late(log.append).serve([Node(service)])
    service.send_response("answer", "header")
    assert wait_for(lambda: len(service.sends) == 3)
    assert [thread for _, thread in service.sends] == ["dds-out"] + ["late-responses"] * 2
    time.sleep(0.3)
    assert len(service.sends) == 3 and log == []


def test_a_delivered_response_is_sent_once():
    service = Service(reachable_after=0)
    late(print).serve([Node(service)])
    service.send_response("answer", "header")
    time.sleep(0.2)
    assert len(service.sends) == 1


def test_a_client_that_never_appears_is_given_up_with_one_line(monkeypatch):
    monkeypatch.setattr(responses, "RETRY_AFTER_S", (0.01, 0.01, 0.01))
    log: list[str] = []
    service = Service(reachable_after=10**6)
    late(log.append).serve([Node(service)])
    service.send_response("a", "h")
    service.send_response("b", "h")
    assert wait_for(lambda: len(service.sends) == 8)
    time.sleep(0.1)
    assert len(service.sends) == 8
    assert log == ["a response to /node/op was never delivered: its client was not discovered "
                   "within 0 s"]


def test_other_warnings_are_still_shown(recwarn):
    late(print).serve([])
    warnings.warn("something else", UserWarning)
    assert [str(w.message) for w in recwarn] == ["something else"]


def test_a_response_that_cannot_be_sent_is_one_log_line_not_an_exception():
    class Broken(Service):
        def send_response(self, response: str, header: str) -> None:
            raise RuntimeError("failed to send response: rmw error")
    log: list[str] = []
    service = Broken(reachable_after=0)
    late(log.append).serve([Node(service)])
    service.send_response("a", "h")
    assert wait_for(lambda: log)
    assert log == ["a response to /node/op could not be sent: RuntimeError: failed to send "
                   "response: rmw error"]
