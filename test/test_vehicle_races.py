"""Spec races and bounds of the base without ROS: the jog deadman counts the job's clock, pause where
nothing can move is ignored, clear_alarm clears all, a blocked move ends Stuck (not completed),
battery alarms have hysteresis, and absurd inputs are refused without touching the queue, with
every plan's cost bounded."""
import math
import threading
import time

import pytest

from acti_motion.vehicle import cruise
from acti_motion.vehicle.alarms import AlarmCode, Kind
from acti_motion.vehicle.core import VehicleConfig, VehicleCore, VehicleState
from sim_fixtures import executor, run_until  # noqa: F401
from vehicle_fixtures import base, blind_base, position, ready, settle, state, state_msg, steps, trace  # noqa: F401

BUMPER_FRONT = 321.0          # mm ahead of base_link


# --- the deadman --------------------------------------------------------------------------
@pytest.mark.parametrize("drive", ["move_jog", "joystick"])
def test_a_paused_jog_resumed_after_its_timeout_does_not_drive_again(base, executor, trace, drive):  # noqa: F811
    ready(base)
    base.set_jog_timeout(300)
    if drive == "move_jog":
        assert base.move_jog(300.0, 0.0, 0.0).ok
    else:
        base.set_joystick(True)
        assert base.joy_input([0.0, 1.0], [])
    trace.step(0.1)
    assert base.pause().ok
    trace.until(lambda: state(base) == VehicleState.PAUSED, 2.0)
    deadline = base._drive_deadline
    trace.until(lambda: executor.world.time > deadline, 60.0)  # the job's clock runs while held
    trace.step(0.05)
    held = position(base)
    assert base.resume().ok
    trace.until_idle(5.0)
    trace.check()
    assert math.dist(position(base)[:2], held[:2]) < 2.0        # not another 100 mm


def test_a_renewal_between_the_deadmans_check_and_its_brake_drives_on(base, executor):  # noqa: F811
    """The deadman decided on a passed deadline, a renewal then came and was answered OK, and
    the deadman braked the renewed jog anyway."""
    ready(base)
    assert base.set_jog_timeout(30000).ok
    assert base.move_jog(300.0, 0.0, 0.0).ok
    steps(executor, 0.3)
    base._drive_deadline = executor.world.time - 0.001       # a late client: the timeout passed
    decided, go = threading.Event(), threading.Event()
    edit_planned, simulation = base.device.edit_planned, threading.current_thread()

    def held(*args, **kwargs):
        if threading.current_thread() is simulation:
            decided.set()
            assert go.wait(30.0)
        return edit_planned(*args, **kwargs)
    base.device.edit_planned = held
    simulation = threading.Thread(target=executor.step, daemon=True)
    simulation.start()
    assert decided.wait(30.0)
    assert base.move_jog(300.0, 0.0, 0.0).ok                  # the renewal
    go.set()
    simulation.join(30.0)
    base.device.edit_planned = edit_planned
    steps(executor, 1.0)
    assert base.odometry.v == pytest.approx(0.3, abs=0.01)   # it drives on


def test_the_deadman_counts_the_jobs_clock_not_the_wall_clock(base, executor, trace):  # noqa: F811
    """A simulation that lags the wall clock (here: not stepped at all for longer than the
    timeout) does not end a jog early: it drives its timeout of the job's clock after the last
    call, as far as in a simulation at real time, so a recording replays it. Then the next
    control period past the deadline brakes it."""
    ready(base)
    base.set_acceleration((1000.0, 180.0))
    base.set_jog_timeout(200)
    motion = base.move_jog(300.0, 0.0, 0.0).values["motion_id"]
    deadline = base._drive_deadline
    assert deadline == pytest.approx(executor.world.time + 0.2)
    trace.step(0.1)
    speed, wall = trace.points[-1].v, time.monotonic() + 0.3
    while time.monotonic() <= wall:                          # wall time passes, the world waits
        threading.Event().wait(0.01)
    trace.step(0.05)
    assert base._deadman_fired is None and trace.points[-1].v > speed + 0.02   # speeding up
    trace.until(lambda: base._deadman_fired == motion, 1.0)
    assert executor.world.time == pytest.approx(deadline, abs=executor.dt + 1e-9)
    trace.until_idle(2.0)
    trace.check()


