"""python -m acti_middle_node [--ros-args ...]: the arm node alone, with its own world."""
from __future__ import annotations

from acti_bringup.simulation import run_alone
from acti_middle_node.node import ArmNode


def main(args: list[str] | None = None) -> None:
    run_alone(ArmNode, args)


if __name__ == "__main__":
    main()
