"""The few `ros2` commands this README uses, for a checkout without a full ROS install.

The `ros2` CLI is not on PyPI, so `make run` cannot install it; `tools/env.sh` puts this one on
PATH only when no `ros2` is found. It covers `service call|list`, `topic pub|echo|list`,
`action send_goal` and `param get|set|describe|list` with the real CLI's arguments and the same
request syntax (a YAML mapping of the fields; integers are accepted for floating-point fields),
over rclpy and DDS as any ROS 2 client. Anything else: install ROS 2 Jazzy and source it.
"""
from __future__ import annotations

import argparse
import array
import importlib
import signal
import sys
import time
from typing import Any, Callable

import numpy as np
import rclpy
import yaml
from rclpy.action import ActionClient
from rclpy.node import Node
from rclpy.parameter import Parameter

DISCOVERY_TIMEOUT_S = 30.0
MATCH_WAIT_S = 2.0
TEARDOWN_S = 5             # s the DDS teardown may take after the command is done
LIST_WAIT_S = 4.0          # s a `list` waits at least for discovery
SEQUENCES = (list, tuple, array.array, np.ndarray)


class Usage(Exception):
    """A command line or request this tool cannot carry out: one line, exit status 1."""


# --- types and messages ------------------------------------------------------------------------
def interface(name: str) -> type:
    """The class of `pkg/msg/Type`, `pkg/srv/Type` or `pkg/action/Type`."""
    parts = name.split("/")
    if len(parts) != 3 or parts[1] not in ("msg", "srv", "action"):
        raise Usage(f"the type must be pkg/msg|srv|action/Name, got {name!r}")
    try:
        return getattr(importlib.import_module(f"{parts[0]}.{parts[1]}"), parts[2])
    except (ImportError, AttributeError):
        raise Usage(f"the type {name} is not known here") from None


def is_message(value: Any) -> bool:
    return hasattr(value, "get_fields_and_field_types")


def fill(msg: Any, values: Any) -> Any:
    """Set the fields of `msg` from a mapping, as the real CLI does: nested mappings fill nested
    messages, lists of mappings sequences of messages, other values are converted to the
    field's Python type (so 500 fills a float64 field)."""
    if not isinstance(values, dict):
        raise Usage(f"the values of a {type(msg).__name__} must be a mapping, got {values!r}")
    for name, value in values.items():
        if name not in msg.get_fields_and_field_types():
            raise Usage(f"{type(msg).__name__} has no field {name!r} "
                        f"(fields: {', '.join(msg.get_fields_and_field_types())})")
        current = getattr(msg, name)
        try:
            setattr(msg, name, _converted(current, msg, name, value))
        except (AssertionError, TypeError, ValueError) as e:
            raise Usage(f"{type(msg).__name__}.{name} cannot be {value!r}: {e}") from None
    return msg


def _converted(current: Any, msg: Any, name: str, value: Any) -> Any:
    if is_message(current):
        return fill(type(current)(), value)
    if isinstance(current, SEQUENCES):
        if not isinstance(value, list):
            raise Usage(f"{type(msg).__name__}.{name} is a sequence, got {value!r}")
        item_class = _item_class(msg, name)
        return [fill(item_class(), v) for v in value] if item_class else value
    return type(current)(value)


def _item_class(msg: Any, name: str) -> type | None:
    """The message class of a sequence field's items, None for basic items."""
    spec = msg.get_fields_and_field_types()[name]
    inner = spec.split("<", 1)[1].split(">", 1)[0] if "<" in spec else spec.split("[", 1)[0]
    if "/" not in inner:
        return None
    package, type_name = inner.split("/")
    return interface(f"{package}/msg/{type_name}")


def as_plain(value: Any) -> Any:
    """A message as nested dicts and lists (what `topic echo` and feedback print as YAML)."""
    if is_message(value):
        return {name: as_plain(getattr(value, name)) for name in value.get_fields_and_field_types()}
    if isinstance(value, SEQUENCES):
        return [as_plain(v) for v in value]
    if isinstance(value, np.generic):
        return value.item()
    return value


def show(value: Any, indent: int = 0) -> str:
    text = yaml.safe_dump(as_plain(value), sort_keys=False, allow_unicode=True).rstrip()
    return "\n".join(" " * indent + line for line in text.splitlines())


def request(cls: type, text: str | None) -> Any:
    try:
        values = yaml.safe_load(text) if text else {}
    except yaml.YAMLError as e:
        raise Usage(f"the values are not YAML: {e}") from None
    return fill(cls(), values or {})


# --- waiting --------------------------------------------------------------------------------------
def spin_until(node: Node, done: Callable[[], bool], timeout: float | None, what: str) -> None:
    deadline = None if timeout is None else time.monotonic() + timeout
    while not done():
        if deadline is not None and time.monotonic() > deadline:
            raise Usage(f"{what}: no answer within {timeout:g} s")
        rclpy.spin_once(node, timeout_sec=0.1)


