"""Baseline for the round-trip benchmarks: a bare std_srvs/Trigger server, nothing behind it.

Served the way the nodes serve their control plane (`acti_bringup.serving.spinning`: an EventsExecutor
driven by a spin_once loop), so the ratio measures the nodes' own cost, not an executor choice:

    python -m bench.trigger_server [events|single|multi]
"""
import sys

import rclpy
from rclpy.executors import MultiThreadedExecutor, SingleThreadedExecutor
from rclpy.experimental import EventsExecutor
from std_srvs.srv import Trigger

from acti_bringup.serving.spinning import SpinLoop, init, wait_for_signal

EXECUTORS = {"events": EventsExecutor, "single": SingleThreadedExecutor,
             "multi": MultiThreadedExecutor}
KIND = "events"


def main() -> None:
    args = rclpy.utilities.remove_ros_args(sys.argv)
    kind = args[1] if len(args) > 1 else KIND
    init(sys.argv)
    node = rclpy.create_node("bare_trigger")

    def answer(_req, resp):
        resp.success = True
        return resp
    node.create_service(Trigger, "~/trigger", answer)
    executor = EXECUTORS[kind]()
    executor.add_node(node)
    loop = SpinLoop(executor, "bare").start()
    try:
        wait_for_signal(lambda: loop.alive)
    finally:
        loop.stop()
        executor.shutdown()
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
