"""Service responses that DDS could not deliver yet are sent again, off the serving thread.

A client that calls as soon as it has discovered the server can be answered before the server has
discovered the client's response reader. Fast DDS then waits 100 ms for that reader and gives up;
rclpy turns the failure into a RuntimeWarning and the response is lost: the client waits forever
(ros2/ros2#1253). A late client is therefore answered again, a few times over a few seconds, by a
thread of its own, and the log says so once per service when it never could be. A response
that cannot be sent at all is one log line: raised, it would end the executor's serving.

Every response is converted at once and sent without the GIL (`acti_bringup.serving.unlocked`):
rclpy's own send keeps the GIL while Fast DDS holds a send (a third of a second at a starting
participant's shared-memory port, also to a client answered before), and every thread of the
process, the control loop with it, waited. A client's first responses leave through the
process's outbox (`acti_bringup.serving.outbox`): DDS holds the first sends to a new client
most often (it waits up to 100 ms to discover the client's reader), and they must not hold the
serving thread. A client answered before is answered at once on the serving thread: through
the outbox every call cost ~50 µs more. There, one call of a C extension reads the header,
converts and sends (`UnlockedSender.answer_now`): the same through ctypes and Python cost the
serving thread ~13 µs more per response than rclpy's send (PTP accepts in the node), now ~2."""
from __future__ import annotations

import ctypes
import heapq
import threading
import time
import warnings
from typing import Any, Callable, Iterable, NamedTuple

from rclpy.node import Node

from acti_bringup.serving.outbox import Outbox
from acti_bringup.serving.unlocked import (GUID_BYTES, CMessage, MessageKind, header_address, rcl,
                                          request_id, respond, sent)

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


class Prepared(NamedTuple):
    """One response ready to go: send() says whether DDS delivered it; discard() if never sent."""
    send: Callable[[], bool]
    discard: Callable[[], None] = lambda: None


class RclpySender:
    """Prepares responses for rclpy's own send (under the GIL)."""

    def __init__(self, service: Any) -> None:
        self._send = service.send_response

    def answer_now(self, response: Any, header: Any) -> bool | None:
        """Nothing is sent at once: every response is prepared."""
        return None

    def prepare(self, response: Any, header: Any) -> Prepared:
        return Prepared(lambda: delivered(self._send, response, header))


class UnlockedSender:
    """Sends responses through rcl without the GIL (`unlocked`): to a client answered before
    (by its request writer's GUID) at once, on the serving thread, in one foreign call
    (`answer_now`); to a new one, converted now, through the outbox (`prepare`). Where the
    header cannot be read or rcl is not found, rclpy's send (through the outbox). The C message
    of a response sent twice in a row at once is kept: the service callback answers an
    unchanged reply with the same response object (`acti_bringup.serving.adapter`), which is
    then not converted again."""

    ANSWERED_KEPT = 4096

    def __init__(self, service: Any) -> None:
        self._rclpy = RclpySender(service)
        self._handle = service.handle
        self._kind = MessageKind(service.srv_type.Response)
        self._answered: set[bytes] = set()
        self._kept: tuple[Any, CMessage] | None = None    # serving thread only
        self._last: Any = None                             # the response sent last at once
        lib = rcl()
        self._functions = None if lib is None else (lib.send_response_address, *self._kind.addresses)
        self._read_in_c = False    # `respond` reads this service's headers as header_address does

    def answer_now(self, response: Any, header: Any) -> bool | None:
        """Send `response` here and now when its client was answered before: whether DDS
        delivered it; None when nothing was sent (a new client, a header not read yet)."""
        if not self._read_in_c:
            return None
        kept = self._kept
        if kept is not None and kept[0] is response:      # an unchanged reply
            message = kept[1].address
        elif response is self._last:                      # sent twice in a row: kept from now on
            message = self._keep(response).address
        else:
            self._kind.check(response)
            self._last, message = response, 0
        with self._handle:
            ret = respond.respond(header, self._answered, self._handle.pointer, self._functions,
                                  message, response)
        return None if ret is None else sent(ret)

    def prepare(self, response: Any, header: Any) -> Prepared:
        """A response to send later, off the serving thread: converted now."""
        lib = rcl()
        address = header_address(header) if lib is not None else None
        if address is None:
            return self._rclpy.prepare(response, header)
        if not self._read_in_c and respond is not None:
            self._read_in_c = respond.request_id(header) == address
        client = ctypes.string_at(address, GUID_BYTES)
        message = CMessage(self._kind, response)
        copied = request_id(address)

        def send() -> bool:
            # noted before it is sent: once answered, the client may call again at once
            if len(self._answered) >= self.ANSWERED_KEPT:
                self._answered.clear()
            self._answered.add(client)
            sent = message.send(self._handle, lambda s, m: lib.send_response(s, copied, m))
            if not sent:
                self._answered.discard(client)
            return sent
        return Prepared(send, message.discard)

    def _keep(self, response: Any) -> CMessage:
        """A new C message of `response`, kept instead of the one kept before (which is freed:
        its send is over, on this same thread)."""
        old, self._kept = self._kept, (response, CMessage(self._kind, response))
        if old is not None:
            old[1].discard()
        return self._kept[1]


