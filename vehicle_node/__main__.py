"""python -m vehicle_node [--ros-args ...]: the base node alone, with its own world."""
from __future__ import annotations

import sys

from acti_bringup.serving.usage import exit_if_help


def main(args: list[str] | None = None) -> None:
    args = sys.argv if args is None else args
    exit_if_help(args, __doc__, "vehicle_node.node:VehicleNode")
    from acti_bringup.simulation import run_alone      # after --help: seconds
    from vehicle_node.node import VehicleNode
    run_alone(VehicleNode, args)


if __name__ == "__main__":
    main()