# --- pause where nothing moves ------------------------------------------------------------
@pytest.mark.parametrize("situation", ["unpowered", "powered", "locked"])
def test_pause_is_ignored_where_no_motion_can_run(base, executor, situation):  # noqa: F811
    if situation != "unpowered":
        base.set_power(True)
    if situation == "locked":
        base.set_servo(True)
        base.locked = True
    r = base.pause()
    assert r.ok and "ignored" in r.comment and not base.device.paused
    base.set_power(True)
    base.unlock()
    base.set_servo(True)
    assert state(base) == VehicleState.READY
    assert base.move_forward(200.0).ok
    settle(executor, base, 5.0)
    assert base.device.completed == 1


def test_pause_of_an_idle_base_is_visible_and_resume_leaves_it(base):
    ready(base)
    assert base.pause().ok and state(base) == VehicleState.PAUSED
    assert base.resume().ok and state(base) == VehicleState.READY
    r = base.resume()                                          # nothing paused: true, and said
    assert r.ok and r.comment == "ignored: the base is not paused"


# --- clear_alarm (1.4.1: 発生した全てのアラームを解除) --------------------------------------
def test_clear_alarm_clears_every_alarm_and_a_present_cause_raises_its_own_again(base, executor):  # noqa: F811
    ready(base)
    base.set_output(0, 1, 1)                                    # warning 104
    base.battery.charge = 0.25                                 # ~45 V: warning 110
    executor.step()
    base.locked = True                                         # contact 301, Locked
    base.alarms.raise_(AlarmCode.CONTACT, "contact sensor", Kind.CONTACT)
    assert {a[0] for a in base.get_active_alarm(9).values["active_alarms"]} == {104, 110, 301}
    r = base.clear_alarm()
    assert r.ok
    # every alarm goes, the contact's 301 too; the battery's cause is there, and Locked is a
    # state that only unlock leaves (1.4.34): the reply says both (it was true and silent:
    # 全てのアラームを解除 read as done)
    assert [a[0] for a in base.get_active_alarm(9).values["active_alarms"]] == [110]
    assert r.comment == ("still active: 110 until the battery is back at 47 V and clear_alarm "
                         "is called; Locked until unlock (a contact)"), r.comment
    assert state(base) == VehicleState.LOCKED
    base.battery.charge = 1.0
    assert base.unlock().ok
    r = base.clear_alarm()
    assert r.ok and not r.comment
    assert base.get_active_alarm(9).values["num_of_active_alarm"] == 0


# --- battery hysteresis -------------------------------------------------------------------
def test_the_battery_fault_does_not_end_when_the_load_drops(base, executor):  # noqa: F811
    ready(base)
    c = base.config
    model = base.battery.model
    # just above the cut-off at rest, below it under the servo's and electronics' load
    base.battery.charge = (c.battery_cutoff_voltage + 0.2 - model.empty_voltage) / (
        model.full_voltage - model.empty_voltage)
    base.set_velocity((1000.0, 90.0))
    base.move_forward(3000.0)
    run_until(executor, lambda: state(base) == VehicleState.ALARM, 10.0)
    settle(executor, base, 3.0)
    steps(executor, 0.5)
    assert base.battery.voltage > c.battery_cutoff_voltage       # the load dropped …
    assert base.clear_alarm().ok
    assert state_msg(base) == "Alarm-201"                       # … the fault stays
    released = c.battery_cutoff_voltage + c.battery_hysteresis
    alarm = base.get_active_alarm(1).values["active_alarms"][0]
    assert f"released at {released:g} V" in alarm[2], alarm      # not "44.1 V (below 44 V)"
    r = base.set_servo(True)
    assert not r.ok and f"back at {released:g} V" in r.comment, r.comment
    base.battery.charge = 1.0
    assert base.clear_alarm().ok and base.set_servo(True).ok and state(base) == VehicleState.READY


