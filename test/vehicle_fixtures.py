"""ROS-free fixtures of the base: a VehicleCore on a real world, stepped by the test."""
from __future__ import annotations

import math

import pytest

from acti_motion.vehicle.core import VehicleConfig, VehicleCore, VehicleState
from acti_motion.vehicle.obstacles import ObstacleConfig
from sim_fixtures import executor, run_until  # noqa: F401


@pytest.fixture
def base(executor):  # noqa: F811
    return VehicleCore(executor, VehicleConfig(queue_size=4))


# no obstacle zones: the base drives into what is ahead (the contact sensor, a blockage)
BLIND = ObstacleConfig(caution_distance=0.0, stop_distance=0.0)


@pytest.fixture
def blind_base(executor):  # noqa: F811
    return VehicleCore(executor, VehicleConfig(queue_size=4), BLIND)


def state(base) -> int:
    return base.get_state().values["state"]


def state_msg(base) -> str:
    return base.get_state().values["msg"]


def ready(base) -> None:
    assert base.set_power(True).ok and base.set_servo(True).ok
    assert state(base) == VehicleState.READY


def settle(executor, base, max_seconds: float = 30.0) -> float:  # noqa: F811
    """Run until the base has nothing left to do; simulated seconds it took."""
    return run_until(executor, lambda: not base.device.busy, max_seconds)


def position(base) -> tuple[float, float, float]:
    return base.get_position().values["pos"]


def assert_at(base, x: float, y: float, theta: float, mm: float = 5.0, deg: float = 0.5) -> None:
    px, py, pth = position(base)
    assert math.hypot(px - x, py - y) < mm, (px, py, pth)
    assert abs(math.remainder(pth - theta, 360.0)) < deg, (px, py, pth)


def steps(executor, seconds: float) -> None:  # noqa: F811
    for _ in range(round(seconds / executor.dt)):
        executor.step()


@pytest.fixture
def trace(base, executor):  # noqa: F811
    """A BaseTrace of the base (trajectory_check_base): step through it, then check it."""
    from trajectory_check_base import BaseTrace
    return BaseTrace(executor, base)
