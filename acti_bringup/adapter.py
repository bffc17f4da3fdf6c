"""Table-driven service registration: one row per IDL operation, one core method per row."""
from __future__ import annotations

import traceback
from dataclasses import dataclass
from typing import Any, Callable

from rclpy.callback_groups import ReentrantCallbackGroup
from rclpy.node import Node

from acti_bringup.conversions import fill, to_core
from acti_motion.replies import Reply, ReturnCode


@dataclass(frozen=True)
class Operation:
    """An IDL operation: the service (and core method) name and its `acti_msgs` service type."""
    name: str
    srv_type: type


StatusWriter = Callable[[Any, Reply], None]


def serve_operations(node: Node, core: Any, operations: tuple[Operation, ...],
                     write_status: StatusWriter) -> list:
    """Create `~/<name>` for every row, calling `core.<name>(**request fields)`."""
    group = ReentrantCallbackGroup()
    services = []
    for op in operations:
        method = getattr(core, op.name)
        services.append(node.create_service(op.srv_type, f"~/{op.name}",
                                            _handler(node, op, method, write_status),
                                            callback_group=group))
    node.get_logger().info(f"{len(services)} services under {node.get_fully_qualified_name()}/: "
                           + ", ".join(op.name for op in operations))
    return services


def _handler(node: Node, op: Operation, method: Callable[..., Reply],
             write_status: StatusWriter) -> Callable[[Any, Any], Any]:
    def handle(request: Any, response: Any) -> Any:
        kwargs = {f: to_core(getattr(request, f)) for f in request.get_fields_and_field_types()}
        try:
            reply = method(**kwargs)
            write_status(response, reply)
            fill(response, reply.values)
        except Exception as e:  # a bug must not take the node down; the caller is told
            node.get_logger().error(f"{op.name} failed: {traceback.format_exc()}")
            write_status(response, Reply(ReturnCode.NG, f"internal error in {op.name}: {e}"))
        return response
    return handle
