"""Table-driven service registration: one row per IDL operation, one core method per row.

Operations that plan a motion are served by the device's motion plane (a `Plane` node), every
other one by the device node itself on the control plane (see `acti_bringup.serving.spinning`): a move
planning for milliseconds never delays stop, pause or get_state. Clients see one node's services
either way (`/<ns>/<node>/<operation>`).
"""
from __future__ import annotations

import traceback
from dataclasses import dataclass
from typing import Any, Callable, Protocol

from rclpy.action import ActionServer
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from acti_bringup.serving.conversions import fill, reply_key, request_reader
from acti_motion.replies import Reply, ReturnCode

@dataclass(frozen=True)
class Operation:
    """An IDL operation: the service (and core method) name and its `acti_msgs` service type."""
    name: str
    srv_type: type


class GoalEnd(Protocol):
    """What ends the goals an action server holds when the process stops
    (`acti_bringup.serving.waiting.end_goals`)."""

    def close(self, why: str) -> None: ...

    @property
    def idle(self) -> bool: ...


class Plane(Node):
    """A node that holds part of a device node's entities so that another executor serves them
    (`acti_bringup.serving.spinning`): "motion" (planning services, command topics) or "goals" (action
    servers). An implementation detail (hidden name, no parameters of its own): its services
    and actions are named under the device node."""

    def __init__(self, owner: Node, plane: str) -> None:
        super().__init__(f"_{owner.get_name()}_{plane}", namespace=owner.get_namespace(),
                         start_parameter_services=False)
        self.owner, self.plane = owner, plane
        self.goal_ends: list[GoalEnd] = []

    def name(self, entity: str) -> str:
        """`~/entity` of the device node, as an absolute name."""
        return f"{self.owner.get_fully_qualified_name()}/{entity.removeprefix('~/')}"


StatusWriter = Callable[[Any, Reply], None]

# One response writer serves every client of a service. With the default history (10), a storm
# of clients can push a starved client's response out of it before that client acknowledged it,
# and a response the transport dropped (a full receive queue) can then never be repaired: that
# client waits for ever. A deeper history keeps every response until its client has it.
# The same holds for a client: DDS delivers every response of a service to every client of it
# (each keeps only its own), so a client that keeps rclpy's 10 loses its answer when more than
# 10 answers to other clients arrive before it takes it — a busy client under a storm of others.
# The harness's clients (tests, benchmarks) keep 100 (CLIENT_QOS); a user's busy client should too.
SERVICE_QOS = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=100,
                         reliability=ReliabilityPolicy.RELIABLE, durability=DurabilityPolicy.VOLATILE)
CLIENT_QOS = SERVICE_QOS
CLIENT_ACTION_QOS = {f"{kind}_service_qos_profile": CLIENT_QOS
                     for kind in ("goal", "result", "cancel")}


def action_server(host: Node, action_type: Any, name: str, execute: Callable,
                  **callbacks: Any) -> ActionServer:
    """An ActionServer whose goal, cancel and result services keep as many requests as the
    services do (SERVICE_QOS): with rclpy's 10, a burst of 20 goals lost 10 of them without any
    answer, not even the rejection the goal bound promises. Its name is kept as `action_name`
    (rclpy keeps none): the action's introspection publishes under it
    (`acti_bringup.recording.introspection`)."""
    server = ActionServer(host, action_type, name, execute, goal_service_qos_profile=SERVICE_QOS,
                          result_service_qos_profile=SERVICE_QOS,
                          cancel_service_qos_profile=SERVICE_QOS, **callbacks)
    server.action_name = name
    return server


def serve_operations(node: Node, motion: Plane, core: Any,
                     operations: tuple[Operation, ...], write_status: StatusWriter) -> list:
    """Create `~/<name>` for every row, calling `core.<name>(**request fields)`: on `motion`
    for the operations the core marks as planning (`acti_motion.replies.plans`), on `node` for
    the others."""
    services = []
    for op in operations:
        method = getattr(core, op.name)
        handler = _handler(node, op, method, write_status)
        plans = getattr(method, "plans", False)
        host, name = (motion, motion.name(op.name)) if plans else (node, f"~/{op.name}")
        services.append(host.create_service(op.srv_type, name, handler, qos_profile=SERVICE_QOS))
    node.get_logger().info(f"{len(services)} services under {node.get_fully_qualified_name()}/: "
                           + ", ".join(op.name for op in operations))
    return services


def _handler(node: Node, op: Operation, method: Callable[..., Reply],
             write_status: StatusWriter) -> Callable[[Any, Any], Any]:
    """The service callback of one operation. A reply equal to the last one (a getter asked
    again while nothing changed) is answered with the response that carried it: filling it
    and converting it to its C message (kept by `UnlockedSender`) were most of a getter's work
    in the job (the soft limits: 31 µs of 38 on a warm core). Responses are never changed once
    returned."""
    read = request_reader(op.srv_type.Request)
    last: tuple[Any, Any] = (None, None)      # the last reply, hashable, and its response
    plans = getattr(method, "plans", False)   # a move: each accept answers a new motion id

    def handle(request: Any, response: Any) -> Any:
        nonlocal last
        try:
            reply = method(**read(request))
            key = None if plans else reply_key(reply.code, reply.comment, reply.values)
            if key is not None and key == last[0]:
                return last[1]
            write_status(response, reply)
            fill(response, reply.values)
            last = (key, response)
        except Exception as e:  # a bug must not take the node down; the caller is told
            node.get_logger().error(f"{op.name} failed: {traceback.format_exc()}")
            write_status(response, Reply(ReturnCode.NG, f"internal error in {op.name}: {e}"))
        return response
    return handle
