"""Velocity drive without ROS: move_jog (timeout, limits, updates) and the joystick."""
import math

import pytest

from acti_motion.executor import STALE
from acti_motion.vehicle.core import VehicleState
from sim_fixtures import executor, run_until  # noqa: F401
from vehicle_fixtures import base, ready, settle, state, steps  # noqa: F401


def test_jog_runs_while_repeated_and_stops_by_itself_after_the_timeout(base, executor):  # noqa: F811
    ready(base)
    assert base.set_jog_timeout(400).ok
    ids = set()
    for _ in range(8):                                    # 1.6 s of commands every 0.2 s
        r = base.move_jog(250.0, 0.0, -15.0)
        assert r.ok
        ids.add(r.values["motion_id"])
        steps(executor, 0.2)
    assert ids == {1}                                     # one jog, updated in place
    assert base.odometry.v == pytest.approx(0.25, abs=0.01)
    assert math.degrees(base.odometry.w) == pytest.approx(-15.0, abs=0.5)
    steps(executor, 0.15)                                 # 0.35 s after the last call: still on
    assert base.odometry.v == pytest.approx(0.25, abs=0.01)
    steps(executor, 0.15 + 0.25 / 0.5 + 0.05)             # past the timeout and the deceleration
    assert abs(base.odometry.v) < 0.01
    settle(executor, base, 1.0)
    assert state(base) == VehicleState.READY


def test_jog_accelerates_at_the_setting_and_backwards_is_allowed(base, executor):  # noqa: F811
    ready(base)
    base.set_acceleration((200.0, 90.0))
    base.set_jog_timeout(2000)
    base.move_jog(-400.0, 0.0, 0.0)
    steps(executor, 1.0)
    assert base.odometry.v == pytest.approx(-0.2, abs=0.02)    # 1 s at 200 mm/s²


@pytest.mark.parametrize("x_vel, y_vel, theta_vel, words", [
    (math.nan, 0.0, 0.0, "finite"), (0.0, 0.0, math.inf, "finite"),
    (1000.5, 0.0, 0.0, "limit"), (-1200.0, 0.0, 0.0, "limit"), (0.0, 0.0, 91.0, "limit"),
    (100.0, 5.0, 0.0, "sideways"),
])
def test_jog_refuses_bad_velocities(base, x_vel, y_vel, theta_vel, words):
    ready(base)
    r = base.move_jog(x_vel, y_vel, theta_vel)
    assert not r.ok and words in r.comment and base.device.last_id == 0


def test_cmd_vel_clamps_to_the_limits_and_a_nan_is_no_velocity(base):
    """Was: min/max turned a NaN of cmd_vel into full speed in reverse (-1000 mm/s)."""
    limit_t, limit_r = base.config.velocity_limit_translation, base.config.velocity_limit_rotation
    assert base.clamp_velocity(math.nan, 0.0) is None
    assert base.clamp_velocity(0.0, math.nan) is None
    assert base.clamp_velocity(100.0, -20.0) == (100.0, -20.0, False)
    assert base.clamp_velocity(1e308, -math.inf) == (limit_t, -limit_r, True)


def test_jog_needs_only_the_servo_and_takes_over_a_move(base, executor):  # noqa: F811
    r = base.move_jog(100.0, 0.0, 0.0)
    assert not r.ok and "Unpowered" in r.comment
    ready(base)
    assert base.move_forward(500.0).ok and base.move_linear_abs((0.0, 500.0, 0.0)).ok
    r = base.move_jog(100.0, 0.0, 0.0)                    # accepted, not yet started: replaced
    assert r.ok and r.values["motion_id"] == 3 and base.device.queue_length == 1
    steps(executor, 0.3)
    assert base.device.current.label == "move_jog"
    assert base.move_linear_abs((0.0, 500.0, 0.0)).ok     # queues behind the jog …
    assert base.move_jog(200.0, 0.0, 0.0).values["motion_id"] == 3   # … which the next one drops
    assert base.device.queue_length == 0 and base.device.discarded == 3


