"""The `ros2` commands a user of these nodes needs, for a checkout without a full ROS install.

The `ros2` CLI is not on PyPI, so `make run` cannot install it; `tools/env.sh` puts this one on
PATH only when no `ros2` is found. It covers `service call|list|type|find`,
`topic pub|echo|list|info|type|hz`, `action send_goal|list|info`, `node list|info`,
`param get|set|describe|list|dump` and `interface list|package|show` with the real CLI's
arguments, output and request syntax (a YAML mapping of the fields; integers are accepted for
floating-point fields), over rclpy and DDS as any ROS 2 client, hiding the hidden names as it
does. Ctrl-C and SIGTERM end a command as they end the real one: without a traceback, exit
status 2 and 15. Anything else: install ROS 2 Jazzy and source it.
"""
from __future__ import annotations

import argparse
import array
import importlib
import math
import os
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
from rclpy.signals import SignalHandlerOptions

import ros2_graph
import ros2_interfaces

DISCOVERY_TIMEOUT_S = ros2_graph.DISCOVERY_TIMEOUT_S
MATCH_WAIT_S = 2.0
TEARDOWN_S = 5             # s the DDS teardown may take after the command is done
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
    # else the first message may reach no one: one subscription, for MATCH_WAIT_S at most, or
    # as many as -w says, as long as it takes (the real CLI's -w)
    wanted = 1 if a.wait_matching_subscriptions is None else a.wait_matching_subscriptions
    deadline = time.monotonic() + (MATCH_WAIT_S if a.wait_matching_subscriptions is None
                                   else math.inf)
    while pub.get_subscription_count() < wanted and time.monotonic() < deadline:
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
    cls = interface(a.type or _published_type(node, a.topic))
    got: list[Any] = []

    def on_message(msg: Any) -> None:
        print(show(msg) + "\n---", flush=True)
        got.append(msg)
    node.create_subscription(cls, a.topic, on_message, 10)
    spin_until(node, lambda: a.once and bool(got), None, a.topic)


def _published_type(node: Node, topic: str) -> str:
    """The type of a topic someone publishes, as discovered."""
    types = ros2_graph.types_of(node, topic, node.get_topic_names_and_types)
    if not types:
        raise Usage(f"the topic {topic} does not appear (give its type)")
    return types[0]


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
    if a.verb == "dump":
        param_dump(node, client, a.node)
        return
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


def param_dump(node: Node, client: Any, target: str) -> None:
    """Every parameter as a parameters file holds it (`--params-file` reads it back)."""
    full = "/" + target.lstrip("/")
    names = sorted(_answer(node, client.list_parameters([], 0), target).result.names)
    values = _answer(node, client.get_parameters(names), target).values if names else []
    tree: dict[str, Any] = {}
    for name, value in zip(names, values):
        *groups, leaf = name.split(".")
        branch = tree
        for group in groups:
            branch = branch.setdefault(group, {})
        branch[leaf] = as_plain(Parameter.from_parameter_msg(_named(name, value)).value)
    print(yaml.dump({full: {"ros__parameters": tree}}, default_flow_style=False))


def _named(name: str, value: Any) -> Any:
    from rcl_interfaces.msg import Parameter as ParameterMsg
    return ParameterMsg(name=name, value=value)


# --- command line ---------------------------------------------------------------------------------
def _verbs(groups: Any, group: str) -> Any:
    return groups.add_parser(group).add_subparsers(dest="verb", required=True)


def _hidden(command: argparse.ArgumentParser, *names: str) -> None:
    """The real CLI's option that includes hidden names, and `--include-hidden` for all."""
    command.add_argument("--include-hidden", *names, dest="include_hidden", action="store_true")


def _counted_list(verbs: Any, count: str, run: Callable, hidden: tuple[str, ...] | None) -> None:
    command = verbs.add_parser("list")
    command.add_argument("-t", "--show-types", action="store_true")
    command.add_argument("-c", f"--count-{count}", action="store_true")
    if hidden is not None:
        _hidden(command, *hidden)
    command.set_defaults(run=run)


def _service_parsers(groups: Any) -> None:
    service = _verbs(groups, "service")
    call = service.add_parser("call")
    call.add_argument("name"), call.add_argument("type"), call.add_argument("values", nargs="?")
    call.set_defaults(run=service_call)
    _counted_list(service, "services", ros2_graph.service_list, ("--include-hidden-services",))
    kind = service.add_parser("type")
    kind.add_argument("service_name"), _hidden(kind, "--include-hidden-services")
    kind.set_defaults(run=lambda n, a: ros2_graph.print_types(n, a.service_name,
                                                             n.get_service_names_and_types))
    find = service.add_parser("find")
    find.add_argument("service_type"), find.add_argument("-c", "--count-services",
                                                         action="store_true")
    _hidden(find, "--include-hidden-services")
    find.set_defaults(run=ros2_graph.service_find)


