"""The gripper's outcome is the simulation's: closing on a box between the fingers stops the
finger short of its target (stalled); closing on nothing reaches it."""
from __future__ import annotations

import numpy as np
import pybullet

from acti_motion.arm.gripper import grip_outcome
from arm_fixtures import arm, rest  # noqa: F401
from sim_fixtures import executor  # noqa: F401

FINGER_CENTRE_M = 0.07      # the fingers' middle, from the flange along its z (URDF)
BOX_HALF_WIDTH_M = 0.015


def close(executor, arm) -> float:  # noqa: F811
    """Open fully, then close; where the finger comes to rest (m)."""
    arm.queue_gripper_to(arm.finger_max, "open")
    arm.queue_gripper_to(0.0, "close")
    rest(executor, arm, settle=250)
    return arm.get_feedback_pos_joint().values["pos"][-1] / 2000.0


def test_closing_on_nothing_reaches_the_target(executor, arm):  # noqa: F811
    assert grip_outcome(0.0, close(executor, arm)) == (True, False)


def test_closing_on_a_box_stalls_short_of_it(executor, arm):  # noqa: F811
    world = executor.world
    base_p, base_q = world.base_link_pose()
    flange = arm.kin.flange(arm.feedback_joints)
    centre = flange[:3, 3] + flange[:3, :3] @ np.array([0.0, 0.0, FINGER_CENTRE_M])
    assert flange[2, 2] > 0.99                  # flange up: a box square in x and y fits any yaw
    position, _ = pybullet.multiplyTransforms(base_p, base_q, centre.tolist(), [0, 0, 0, 1])
    arm.queue_gripper_to(arm.finger_max, "open")
    rest(executor, arm)
    box = world.add_box(tuple(position), (BOX_HALF_WIDTH_M, BOX_HALF_WIDTH_M, 0.01))
    assert box >= 0
    finger = close(executor, arm)
    reached, stalled = grip_outcome(0.0, finger)
    assert stalled and not reached, finger
    assert abs(finger - BOX_HALF_WIDTH_M) < 0.002      # its inner face on the box