def test_jog_takes_over_a_running_move_with_continuous_speed(base, executor):  # noqa: F811
    ready(base)
    base.set_jog_timeout(3000)
    forward = base.move_forward(2000.0).values["motion_id"]
    speeds = []
    run_until(executor, lambda: speeds.append(base.odometry.v) or base.odometry.v > 0.25, 5.0)
    r = base.move_jog(-100.0, 0.0, 0.0)
    assert r.ok and base.device.current.label == "move_jog"
    # the move never reaches its goal: over, not completed; the jog is a motion of its own …
    assert base.device.is_over(forward) and base.device.was_discarded(forward)
    assert base.device.discard_reason(forward) == "taken over by move_jog"
    assert r.values["motion_id"] == forward + 1
    assert base.move_jog(-100.0, 0.0, 0.0).values["motion_id"] == forward + 1   # … kept by jogs
    run_until(executor, lambda: speeds.append(base.odometry.v) or base.odometry.v < -0.09, 5.0)
    assert max(abs(b - a) for a, b in zip(speeds, speeds[1:])) / executor.dt < 0.5 * 1.3


def test_joystick_drives_within_the_settings_and_off_brakes_to_ready(base, executor):  # noqa: F811
    ready(base)
    assert not base.joy_input([0.0, 1.0], [])             # off: ignored
    assert base.set_joystick(True).ok
    base.set_velocity((200.0, 30.0))
    for _ in range(20):
        assert base.joy_input([-0.5, 1.5], [])            # full forward (clamped), half right
        steps(executor, 0.05)
    assert base.odometry.v == pytest.approx(0.2, abs=0.01)
    assert math.degrees(base.odometry.w) == pytest.approx(-15.0, abs=0.5)
    assert base.set_joystick(False).ok
    took = run_until(executor, lambda: abs(base.odometry.v) < 0.005, 1.0)
    assert took < 0.2 / 1.0 + 0.1                          # at the maximum acceleration
    settle(executor, base, 1.0)
    assert state(base) == VehicleState.READY
    assert not base.joy_input([0.0, 1.0], [])


@pytest.mark.parametrize("stick", [1.0, -0.5])
def test_a_velocity_setting_changed_while_the_joystick_drives_limits_it_at_once(base, executor, stick):  # noqa: F811
    """1.4.27: the joystick's target speed is limited by setVelocity; 1.4.32: while moving, the
    speed changes continuously to the new setting. The drive went on at the old setting's
    speed until the next Joy sample (or its deadman, with a joystick that sends only changes)."""
    ready(base)
    assert base.set_jog_timeout(5000).ok and base.set_joystick(True).ok
    assert base.joy_input([0.0, stick], [])
    steps(executor, 1.5)
    assert base.odometry.v == pytest.approx(0.3 * stick, abs=0.01)
    assert base.set_velocity((100.0, 45.0)).ok
    took = run_until(executor, lambda: abs(base.odometry.v - 0.1 * stick) < 0.01, 1.0)
    assert took < abs(0.2 * stick) / 0.5 + 0.2                # at the acceleration setting
    steps(executor, 1.0)
    assert base.odometry.v == pytest.approx(0.1 * stick, abs=0.01)
    assert base.device.current.label == "joystick"

def test_joystick_off_brakes_its_drive_with_a_move_queued_behind(base, executor):  # noqa: F811
    """常に真を返します; 減速停止後に Ready: it answered false ("busy with other moves") and the
    drive went on to its deadman."""
    ready(base)
    assert base.set_joystick(True).ok
    base.set_velocity((300.0, 30.0))
    for _ in range(10):
        assert base.joy_input([0.0, 1.0], [])
        steps(executor, 0.05)
    x, y, th = base.get_position().values["pos"]
    assert base.move_linear_abs((x + 500.0, y, th)).ok     # queued behind the joystick drive
    v0 = base.odometry.v
    assert base.set_joystick(False).ok
    took = run_until(executor, lambda: abs(base.odometry.v) < 0.005, 1.0)
    assert took < v0 / 1.0 + 0.1                           # at the maximum acceleration
    settle(executor, base, 5.0)               # … then Ready: the move planned from the drive's
    assert state(base) == VehicleState.READY   # old end is discarded, and says why
    assert base.device.discard_reason(base.device.last_id) == "the joystick was switched off"


