"""The main job: both nodes in one process, sharing one world and one motion-queue executor,
and the live browser view of them (node `acti_view`).

    python -m acti_bringup [--ros-args ...]      (installed as `acti_robot`)
"""
from __future__ import annotations

import sys

from acti_bringup.serving.usage import exit_if_help

BUILDER = "acti_bringup.__main__:nodes"      # what builds the job's nodes (--help lists theirs)


def main(args: list[str] | None = None) -> None:
    args = sys.argv if args is None else args
    exit_if_help(args, __doc__, BUILDER)
    from acti_bringup.serving.spinning import build_or_exit, init   # after --help: seconds
    init(args)
    arm, vehicle, view = build_or_exit(nodes, "acti_bringup", BUILDER)
    arm.simulation.spin(arm, vehicle, view)


def nodes() -> tuple:
    """The job's nodes: the arm's hosts the simulation, the others share it."""
    from acti_bringup.visual.view import ViewNode       # here, not above: --help needs none
    from acti_middle_node.node import ArmNode
    from vehicle_node.node import VehicleNode
    arm = ArmNode()
    vehicle = VehicleNode(simulation=arm.simulation)
    return arm, vehicle, ViewNode(arm.simulation, arm.core, vehicle.core,
                                  program=arm.programs.shown, scan=vehicle.scan)


if __name__ == "__main__":
    main()
