"""Replaying a recording over ROS: its topics republished with their timing, or its service
calls, action goals and command messages sent again to a running job on its own clock
(`acti_record.timing`) and each answer compared with the recorded one (`acti_record.calls`)."""
from __future__ import annotations

import array
import math
import statistics
import time
from typing import Any, Callable

from rclpy.duration import Duration
from rclpy.executors import SingleThreadedExecutor
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy
from rclpy.serialization import deserialize_message
from rosgraph_msgs.msg import Clock

from acti_bringup.recording.introspection import EVENT_QOS
from acti_bringup.recording.types import type_class
from acti_bringup.serving.adapter import CLIENT_QOS
from acti_record.calls import (EVENT_TOPIC_SUFFIX, EVENT_TYPE_SUFFIX, REQUEST_RECEIVED,
                               RESPONSE_SENT, Call, Event, differences, largest_deviation,
                               pair, service_of)
from acti_record.reading import Channel, Contents, Message
from acti_record.timing import ClockMap, Plan, SpeedTrack

SERVICE_WAIT_S = 30.0
REPUBLISH_DEPTH = 1000
ACKED_WAIT_S = 5.0
MATCH_WAIT_S = 10.0       # for the job's clock, its service events, the command topics' listeners
EVENT_WAIT_S = 5.0
SPIN_S = 0.005            # the longest wait for the job's news while an input is not due        # for the job's events of the last calls, after their answers
CLOCK_TYPE = "rosgraph_msgs/msg/Clock"
MOVING = 1.0              # a device's speed changes by more than this (mm/s, degree/s): it reacts


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
    """Send the recorded calls, and the messages of the recording's command topics, to the
    running job in their recorded order and timing (`acti_record.timing.Plan`: on the job's
    clock, scaled by 1/rate) and compare each answer with the recorded one, measured numbers
    within the tolerance and how far the replay's timing errors may have moved the device."""

    def __init__(self, node: Node, contents: Contents, rate: float, answer_timeout_s: float,
                 tolerance: float, stopped: Callable[[], bool],
                 say: Callable[[str], None] = print) -> None:
        self.node, self.contents, self.rate = node, contents, rate
        self.timeout, self.tolerance = answer_timeout_s, tolerance
        self.stopped, self.say = stopped, say
        self.calls = recorded_calls(contents)
        self.executor = SingleThreadedExecutor()
        self.executor.add_node(node)
        self.clients: dict[str, Any] = {}
        self.differences: list[str] = []
        self.commands: list[Message] = []
        self.clock = recorded_clock(contents)     # the recorded job's simulated time
        self.job_clock = ClockMap()
        self.job_speeds: dict[str, tuple[str, list[bytes]]] = {}   # the devices' speed topics
        self.taken: dict[str, list[tuple[int, tuple]]] = {}   # the job's requests taken
        self.answered: dict[tuple, int] = {}                   # (service, client, seq): stamp

    def run(self) -> list[str]:
        """The differences found (a line each; also said, as is every call's outcome)."""
        if not self._clients_ready():
            return self.differences
        publishers, devices = self._command_topics()
        self._watch_the_job()
        plan = Plan(self.calls, self.commands, lambda c: device_of_service(c.service), devices,
                    self.clock)
        sent: dict[int, int] = {}                       # event: when this replay made it
        answers: dict[int, Any] = {}
        pending: dict[int, Any] = {}
        latency: list[int] = []                         # a request sent until the job took it
        following = 0
        while (following < len(plan.inputs) or pending) and not self.stopped():
            wait_s = SPIN_S
            if following < len(plan.inputs) and plan.waits[following] <= set(answers):
                kind, k = plan.inputs[following]
                early = statistics.median(latency) if kind == "call" and latency else 0
                anchor = plan.anchors[following]
                known = {} if anchor is None else {anchor: self._job_time(plan, anchor, sent)}
                due = plan.due_ns(following, known, self.job_clock, self.rate) - early
                left_s = (due - self.job_clock.sim_at(time.time_ns())) / 1e9
                if left_s <= 0:
                    sent[plan.event_of[following]] = time.time_ns()
                    if kind == "call":
                        pending[k] = self.clients[self.calls[k].service].call_async(
                            self.calls[k].request)
                    else:
                        publishers[self.commands[k].channel.topic].publish(
                            self.commands[k].data)
                    following += 1
                    continue
                wait_s = min(wait_s, left_s)
            self.executor.spin_once(timeout_sec=wait_s)
            for k, future in list(pending.items()):
                asked = sent[plan.request_event[k]]
                if future.done() or time.time_ns() - asked > self.timeout * 1e9:
                    del pending[k]
                    answers[k] = future.result() if future.done() else None
                    if plan.answer_event[k] is not None:
                        sent[plan.answer_event[k]] = time.time_ns()
                    taken = self._taken(plan, k)
                    if taken is not None:
                        latency.append(taken[0] - asked)
        _wait(self.executor, lambda: all(self._taken(plan, k) for k in range(len(self.calls))),
              EVENT_WAIT_S)
        self._compare_all(plan, answers, self._job_times(plan, sent))
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

    def _command_topics(self) -> tuple[dict[str, Any], dict[str, str]]:
        """The recorded topics the running job listens to and does not publish itself (commands
        from outside: cmd_vel …): a publisher each, and the node listening (the device)."""
        publishers, devices = {}, {}
        topics = [c for c in self.contents.channels if not is_hidden(c.topic)]
        # the job's endpoints of each are in the graph (discovery comes a little later than
        # the services'), unless the job has none
        _wait(self.executor, lambda: all(self._endpoints(c.topic) for c in topics), MATCH_WAIT_S)
        for channel in topics:
            listeners = [s for s in self.node.get_subscriptions_info_by_topic(channel.topic)
                         if s.node_name != self.node.get_name()]
            if listeners and not self.node.get_publishers_info_by_topic(channel.topic):
                publishers[channel.topic] = self.node.create_publisher(
                    type_class(channel.type), channel.topic, _qos(channel))
                devices[channel.topic] = node_path(listeners[0].node_namespace,
                                                   listeners[0].node_name)
        self.commands = [m for m in self.contents.messages if m.channel.topic in publishers]
        _wait(self.executor, lambda: all(p.get_subscription_count()
                                         for p in publishers.values()), MATCH_WAIT_S)
        return publishers, devices

    def _endpoints(self, topic: str) -> list:
        mine = self.node.get_name()
        return [e for e in (*self.node.get_publishers_info_by_topic(topic),
                            *self.node.get_subscriptions_info_by_topic(topic))
                if e.node_name != mine]

    def _watch_the_job(self) -> None:
        """Subscribe to the job's clock and to the events of the services called (when the job
        took each request, when it answered), and wait until they are heard."""
        watched = []
        clocks = [c.topic for c in self.contents.channels if c.type == CLOCK_TYPE]
        if clocks:
            watched.append(self.node.create_subscription(Clock, clocks[0], self._on_clock, 100))
        for channel in self.contents.channels:
            device = device_of_speed_topic(channel.topic, channel.type)
            if device is not None:      # kept as received, read at the end (cheap meanwhile)
                kept = self.job_speeds.setdefault(device, (channel.type, []))[1]
                watched.append(self.node.create_subscription(
                    type_class(channel.type), channel.topic, kept.append, 100, raw=True))
        for service, service_type in {(c.service, c.service_type) for c in self.calls}:
            watched.append(self.node.create_subscription(
                type_class(service_type + EVENT_TYPE_SUFFIX), service + EVENT_TOPIC_SUFFIX,
                lambda event, name=service: self._on_event(name, event), EVENT_QOS))
        _wait(self.executor, lambda: all(w.get_publisher_count() for w in watched) and
              (not clocks or len(self.job_clock.walls) > 1), MATCH_WAIT_S)

    def _on_clock(self, message: Clock, info: Any) -> None:
        self.job_clock.add(info["source_timestamp"], _ns(message.clock))

    def _on_event(self, service: str, event: Any) -> None:
        info = event.info
        key = (service, bytes(info.client_gid), info.sequence_number)
        if info.event_type == REQUEST_RECEIVED:
            self.taken.setdefault(service, []).append((_ns(info.stamp), key))
        elif info.event_type == RESPONSE_SENT:
            self.answered[key] = _ns(info.stamp)

    def _taken(self, plan: Plan, k: int) -> tuple[int, tuple] | None:
        """When the job took call k's request, and its key (the k-th call of its service)."""
        taken = self.taken.get(self.calls[k].service, [])
        nth = plan.nth_of_service[k]
        return taken[nth] if nth < len(taken) else None

    def _job_time(self, plan: Plan, event: int, sent: dict[int, int]) -> int:
        """When an event made so far happened, on the job's wall clock: a request when the job
        took it and an answer when it sent it (by the job's events, else when this replay sent
        or got it), a message when it was published."""
        if event in plan.call_of_request:
            taken = self._taken(plan, plan.call_of_request[event])
            return sent[event] if taken is None else taken[0]
        if event in plan.call_of_answer:
            taken = self._taken(plan, plan.call_of_answer[event])
            return self.answered.get(taken[1], sent[event]) if taken else sent[event]
        return sent[event]

    def _job_times(self, plan: Plan, sent: dict[int, int]) -> dict[int, int]:
        return {event: self._job_time(plan, event, sent) for event in sent}

    def _job_speed(self, device: str) -> SpeedTrack:
        track = SpeedTrack()
        type_name, kept = self.job_speeds.get(device, ("", []))
        for data in kept:
            track.add(*device_speed(type_name, deserialize_message(data, type_class(type_name))))
        return track

    def _compare_all(self, plan: Plan, answers: dict[int, Any], job_ns: dict[int, int]) -> None:
        errors = plan.errors_s(job_ns, self.job_clock, self.rate)
        speeds = recorded_speeds(self.contents)
        reactions = {device: plan.reaction_errors(device, track, self._job_speed(device),
                                                  job_ns, self.job_clock, MOVING)
                     for device, track in speeds.items()}
        margin_s = self.clock.period_ns() / 1e9
        arrivals = {device: plan.arrivals(device, track, MOVING) for device, track in speeds.items()}
        allowed = plan.allowances(errors, lambda device, t0, t1: speeds[device].peak(t0, t1)
                                  if device in speeds else 0.0, margin_s, reactions, arrivals)
        for k in range(len(self.calls)):
            n = plan.input_of[k]
            self._compare(k, answers.get(k), allowed[n], errors[n])
        if errors:
            self.say(f"timing on the job's clock: {len(errors)} inputs ({len(self.commands)} "
                     f"command messages), errors: median "
                     f"{statistics.median(map(abs, errors)) * 1e3:.1f} ms, largest "
                     f"{max(errors, key=abs) * 1e3:+.1f} ms; margin {margin_s * 1e3:.1f} ms")
        for device, found in reactions.items():
            if found:
                worst = max((e for _, e in found), key=abs)
                self.say(f"{device} reacted to {len(found)} inputs, errors: median "
                         f"{statistics.median(abs(e) for _, e in found) * 1e3:.1f} ms, largest "
                         f"{worst * 1e3:+.1f} ms")

    def _compare(self, k: int, answer: Any, allowance: float, error_s: float) -> None:
        call = self.calls[k]
        what = f"#{k + 1} {call.service} [{error_s * 1e3:+.1f} ms]"
        if answer is None:
            self._differ(f"{what}: no answer in {self.timeout:g} s")
        elif call.response is None:
            self.say(f"{what}: answered (the recording has no answer to compare)")
        else:
            recorded, replayed = plain(call.response), plain(answer)
            found = differences(recorded, replayed, abs_tol=self.tolerance + allowance)
            for line in found:
                self._differ(f"{what} {line} (allowed: {self.tolerance:g} + {allowance:.3g} "
                             "for the timing)")
            deviation = largest_deviation(recorded, replayed)
            if not found and deviation > self.tolerance:
                self.say(f"{what}: equal, numbers {deviation:.3g} apart, within "
                         f"{self.tolerance:g} + {allowance:.3g} (how far the replay's timing "
                         "errors may have moved the device)")
            elif not found:
                self.say(f"{what}: equal")

    def _differ(self, line: str) -> None:
        self.differences.append(line)
        self.say(line)


