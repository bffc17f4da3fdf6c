"""The main job: both nodes in one process, sharing one world and one motion-queue executor,
and the live browser view of them (node `acti_view`).

    python -m acti_bringup [--ros-args ...]
"""
from __future__ import annotations

import sys

from acti_bringup.serving.spinning import build_or_exit, init
from acti_bringup.visual.view import ViewNode
from acti_middle_node.node import ArmNode
from vehicle_node.node import VehicleNode


def main(args: list[str] | None = None) -> None:
    init(sys.argv if args is None else args)
    arm, vehicle, view = build_or_exit(_nodes, "acti_bringup")
    arm.simulation.spin(arm, vehicle, view)


def _nodes() -> tuple[ArmNode, VehicleNode, ViewNode]:
    arm = ArmNode()
    vehicle = VehicleNode(simulation=arm.simulation)
    return arm, vehicle, ViewNode(arm.simulation, arm.core, vehicle.core)


if __name__ == "__main__":
    main()
