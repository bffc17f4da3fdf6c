"""The base's obstacle zones without ROS (acti_motion.vehicle.obstacles): the caution speed, the
stop before contact, Stuck with its alarm, and the ways out of Stuck."""
import math

import pytest

from acti_motion.vehicle.alarms import AlarmCode
from acti_motion.vehicle.core import VehicleConfig, VehicleCore, VehicleState
from acti_motion.vehicle.obstacles import ObstacleConfig
from sim_fixtures import executor, run_until  # noqa: F401
from vehicle_fixtures import position, ready, settle, state, steps  # noqa: F401

FRONT, BACK = 0.321, 0.30       # the footprint's edges ahead of and behind base_link [m]
BOX_X = 2.0                     # the box's near face, ahead of base_link [m]
ZONES = ObstacleConfig(caution_distance=600.0, stop_distance=100.0, caution_velocity=150.0)


@pytest.fixture
def base(executor):  # noqa: F811
    """A box 2 m ahead of base_link, 1 m wide, across the path."""
    executor.world.add_box((BOX_X + 0.2, 0.0, 0.4), (0.2, 0.5, 0.4))
    return VehicleCore(executor, VehicleConfig(), ZONES)


def truth_x(base) -> float:
    return base.odometry.pose.x


def drive_into_the_box(base, executor, start) -> list[tuple[float, float]]:  # noqa: F811
    """Start a drive and step until Stuck; (gap, speed) each step."""
    ready(base)
    base.set_velocity((600.0, 45.0))
    assert start().ok
    trace = []
    while state(base) != VehicleState.STUCK:
        executor.step()
        trace.append((BOX_X - FRONT - truth_x(base), base.odometry.v))
        assert executor.world.time < 30.0, "never Stuck"
    settle(executor, base, 5.0)
    steps(executor, 0.3)
    return trace


@pytest.mark.parametrize("how", ["move_forward", "move_jog"])
def test_a_drive_at_a_box_slows_in_the_caution_zone_and_stops_before_it(base, executor, how):  # noqa: F811
    start = {"move_forward": lambda: base.move_forward(5000.0),
             "move_jog": lambda: base.set_jog_timeout(60000) and base.move_jog(600.0, 0.0, 0.0)}[how]
    trace = drive_into_the_box(base, executor, start)
    assert max(v for g, v in trace) > 0.55                       # at speed before the zone
    caution, _ = base.zones(0.0)
    # inside the caution zone (once the limit has had the braking distance from 0.6 m/s to act)
    a = base.config.accel_limit_translation / 1000.0
    settled = caution - (0.6 ** 2 - 0.15 ** 2) / (2 * a) - 0.02
    inside = [v for g, v in trace if g < settled]
    assert inside and max(inside) <= 0.15 * 1.05
    rest = BOX_X - FRONT - truth_x(base)
    assert 0.0 < rest and rest >= 0.1 * 0.8                      # stopped before contact
    assert not executor.world.bumper_in_contact() and abs(base.odometry.v) < 1e-3
    assert state(base) == VehicleState.STUCK and base.device.queue_length == 0
    alarm = [a for a in base.get_active_alarm(5).values["active_alarms"] if a[0] == AlarmCode.OBSTACLE]
    assert alarm, base.get_active_alarm(5).values
    assert "range" in alarm[0][2] and "bearing" in alarm[0][2]
    assert not base.alarms.has(AlarmCode.STUCK)                  # the tracking blockage's is its own


def test_stuck_ends_by_clear_alarm_or_a_motion_away(base, executor):  # noqa: F811
    drive_into_the_box(base, executor, lambda: base.move_forward(5000.0))
    x = truth_x(base)
    base.set_jog_timeout(60000)                                 # the jog outlasts the test
    assert base.clear_alarm().ok and state(base) == VehicleState.READY
    assert base.move_jog(200.0, 0.0, 0.0).ok                    # toward it again: Stuck at once
    run_until(executor, lambda: state(base) == VehicleState.STUCK, 2.0)
    settle(executor, base, 5.0)
    assert truth_x(base) - x < 0.01 and not executor.world.bumper_in_contact()
    assert base.move_jog(-200.0, 0.0, 0.0).ok                   # backwards: away from it
    assert state(base) == VehicleState.BUSY
    steps(executor, 1.0)
    assert base.stop().ok
    settle(executor, base, 5.0)
    assert truth_x(base) < x - 0.05 and state(base) == VehicleState.READY