def _topic_parsers(groups: Any) -> None:
    topic = _verbs(groups, "topic")
    pub = topic.add_parser("pub")
    pub.add_argument("topic"), pub.add_argument("type"), pub.add_argument("values", nargs="?")
    pub.add_argument("-r", "--rate", type=float, default=1.0)
    pub.add_argument("-1", "--once", action="store_true")
    pub.add_argument("-t", "--times", type=int, default=None)
    pub.add_argument("-w", "--wait-matching-subscriptions", type=int, default=None)
    pub.set_defaults(run=topic_pub)
    echo = topic.add_parser("echo")
    echo.add_argument("topic"), echo.add_argument("type", nargs="?")
    echo.add_argument("--once", action="store_true")
    echo.set_defaults(run=topic_echo)
    _counted_list(topic, "topics", ros2_graph.topic_list, ("--include-hidden-topics",))
    info = topic.add_parser("info")
    info.add_argument("topic_name"), info.add_argument("-v", "--verbose", action="store_true")
    info.set_defaults(run=ros2_graph.topic_info)
    kind = topic.add_parser("type")
    kind.add_argument("topic_name"), _hidden(kind, "--include-hidden-topics")
    kind.set_defaults(run=lambda n, a: ros2_graph.print_types(n, a.topic_name,
                                                             n.get_topic_names_and_types))
    hz = topic.add_parser("hz")
    hz.add_argument("topic_name")
    hz.add_argument("-w", "--window", dest="window_size", type=int, default=ros2_graph.HZ_WINDOW)
    hz.add_argument("--wall-time", dest="use_wtime", action="store_true")
    hz.add_argument("--times", type=int, default=None,
                    help="end after this many reports (this tool only; the real one runs on)")
    hz.set_defaults(run=lambda n, a: ros2_graph.topic_hz(n, a, interface))


def _action_parsers(groups: Any) -> None:
    action = _verbs(groups, "action")
    send = action.add_parser("send_goal")
    send.add_argument("name"), send.add_argument("type"), send.add_argument("values")
    send.add_argument("-f", "--feedback", action="store_true")
    send.set_defaults(run=action_send_goal)
    _counted_list(action, "actions", ros2_graph.action_list, None)
    info = action.add_parser("info")
    info.add_argument("action_name"), info.add_argument("-t", "--show-types", action="store_true")
    info.add_argument("-c", "--count", action="store_true")
    info.set_defaults(run=ros2_graph.action_info)


def _node_parsers(groups: Any) -> None:
    node = _verbs(groups, "node")
    listed = node.add_parser("list")
    listed.add_argument("-a", "--all", "--include-hidden", action="store_true")
    listed.add_argument("-c", "--count-nodes", action="store_true")
    listed.set_defaults(run=ros2_graph.node_list)
    info = node.add_parser("info")
    info.add_argument("node_name"), _hidden(info)
    info.set_defaults(run=ros2_graph.node_info)


def _interface_parsers(groups: Any) -> None:
    verbs = _verbs(groups, "interface")
    listed = verbs.add_parser("list")
    package = verbs.add_parser("package")
    package.add_argument("package_name")
    for command in (listed, package):
        command.add_argument("-m", "--only-msgs", action="store_true")
        command.add_argument("-s", "--only-srvs", action="store_true")
        command.add_argument("-a", "--only-actions", action="store_true")
    listed.set_defaults(offline=ros2_interfaces.interface_list)
    package.set_defaults(offline=ros2_interfaces.interface_package)
    show = verbs.add_parser("show")
    show.add_argument("type")
    comments = show.add_mutually_exclusive_group()
    comments.add_argument("--all-comments", action="store_true")
    comments.add_argument("--no-comments", action="store_true")
    show.set_defaults(offline=ros2_interfaces.interface_show)


def parser() -> argparse.ArgumentParser:
    top = argparse.ArgumentParser(prog="ros2", description=__doc__.splitlines()[0])
    groups = top.add_subparsers(dest="group", required=True)
    for add in (_service_parsers, _topic_parsers, _action_parsers, _node_parsers,
                _interface_parsers):
        add(groups)
    params = groups.add_parser("param")
    params.add_argument("verb", choices=("get", "set", "describe", "list", "dump"))
    params.add_argument("node"), params.add_argument("name", nargs="?")
    params.add_argument("value", nargs="?")
    params.set_defaults(run=param)
    return top


class Terminated(Exception):
    """SIGTERM came: the command ends as after Ctrl-C."""


def _raise_terminated(_signum: int, _frame: Any) -> None:
    raise Terminated()


def main(argv: list[str] | None = None) -> int:
    """Run one command. Exit status: 0 done, 1 refused or not found (one line on stderr), 2
    Ctrl-C, 15 SIGTERM: the real CLI's."""
    args = parser().parse_args(argv)
    signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        if hasattr(args, "offline"):
            args.offline(args)
            return 0
        return _on_ros(args)
    except (Usage, ros2_graph.NotFound, ros2_interfaces.UnknownInterface) as e:
        print(f"ros2: {e}" if isinstance(e, Usage) else e, file=sys.stderr)
        return 1
    except KeyboardInterrupt:
        return signal.SIGINT
    except Terminated:
        return signal.SIGTERM
    except BrokenPipeError:         # `ros2 interface list | head`
        sys.stderr.close()
        return 0


def _on_ros(args: argparse.Namespace) -> int:
    """The command over DDS, from a hidden node as the real CLI's (`_ros2cli_<pid>`)."""
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node(f"_ros2cli_{os.getpid()}")
    try:
        return args.run(node, args) or 0
    finally:
        sys.stdout.flush()
        # No signal ends the teardown half-way; Fast DDS can spin without end tearing a
        # participant down (eprosima/Fast-DDS#6513; a `service call` burned a core for 5 min
        # and ignored SIGTERM): the command is done, so the kernel ends the process if the
        # teardown takes longer than TEARDOWN_S.
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_IGN)
        signal.signal(signal.SIGALRM, signal.SIG_DFL)
        signal.alarm(TEARDOWN_S)
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    sys.exit(main())
