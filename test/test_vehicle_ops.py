"""VehicleCore without ROS: state table 7, servo table 8, alarms, settings, I/O, battery,
set_position, and the refusal of bad inputs by every operation."""
import math

import pytest

from acti_motion.vehicle.core import FIRMWARE_VERSION, IF_VERSION, VehicleConfig, VehicleCore, VehicleState
from acti_motion.vehicle.alarms import AlarmCode, AlarmType
from sim_fixtures import executor, run_until  # noqa: F401
from vehicle_fixtures import base, ready, settle, state, state_msg, steps, trace  # noqa: F401

NAN, INF = math.nan, math.inf


def exhaust_battery(base, executor):  # noqa: F811
    base.battery.charge = 0.0
    executor.step()


# --- table 8 -------------------------------------------------------------------------------
@pytest.mark.parametrize("situation, on_off, ok, servo_after", [
    ("servo on", True, True, True),
    ("servo on", False, True, False),
    ("servo off", True, True, True),
    ("servo off", False, True, False),
    ("servo off, alarm", True, False, False),
    ("servo off, alarm", False, True, False),
    ("power off", True, False, False),
    ("power off", False, False, False),
])
def test_set_servo_follows_table_8(base, executor, situation, on_off, ok, servo_after):  # noqa: F811
    if situation != "power off":
        base.set_power(True)
    if situation == "servo on":
        base.set_servo(True)
    if situation == "servo off, alarm":
        base.set_servo(True)
        exhaust_battery(base, executor)
        assert not base.servo and state(base) == VehicleState.ALARM
    r = base.set_servo(on_off)
    assert r.ok == ok and base.servo == servo_after
    if not ok:
        assert r.comment


def test_state_codes_and_strings_walk_table_7(base, executor):  # noqa: F811
    assert (state(base), state_msg(base)) == (0x019, "Unpowered")
    base.set_power(True)
    assert (state(base), state_msg(base)) == (0x018, "Powered")
    base.set_servo(True)
    assert (state(base), state_msg(base)) == (0x010, "Ready")
    assert base.move_forward(200.0).ok
    assert (state(base), state_msg(base)) == (0x011, "Busy")
    base.pause()
    assert (state(base), state_msg(base)) == (0x015, "Paused")
    base.resume()
    settle(executor, base)
    assert not base.set_velocity((-1.0, 10.0)).ok
    assert (state(base), state_msg(base)) == (0x012, "Warning-101")
    assert base.clear_alarm().ok
    assert (state(base), state_msg(base)) == (0x010, "Ready")


def test_warning_clears_with_the_next_accepted_command(base):
    ready(base)
    assert not base.set_output(0, 1, 1).ok
    assert state_msg(base) == "Warning-104"
    assert base.set_velocity((200.0, 30.0)).ok
    assert state(base) == VehicleState.READY


def test_alarm_refuses_motion_until_cleared_and_the_cause_is_gone(base, executor):  # noqa: F811
    ready(base)
    exhaust_battery(base, executor)
    assert (state(base), state_msg(base)) == (0x013, "Alarm-201")
    r = base.move_linear_abs((100.0, 0.0, 0.0))
    assert not r.ok and "Alarm" in r.comment and "clear_alarm" in r.comment
    assert base.clear_alarm().ok                      # always true …
    assert state(base) == VehicleState.ALARM          # … but the battery is still empty
    base.battery.charge = 1.0
    assert base.clear_alarm().ok
    assert state(base) == VehicleState.POWERED        # the fault turned the servo off
    assert base.set_servo(True).ok and state(base) == VehicleState.READY


def test_power_on_fails_on_an_empty_battery(executor):  # noqa: F811
    base = VehicleCore(executor, VehicleConfig(battery_charge=0.0))
    r = base.set_power(True)
    assert not r.ok and "cut-off" in r.comment and state(base) == VehicleState.UNPOWERED


