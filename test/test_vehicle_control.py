"""The base's control plane without ROS: pause, resume and stop checked set-point by set-point
(trajectory_check_base), also in the window between accept and pick-up and while another thread
plans; planning never holds a lock that stop, the getters or the simulation need."""
import math
import threading

import pytest

from acti_motion.vehicle import cruise
from acti_motion.vehicle.core import VehicleState
from sim_fixtures import Announced, executor  # noqa: F401
from vehicle_fixtures import base, position, ready, state, steps, trace  # noqa: F401

MOVES = {
    "move_forward": lambda b: b.move_forward(1500.0),
    "move_linear_abs": lambda b: b.move_linear_abs((1200.0, 600.0, 90.0)),
    "move_circular_rel": lambda b: b.move_circular_rel((0.0, 800.0), 120.0),
    "move_cruise_abs": lambda b: [b.move_cruise_abs(p) for p in ((800.0, 400.0), (1600.0, 0.0))][-1],
    "move_continuous_rel": lambda b: b.move_continuous_rel((1500.0, 300.0, 20.0)),
    "move_jog": lambda b: b.move_jog(400.0, 0.0, 20.0),
}


@pytest.mark.parametrize("move", sorted(MOVES))
@pytest.mark.parametrize("after", [0.0, 0.7])
def test_pause_then_resume_ramps_within_the_settings(base, executor, trace, move, after):  # noqa: F811
    """Pause at accept (before the simulation picks the move up) or on the way; resume seconds
    later: decelerates and accelerates smoothly, then ends where it would have."""
    ready(base)
    base.set_jog_timeout(60000)
    assert MOVES[move](base).ok
    trace.step(after)
    assert base.pause().ok
    trace.step(2.0)
    assert state(base) == VehicleState.PAUSED and abs(base.odometry.v) < 0.01
    held = position(base)
    trace.step(1.0)
    assert position(base) == pytest.approx(held, abs=1.0)
    assert base.resume().ok
    if move == "move_jog":
        trace.step(1.0)
        assert base.stop().ok
    trace.until_idle()
    trace.check()


@pytest.mark.parametrize("move", sorted(MOVES))
@pytest.mark.parametrize("after", [0.0, 0.7])
def test_stop_rests_where_announced_and_discards_everything(base, executor, trace, move, after):  # noqa: F811
    ready(base)
    assert MOVES[move](base).ok
    base.move_linear_abs((0.0, 0.0, 0.0))
    trace.step(after)
    assert base.stop().ok
    rest = base.device.queued_end
    assert base.device.queue_length == 0
    trace.until_idle()
    trace.check(rest=rest)
    assert base.device.completed == 0 and state(base) == VehicleState.READY


@pytest.mark.parametrize("after", [0.0, 0.7])
def test_stop_while_paused_rests_where_the_pause_held(base, executor, trace, after):  # noqa: F811
    ready(base)
    base.move_forward(1500.0)
    trace.step(after)
    base.pause()
    trace.step(1.5)
    held = trace.points[-1].pose
    assert base.stop().ok
    trace.until_idle()
    trace.check(rest=held)


@pytest.mark.parametrize("later", ["move_forward", "move_linear_abs", "move_cruise_abs",
                                   "move_continuous_rel", "move_jog"])
def test_moves_sent_during_the_stops_deceleration_are_discarded(base, executor, trace, later):  # noqa: F811
    """停止後は全ての動作指令を廃棄: a move given while the stop decelerates is not run either."""
    ready(base)
    base.set_velocity((800.0, 45.0))
    base.move_cruise_abs((3000.0, 0.0))
    trace.until(lambda: base.odometry.v > 0.7, 5.0)
    base.stop()
    rest = base.device.queued_end
    r = MOVES[later](base)
    assert r.ok and "discarded" in r.comment      # Ready only or not: true, discarded (it was
    assert base.device.queue_length == 0          # refused as Busy, leaving Warning-102)
    trace.until_idle()
    trace.check(rest=rest)
    trace.step(1.0)
    assert not base.device.busy and state(base) == VehicleState.READY


def test_a_pause_during_the_stops_deceleration_holds_once_the_base_is_at_rest(base, executor, trace):  # noqa: F811
    """1.4.22 pause (常に真): 動作中の場合は…完全停止後に一時停止状態となります. Given while a stop
    decelerated, the pause was true and lost: the base came to rest Ready and ran the next
    move at once."""
    ready(base)
    base.set_velocity((800.0, 45.0))
    base.move_forward(3000.0)
    trace.until(lambda: base.odometry.v > 0.7, 5.0)
    base.stop()
    rest = base.device.queued_end
    assert base.pause().ok and state(base) == VehicleState.BUSY
    assert "discarded" in base.move_forward(100.0).comment      # the stop still discards it
    trace.until_idle()
    trace.check(rest=rest)
    assert state(base) == VehicleState.PAUSED
    r = base.move_forward(200.0)                                # kept for resume
    assert r.ok and not r.comment
    trace.step(1.0)
    assert base.device.queue_length == 1 and state(base) == VehicleState.PAUSED
    assert base.resume().ok
    trace.until_idle(5.0)
    assert base.device.completed == 1 and state(base) == VehicleState.READY


