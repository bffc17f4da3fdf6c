"""acti_middle_node with its move services' callbacks timed, for bench_arm.py: what the handler
(the checks, the plan, the reply) costs in the node, told apart from what the round trip adds.

    python -m bench.timed_node OUT.json [--ros-args ...]

Every call of the services named in TIMED records its thread CPU and wall seconds; OUT.json gets
them, by service, when the node ends. The product's nodes carry no timing code: the callbacks are
wrapped here, as rclpy creates the services (a wrapper costs ~1 µs of a 100 µs callback)."""
from __future__ import annotations

import atexit
import json
import sys
import time
from typing import Any, Callable

import rclpy.node

TIMED = ("move_ptp_joint_rel", "move_linear_cartesian_rel")


def timing(create: Callable[..., Any], times: dict[str, list[tuple[float, float]]]) -> Callable[..., Any]:
    """Node.create_service whose callbacks of the TIMED services append (thread CPU, wall)
    seconds of each call to times[service]."""
    def create_service(node: rclpy.node.Node, srv_type: type, name: str, callback: Callable,
                       **kwargs: Any) -> Any:
        service = name.rsplit("/", 1)[-1]
        if service in TIMED:
            inner, calls = callback, times.setdefault(service, [])

            def callback(request: Any, response: Any) -> Any:
                c0, t0 = time.thread_time(), time.perf_counter()
                answer = inner(request, response)
                calls.append((time.thread_time() - c0, time.perf_counter() - t0))
                return answer
        return create(node, srv_type, name, callback, **kwargs)
    return create_service


def main() -> None:
    out = sys.argv.pop(1)
    times: dict[str, list[tuple[float, float]]] = {}
    rclpy.node.Node.create_service = timing(rclpy.node.Node.create_service, times)

    def write() -> None:
        with open(out, "w") as f:
            json.dump(times, f)
    atexit.register(write)
    from acti_middle_node.__main__ import main as node_main
    node_main()


if __name__ == "__main__":
    main()
