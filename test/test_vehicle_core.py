"""VehicleCore in the real simulation, without ROS: power/servo (table 8), state, move_forward."""
import math

import pytest

from acti_motion.vehicle import VehicleCore, VehicleState
from sim_fixtures import executor, run_until  # noqa: F401


@pytest.fixture
def base(executor):  # noqa: F811
    return VehicleCore(executor)


def state(base):
    return base.get_state().values["state"]


def test_power_and_servo_walk_through_the_state_table(base):
    assert state(base) == VehicleState.UNPOWERED
    r = base.set_servo(True)
    assert not r.ok and "power" in r.comment           # table 8: power off → false
    assert base.set_power(True).ok and state(base) == VehicleState.POWERED
    assert base.set_servo(True).ok and state(base) == VehicleState.READY
    assert base.set_servo(True).ok and state(base) == VehicleState.READY   # stays on
    assert base.set_servo(False).ok and state(base) == VehicleState.POWERED
    assert base.set_servo(False).ok and state(base) == VehicleState.POWERED
    assert base.get_state().values["msg"] == "Powered"


@pytest.mark.parametrize("x", [math.nan, math.inf, -math.inf])
def test_move_forward_bad_distance(base, x):
    base.set_power(True)
    base.set_servo(True)
    r = base.move_forward(x)
    assert not r.ok and "finite" in r.comment
    assert base.device.queue_length == 0


def test_move_forward_needs_ready(base):
    r = base.move_forward(100.0)
    assert not r.ok and "Unpowered" in r.comment


@pytest.mark.parametrize("distance", [500.0, -300.0])
def test_move_forward_ends_within_5_mm(base, executor, distance):  # noqa: F811
    base.set_power(True)
    base.set_servo(True)
    assert base.move_forward(distance).ok
    assert state(base) == VehicleState.BUSY
    x0 = executor.world.base_pose()[0]
    run_until(executor, lambda: not base.device.busy, 10.0)
    x, y, theta = base.get_position().values["pos"]
    assert abs(x - distance) < 5.0 and abs(y) < 5.0 and abs(theta) < 0.5
    assert state(base) == VehicleState.READY
    # wheel odometry agrees with the ground truth (the wheels roll on true cylinders)
    assert abs(1000.0 * (executor.world.base_pose()[0] - x0) - distance) < 2.0
