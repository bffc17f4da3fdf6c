"""What the process sends over DDS leaves from one thread of its own, with the GIL released.

Fast DDS can hold a send for a third of a second. When it meets the shared-memory port of a
participant that is starting or ending (any `ros2` command, any node coming or going), it checks
that port's health and sleeps (1000 / 3 ms by default) while it holds its participant's send
lock, and every other send of the participant waits for it. rclpy publishes and responds with
the GIL held, so one such send froze the whole process: the control loop (it publishes the
clock, the joints, the TF), `stop`, every getter. Measured with clients coming and going
(`bench/bench_fresh_clients.py`): the job froze for 335 ms about once in five new clients.

So the control loop and the serving planes only convert their messages (under the GIL, as rclpy
would) and hand them to the outbox, a bounded FIFO; the outbox's thread sends them through rcl
with the GIL released (`acti_bringup.serving.unlocked`). A stalled send now delays messages,
never the control loop, nor the handling of the next request: a `stop` acts at once, and its
answer leaves when DDS lets it (as any node's would).
"""
from __future__ import annotations

import threading
from collections import deque
from typing import Any, Callable

from acti_bringup.serving.unlocked import CMessage, MessageKind, header_address, rcl, request_id

Send = Callable[[], Any]
Discard = Callable[[], None]


class Outbox:
    """One thread that sends what other threads hand it, in the order they did. `put` never
    waits: beyond CAPACITY items waiting (DDS stalled that long), the oldest are dropped, and
    the log says how many once the outbox runs again."""

    CAPACITY = 10_000
    STOP_TIMEOUT_S = 2.0

    def __init__(self, log: Callable[[str], None]) -> None:
        self._log = log
        self._items: deque[tuple[Send, Discard]] = deque()
        self._wake = threading.Event()
        self._running = True
        self.dropped = 0
        self._reported_drops = 0
        self._reported_errors: set[str] = set()
        self._thread = threading.Thread(target=self._run, name="dds-out", daemon=True)
        self._thread.start()

    def put(self, send: Send, discard: Discard = lambda: None) -> None:
        """Have send() called on the outbox thread (discard() instead if it is dropped)."""
        if len(self._items) >= self.CAPACITY:
            try:
                self._items.popleft()[1]()
                self.dropped += 1
            except IndexError:          # the outbox emptied it meanwhile
                pass
        self._items.append((send, discard))
        self._wake.set()

    def _run(self) -> None:
        while True:
            self._wake.wait()
            self._wake.clear()
            while self._items:
                send, _ = self._items.popleft()
                try:
                    send()
                except Exception as e:      # a destroyed entity at shutdown, a refused message
                    self._report(e)
            if self.dropped != self._reported_drops:
                self._log(f"DDS held the sends back: {self.dropped - self._reported_drops} "
                          f"messages dropped (more than {self.CAPACITY} were waiting)")
                self._reported_drops = self.dropped
            if not self._running:
                return

    def _report(self, error: Exception) -> None:
        """Log a failed send once per kind of failure."""
        what = f"{type(error).__name__}: {error}"
        if what not in self._reported_errors:
            self._reported_errors.add(what)
            self._log(f"a message could not be sent: {what}")

    def stop(self) -> None:
        """Send what is waiting (for at most STOP_TIMEOUT_S), then end the thread."""
        self._running = False
        self._wake.set()
        self._thread.join(timeout=self.STOP_TIMEOUT_S)
        while self._items:
            self._items.popleft()[1]()


def unlocked_publish(outbox: Outbox, publisher: Any) -> Callable[[Any], None]:
    """publisher.publish through the outbox: converted now, published without the GIL (rclpy's
    own publish where rcl is not found)."""
    lib = rcl()
    if lib is None:
        return publisher.publish
    kind, handle = MessageKind(publisher.msg_type), publisher.handle

    def publish(msg: Any) -> None:
        message = CMessage(kind, msg)
        outbox.put(lambda: message.send(handle, lambda p, m: lib.publish(p, m, None)),
                   message.discard)
    return publish


class UnlockedActionHandle:
    """An rclpy ActionServer's handle whose feedback and answers (to goal, cancel and result
    requests) go through the outbox without the GIL; its status stays rclpy's (rcl builds that
    message from the goals it holds). A `ros2 action send_goal` is a starting participant, whose
    first answers DDS holds most often."""

    def __init__(self, handle: Any, outbox: Outbox) -> None:
        self._handle, self._outbox = handle, outbox
        self._kinds: dict[type, MessageKind] = {}

    def __getattr__(self, name: str) -> Any:
        send = rcl().action_answers.get(name)
        if send is None:
            return getattr(self._handle, name)
        return lambda header, msg: self._answer(send, getattr(self._handle, name), header, msg)

    def __enter__(self) -> Any:
        return self._handle.__enter__()

    def __exit__(self, *exc: Any) -> Any:
        return self._handle.__exit__(*exc)

    def _message(self, msg: Any) -> CMessage:
        kind = self._kinds.get(type(msg)) or self._kinds.setdefault(type(msg), MessageKind(type(msg)))
        return CMessage(kind, msg)

    def publish_feedback(self, msg: Any) -> None:
        message, handle, publish = self._message(msg), self._handle, rcl().publish_feedback
        self._outbox.put(lambda: message.send(handle, publish), message.discard)

    def _answer(self, send: Any, rclpy_send: Callable[[Any, Any], None], header: Any,
                msg: Any) -> None:
        """send(server, request id, message) from the outbox; rclpy's send where the header
        cannot be read."""
        address = header_address(header)
        if address is None:
            self._outbox.put(lambda: rclpy_send(header, msg))
            return
        copied, message, handle = request_id(address), self._message(msg), self._handle
        self._outbox.put(lambda: message.send(handle, lambda s, m: send(s, copied, m)),
                         message.discard)


def unlock_action(action_server: Any, outbox: Outbox) -> None:
    """Send this ActionServer's feedback and answers through the outbox (left to rclpy
    without rcl)."""
    if rcl() is not None and not isinstance(action_server._handle, UnlockedActionHandle):
        action_server._handle = UnlockedActionHandle(action_server._handle, outbox)