Sender = Callable[[Any], "RclpySender | UnlockedSender"]


class LateResponses:
    """Sends every response through the outbox, and again, on its own thread, the responses
    that DDS could not deliver at once."""

    def __init__(self, log: Callable[[str], None], outbox: Outbox,
                 sender_of: Sender = UnlockedSender) -> None:
        self._log = log
        self._outbox = outbox
        self._sender_of = sender_of
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
                service.send_response = self._responder(self._sender_of(service),
                                                        service.service_name)

    def _responder(self, sender: RclpySender | UnlockedSender,
                   name: str) -> Callable[[Any, Any], None]:
        """service.send_response: sent here to a client answered before, else prepared here
        and sent on the outbox's thread."""
        def send_response(response: Any, header: Any) -> None:
            try:
                delivered = sender.answer_now(response, header)
                if delivered is None:
                    prepared = sender.prepare(response, header)
                    self._outbox.put(lambda: self._deliver(prepared, sender, response, header, name),
                                     prepared.discard)
                elif not delivered:
                    self._later(0, sender, response, header, name)
            except Exception as e:   # raised out of the executor, it would end the serving
                self._log(f"a response to {name} could not be sent: {type(e).__name__}: {e}")
        return send_response

    def _deliver(self, prepared: Prepared, sender: Any, response: Any, header: Any,
                 name: str) -> None:
        try:
            if not prepared.send():
                self._later(0, sender, response, header, name)
        except Exception as e:
            self._log(f"a response to {name} could not be sent: {type(e).__name__}: {e}")

    def _later(self, attempt: int, sender: Any, response: Any, header: Any, name: str) -> None:
        with self._wake:
            self._count += 1
            due = time.monotonic() + RETRY_AFTER_S[attempt]
            heapq.heappush(self._due, (due, self._count, attempt, sender, response, header, name))
            self._wake.notify()

    def _run(self) -> None:
        while True:
            with self._wake:
                while not self._due or self._due[0][0] > time.monotonic():
                    self._wake.wait(None if not self._due else self._due[0][0] - time.monotonic())
                _, _, attempt, sender, response, header, name = heapq.heappop(self._due)
            try:
                if sender.prepare(response, header).send():
                    continue
            except Exception as e:   # the service was destroyed, the process ends
                self._log(f"response to {name} not sent again: {e}")
                continue
            if attempt + 1 < len(RETRY_AFTER_S):
                self._later(attempt + 1, sender, response, header, name)
            elif name not in self._given_up:
                self._given_up.add(name)
                self._log(f"a response to {name} was never delivered: its client was not "
                          f"discovered within {sum(RETRY_AFTER_S):.0f} s")
