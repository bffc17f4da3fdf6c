"""Baseline for the round-trip benchmarks: a bare std_srvs/Trigger server, nothing behind it."""
import sys

import rclpy
from rclpy.executors import ExternalShutdownException
from std_srvs.srv import Trigger


def main() -> None:
    rclpy.init(args=sys.argv)
    node = rclpy.create_node("bare_trigger")

    def answer(_req, resp):
        resp.success = True
        return resp
    node.create_service(Trigger, "~/trigger", answer)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        node.destroy_node()
        rclpy.try_shutdown()


if __name__ == "__main__":
    main()
