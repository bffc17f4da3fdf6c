"""The graph commands of tools/ros2_lite.py (`node list|info`, `topic list|info|type|hz`,
`service list|type|find`, `action list|info`), printing what the real CLI prints (ros2cli,
jazzy) and hiding what it hides: a node whose name starts with `_`, a topic or service with a
`_` part (`/arm/_action/status`), unless asked to include them.

The real CLI asks its daemon, which has watched the graph for a while; this one has no daemon,
so it waits until discovery has settled (`settled`) before it answers."""
from __future__ import annotations

import argparse
import math
import sys
import time
from typing import Any, Callable, Sequence

import rclpy
from rclpy.action.graph import (get_action_client_names_and_types_by_node,
                                get_action_names_and_types,
                                get_action_server_names_and_types_by_node)
from rclpy.impl.implementation_singleton import rclpy_implementation
from rclpy.node import Node, NodeNameNonExistentError
from rclpy.qos import qos_profile_sensor_data
from rclpy.topic_or_service_is_hidden import topic_or_service_is_hidden

DISCOVERY_TIMEOUT_S = 30.0
SETTLE_S = 2.0             # s without a new node or name: discovery has settled
LIST_WAIT_S = 4.0          # s an answer waits at least for discovery
HZ_WINDOW = 10000          # messages the rate is averaged over (ros2cli's default)

NamesAndTypes = Sequence[tuple[str, Sequence[str]]]


class NotFound(Exception):
    """What was asked for is not in the graph: one line on stderr, exit status 1."""


def settled(node: Node, snapshot: Callable[[], Any], found: Callable[[Any], bool] = bool) -> Any:
    """snapshot() once discovery has settled: no new node and no change of the snapshot for
    SETTLE_S, and not before LIST_WAIT_S; or as soon as found(snapshot()) when looking for
    something. A new participant learns the others' nodes and endpoints over a few seconds,
    longer on a busy machine (after 2 s, one list in five held only its own)."""
    def seen() -> tuple[Any, int]:
        return snapshot(), len(node.get_node_names_and_namespaces())
    start = time.monotonic()
    last, settled_at = seen(), start
    while time.monotonic() < start + DISCOVERY_TIMEOUT_S:
        if found is not bool and found(last[0]):
            break
        if time.monotonic() - settled_at >= SETTLE_S and time.monotonic() - start >= LIST_WAIT_S:
            break
        rclpy.spin_once(node, timeout_sec=0.1)
        now = seen()
        if now != last:
            last, settled_at = now, time.monotonic()
    return last[0]


def of_node(query: Callable[..., NamesAndTypes], *args: Any) -> NamesAndTypes:
    """query(*args), a by-node graph query; nothing for a node that left the graph since it was
    listed (rcl then fails, "error not set" for an action's ends): it has no endpoints now."""
    try:
        return query(*args)
    except (NodeNameNonExistentError, rclpy_implementation.RCLError):
        return []


def visible(names_and_types: NamesAndTypes, include_hidden: bool) -> list:
    return sorted((n, list(t)) for n, t in names_and_types
                  if include_hidden or not topic_or_service_is_hidden(n))


def full_name(name: str, namespace: str) -> str:
    return namespace + ("" if namespace.endswith("/") else "/") + name


def node_names(node: Node, include_hidden: bool) -> list[str]:
    return sorted(full_name(n, ns) for n, ns in node.get_node_names_and_namespaces()
                  if include_hidden or (n and not n.startswith("_")))


def print_names(found: NamesAndTypes, show_types: bool, count: bool) -> None:
    """A `list`: the count, or one name a line (with its types in brackets)."""
    if count:
        print(len(found))
        return
    for name, types in found:
        print(f"{name} [{', '.join(types)}]" if show_types else name)


# --- node -----------------------------------------------------------------------------------------
def node_list(node: Node, a: argparse.Namespace) -> None:
    names = settled(node, lambda: node_names(node, a.all))
    if a.count_nodes:
        print(len(names))
        return
    if len(set(names)) < len(names):
        print("WARNING: Be aware that there are nodes in the graph that share an exact name, "
              "which can have unintended side effects.", file=sys.stderr)
    for name in names:
        print(name)


def _split(node_name: str) -> tuple[str, str]:
    """(name, namespace) of `/ns/name` (a name without `/` is in `/`)."""
    namespace, name = ("/" + node_name.lstrip("/")).rsplit("/", 1)
    return name, namespace or "/"


def node_info(node: Node, a: argparse.Namespace) -> None:
    target = "/" + a.node_name.lstrip("/")
    name, namespace = _split(target)

    def endpoints() -> tuple[bool, ...]:
        present = target in node_names(node, include_hidden=True)
        if not present:
            return (False,)
        by_node = (node.get_subscriber_names_and_types_by_node,
                   node.get_publisher_names_and_types_by_node,
                   node.get_service_names_and_types_by_node,
                   node.get_client_names_and_types_by_node)
        found = [visible(of_node(f, name, namespace), a.include_hidden) for f in by_node]
        found += [visible(of_node(f, node, name, namespace), a.include_hidden)
                  for f in (get_action_server_names_and_types_by_node,
                            get_action_client_names_and_types_by_node)]
        return (True, *found)
    info = settled(node, endpoints)
    if not info[0]:
        raise NotFound(f"Unable to find node '{target}'")
    count = node_names(node, include_hidden=True).count(target)
    if count > 1:
        print(f'There are {count} nodes in the graph with the exact name "{target}". '
              "You are seeing information about only one of them.", file=sys.stderr)
    print(target)
    headings = ("Subscribers", "Publishers", "Service Servers", "Service Clients",
                "Action Servers", "Action Clients")
    for heading, found in zip(headings, info[1:]):
        print(f"  {heading}:")
        print(*[f"    {n}: {', '.join(t)}" for n, t in found], sep="\n")