# --- a blocked move ends Stuck ------------------------------------------------------------
@pytest.mark.parametrize("distance", [100.0, 1000.0])
def test_a_move_into_a_wall_ends_stuck_and_not_completed(blind_base, executor, distance):  # noqa: F811
    base = blind_base                                          # no zones to stop it before the wall
    gap = 0.03                                                 # 30 mm ahead of the bumper
    executor.world.add_box((BUMPER_FRONT / 1000.0 + gap + 0.1, 0.0, 0.25), (0.1, 0.6, 0.25))
    ready(base)
    motion = base.move_forward(distance).values["motion_id"]
    settle(executor, base, 10.0)
    assert state(base) == VehicleState.STUCK
    assert base.device.was_discarded(motion)                    # not completed (a brake ran)
    assert base.device.discard_reason(motion).startswith("a blockage: the base")   # and why
    assert position(base)[0] < 60.0
    assert AlarmCode.STUCK in [a[0] for a in base.get_active_alarm(5).values["active_alarms"]]
    assert not base.move_forward(-100.0).ok                     # Ready only: not while Stuck
    back = base.move_continuous_rel((-100.0, 0.0, 0.0)).values["motion_id"]   # backs away
    settle(executor, base, 5.0)
    assert not base.device.was_discarded(back) and state(base) == VehicleState.READY


# --- bounds ---------------------------------------------------------------------------------
BIG, TINY = 1e308, 5e-324
ABSURD = [
    ("move_forward", dict(x=BIG)), ("move_forward", dict(x=-2e5)),
    ("move_turn", dict(theta=BIG)), ("move_turn", dict(theta=4000.0)),
    ("move_linear_rel", dict(pos=(BIG, 0.0, 0.0))), ("move_linear_rel", dict(pos=(0.0, 0.0, BIG))),
    ("move_linear_abs", dict(pos=(0.0, 1e6, 0.0))), ("move_linear_abs", dict(pos=(0.0, 0.0, -BIG))),
    ("move_circular_rel", dict(center_point=(0.0, BIG), theta=1.0)),
    ("move_circular_rel", dict(center_point=(0.0, 1000.0), theta=BIG)),
    ("move_circular_rel", dict(center_point=(0.0, 99000.0), theta=180.0)),
    ("move_continuous_rel", dict(pos=(BIG, 0.0, 0.0))), ("move_continuous_rel", dict(pos=(0.0, 0.0, 1e5))),
    ("move_cruise_abs", dict(cruise_point=(1e6, 0.0))), ("move_cruise_abs", dict(cruise_point=(0.0, -BIG))),
    ("move_cruise_abs", dict(cruise_point=(math.nan, 0.0))),
    ("set_velocity", dict(vel=(TINY, 10.0))), ("set_velocity", dict(vel=(100.0, TINY))),
    ("set_acceleration", dict(accel=(TINY, 10.0))), ("set_acceleration", dict(accel=(100.0, TINY))),
    ("set_position", dict(pos=(0.0, 0.0, BIG))), ("set_position", dict(pos=(BIG, 0.0, 0.0))),
    ("set_position", dict(pos=(0.0, math.inf, 0.0))),
]


@pytest.mark.parametrize("name, kwargs", ABSURD, ids=[f"{n}-{i}" for i, (n, _) in enumerate(ABSURD)])
def test_absurd_values_are_refused_with_a_reason_and_the_running_move_goes_on(
        base, executor, name, kwargs):  # noqa: F811
    ready(base)
    assert base.move_linear_abs((800.0, 0.0, 0.0)).ok
    steps(executor, 0.5)
    before = (base.device.current.id, base.device.queue_length, base.device.last_id, position(base))
    started = time.monotonic()
    r = getattr(base, name)(**kwargs)
    assert time.monotonic() - started < 1.0
    assert not r.ok and len(r.comment) > 10 and "could not be carried out" not in r.comment
    assert (base.device.current.id, base.device.queue_length, base.device.last_id) == before[:3]
    assert base.get_position().values["pos"] == pytest.approx(before[3], abs=20.0)
    settle(executor, base)
    assert base.device.completed == 1