def topic_type(node: Node, topic: str) -> str:
    """The type of a topic someone publishes, as discovered."""
    deadline = time.monotonic() + DISCOVERY_TIMEOUT_S
    while time.monotonic() < deadline:
        for name, types in node.get_topic_names_and_types():
            if name == topic and types:
                return types[0]
        rclpy.spin_once(node, timeout_sec=0.1)
    raise Usage(f"the topic {topic} does not appear (give its type)")


# --- commands -------------------------------------------------------------------------------------
def service_call(node: Node, a: argparse.Namespace) -> None:
    cls = interface(a.type)
    req = request(cls.Request, a.values)
    client = node.create_client(cls, a.name)
    print("waiting for service to become available...")
    if not client.wait_for_service(timeout_sec=DISCOVERY_TIMEOUT_S):
        raise Usage(f"the service {a.name} does not appear")
    print(f"requester: making request: {req!r}\n")
    future = client.call_async(req)
    spin_until(node, future.done, None, a.name)
    print(f"response:\n{future.result()!r}\n")


def topic_pub(node: Node, a: argparse.Namespace) -> None:
    cls = interface(a.type)
    msg = request(cls, a.values)
    pub = node.create_publisher(cls, a.topic, 10)
    times = 1 if a.once else a.times
    deadline = time.monotonic() + MATCH_WAIT_S   # else the first message may reach no one
    while pub.get_subscription_count() == 0 and time.monotonic() < deadline:
        rclpy.spin_once(node, timeout_sec=0.05)
    print("publisher: beginning loop")
    sent = 0
    while times is None or sent < times:
        pub.publish(msg)
        sent += 1
        print(f"publishing #{sent}: {msg!r}\n")
        if times is None or sent < times:
            rclpy.spin_once(node, timeout_sec=1.0 / a.rate)
    time.sleep(0.2)         # let DDS deliver the last one before the process ends


def topic_echo(node: Node, a: argparse.Namespace) -> None:
    cls = interface(a.type or topic_type(node, a.topic))
    got: list[Any] = []

    def on_message(msg: Any) -> None:
        print(show(msg) + "\n---", flush=True)
        got.append(msg)
    node.create_subscription(cls, a.topic, on_message, 10)
    spin_until(node, lambda: a.once and bool(got), None, a.topic)


def listing(node: Node, names_and_types: Callable[[], list], show_types: bool) -> None:
    """What discovery finds, once it has found no new node and no new name for MATCH_WAIT_S,
    and not before LIST_WAIT_S: a new participant learns the others' nodes and endpoints over a
    few seconds, longer on a busy machine (after 2 s, one list in five held only its own)."""
    def seen() -> tuple[list, int]:
        return names_and_types(), len(node.get_node_names_and_namespaces())
    (found, nodes), start = seen(), time.monotonic()
    settled_at = start
    while (time.monotonic() - settled_at < MATCH_WAIT_S or time.monotonic() - start < LIST_WAIT_S) \
            and time.monotonic() < start + DISCOVERY_TIMEOUT_S:
        rclpy.spin_once(node, timeout_sec=0.1)
        now, now_nodes = seen()
        if (len(now), now_nodes) != (len(found), nodes):
            (found, nodes), settled_at = (now, now_nodes), time.monotonic()
    for name, types in sorted(found):
        print(f"{name} [{', '.join(types)}]" if show_types else name)


def action_send_goal(node: Node, a: argparse.Namespace) -> None:
    cls = interface(a.type)
    goal = request(cls.Goal, a.values)
    client = ActionClient(node, cls, a.name)
    print("Waiting for an action server to become available...")
    if not client.wait_for_server(timeout_sec=DISCOVERY_TIMEOUT_S):
        raise Usage(f"the action {a.name} does not appear")
    print(f"Sending goal:\n{show(goal, 5)}\n")
    feedback = (lambda fb: print(f"Feedback:\n{show(fb.feedback, 4)}\n", flush=True)) \
        if a.feedback else None
    sent = client.send_goal_async(goal, feedback_callback=feedback)
    spin_until(node, sent.done, None, a.name)
    handle = sent.result()
    if not handle.accepted:
        print("Goal was rejected.")
        return
    print(f"Goal accepted with ID: {bytes(handle.goal_id.uuid).hex()}\n")
    result = handle.get_result_async()
    spin_until(node, result.done, None, a.name)
    status = {4: "SUCCEEDED", 5: "CANCELED", 6: "ABORTED"}.get(result.result().status,
                                                               str(result.result().status))
    print(f"Result:\n{show(result.result().result, 4)}\n\nGoal finished with status: {status}")


