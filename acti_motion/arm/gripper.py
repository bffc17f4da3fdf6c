"""How a gripper command ended, from what the simulation measured: the finger's rest position
against the target. Shared by the gripper actions (acti_middle_node.gripper_controller)."""
from __future__ import annotations

REACHED_TOLERANCE_M = 0.0005    # a finger at rest this close to its target reached it


def grip_outcome(target: float, finger: float) -> tuple[bool, bool]:
    """(reached_goal, stalled) of a finger at rest at `finger` (m) after a move to `target`: it
    reached the target, or it stopped short of it (it pushes on an object and cannot move)."""
    reached = abs(finger - target) <= REACHED_TOLERANCE_M
    return reached, not reached
