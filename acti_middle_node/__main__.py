"""python -m acti_middle_node [--ros-args ...]: the arm node alone, with its own world."""
from __future__ import annotations

import sys

import rclpy

from acti_middle_node.node import ArmNode


def main(args: list[str] | None = None) -> None:
    rclpy.init(args=sys.argv if args is None else args)
    node = ArmNode()
    node.simulation.spin(node)


if __name__ == "__main__":
    main()