def _parameter_client(node: Node, target: str) -> Any:
    from rclpy.parameter_client import AsyncParameterClient
    client = AsyncParameterClient(node, target)
    if not client.wait_for_services(timeout_sec=DISCOVERY_TIMEOUT_S):
        raise Usage(f"the node {target} does not appear")
    return client


def _answer(node: Node, future: Any, what: str) -> Any:
    spin_until(node, future.done, DISCOVERY_TIMEOUT_S, what)
    return future.result()


def param(node: Node, a: argparse.Namespace) -> None:
    client = _parameter_client(node, a.node)
    if a.verb == "list":
        for name in sorted(_answer(node, client.list_parameters([], 0), a.node).result.names):
            print(f"  {name}")
        return
    if not a.name:
        raise Usage(f"param {a.verb} needs a parameter name")
    if a.verb == "get":
        values = _answer(node, client.get_parameters([a.name]), a.node).values
        if not values or values[0].type == 0:
            print("Parameter not set.")
            return
        value = Parameter.from_parameter_msg(_named(a.name, values[0])).value
        print(f"Parameter value is: {value}")
    elif a.verb == "describe":
        for d in _answer(node, client.describe_parameters([a.name]), a.node).descriptors:
            print(f"Parameter name: {d.name}\n  Type: {Parameter.Type(d.type).name.lower()}\n"
                  f"  Description: {d.description}\n  Read only: {d.read_only}"
                  + "".join(f"\n  Range: {r.from_value} … {r.to_value}"
                            for r in (*d.floating_point_range, *d.integer_range)))
    else:
        if a.value is None:
            raise Usage("param set needs a value")
        value = yaml.safe_load(a.value)
        result = _answer(node, client.set_parameters([Parameter(a.name, value=value)]),
                         a.node).results[0]
        print("Set parameter successful" if result.successful
              else f"Setting parameter failed: {result.reason}")


def _named(name: str, value: Any) -> Any:
    from rcl_interfaces.msg import Parameter as ParameterMsg
    return ParameterMsg(name=name, value=value)


# --- command line ---------------------------------------------------------------------------------
def parser() -> argparse.ArgumentParser:
    top = argparse.ArgumentParser(prog="ros2", description=__doc__.splitlines()[0])
    groups = top.add_subparsers(dest="group", required=True)
    service = groups.add_parser("service").add_subparsers(dest="verb", required=True)
    call = service.add_parser("call")
    call.add_argument("name"), call.add_argument("type"), call.add_argument("values", nargs="?")
    call.set_defaults(run=service_call)
    _add_list(service, "get_service_names_and_types")
    topic = groups.add_parser("topic").add_subparsers(dest="verb", required=True)
    pub = topic.add_parser("pub")
    pub.add_argument("topic"), pub.add_argument("type"), pub.add_argument("values", nargs="?")
    pub.add_argument("-r", "--rate", type=float, default=1.0)
    pub.add_argument("-1", "--once", action="store_true")
    pub.add_argument("-t", "--times", type=int, default=None)
    pub.set_defaults(run=topic_pub)
    echo = topic.add_parser("echo")
    echo.add_argument("topic"), echo.add_argument("type", nargs="?")
    echo.add_argument("--once", action="store_true")
    echo.set_defaults(run=topic_echo)
    _add_list(topic, "get_topic_names_and_types")
    action = groups.add_parser("action").add_subparsers(dest="verb", required=True)
    send = action.add_parser("send_goal")
    send.add_argument("name"), send.add_argument("type"), send.add_argument("values")
    send.add_argument("-f", "--feedback", action="store_true")
    send.set_defaults(run=action_send_goal)
    params = groups.add_parser("param")
    params.add_argument("verb", choices=("get", "set", "describe", "list"))
    params.add_argument("node"), params.add_argument("name", nargs="?")
    params.add_argument("value", nargs="?")
    params.set_defaults(run=param)
    return top


def _add_list(verbs: Any, names_and_types: str) -> None:
    """`list [-t]` of a group: what node.<names_and_types>() finds."""
    command = verbs.add_parser("list")
    command.add_argument("-t", "--show-types", action="store_true")
    command.set_defaults(run=lambda n, a: listing(n, getattr(n, names_and_types), a.show_types))


def main(argv: list[str] | None = None) -> int:
    args = parser().parse_args(argv)
    rclpy.init()
    node = rclpy.create_node(f"ros2_lite_{int(time.time() * 1000) % 100000}")
    try:
        args.run(node, args)
    except Usage as e:
        print(f"ros2: {e}", file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        pass
    finally:
        sys.stdout.flush()
        # Fast DDS can spin without end tearing a participant down (eprosima/Fast-DDS#6513;
        # a `service call` burned a core for 5 min and ignored SIGTERM): the command is done,
        # so the kernel ends the process if the teardown takes longer than TEARDOWN_S.
        signal.signal(signal.SIGALRM, signal.SIG_DFL)
        signal.alarm(TEARDOWN_S)
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
