"""python -m vehicle_node [--ros-args ...]: the base node alone, with its own world."""
from __future__ import annotations

from acti_bringup.simulation import run_alone
from vehicle_node.node import VehicleNode


def main(args: list[str] | None = None) -> None:
    run_alone(VehicleNode, args)


if __name__ == "__main__":
    main()
