"""Replaying a recording over ROS: its topics republished with their timing, or its service
calls and action goals sent again to a running job and each answer compared with the recorded
one (`acti_record.calls`)."""
from __future__ import annotations

import array
import time
from typing import Any, Callable

from rclpy.duration import Duration
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message

from acti_bringup.recording.types import type_class
from acti_bringup.serving.adapter import CLIENT_QOS
from acti_record.calls import Call, Event, answered_before, differences, pair, service_of
from acti_record.reading import Channel, Contents

SERVICE_WAIT_S = 30.0
REPUBLISH_DEPTH = 1000
ACKED_WAIT_S = 5.0


def plain(value: Any) -> Any:
    """A message as dicts, lists and numbers (what `differences` compares)."""
    if hasattr(value, "get_fields_and_field_types"):
        return {name: plain(getattr(value, name)) for name in value.get_fields_and_field_types()}
    if isinstance(value, (list, tuple, array.array)) or type(value).__name__ == "ndarray":
        return [plain(v) for v in value]
    if isinstance(value, bytes):
        return list(value)
    return value.item() if hasattr(value, "item") else value


def is_hidden(topic: str) -> bool:
    """A hidden name (a part starting with _): service events, the actions' own topics."""
    return any(part.startswith("_") for part in topic.split("/"))


# --- topics ----------------------------------------------------------------------------------
def republish(node: Node, contents: Contents, wanted: Callable[[str], bool], rate: float,
              stopped: Callable[[], bool], subscribers_wait_s: float = 0.0) -> int:
    """Publish the recorded messages of the wanted topics again, each when its log time comes
    (scaled by 1/rate), after waiting up to `subscribers_wait_s` for a subscriber on each, and
    wait (up to ACKED_WAIT_S) until the reliable subscribers have them all; the count
    published."""
    publishers: dict[str, Any] = {}
    for channel in contents.channels:
        if wanted(channel.topic):
            publishers[channel.topic] = node.create_publisher(
                type_class(channel.type), channel.topic, _qos(channel))
    messages = [m for m in contents.messages if m.channel.topic in publishers]
    if not messages:
        return 0
    deadline = time.monotonic() + subscribers_wait_s
    while not stopped() and time.monotonic() < deadline and \
            not all(p.get_subscription_count() for p in publishers.values()):
        time.sleep(0.05)
    start, t0 = time.monotonic(), messages[0].log_ns
    for count, m in enumerate(messages):
        while not stopped():
            left = start + (m.log_ns - t0) / 1e9 / rate - time.monotonic()
            if left <= 0:
                break
            time.sleep(min(left, 0.1))
        if stopped():
            return count
        publishers[m.channel.topic].publish(m.data)     # the recorded bytes, as they were
    for publisher in publishers.values():                # delivered before the process ends
        publisher.wait_for_all_acked(Duration(seconds=ACKED_WAIT_S))
    return len(messages)


def _qos(channel: Channel) -> QoSProfile:
    """The recorded publishers' reliability and durability (a transient-local one keeps up to
    REPUBLISH_DEPTH messages for late subscribers)."""
    offered = channel.qos_profiles[0] if channel.qos_profiles else {}
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST, depth=REPUBLISH_DEPTH,
        reliability=ReliabilityPolicy.BEST_EFFORT if offered.get("reliability") == "best_effort"
        else ReliabilityPolicy.RELIABLE,
        durability=DurabilityPolicy.TRANSIENT_LOCAL
        if offered.get("durability") == "transient_local" else DurabilityPolicy.VOLATILE)


# --- requests --------------------------------------------------------------------------------
def recorded_calls(contents: Contents) -> list[Call]:
    """The service calls (and action goals, results, cancels) of a recording, paired."""
    events, classes = [], {}
    for m in contents.messages:
        service = service_of(m.channel.topic, m.channel.type)
        if service is None:
            continue
        if m.channel.type not in classes:
            classes[m.channel.type] = type_class(m.channel.type)
        event = deserialize_message(m.data, classes[m.channel.type])
        message = (event.request or event.response or [None])[0]
        if message is None:
            continue                          # recorded without contents (metadata only)
        info = event.info
        events.append(Event(service[0], service[1], info.event_type,
                            (bytes(info.client_gid), info.sequence_number),
                            info.stamp.sec * 1_000_000_000 + info.stamp.nanosec, message))
    return pair(events)


class RequestReplay:
    """Send the calls to the running job in their recorded order and timing (scaled by 1/rate),
    and compare each answer with the recorded one."""

    def __init__(self, node: Node, calls: list[Call], rate: float, answer_timeout_s: float,
                 tolerance: float, stopped: Callable[[], bool],
                 say: Callable[[str], None] = print) -> None:
        self.node, self.calls, self.rate, self.timeout = node, calls, rate, answer_timeout_s
        self.tolerance = tolerance
        self.stopped, self.say = stopped, say
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(node)
        self.clients: dict[str, Any] = {}
        self.differences: list[str] = []

    def run(self) -> list[str]:
        """The differences found (a line each); also those said as they are found."""
        if not self._clients_ready():
            return self.differences
        must_wait = answered_before(self.calls)
        futures: dict[int, tuple[Any, float]] = {}
        answered: set[int] = set()
        start, t0 = time.monotonic(), self.calls[0].request_ns if self.calls else 0
        following = 0
        while (following < len(self.calls) or futures) and not self.stopped():
            now = time.monotonic()
            while following < len(self.calls) and set(must_wait[following]) <= answered \
                    and now >= start + (self.calls[following].request_ns - t0) / 1e9 / self.rate:
                call = self.calls[following]
                futures[following] = (self.clients[call.service].call_async(call.request), now)
                following += 1
            self.executor.spin_once(timeout_sec=0.01)
            for i, (future, sent) in list(futures.items()):
                if future.done() or time.monotonic() - sent > self.timeout:
                    del futures[i]
                    answered.add(i)
                    self._compare(i, future.result() if future.done() else None)
        self.executor.remove_node(self.node)
        return self.differences

    def _clients_ready(self) -> bool:
        for call in self.calls:
            if call.service not in self.clients:
                self.clients[call.service] = self.node.create_client(
                    type_class(call.service_type), call.service, qos_profile=CLIENT_QOS)
        deadline = time.monotonic() + SERVICE_WAIT_S
        for name, client in self.clients.items():
            if not client.wait_for_service(timeout_sec=max(0.1, deadline - time.monotonic())):
                self._differ(f"{name}: not offered (is the job running, in this ROS_DOMAIN_ID "
                             "and namespace?)")
                return False
        return True

    def _compare(self, index: int, answer: Any) -> None:
        call = self.calls[index]
        what = f"#{index + 1} {call.service}"
        if answer is None:
            self._differ(f"{what}: no answer in {self.timeout:g} s")
        elif call.response is None:
            self.say(f"{what}: answered (the recording has no answer to compare)")
        else:
            found = differences(plain(call.response), plain(answer), abs_tol=self.tolerance)
            for line in found:
                self._differ(f"{what} {line}")
            if not found:
                self.say(f"{what}: equal")

    def _differ(self, line: str) -> None:
        self.differences.append(line)
        self.say(line)