def test_power_on_while_on_is_true_below_the_cut_off(base, executor):  # noqa: F811
    """1.4.30 setPower: 偽 = 主回路電源投入に失敗. With the power on and the battery under its
    cut-off (Alarm-201), set_power(true) answered false, "power stays off", and the power
    stayed on: nothing failed to switch on."""
    ready(base)
    exhaust_battery(base, executor)
    r = base.set_power(True)
    assert r.ok and base.power and state_msg(base) == "Alarm-201"
    assert base.set_power(False).ok
    r = base.set_power(True)
    assert not r.ok and "power stays off" in r.comment and not base.power


# --- alarms --------------------------------------------------------------------------------
def test_get_active_alarm_fills_at_most_what_is_asked_and_counts_all(base):
    ready(base)
    base.set_velocity((NAN, 1.0))                     # 101
    base.get_input(99)                                # 104
    base.move_circular_rel((10.0, 0.0), 90.0)         # 105
    r = base.get_active_alarm(2)
    assert r.ok and r.values["num_of_active_alarm"] == 3
    alarms = r.values["active_alarms"]
    assert [a[0] for a in alarms] == [101, 104]
    assert all(a[1] == AlarmType.WARNING for a in alarms)
    assert "set_velocity" in alarms[0][2] and "finite" in alarms[0][2]
    for n in (0, -1):
        r = base.get_active_alarm(n)
        assert r.values["active_alarms"] == [] and r.values["num_of_active_alarm"] == 3
    assert len(base.get_active_alarm(10).values["active_alarms"]) == 3
    base.clear_alarm()
    assert base.get_active_alarm(10).values["num_of_active_alarm"] == 0


def test_faults_come_first_with_the_idl_alarm_type(base, executor):  # noqa: F811
    ready(base)
    base.get_servo_status(7)
    exhaust_battery(base, executor)
    codes = [(a[0], a[1]) for a in base.get_active_alarm(10).values["active_alarms"]]
    assert codes[0] == (AlarmCode.BATTERY_EMPTY, 1)           # fault = 1 in the IDL's order
    assert (AlarmCode.UNKNOWN_ID, 2) in codes                 # warning = 2


# --- versions, limits, defaults ------------------------------------------------------------
def test_versions(base):
    assert base.get_if_version().values == {"version": "RTC VehicleService interface: ver.2.0.0"}
    assert IF_VERSION == "RTC VehicleService interface: ver.2.0.0"
    ver = base.get_version().values["ver"]
    assert ver == FIRMWARE_VERSION and ver.startswith("Ver.")


def test_limits_and_defaults_are_readable(base):
    c = VehicleConfig()
    assert base.get_velocity_limit().values == {"vel_limit_t": c.velocity_limit_translation,
                                                "vel_limit_r": c.velocity_limit_rotation}
    assert base.get_acceleration_limit().values == {"acc_limit_t": c.accel_limit_translation,
                                                    "acc_limit_r": c.accel_limit_rotation}
    assert base.get_default_velocity().values["default_vel"] == (
        c.default_velocity_translation, c.default_velocity_rotation)
    assert base.get_default_acceleration().values["default_accel"] == (
        c.default_accel_translation, c.default_accel_rotation)
    assert base.velocity == base.get_default_velocity().values["default_vel"]


# --- settings ------------------------------------------------------------------------------
BAD_PAIRS = [(NAN, 10.0), (10.0, INF), (0.0, 10.0), (10.0, 0.0), (-5.0, 10.0), (10.0, -1.0),
             (1000.1, 10.0), (10.0, 90.5)]


@pytest.mark.parametrize("pair", BAD_PAIRS)
def test_set_velocity_refuses_bad_values(base, pair):
    r = base.set_velocity(pair)
    assert not r.ok and r.comment and base.velocity == (300.0, 45.0)