# --- topic ----------------------------------------------------------------------------------------
def topic_list(node: Node, a: argparse.Namespace) -> None:
    found = settled(node, lambda: visible(node.get_topic_names_and_types(), a.include_hidden))
    print_names(found, a.show_types, a.count_topics)


def types_of(node: Node, name: str, names_and_types: Callable[[], NamesAndTypes]) -> list[str]:
    """The types of `name` once discovered (empty if it does not appear before discovery
    settles)."""
    def types() -> list[str]:
        return next((list(t) for n, t in names_and_types() if n == name), [])
    return settled(node, types, found=bool)


def print_types(node: Node, name: str, names_and_types: Callable[[], NamesAndTypes]) -> int:
    """`topic type`, `service type`: the types, one a line; exit status 1 if none."""
    types = types_of(node, name, names_and_types)
    for t in types:
        print(t)
    return 0 if types else 1


def topic_info(node: Node, a: argparse.Namespace) -> None:
    types = types_of(node, a.topic_name, node.get_topic_names_and_types)
    if not types:
        raise NotFound(f"Unknown topic '{a.topic_name}'")
    end = "\n\n" if a.verbose else "\n"
    print(f"Type: {types[0] if len(types) == 1 else types}", end=end)
    print(f"Publisher count: {node.count_publishers(a.topic_name)}", end=end)
    if a.verbose:
        for info in node.get_publishers_info_by_topic(a.topic_name):
            print(info, end=end)
    print(f"Subscription count: {node.count_subscribers(a.topic_name)}", end=end)
    if a.verbose:
        for info in node.get_subscriptions_info_by_topic(a.topic_name):
            print(info, end=end)


class Rate:
    """The arrival rate of messages over the last `window` intervals, as `ros2 topic hz`
    prints it: once a second of message time, while new messages come."""

    def __init__(self, window: int) -> None:
        self.window = window
        self.intervals: list[int] = []      # ns
        self.last: int | None = None        # ns, the last message's arrival
        self.printed: int | None = None     # ns, the arrival at the last print

    def arrived(self, now_ns: int) -> None:
        if self.last is not None and now_ns >= self.last:
            self.intervals.append(now_ns - self.last)
            del self.intervals[:-self.window]
        self.last = now_ns

    def report(self) -> str | None:
        """The lines to print now, None while there is nothing new to say."""
        if not self.intervals:
            return None
        if self.printed is None:
            self.printed = self.last
            return None
        if self.last < self.printed + 1e9:
            return None
        self.printed = self.last
        n, mean = len(self.intervals), sum(self.intervals) / len(self.intervals)
        std = math.sqrt(sum((x - mean) ** 2 for x in self.intervals) / n)
        rate = 1e9 / mean if mean > 0 else 0.0
        return (f"average rate: {rate:.3f}\n\tmin: {min(self.intervals) * 1e-9:.3f}s "
                f"max: {max(self.intervals) * 1e-9:.3f}s std dev: {std * 1e-9:.5f}s "
                f"window: {n}")


def topic_hz(node: Node, a: argparse.Namespace, message_class: Callable[[str], type]) -> None:
    """Until Ctrl-C (or `--times` reports), the rate at which the topic's messages arrive."""
    types = types_of(node, a.topic_name, node.get_topic_names_and_types)
    if not types:
        raise NotFound(f"the topic {a.topic_name} does not appear")
    rate = Rate(a.window_size)
    clock = node.get_clock()
    node.create_subscription(message_class(types[0]), a.topic_name,
                             lambda _m: rate.arrived(clock.now().nanoseconds
                                                     if not a.use_wtime else time.time_ns()),
                             qos_profile_sensor_data)
    reports = 0
    while a.times is None or reports < a.times:
        rclpy.spin_once(node, timeout_sec=0.1)
        said = rate.report()
        if said:
            print(said, flush=True)
            reports += 1


# --- service --------------------------------------------------------------------------------------
def service_list(node: Node, a: argparse.Namespace) -> None:
    found = settled(node, lambda: visible(node.get_service_names_and_types(), a.include_hidden))
    print_names(found, a.show_types, a.count_services)


def service_find(node: Node, a: argparse.Namespace) -> None:
    found = settled(node, lambda: visible(node.get_service_names_and_types(), a.include_hidden))
    names = [n for n, types in found if a.service_type in types]
    print_names([(n, []) for n in names], False, a.count_services)


# --- action ---------------------------------------------------------------------------------------
def action_list(node: Node, a: argparse.Namespace) -> None:
    found = settled(node, lambda: sorted((n, list(t))
                                         for n, t in get_action_names_and_types(node)))
    print_names(found, a.show_types, a.count_actions)


def action_info(node: Node, a: argparse.Namespace) -> None:
    name = "/" + a.action_name.lstrip("/")

    def ends() -> tuple[list, list]:
        clients, servers = [], []
        for node_name, namespace in node.get_node_names_and_namespaces():
            for found, by_node in ((clients, get_action_client_names_and_types_by_node),
                                   (servers, get_action_server_names_and_types_by_node)):
                found += [(full_name(node_name, namespace), list(t))
                          for n, t in of_node(by_node, node, node_name, namespace) if n == name]
        return sorted(clients), sorted(servers)
    clients, servers = settled(node, ends)
    print(f"Action: {a.action_name}")
    for heading, found in (("Action clients", clients), ("Action servers", servers)):
        print(f"{heading}: {len(found)}")
        if not a.count:
            for who, types in found:
                print(f"    {who} [{', '.join(types)}]" if a.show_types else f"    {who}")
