"""Recorded service calls: the events of a call (request received, response sent) paired, put
in the order they were made, and a replayed answer compared with the recorded one.

An action's goal, result and cancel requests are calls too (their services are under
`<action>/_action/`), so a goal is replayed and its result compared like any other call."""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Iterable, Iterator

EVENT_TOPIC_SUFFIX = "/_service_event"
EVENT_TYPE_SUFFIX = "_Event"
REQUEST_RECEIVED, RESPONSE_SENT = 1, 2           # service_msgs/msg/ServiceEventInfo
# fields whose values differ from run to run by design: motion ids count from the job's start,
# stamps and durations are times of the run
NORMALISED = frozenset({"motion_id", "current_motion_id", "stamp", "duration"})
# floating-point numbers are measured (a joint at rest, the base's pose): equal within
# ABS_TOL in the services' units (mm, degree, s …), or REL_TOL of their size
ABS_TOL, REL_TOL = 0.05, 1e-6


@dataclass(frozen=True)
class Event:
    """One service event of a recording, its contents decoded by the caller."""
    service: str              # the service's name (the event topic without /_service_event)
    service_type: str         # pkg/srv/Name (pkg/action/Name_SendGoal …)
    kind: int                 # REQUEST_RECEIVED, RESPONSE_SENT (others are not replayed)
    client: tuple             # (client gid, sequence number): the call it belongs to
    stamp_ns: int             # when the server took the request or sent the response (its
                              # clock: the recorder receives the events of several services
                              # in another order)
    message: Any              # the request or the response


@dataclass
class Call:
    service: str
    service_type: str
    request: Any
    request_ns: int
    response: Any = None      # None: the recording has no answer
    response_ns: int | None = None


def service_of(topic: str, event_type: str) -> tuple[str, str] | None:
    """(service name, service type) of a service event channel; None for another topic."""
    if topic.endswith(EVENT_TOPIC_SUFFIX) and event_type.endswith(EVENT_TYPE_SUFFIX):
        return topic.removesuffix(EVENT_TOPIC_SUFFIX), event_type.removesuffix(EVENT_TYPE_SUFFIX)
    return None


def pair(events: Iterable[Event]) -> list[Call]:
    """The calls of the events, in the order their requests were received."""
    calls: dict[tuple, Call] = {}
    for e in sorted(events, key=lambda e: e.stamp_ns):
        key = (e.service, e.client)
        if e.kind == REQUEST_RECEIVED:
            calls[key] = Call(e.service, e.service_type, e.message, e.stamp_ns)
        elif e.kind == RESPONSE_SENT and key in calls and calls[key].response is None:
            calls[key].response, calls[key].response_ns = e.message, e.stamp_ns
    return sorted(calls.values(), key=lambda c: c.request_ns)


def leaves(recorded: Any, replayed: Any, path: str = "response"
           ) -> Iterator[tuple[str, Any, Any]]:
    """The pairs of plain values (dicts, lists, numbers, strings) to compare, with their path:
    the NORMALISED fields left out; lists of another length and other values whole."""
    if isinstance(recorded, dict) and isinstance(replayed, dict):
        for key in dict.fromkeys([*recorded, *replayed]):
            if key not in NORMALISED:
                yield from leaves(recorded.get(key), replayed.get(key), f"{path}.{key}")
    elif isinstance(recorded, list) and isinstance(replayed, list) and \
            len(recorded) == len(replayed):
        for i, (a, b) in enumerate(zip(recorded, replayed)):
            yield from leaves(a, b, f"{path}[{i}]")
    else:
        yield path, recorded, replayed


def _measured(recorded: Any, replayed: Any) -> bool:
    return (isinstance(recorded, float) or isinstance(replayed, float)) and \
        all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (recorded, replayed))


def differences(recorded: Any, replayed: Any, abs_tol: float = ABS_TOL) -> list[str]:
    """Where two plain values differ, one line each: floating-point numbers (measured) within
    REL_TOL or abs_tol, everything else (states, flags, ids, texts) exactly."""
    return [f"{path}: recorded {a!r}, replayed {b!r}" for path, a, b in leaves(recorded, replayed)
            if not (math.isclose(a, b, rel_tol=REL_TOL, abs_tol=abs_tol) if _measured(a, b)
                    else a == b)]


def largest_deviation(recorded: Any, replayed: Any) -> float:
    """The largest difference of two measured numbers (0 when none differ)."""
    return max((abs(a - b) for _, a, b in leaves(recorded, replayed) if _measured(a, b)),
               default=0.0)