@pytest.mark.parametrize("call, shown", [
    (lambda b: b.set_velocity((1000.0001, 90.0)), "1000.0001 mm/s"),
    (lambda b: b.move_turn(3600.0001), "3600.0001 degree"),
    (lambda b: b.move_linear_abs((100000.1, 0.0, 0.0)), "(100000.1, 0) mm"),
    (lambda b: b.move_circular_rel((0.0, 100000.1), 90.0), "100000.1 mm")])
def test_a_refusal_shows_the_value_that_was_refused(base, call, shown):
    """Just past a limit, the value as sent: rounded, it read as allowed (1000 … 1000 mm/s)."""
    ready(base)
    r = call(base)
    assert not r.ok and shown in r.comment, r.comment


@pytest.mark.parametrize("pair", [(NAN, 10.0), (10.0, INF), (0.0, 10.0), (-5.0, 10.0),
                                  (1000.1, 10.0), (10.0, 180.5)])
def test_set_acceleration_refuses_bad_values(base, pair):
    r = base.set_acceleration(pair)
    assert not r.ok and r.comment and base.acceleration == (500.0, 90.0)


def test_settings_at_the_limits_are_taken(base):
    assert base.set_velocity((1000.0, 90.0)).ok and base.velocity == (1000.0, 90.0)
    assert base.set_acceleration((1000.0, 180.0)).ok and base.acceleration == (1000.0, 180.0)


def test_set_acceleration_is_refused_while_moving_and_velocity_is_not(base, executor):  # noqa: F811
    ready(base)
    base.move_forward(300.0)
    r = base.set_acceleration((800.0, 100.0))
    assert not r.ok and "moving" in r.comment and base.acceleration == (500.0, 90.0)
    assert base.set_velocity((200.0, 30.0)).ok
    settle(executor, base)
    assert base.set_acceleration((800.0, 100.0)).ok


@pytest.mark.parametrize("timeout", [0, -1, -32768])
def test_set_jog_timeout_refuses_zero_and_negative(base, timeout):
    r = base.set_jog_timeout(timeout)
    assert not r.ok and "> 0" in r.comment and base.jog_timeout == 500


def test_set_jog_timeout(base):
    assert base.set_jog_timeout(250).ok and base.jog_timeout == 250


# --- servo status, I/O, battery ------------------------------------------------------------
def test_get_servo_status_per_wheel(base):
    assert base.get_servo_status(0).values["status"] is False
    ready(base)
    assert base.get_servo_status(0).values["status"] and base.get_servo_status(1).values["status"]
    r = base.get_servo_status(2)
    assert not r.ok and "axis 2" in r.comment


def test_io_module_from_its_config(base):
    assert base.get_input(4).values["input"] == 5                  # a constant input
    assert base.get_input(1).values["input"] == 0                  # the bumper, free
    assert base.set_output(1, 0xFF, 0x0F).ok
    assert base.get_input(2).values["input"] == 0x0F               # loop-back of output 1
    assert base.set_output(1, 0x00, 0x03).ok
    assert base.get_input(2).values["input"] == 0x0C               # only the masked bits changed
    assert base.get_input(3).values["input"] == 0                  # output 2 untouched


@pytest.mark.parametrize("text, words", [
    (None, "FileNotFoundError"), ("inputs:\n  - {name: x}\n", "KeyError: 'id'"),
    ("inputs: [\n", "ParserError"), ("inputs: 7\n", "TypeError")])
def test_an_io_config_that_cannot_be_read_is_a_clear_start_up_error(executor, tmp_path, text,
                                                                    words):  # noqa: F811
    """Was: a FileNotFoundError (or YAML error) traceback at start-up."""
    path = tmp_path / "io.yaml"
    if text is not None:
        path.write_text(text)
    with pytest.raises(ValueError, match=f"io_config {path}: not an I/O description") as refused:
        VehicleCore(executor, VehicleConfig(io_config=str(path)))
    assert words in str(refused.value)