def _ns(stamp: Any) -> int:
    return stamp.sec * 1_000_000_000 + stamp.nanosec


def _wait(executor: SingleThreadedExecutor, done: Callable[[], bool], timeout_s: float) -> bool:
    deadline = time.monotonic() + timeout_s
    while not done() and time.monotonic() < deadline:
        executor.spin_once(timeout_sec=0.05)
    return done()


def node_path(namespace: str, name: str) -> str:
    return f"{namespace.rstrip('/')}/{name}"


def device_of_service(service: str) -> str:
    """The node a service belongs to (an action's too): the device its calls drive or read."""
    return service.split("/_action/", 1)[0].rsplit("/", 1)[0]


def recorded_clock(contents: Contents) -> ClockMap:
    """The recorded job's simulated time by its wall clock, from its /clock messages."""
    clock = ClockMap()
    for m in contents.messages:
        if m.channel.type == CLOCK_TYPE:
            clock.add(m.publish_ns, _ns(deserialize_message(m.data, Clock).clock))
    return clock


def _base_speed(odometry: Any) -> float:
    twist = odometry.twist.twist
    return max(math.hypot(twist.linear.x, twist.linear.y) * 1000.0,      # mm/s
               math.degrees(abs(twist.angular.z)))                      # degree/s


def _arm_speed(joints: Any) -> float:
    """degree/s of the arm's joints, mm/s of the gripper's opening (both fingers); the base's
    wheels are not the arm's."""
    return max((abs(v) * (2000.0 if name.startswith("gripper") else math.degrees(1.0))
                for name, v in zip(joints.name, joints.velocity) if "wheel" not in name),
               default=0.0)


