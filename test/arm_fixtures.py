"""ROS-free arm fixtures: an ArmCore in a real world, servo on, speeds at 50 %, in a posture with
room to move every way (wrist above the shoulder, flange up)."""
from __future__ import annotations

import pytest

from acti_motion.arm.core import ArmConfig, ArmCore
from sim_fixtures import executor, run_until  # noqa: F401

WORK = (0.0, 45.0, 0.0, -90.0, 0.0, 45.0, 0.0)
IDENTITY = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]


@pytest.fixture
def arm(executor):  # noqa: F811
    a = ArmCore(executor, ArmConfig(queue_size=8, initial_joints_deg=WORK))
    for r in (a.servo_on(), a.set_speed_joint(50), a.set_speed_cartesian(50)):
        assert r.ok
    return a


def rest(executor, arm, max_seconds: float = 15.0, settle: int = 60) -> float:  # noqa: F811
    """Run until the arm has nothing left to do, then `settle` steps more; simulated seconds
    it took to be done."""
    took = run_until(executor, lambda: not arm.device.busy, max_seconds)
    for _ in range(settle):
        executor.step()
    return took
