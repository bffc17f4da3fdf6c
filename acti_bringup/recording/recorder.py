"""The recorder: a node that subscribes to every topic (or the ones named), hidden ones included
(the service events of `introspection`, the actions' feedback and status), and writes the bytes
rclpy received, unconverted, to a recording (`acti_record.writing`).

Topics are discovered from the graph every DISCOVERY_PERIOD_S; each is subscribed with the QoS
its publishers offer (reliable and transient-local only when all of them are, as rosbag2 does),
and recorded with their QoS profiles and type hash. A topic that is only listened to so far (a
command topic: cmd_vel) is subscribed at once to match any publisher its listeners can hear."""
from __future__ import annotations

import time
from typing import Any, Callable

from rclpy.event_handler import SubscriptionEventCallbacks
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from acti_bringup.recording.types import share_dir, type_class
from acti_record.definitions import DefinitionNotFound, full_text
from acti_record.writing import FLUSH_PERIOD_S, Recording, Topic, qos_profile

DISCOVERY_PERIOD_S = 0.5
RECEIVE_DEPTH = 1000          # messages a subscription holds while the recorder is busy
# no QoS event handler per subscription (rclpy's default adds one): each is one more entity in
# the executor's wait set, rebuilt for every message (half the recorder's CPU with ~150 topics)
NO_EVENTS = SubscriptionEventCallbacks(use_default_callbacks=False)


class Recorder:
    """Subscriptions of `node` to the topics that `wanted(name)` accepts, written to
    `recording`, whose chunk in progress reaches the file every FLUSH_PERIOD_S."""

    def __init__(self, node: Node, recording: Recording, wanted: Callable[[str], bool]) -> None:
        self.node, self.recording, self.wanted = node, recording, wanted
        self._subscriptions: dict[str, Any] = {}
        self._refused: set[str] = set()
        self.discover()
        self._timers = [node.create_timer(DISCOVERY_PERIOD_S, self.discover),
                        node.create_timer(FLUSH_PERIOD_S, recording.flush)]

    def discover(self) -> None:
        for name, types in self.node.get_topic_names_and_types():
            if name in self._subscriptions or name in self._refused or not self.wanted(name):
                continue
            try:
                self._subscribe(name, types[0])
            except LookupError as e:
                self._refused.add(name)
                self.node.get_logger().warning(f"{name} is not recorded: {e}")

    def _subscribe(self, name: str, type_name: str) -> None:
        msg_class = type_class(type_name)
        publishers = self._publishers(name, type_name)
        if publishers:
            qos = _subscription_qos(publishers)
        else:
            # a topic the job listens to that nobody publishes yet (cmd_vel …): subscribed now,
            # so that the first messages of a publisher that comes later are recorded too (the
            # graph is looked at every DISCOVERY_PERIOD_S: a jog would lose its first half second)
            listeners = [s.qos_profile for s in self.node.get_subscriptions_info_by_topic(name)
                         if s.topic_type == type_name]
            if not listeners:
                return
            qos = _listening_qos(listeners)
        try:
            definition = full_text(type_name, share_dir)
        except DefinitionNotFound as e:
            self.node.get_logger().warning(f"{name}: no definition of {type_name} ({e}): "
                                           "recorded without one")
            definition = ""
        write = self.recording.write
        topic: list[Topic] = []          # made at the first message, with its publishers

        def received(data: bytes, info: Any) -> None:
            now = time.time_ns()
            if not topic:
                offered = publishers or self._publishers(name, type_name)
                topic.append(Topic(name, type_name, definition,
                                   tuple(_profile(p.qos_profile) for p in offered),
                                   str(offered[0].topic_type_hash) if offered else ""))
            write(topic[0], data, now, info.get("source_timestamp", now)
                  if isinstance(info, dict) else now)
        self._subscriptions[name] = self.node.create_subscription(
            msg_class, name, received, qos, raw=True, event_callbacks=NO_EVENTS)

    def _publishers(self, name: str, type_name: str) -> list:
        return [p for p in self.node.get_publishers_info_by_topic(name)
                if p.topic_type == type_name]


def _subscription_qos(publishers: list) -> QoSProfile:
    """Reliable, transient-local when every publisher offers it (else best effort, volatile)."""
    offered = [p.qos_profile for p in publishers]
    reliable = all(q.reliability == ReliabilityPolicy.RELIABLE for q in offered)
    lasting = all(q.durability == DurabilityPolicy.TRANSIENT_LOCAL for q in offered)
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=RECEIVE_DEPTH,
                      reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
                      durability=DurabilityPolicy.TRANSIENT_LOCAL if lasting else DurabilityPolicy.VOLATILE)


def _listening_qos(listeners: list[QoSProfile]) -> QoSProfile:
    """Matches every publisher the listeners can hear: reliable when they all ask for it (then
    every publisher they hear offers it), else best effort; volatile."""
    reliable = all(q.reliability == ReliabilityPolicy.RELIABLE for q in listeners)
    return QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=RECEIVE_DEPTH,
                      reliability=ReliabilityPolicy.RELIABLE if reliable else ReliabilityPolicy.BEST_EFFORT,
                      durability=DurabilityPolicy.VOLATILE)


def _profile(q: QoSProfile) -> dict:
    return qos_profile(q.history.name.lower(), q.depth, q.reliability.name.lower(),
                       q.durability.name.lower(), q.deadline.nanoseconds, q.lifespan.nanoseconds,
                       q.liveliness.name.lower(), q.liveliness_lease_duration.nanoseconds)