@pytest.mark.parametrize("resume_after", [0.0, 0.2])
def test_a_resume_during_the_stops_deceleration_undoes_a_pause_given_there(base, executor, trace,  # noqa: F811
                                                                           resume_after):
    """… and does not speed the base up again: resumed, the stop's ramp ran back up to full
    speed, and the clock then jumped to the stop's rest point (11 m/s² of deceleration against
    the 1 m/s² limit)."""
    ready(base)
    base.set_velocity((800.0, 45.0))
    base.move_forward(3000.0)
    trace.until(lambda: base.odometry.v > 0.7, 5.0)
    base.stop()
    rest, stopped_at = base.device.queued_end, len(trace.points) - 1
    assert base.pause().ok
    trace.step(resume_after)
    assert base.resume().ok
    trace.until_idle()
    trace.check(rest=rest)
    speeds = [p.v for p in trace.points[stopped_at:]]
    assert all(b <= a + 1e-9 for a, b in zip(speeds, speeds[1:])), "sped up during the stop"
    assert state(base) == VehicleState.READY


def test_a_pause_before_the_move_starts_then_stop_lets_the_next_move_run(base, executor, trace):  # noqa: F811
    """Paused before the simulation picked the move up, then stopped: the next move was
    accepted and never ran (the device's rate stayed held at 0: moving for ever)."""
    ready(base)
    assert base.move_forward(500.0).ok
    assert base.pause().ok and base.stop().ok
    assert state(base) == VehicleState.READY
    motion_id = base.move_forward(200.0).values["motion_id"]
    trace.until_idle(10.0)
    assert base.device.is_over(motion_id) and not base.device.was_discarded(motion_id)
    assert position(base)[0] == pytest.approx(200.0, abs=5.0)
    trace.check()


# --- planning never blocks the control plane ------------------------------------------------
@pytest.fixture
def planning_gate(monkeypatch):
    """Holds every TOPP-RA timing (the real one runs after the gate opens) so the test can act
    while another thread is planning."""
    entered, gate = threading.Event(), threading.Event()
    real = cruise.time_optimal

    def gated(*args, **kwargs):
        entered.set()
        assert gate.wait(10.0)
        return real(*args, **kwargs)
    monkeypatch.setattr(cruise, "time_optimal", gated)
    yield entered, gate
    gate.set()


def in_thread(fn):
    out = {}
    thread = threading.Thread(target=lambda: out.setdefault("reply", fn()), daemon=True)
    thread.start()
    return thread, out


def answers_at_once(fn, seconds=2.0):
    thread, out = in_thread(fn)
    thread.join(seconds)
    assert not thread.is_alive(), "waited behind the planner"
    return out["reply"]


@pytest.mark.parametrize("planner", ["first point", "added point", "retarget", "set_velocity"])
def test_stop_pause_getters_and_the_simulation_never_wait_for_a_plan(
        base, executor, trace, planning_gate, planner):  # noqa: F811
    entered, gate = planning_gate
    ready(base)
    if planner != "first point":
        gate.set()
        base.move_cruise_abs((2000.0, 500.0))
        trace.until(lambda: base.odometry.v > 0.2, 5.0)
        gate.clear()
        entered.clear()
    call = {"first point": lambda: base.move_cruise_abs((2000.0, 0.0)),
            "added point": lambda: base.move_cruise_abs((3000.0, 0.0)),
            "retarget": lambda: base.move_continuous_rel((1500.0, -200.0, 0.0)),
            "set_velocity": lambda: base.set_velocity((200.0, 30.0))}[planner]
    planning, _ = in_thread(call)
    assert entered.wait(10.0)
    assert answers_at_once(base.get_state).ok
    assert answers_at_once(base.get_position).ok
    answers_at_once(lambda: trace.step(0.2))               # the simulation steps on
    assert answers_at_once(base.pause).ok
    assert answers_at_once(base.stop).ok
    rest = base.device.queued_end
    gate.set()
    planning.join(10.0)
    assert not planning.is_alive()
    trace.until_idle()
    trace.check(rest=rest if base.device.discarded else None)
    assert base.device.completed == 0


def test_servo_off_while_a_move_is_planned_queues_nothing(base, executor, planning_gate):  # noqa: F811
    entered, gate = planning_gate
    ready(base)
    planning, out = in_thread(lambda: base.move_cruise_abs((2000.0, 0.0)))
    assert entered.wait(10.0)
    assert answers_at_once(lambda: base.set_servo(False)).ok
    gate.set()
    planning.join(10.0)
    r = out["reply"]
    # refused in the new state, or accepted as a command the servo off then discarded
    # (Device.submit: a stop or halt that overtook the planning discards what it planned)
    assert (not r.ok and "Powered" in r.comment) or \
        (r.ok and base.device.was_discarded(r.values["motion_id"]))
    assert not base.device.busy


def test_a_move_sent_before_a_stop_and_planned_after_it_is_discarded(base, executor, planning_gate):  # noqa: F811
    """B waited for the planning lock while A planned; a stop came (the base idle, so at rest
    at once); B then began under the stop's new generation and ran: a command given before
    the stop (停止後は全ての動作指令を廃棄)."""
    entered, gate = planning_gate
    ready(base)
    start = position(base)
    a_thread, a = in_thread(lambda: base.move_cruise_abs((2000.0, 0.0)))
    assert entered.wait(10.0)
    announced = base.planning = Announced(base.planning)
    b_thread, b = in_thread(lambda: base.move_forward(500.0))
    assert announced.waits.wait(10.0)
    assert answers_at_once(base.stop).ok
    gate.set()
    a_thread.join(10.0)
    b_thread.join(10.0)
    for r in (a["reply"], b["reply"]):        # true, and discarded (said, or by its id)
        assert r.ok and ("discarded" in r.comment
                         or base.device.was_discarded(r.values["motion_id"])), r
    steps(executor, 2.0)
    assert not base.device.busy and base.device.completed == 0
    assert math.dist(position(base)[:2], start[:2]) < 1.0