def test_jogs_with_tiny_values_and_the_slowest_settings_are_fine(base, executor):  # noqa: F811
    ready(base)
    assert base.move_jog(TINY, 0.0, TINY).ok
    c = base.config
    assert base.set_velocity((c.velocity_min_translation, c.velocity_min_rotation)).ok
    for point in ((99000.0, 99000.0), (-99000.0, 99000.0)):      # days of driving, planned at once
        started = time.monotonic()
        assert base.move_cruise_abs(point).ok
        assert time.monotonic() - started < 1.5                  # ~0.1 s on a quiet machine
    assert base.stop().ok


def test_the_work_area_is_a_setting(executor):  # noqa: F811
    base = VehicleCore(executor, VehicleConfig(work_area=2000.0))
    ready(base)
    assert not base.move_linear_abs((2500.0, 0.0, 0.0)).ok
    assert base.move_linear_abs((1500.0, 0.0, 0.0)).ok
    r = base.move_forward(600.0)                                   # Ready only: refused, Busy
    assert not r.ok


def test_cruise_points_added_one_by_one_plan_a_window_of_constant_size(base, executor, monkeypatch):  # noqa: F811
    """Adding the n-th point re-plans at most the last WINDOW points and the new one, so n
    points cost n times one (it was n²)."""
    sizes = []
    real = cruise.plan_curve

    def counted(start, points, *args, **kwargs):
        sizes.append(len(points))
        return real(start, points, *args, **kwargs)
    monkeypatch.setattr(cruise, "plan_curve", counted)
    ready(base)
    for i in range(40):
        assert base.move_cruise_abs((400.0 * (i + 1), 300.0 * (i % 2))).values["motion_id"] == 1
    assert max(sizes[cruise.WINDOW:]) <= cruise.WINDOW + 1 and len(sizes) == 40
    steps(executor, 3.0)                                         # and while it runs
    for i in range(40, 50):
        assert base.move_cruise_abs((400.0 * (i + 1), 300.0 * (i % 2))).values["motion_id"] == 1
    assert max(sizes[cruise.WINDOW:]) <= cruise.WINDOW + 1


# --- pause and stop of a brake ----------------------------------------------------------------
def braking(base, executor):  # noqa: F811
    """A fast move given up (a blockage, as the simulation thread declares it): the brake runs."""
    ready(base)
    assert base.set_velocity((1000.0, 90.0)).ok and base.move_forward(3000.0).ok
    run_until(executor, lambda: base.odometry.v > 0.5, 10.0)
    base._declare_stuck(0.5, 0.0, "could not follow its path")
    steps(executor, 0.02)
    assert base.device.current.label == "brake" and base.odometry.v > 0.3


def test_pause_then_stop_of_a_brake_brings_the_base_to_rest(base, executor):  # noqa: F811
    """The pause froze the brake's clock, and with it the wheel speeds it commands: the base
    rolled on at ~0.4 m/s for ever, Paused, and neither stop nor servo off ended it."""
    braking(base, executor)
    assert base.pause().ok
    steps(executor, 1.0)
    assert base.stop().ok and base.set_servo(False).ok
    steps(executor, 2.0)
    at = position(base)
    steps(executor, 1.0)
    assert abs(base.odometry.v) < 0.01 and math.dist(position(base)[:2], at[:2]) < 1.0
    assert not base.device.busy


def test_a_move_given_after_a_stop_while_a_brake_runs_is_discarded(base, executor):  # noqa: F811
    """停止後は全ての動作指令を廃棄: the stop of a brake discarded only what was queued then,
    and a move given until the base was at rest ran after the brake."""
    braking(base, executor)
    assert base.stop().ok
    r = base.move_linear_abs((0.0, 0.0, 0.0))
    assert r.ok and "discarded" in r.comment, r
    settle(executor, base, 5.0)
    steps(executor, 1.0)
    assert base.device.completed == 0 and abs(base.odometry.v) < 0.01