def test_reversing_watches_behind(executor):  # noqa: F811
    executor.world.add_box((-1.0 - 0.2, 0.0, 0.4), (0.2, 0.5, 0.4))
    base = VehicleCore(executor, VehicleConfig(), ZONES)
    ready(base)
    assert base.move_forward(-3000.0).ok
    run_until(executor, lambda: state(base) == VehicleState.STUCK, 20.0)
    settle(executor, base, 5.0)
    assert -1.0 + BACK < truth_x(base) + 0.0 and truth_x(base) - BACK > -1.0 + 0.05


def test_turning_in_place_is_not_watched(base, executor):  # noqa: F811
    executor.world.add_box((0.0, 0.9, 0.4), (0.5, 0.2, 0.4))    # beside it
    ready(base)
    assert base.move_turn(90.0).ok
    settle(executor, base, 10.0)
    assert state(base) == VehicleState.READY
    assert math.degrees(base.odometry.pose.theta) == pytest.approx(90.0, abs=1.0)


def test_caution_velocity_is_bounded_as_set_velocity(executor):  # noqa: F811
    with pytest.raises(ValueError, match="caution_velocity is 2000 mm/s: as set_velocity"):
        VehicleCore(executor, VehicleConfig(), ObstacleConfig(caution_velocity=2000.0))


def avoiding_base(executor, boxes):  # noqa: F811
    """A base with avoid_obstacles on, knowing a map of `boxes` ((x, y, half x, half y))."""
    from acti_sim.surroundings.occupancy import rasterise
    from acti_sim.surroundings.worldfile import Box, WorldSpec
    for x, y, hx, hy in boxes:
        executor.world.add_box((x, y, 0.4), (hx, hy, 0.4))
    base = VehicleCore(executor, VehicleConfig(), ObstacleConfig(
        caution_distance=600.0, stop_distance=100.0, caution_velocity=150.0, avoid_obstacles=True))
    base.know_map(rasterise(WorldSpec(boxes=tuple(
        Box("", (2 * hx, 2 * hy, 0.8), (x, y, 0.0)) for x, y, hx, hy in boxes)), 0.05))
    ready(base)
    base.set_velocity((400.0, 45.0))
    return base


def run_watching_contact(executor, base, until, seconds):  # noqa: F811
    """Step until until(); the states seen; fails on any bumper contact."""
    seen = set()

    def done():
        seen.add(state(base))
        assert not executor.world.bumper_in_contact()
        return until()
    run_until(executor, done, seconds)
    return seen


def test_avoid_detours_around_the_box_to_the_target(executor):  # noqa: F811
    base = avoiding_base(executor, [(2.2, 0.0, 0.2, 0.5)])
    assert base.move_linear_abs((3500.0, 0.0, 0.0)).ok
    seen = run_watching_contact(
        executor, base, lambda: state(base) == VehicleState.READY and not base.device.busy, 90.0)
    assert VehicleState.AVOID in seen and VehicleState.STUCK not in seen
    x, y, th = position(base)
    assert (x, y) == pytest.approx((3500.0, 0.0), abs=30.0) and abs(th) < 3.0
    assert not base.alarms.has(AlarmCode.OBSTACLE)


def test_avoid_without_a_way_around_ends_stuck(executor):  # noqa: F811
    base = avoiding_base(executor, [(2.7, 0.0, 0.05, 0.8), (4.3, 0.0, 0.05, 0.8),   # the target
                                    (3.5, 0.75, 0.85, 0.05), (3.5, -0.75, 0.85, 0.05)])  # walled in
    assert base.move_linear_abs((3500.0, 0.0, 0.0)).ok
    seen = run_watching_contact(executor, base, lambda: state(base) == VehicleState.STUCK, 60.0)
    assert VehicleState.AVOID in seen
    alarm = [a for a in base.get_active_alarm(5).values["active_alarms"] if a[0] == AlarmCode.OBSTACLE]
    assert alarm and "no way around" in alarm[0][2]


def test_avoid_backs_away_from_an_obstacle_met_in_reverse(executor):  # noqa: F811
    base = avoiding_base(executor, [(-2.2, 0.0, 0.2, 0.5)])
    assert base.move_forward(-3500.0).ok
    seen = run_watching_contact(
        executor, base, lambda: state(base) == VehicleState.READY and not base.device.busy, 90.0)
    assert VehicleState.AVOID in seen and VehicleState.STUCK not in seen
    x, y, _ = position(base)
    assert (x, y) == pytest.approx((-3500.0, 0.0), abs=30.0)