def test_joystick_is_ignored_while_moves_are_queued(base):
    ready(base)
    base.set_joystick(True)
    base.move_forward(300.0)
    assert not base.joy_input([0.0, 1.0], [])
    assert base.device.last_id == 1 and not base.alarms.active()


def test_a_zero_jog_on_an_idle_base_queues_nothing(base):
    ready(base)
    r = base.move_jog(0.0, 0.0, 0.0)
    assert r.ok and r.values["motion_id"] == 0 and state(base) == VehicleState.READY


def test_a_zero_jog_brakes_a_running_jog(base, executor):  # noqa: F811
    ready(base)
    base.set_jog_timeout(5000)
    base.move_jog(300.0, 0.0, 0.0)
    steps(executor, 1.0)
    assert base.move_jog(0.0, 0.0, 0.0).values["motion_id"] == 1
    took = run_until(executor, lambda: abs(base.odometry.v) < 0.005, 2.0)
    assert took == pytest.approx(0.3 / 0.5, abs=0.1)            # at the acceleration setting


def test_joystick_off_as_its_drive_ends_is_still_true(base, executor):  # noqa: F811
    """The drive retired (its deadman) and the queued move started between set_joystick's look
    and its brake: it answered false ("busy") though the joystick was off."""
    ready(base)
    assert base.set_joystick(True).ok
    for _ in range(10):
        assert base.joy_input([0.0, 0.5], [])
        steps(executor, 0.05)
    x, y, th = base.get_position().values["pos"]
    assert base.move_linear_abs((x + 300.0, y, th)).ok
    edit_planned, once = base.device.edit_planned, []

    def drive_ends_first(look, plan, tries=6):
        if not once:
            once.append(1)
            base._drive_deadline = 0.0                  # the deadman fires here
            run_until(executor, lambda: base.device.current is not None
                      and base.device.current.label != "joystick", 3.0)
        return edit_planned(look, plan, tries)
    base.device.edit_planned = drive_ends_first
    r = base.set_joystick(False)
    assert r.ok and not base.joystick and not base.alarms.active(), r.comment


@pytest.mark.parametrize("meanwhile", ["pause", "outrun"])
def test_joystick_off_is_true_when_a_pause_or_the_base_outruns_its_brake(base, executor,  # noqa: F811
                                                                          meanwhile):
    """A pause between set_joystick's look and its brake's, or a brake the base outran on every
    try, answered false and raised Warning-102, with the joystick already off (setJoystick:
    常に真を返します). Paused, the drive stays held and its deadman ends it after resume."""
    ready(base)
    assert base.set_joystick(True).ok
    for _ in range(10):
        assert base.joy_input([0.0, 0.5], [])
        steps(executor, 0.05)
    edit_planned = base.device.edit_planned

    def interfere(look, plan, tries=6):
        if meanwhile == "pause":
            assert base.pause().ok
            return edit_planned(look, plan, tries)
        return STALE
    base.device.edit_planned = interfere
    r = base.set_joystick(False)
    assert r.ok and not base.joystick and not base.alarms.active(), r.comment
    base.device.edit_planned = edit_planned
    if meanwhile == "pause":
        assert base.resume().ok
    settle(executor, base, 5.0)
    assert state(base) == VehicleState.READY


def test_the_joystick_does_not_take_over_a_jog(base, executor):  # noqa: F811
    """The joystick drives only an idle base (or its own drive): it took over a running jog
    (also with its sticks at rest), and the jog ended "taken over by joystick"."""
    ready(base)
    assert base.set_joystick(True).ok
    jog = base.move_jog(-100.0, 0.0, 0.0).values["motion_id"]
    steps(executor, 0.05)
    assert not base.joy_input([0.0, 0.5], []) and not base.joy_input([0.0, 0.0], [])
    run_until(executor, lambda: base.odometry.v < -0.09, 2.0)
    assert base.device.current.id == jog and not base.device.was_discarded(jog)