# a node's device: the topic (beside the node, in its namespace) that says how fast it moves,
# in the units of its answers per second, stamped with the simulated time
DEVICE_SPEEDS = {"vehicle_node": ("odom", "nav_msgs/msg/Odometry", _base_speed),
                 "acti_middle_node": ("joint_states", "sensor_msgs/msg/JointState", _arm_speed)}


def recorded_speeds(contents: Contents) -> dict[str, SpeedTrack]:
    """Each device's recorded speed by the job's simulated time (the messages' stamps)."""
    tracks: dict[str, SpeedTrack] = {}
    for m in contents.messages:
        device = device_of_speed_topic(m.channel.topic, m.channel.type)
        if device is not None:
            tracks.setdefault(device, SpeedTrack()).add(
                *device_speed(m.channel.type, deserialize_message(m.data, type_class(m.channel.type))))
    return tracks


def device_of_speed_topic(topic: str, type_name: str) -> str | None:
    """The device (node path) whose speed a topic tells, None for another topic."""
    namespace, name = topic.rsplit("/", 1)
    for node, (speed_topic, speed_type, _) in DEVICE_SPEEDS.items():
        if name == speed_topic and type_name == speed_type:
            return node_path(namespace, node)
    return None


def device_speed(type_name: str, message: Any) -> tuple[int, float]:
    """(simulated time of the message's stamp [ns], the device's speed then)."""
    speed = next(fn for _, t, fn in DEVICE_SPEEDS.values() if t == type_name)
    return _ns(message.header.stamp), speed(message)