@pytest.mark.parametrize("ioid, words", [(0, "reserved"), (3, "not declared"), (99, "not declared")])
def test_set_output_refuses_reserved_and_unknown_ids(base, ioid, words):
    r = base.set_output(ioid, 1, 1)
    assert not r.ok and words in r.comment
    assert base.io.values == {0: 0, 1: 0, 2: 0}


def test_get_input_refuses_unknown_ids(base):
    r = base.get_input(42)
    assert not r.ok and "42" in r.comment and state_msg(base) == "Unpowered"


def test_battery_voltage_in_tenths_of_a_volt_drains_faster_when_moving(base, executor):  # noqa: F811
    v = base.get_battery_voltage().values["voltage"]
    assert 540.0 < v <= 546.0                                     # 54.6 V full: "×10 V"
    ready(base)
    c0 = base.battery.charge
    steps(executor, 3.0)
    idle = c0 - base.battery.charge
    c1 = base.battery.charge
    base.set_velocity((800.0, 90.0))
    base.move_forward(2000.0)
    steps(executor, 3.0)
    moving = c1 - base.battery.charge
    assert moving > 1.5 * idle > 0.0
    assert base.get_battery_voltage().values["voltage"] < v


def test_battery_low_warning(base, executor):  # noqa: F811
    ready(base)
    base.battery.charge = 0.25                        # ~45 V: below 46 V, above 44 V
    executor.step()
    assert state_msg(base) == "Warning-110"
    r = base.move_forward(100.0)                      # Ready only: refused, and says why
    assert not r.ok and "Warning-110" in r.comment and "the battery is back at 47 V" in r.comment
    assert base.move_linear_abs((100.0, 0.0, 0.0)).ok  # a warning does not refuse servo-on moves


# --- set_position --------------------------------------------------------------------------
def test_set_position_redefines_the_origin(base, executor):  # noqa: F811
    ready(base)
    assert base.set_position((1000.0, -500.0, 90.0)).ok
    assert base.get_position().values["pos"] == pytest.approx((1000.0, -500.0, 90.0))
    base.move_forward(300.0)
    settle(executor, base)
    x, y, th = base.get_position().values["pos"]
    assert abs(x - 1000.0) < 5 and abs(y + 200.0) < 5 and abs(th - 90.0) < 0.5
    for given, read in ((200.0, -160.0), (-300.0, 60.0)):     # wrapped at once, not a step later
        assert base.set_position((0.0, 0.0, given)).ok
        assert base.get_position().values["pos"][2] == pytest.approx(read)


def test_set_position_while_moving_keeps_the_path_on_the_floor(base, executor):  # noqa: F811
    ready(base)
    truth0 = executor.world.base_pose()
    base.move_forward(600.0)
    steps(executor, 1.0)
    x, y, th = base.get_position().values["pos"]
    assert base.set_position((x + 5000.0, y, th)).ok
    settle(executor, base)
    x, y, th = base.get_position().values["pos"]
    assert abs(x - 5600.0) < 5 and abs(y) < 5
    assert abs(executor.world.base_pose()[0] - truth0[0] - 0.6) < 0.01


