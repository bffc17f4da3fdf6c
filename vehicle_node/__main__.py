"""python -m vehicle_node [--ros-args ...]: the base node alone, with its own world."""
from __future__ import annotations

import sys

import rclpy

from vehicle_node.node import VehicleNode


def main(args: list[str] | None = None) -> None:
    rclpy.init(args=sys.argv if args is None else args)
    node = VehicleNode()
    node.simulation.spin(node)


if __name__ == "__main__":
    main()
