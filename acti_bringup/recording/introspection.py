"""Every request a node serves, and its answer, on a `<service>/_service_event` topic, so that a
recorder keeps the calls that drive the robot.

Services: Jazzy's service introspection (`configure_introspection`), which rcl carries out as
it takes a request and sends a response. Actions: Jazzy's rcl_action has no introspection
(Kilted adds it), so each action server's handle is wrapped to publish the same events Kilted
does, on the same hidden topics: `<action>/_action/send_goal/_service_event` (type
`X_SendGoal_Event`), `…/get_result/_service_event`, `…/cancel_goal/_service_event`. An action's
feedback and status are topics already (`<action>/_action/feedback`, `…/status`)."""
from __future__ import annotations

import ctypes
from typing import Any, Iterable

from builtin_interfaces.msg import Time
from rclpy.action import ActionServer
from rclpy.node import Node
from rclpy.qos import qos_profile_services_default
from rclpy.service_introspection import ServiceIntrospectionState
from service_msgs.msg import ServiceEventInfo
from type_description_interfaces.srv import GetTypeDescription

from acti_bringup.serving.unlocked import GUID_BYTES, header_address

# "disabled", not "off": YAML (the parameters' syntax) reads off as false
STATES = {"disabled": ServiceIntrospectionState.OFF, "metadata": ServiceIntrospectionState.METADATA,
          "contents": ServiceIntrospectionState.CONTENTS}
EVENT_QOS = qos_profile_services_default        # rcl's default for introspection publishers
EVENT_TOPIC = "_service_event"


def introspect(nodes: Iterable[Node], state: str) -> list[str]:
    """Introspection `state` (disabled | metadata | contents) on every service and action server
    of `nodes`, but the nodes' `get_type_description` (rcl's own service: rclpy refuses to
    configure it, and crashes on the second refusal). Call it after the nodes' action servers got their final handles (the job's
    outbox wraps them: `acti_bringup.serving.spinning.Planes.add`). The event topics."""
    if state not in STATES:
        raise ValueError(f"service_introspection {state!r}: use one of {', '.join(STATES)}")
    topics: list[str] = []
    if state == "disabled":
        return topics
    for node in nodes:
        for service in node.services:
            if service.srv_type is not GetTypeDescription:
                service.configure_introspection(node.get_clock(), EVENT_QOS, STATES[state])
                topics.append(f"{service.service_name}/{EVENT_TOPIC}")
        for waitable in node.waitables:
            if isinstance(waitable, ActionServer):
                waitable._handle = handle = IntrospectedActionHandle(node, waitable,
                                                                     state == "contents")
                topics += handle.topics
    return topics


# the action's services: (the name under `<action>/_action/`, the Impl attribute, rclpy's
# take and send method names)
ACTION_SERVICES = (("send_goal", "SendGoalService", "goal"),
                   ("get_result", "GetResultService", "result"),
                   ("cancel_goal", "CancelGoalService", "cancel"))


class IntrospectedActionHandle:
    """The handle of an ActionServer (made by `acti_bringup.serving.adapter.action_server`, which
    names it `action_name`) that publishes a service event for every goal, result and cancel
    request it takes and every answer it sends; everything else is the handle's."""

    def __init__(self, node: Node, server: ActionServer, contents: bool) -> None:
        self._handle, self._contents, self._clock = server._handle, contents, node.get_clock()
        self._events: dict[str, tuple[Any, Any]] = {}
        name = node.resolve_topic_name(server.action_name)
        self.topics = [f"{name}/_action/{service}/{EVENT_TOPIC}" for service, _, _ in ACTION_SERVICES]
        for topic, (_, impl, kind) in zip(self.topics, ACTION_SERVICES):
            srv_type = getattr(server._action_type.Impl, impl)
            self._events[kind] = (srv_type.Event,
                                  node.create_publisher(srv_type.Event, topic, EVENT_QOS))

    def __getattr__(self, name: str) -> Any:
        method = getattr(self._handle, name)
        for kind in ("goal", "cancel", "result"):
            if name == f"take_{kind}_request":
                return lambda cls: self._took(kind, method(cls))
            if name == f"send_{kind}_response":
                return lambda header, msg: self._sent(kind, method, header, msg)
        return method

    def __enter__(self) -> Any:
        return self._handle.__enter__()

    def __exit__(self, *exc: Any) -> Any:
        return self._handle.__exit__(*exc)

    def _took(self, kind: str, taken: tuple[Any, Any]) -> tuple[Any, Any]:
        header, request = taken
        if request is not None:
            self._publish(kind, ServiceEventInfo.REQUEST_RECEIVED, header, request=request)
        return taken

    def _sent(self, kind: str, send: Any, header: Any, response: Any) -> None:
        send(header, response)
        self._publish(kind, ServiceEventInfo.RESPONSE_SENT, header, response=response)

    def _publish(self, kind: str, event_type: int, header: Any, request: Any = None,
                 response: Any = None) -> None:
        event_class, publisher = self._events[kind]
        event = event_class()
        nanoseconds = self._clock.now().nanoseconds
        event.info = ServiceEventInfo(
            event_type=event_type, sequence_number=header.sequence_number,
            client_gid=_client_gid(header),
            stamp=Time(sec=nanoseconds // 1_000_000_000, nanosec=nanoseconds % 1_000_000_000))
        if self._contents:
            event.request = [request] if request is not None else []
            event.response = [response] if response is not None else []
        publisher.publish(event)


def _client_gid(header: Any) -> list[int]:
    """The requesting client's writer GUID (rclpy does not expose it; read from the C header)."""
    address = header_address(header)
    return list(ctypes.string_at(address, GUID_BYTES)) if address else [0] * GUID_BYTES