# --- bad inputs everywhere -----------------------------------------------------------------
BAD_CALLS = [
    ("move_forward", dict(x=NAN)), ("move_forward", dict(x=INF)),
    ("move_turn", dict(theta=NAN)), ("move_turn", dict(theta=-INF)),
    ("move_linear_rel", dict(pos=(NAN, 0.0, 0.0))), ("move_linear_rel", dict(pos=(0.0, 0.0, INF))),
    ("move_linear_abs", dict(pos=(0.0, INF, 0.0))), ("move_linear_abs", dict(pos=(NAN, 0.0, 0.0))),
    ("move_circular_rel", dict(center_point=(0.0, NAN), theta=90.0)),
    ("move_circular_rel", dict(center_point=(0.0, 100.0), theta=INF)),
    ("move_circular_rel", dict(center_point=(50.0, 100.0), theta=90.0)),
    ("move_continuous_rel", dict(pos=(0.0, NAN, 0.0))), ("move_cruise_abs", dict(cruise_point=(INF, 0.0))),
    ("move_jog", dict(x_vel=NAN, y_vel=0.0, theta_vel=0.0)),
    ("move_jog", dict(x_vel=0.0, y_vel=0.0, theta_vel=-91.0)),
    ("set_velocity", dict(vel=(NAN, 1.0))), ("set_acceleration", dict(accel=(1.0, -1.0))),
    ("set_jog_timeout", dict(timeout=0)), ("set_position", dict(pos=(NAN, 0.0, 0.0))),
    ("set_output", dict(ioid=0, output=1, mask=1)), ("set_output", dict(ioid=77, output=1, mask=1)),
    ("get_input", dict(ioid=77)), ("get_servo_status", dict(axisid=5)),
]


@pytest.mark.parametrize("name, kwargs", BAD_CALLS, ids=[f"{n}-{i}" for i, (n, _) in enumerate(BAD_CALLS)])
def test_bad_inputs_are_refused_with_a_reason_and_the_queue_intact(base, name, kwargs):
    ready(base)
    assert base.move_linear_abs((500.0, 0.0, 0.0)).ok
    queued = (base.device.queue_length, base.device.last_id)
    r = getattr(base, name)(**kwargs)
    assert not r.ok and len(r.comment) > 10
    assert (base.device.queue_length, base.device.last_id) == queued
    assert base.alarms.active()[-1].source.startswith(name)


@pytest.mark.parametrize("name, kwargs", [
    ("move_forward", dict(x=100.0)), ("move_turn", dict(theta=10.0)),
    ("move_linear_rel", dict(pos=(100.0, 0.0, 0.0))),
    ("move_circular_rel", dict(center_point=(0.0, 100.0), theta=10.0)),
    ("move_linear_abs", dict(pos=(100.0, 0.0, 0.0))),
    ("move_continuous_rel", dict(pos=(100.0, 0.0, 0.0))), ("move_cruise_abs", dict(cruise_point=(100.0, 0.0))),
    ("move_jog", dict(x_vel=100.0, y_vel=0.0, theta_vel=0.0)),
])
@pytest.mark.parametrize("situation", ["unpowered", "powered", "locked"])
def test_motion_is_refused_without_servo_or_while_locked(base, name, kwargs, situation):
    if situation != "unpowered":
        base.set_power(True)
    if situation == "locked":
        base.set_servo(True)
        base.locked = True
    r = getattr(base, name)(**kwargs)
    assert not r.ok and situation.capitalize() in r.comment
    assert base.device.last_id == 0


READY_ONLY_MOVES = [
    ("move_forward", dict(x=100.0)), ("move_turn", dict(theta=10.0)),
    ("move_linear_rel", dict(pos=(100.0, 0.0, 0.0))),
    ("move_circular_rel", dict(center_point=(0.0, 100.0), theta=10.0)),
]
# how the base gets into a state other than Ready, and what the refusal says to leave it
NOT_READY = {
    "Busy": (lambda b: b.move_forward(300.0), "(wait, or call stop)"),
    "Warning-104": (lambda b: b.set_output(77, 1, 1), "(it lasts until clear_alarm)"),
    "Stuck": (lambda b: b._declare_stuck(0.5, 0.0, "could not follow its path"),
              "(call clear_alarm or stop)"),
}


