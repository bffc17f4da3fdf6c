"""python -m acti_middle_node [--ros-args ...]: the arm node alone, with its own world."""
from __future__ import annotations

import sys

from acti_bringup.serving.usage import exit_if_help


def main(args: list[str] | None = None) -> None:
    args = sys.argv if args is None else args
    exit_if_help(args, __doc__, "acti_middle_node.node:ArmNode")
    from acti_bringup.simulation import run_alone      # after --help: seconds
    from acti_middle_node.node import ArmNode
    run_alone(ArmNode, args)


if __name__ == "__main__":
    main()
