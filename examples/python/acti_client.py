"""What the examples share: one rclpy node that calls the nodes' services and sends goals to their
actions, waiting for each answer (a script's way; a node that serves would use callbacks).

A refusal ends the script with the node's reason: the arm's services answer `return_id` (id 0 is
OK, its `comment` says why not), the base's `success` and `message`."""
from __future__ import annotations

from typing import Any, Callable

import rclpy
from rclpy.action import ActionClient

DISCOVERY_S = 10.0      # how long a service or action may take to appear
ANSWER_S = 10.0         # how long a service or a goal's acceptance may take


class Client:
    def __init__(self, name: str) -> None:
        rclpy.init()
        self.node = rclpy.create_node(name)
        self._clients: dict[str, Any] = {}

    def call(self, srv_type: type, service: str, **fields: Any) -> Any:
        """The response of `service`; a refusal ends the script with the node's reason."""
        client = self._clients.get(service)
        if client is None:
            client = self._clients[service] = self.node.create_client(srv_type, service)
        if not client.wait_for_service(timeout_sec=DISCOVERY_S):
            raise SystemExit(f"{service} is not served: is `make run` running in this ROS_DOMAIN_ID?")
        response = self._wait(client.call_async(srv_type.Request(**fields)), service, ANSWER_S)
        refusal = refused(response)
        if refusal:
            raise SystemExit(f"{service} refused: {refusal}")
        return response

    def run_goal(self, action_type: type, action: str,
                 feedback: Callable[[Any], None] | None = None, **fields: Any) -> Any:
        """The result of one goal of `action`, `feedback` called with each feedback message."""
        client = self._clients.get(action)
        if client is None:
            client = self._clients[action] = ActionClient(self.node, action_type, action)
        if not client.wait_for_server(timeout_sec=DISCOVERY_S):
            raise SystemExit(f"{action} is not served: is `make run` running in this ROS_DOMAIN_ID?")
        on_feedback = (lambda message: feedback(message.feedback)) if feedback else None
        handle = self._wait(client.send_goal_async(action_type.Goal(**fields), on_feedback),
                            action, ANSWER_S)
        if not handle.accepted:
            raise SystemExit(f"{action} rejected the goal")
        return self._wait(handle.get_result_async(), action, None).result

    def close(self) -> None:
        self.node.destroy_node()
        rclpy.shutdown()

    def _wait(self, future: Any, what: str, timeout: float | None) -> Any:
        rclpy.spin_until_future_complete(self.node, future, timeout_sec=timeout)
        if not future.done():
            raise SystemExit(f"{what} did not answer in {timeout} s")
        return future.result()


def refused(response: Any) -> str:
    """Why the node refused (empty: it did not)."""
    if hasattr(response, "return_id") and response.return_id.id != 0:
        return f"return id {response.return_id.id}: {response.return_id.comment}"
    if hasattr(response, "success") and not response.success:
        return response.message
    return ""