@pytest.mark.parametrize("name, kwargs", READY_ONLY_MOVES)
@pytest.mark.parametrize("situation", sorted(NOT_READY))
def test_ready_only_moves_are_refused_in_every_state_but_ready(base, executor, name, kwargs,  # noqa: F811
                                                               situation):
    """1.4.14, 1.4.17, 1.4.20, 1.4.21: Ready 状態以外で実行すると設定値を無視し，偽を返します. In
    Warning-104 move_forward(100) drove 100.1 mm; in Stuck move_turn ran against the wall."""
    ready(base)
    enter, remedy = NOT_READY[situation]
    enter(base)
    assert state_msg(base) == situation
    ids = base.device.last_id
    r = getattr(base, name)(**kwargs)
    assert not r.ok and f"the base is {situation}: {name} needs Ready" in r.comment, r.comment
    assert r.comment.endswith(remedy) and base.device.last_id == ids


@pytest.mark.parametrize("name, kwargs", READY_ONLY_MOVES)
def test_ready_only_moves_given_while_paused_run_after_resume(base, executor, name, kwargs):  # noqa: F811
    """1.4.22: 一時停止状態で入力された動作指令は内部に蓄積され…resume()実行後に実行されます."""
    ready(base)
    assert base.pause().ok and state(base) == VehicleState.PAUSED
    r = getattr(base, name)(**kwargs)
    assert r.ok and base.device.queue_length == 1
    steps(executor, 0.5)
    assert base.device.queue_length == 1 and state(base) == VehicleState.PAUSED
    assert base.resume().ok
    settle(executor, base)
    assert base.device.completed == 1 and state(base) == VehicleState.READY


@pytest.mark.parametrize("name, kwargs", [
    ("move_forward", dict(x=0.0)), ("move_turn", dict(theta=0.0)),
    ("move_linear_rel", dict(pos=(0.0, 0.0, 0.0))),
    ("move_circular_rel", dict(center_point=(0.0, 100.0), theta=0.0)),
    ("move_linear_abs", dict(pos=(0.0, 0.0, 0.0))),
])
def test_a_move_of_no_length_is_over_at_once(base, executor, name, kwargs):  # noqa: F811
    """It kept the base Busy for the 400 ms settle, so an immediate Ready-only move was refused."""
    ready(base)
    motion_id = getattr(base, name)(**kwargs).values["motion_id"]
    assert base.device.is_over(motion_id) and not base.device.was_discarded(motion_id)
    assert state(base) == VehicleState.READY
    moved = base.move_forward(100.0).values["motion_id"]     # no step needed in between
    took = settle(executor, base)
    assert base.device.completed == 2 and base.device.is_over(moved)
    x, y, theta = base.device.queued_end.x, base.device.queued_end.y, base.device.queued_end.theta
    assert base.move_forward(100.0).ok                       # behind a move: no settle of its own
    assert base.move_linear_abs((1000.0 * x + 100.0, 1000.0 * y, math.degrees(theta))).ok
    assert settle(executor, base) <= took + 2 * executor.dt and base.device.completed == 4


def test_always_true_operations(base):
    for op in (base.clear_alarm, base.pause, base.resume, base.stop, base.unlock):
        assert op().ok
    assert base.set_digital_sensor_lock(True).ok and base.set_digital_sensor_lock(False).ok
    assert base.get_position().ok and base.get_battery_voltage().ok


def test_set_power_off_while_moving_stops_and_drops_the_servo(base, executor, trace):  # noqa: F811
    ready(base)
    base.move_forward(1000.0)
    trace.step(1.0)
    assert base.set_power(False).ok and state(base) == VehicleState.UNPOWERED and not base.servo
    assert base.device.queue_length == 0
    rest = base.device.queued_end
    trace.until_idle(2.0)
    trace.check(rest=rest)
    steps(executor, 0.3)
    assert abs(base.odometry.v) < 1e-3
    assert base.set_power(True).ok and state(base) == VehicleState.POWERED


def test_pause_reports_busy_until_the_base_is_at_rest(base, executor, trace):  # noqa: F811
    ready(base)
    base.set_velocity((800.0, 45.0))
    base.move_forward(2000.0)
    trace.until(lambda: base.odometry.v > 0.79, 5.0)
    base.pause()
    assert state(base) == VehicleState.BUSY                  # decelerating at the maximum
    took = trace.until(lambda: state(base) == VehicleState.PAUSED, 2.0)
    assert took == pytest.approx(0.8 / 1.0, abs=0.05)        # 800 mm/s at 1000 mm/s²
    assert abs(base.odometry.v) < 0.02
    trace.check()


@pytest.mark.parametrize("config, words", [
    (dict(default_velocity_translation=2000.0), "default velocity"),
    (dict(default_accel_rotation=0.0), "default_accel_rotation is 0.0"),
    (dict(default_accel_rotation=0.5), "default acceleration"),     # within its range, below the minimum
    # a negative minimum let set_velocity take -5 mm/s (the base went Stuck)
    (dict(velocity_min_translation=-5.0), "velocity_min_translation is -5.0"),
    (dict(jog_timeout=0), "jog_timeout is 0"),
    (dict(jog_timeout=0), "jog_timeout"),
    # was accepted: a target anywhere in 1e300 mm, a stop that would take hours, a NaN charge
    (dict(work_area=1e300), "work_area is 1e+300: it must be within 1 … 1e+06"),
    (dict(accel_limit_translation=10.0, accel_min_translation=1.0, default_accel_translation=5.0),
     "would take 100 s"),
    (dict(velocity_limit_rotation=90.0, accel_limit_rotation=2.0, accel_min_rotation=1.0,
          default_accel_rotation=1.0), "would take 45 s"),
    (dict(battery_charge=math.nan), "battery_charge is nan"),
    # were accepted too (a negative axis read the Joy message from its end)
    (dict(arrival_error=-1.0), "arrival_error is -1"), (dict(joy_axis_linear=-3), "joy_axis_linear"),
    (dict(battery_cutoff_voltage=50.0), "must be below battery_low_voltage"),
])
def test_start_up_settings_outside_the_limits_are_rejected(executor, config, words):  # noqa: F811
    with pytest.raises(ValueError, match="vehicle configuration") as refused:
        VehicleCore(executor, VehicleConfig(**config))
    assert words in str(refused.value)


@pytest.mark.parametrize("move", [lambda b: b.move_turn(30.0), lambda b: b.move_forward(100.0),
                                  lambda b: b.move_linear_rel((100.0, 0.0, 0.0)),
                                  lambda b: b.move_circular_rel((0.0, 500.0), 30.0)])
def test_a_ready_only_move_during_a_stop_is_true_and_discarded(base, executor, move):  # noqa: F811
    """停止後は全ての動作指令を廃棄: it was refused as Busy, and the stopped base showed
    Warning-102."""
    ready(base)
    base.move_forward(-600.0)
    steps(executor, 0.8)
    assert base.stop().ok
    r = move(base)
    assert r.ok and r.comment.startswith("discarded: the base is stopping"), r.comment
    settle(executor, base, 3.0)
    assert state(base) == VehicleState.READY


@pytest.mark.parametrize("move", [lambda b: b.move_forward(1e308),
                                  lambda b: b.move_linear_rel((1e308, 0.0, 0.0)),
                                  lambda b: b.move_continuous_rel((0.0, -3e5, 0.0))])
@pytest.mark.parametrize("stopping", [False, True])
def test_a_step_that_leaves_the_work_area_from_any_start_is_refused_in_every_state(
        base, executor, move, stopping):  # noqa: F811
    """During a stop's deceleration a 1e308 mm step was true and discarded, though it is wrong
    whatever the start (the arm's VALUE_ERR rule): refused, warning 101, saying why."""
    ready(base)
    if stopping:
        base.move_forward(-600.0)
        steps(executor, 0.8)
        assert base.stop().ok
    r = move(base)
    assert not r.ok and "longer than the work area's diagonal" in r.comment, r.comment
    assert [a.code for a in base.alarms.active()] == [101]
