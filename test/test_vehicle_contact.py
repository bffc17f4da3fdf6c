"""Contact sensor and blockage without ROS: a bumper contact locks the base until unlock; a
blocked base stops as Stuck."""
from dataclasses import replace

import pytest

from acti_motion.vehicle.core import VehicleState
from acti_motion.vehicle.alarms import AlarmCode
from acti_sim.world import WHEEL_JOINTS
from sim_fixtures import executor, run_until  # noqa: F401
from vehicle_fixtures import blind_base, position, ready, settle, state, state_msg, steps  # noqa: F401

BUMPER_FRONT = 321.0          # mm ahead of base_link


@pytest.fixture
def base(blind_base):  # noqa: F811
    """Without obstacle zones, which would stop it before the wall (test_obstacles.py)."""
    return blind_base


@pytest.fixture
def wall(executor):  # noqa: F811
    """A fixed wall 300 mm ahead of the bumper."""
    gap = 0.3
    executor.world.add_box((BUMPER_FRONT / 1000.0 + gap + 0.1, 0.0, 0.25), (0.1, 0.6, 0.25))
    return BUMPER_FRONT + 1000.0 * gap


def test_contact_locks_the_base_until_unlock(base, executor, wall):  # noqa: F811
    ready(base)
    base.set_velocity((200.0, 45.0))
    assert base.set_digital_sensor_lock(True).ok
    base.move_forward(1000.0)
    base.move_turn(90.0)
    run_until(executor, lambda: state(base) == VehicleState.LOCKED, 5.0)
    assert state_msg(base) == "Locked" and base.device.queue_length == 0
    settle(executor, base, 2.0)
    x, _, _ = position(base)
    assert wall - BUMPER_FRONT - 5.0 < x < wall - BUMPER_FRONT + 30.0     # stopped at the wall
    steps(executor, 0.5)
    assert abs(base.odometry.v) < 5e-3 and state(base) == VehicleState.LOCKED
    alarms = base.get_active_alarm(5).values["active_alarms"]
    assert (AlarmCode.CONTACT, 1) in [(a[0], a[1]) for a in alarms]       # a FAULT
    r = base.move_forward(-200.0)
    assert not r.ok and "Locked" in r.comment and "unlock" in r.comment
    r = base.move_jog(-100.0, 0.0, 0.0)                         # the servo is on: not the reason
    assert not r.ok and "needs it unlocked (call unlock)" in r.comment, r.comment
    r = base.clear_alarm()                      # 1.4.1: every alarm, the contact's too …
    assert r.ok and base.get_active_alarm(5).values["num_of_active_alarm"] == 0
    assert state_msg(base) == "Locked"          # … but Locked is left by unlock only (1.4.34)
    assert r.comment == "still active: Locked until unlock (a contact)"
    assert not base.move_forward(-200.0).ok
    assert base.unlock().ok and state(base) == VehicleState.READY
    assert base.move_forward(-200.0).ok                                   # back away
    settle(executor, base)
    assert position(base)[0] == pytest.approx(x - 200.0, abs=5.0)
    assert base.move_forward(400.0).ok                                    # re-armed: locks again
    run_until(executor, lambda: state(base) == VehicleState.LOCKED, 5.0)


def test_contact_with_the_sensor_off_is_a_blockage(base, executor, wall):  # noqa: F811
    ready(base)
    base.set_velocity((200.0, 45.0))
    base.move_forward(1000.0)
    base.move_forward(500.0)
    run_until(executor, lambda: state(base) == VehicleState.STUCK, 8.0)
    assert state_msg(base) == "Stuck" and base.device.queue_length == 0
    assert base.alarms.has(AlarmCode.STUCK)
    assert base.get_input(1).values["input"] == 1                          # the bumper input
    settle(executor, base, 2.0)
    steps(executor, 0.3)
    assert abs(base.odometry.v) < 5e-3
    assert base.stop().ok and state(base) == VehicleState.READY           # 停止後は…待機状態に
    base.move_forward(500.0)
    run_until(executor, lambda: state(base) == VehicleState.STUCK, 8.0)
    settle(executor, base, 2.0)
    r = base.move_forward(-300.0)                                         # Ready only (1.4.17)
    assert not r.ok and "the base is Stuck" in r.comment and "clear_alarm or stop" in r.comment
    assert base.move_continuous_rel((-300.0, 0.0, 0.0)).ok                # a servo-on move …
    assert state(base) == VehicleState.BUSY                                # … moving on clears it
    settle(executor, base)
    assert state(base) == VehicleState.READY and base.get_input(1).values["input"] == 0


def test_a_distance_lag_alone_makes_the_base_stuck_within_the_stuck_time(base, executor, wall):  # noqa: F811
    """Pushing into a wall: only the distance lags (the heading holds). It went Stuck only when
    the move was about to end (11 s instead of 1 s) when the watch wanted both lags."""
    ready(base)
    assert base.move_forward(3000.0).ok                          # 10 s at 300 mm/s
    run_until(executor, lambda: base.get_input(1).values["input"] == 1, 3.0)
    took = run_until(executor, lambda: state(base) == VehicleState.STUCK, 2.0)
    assert took < 1.5, took


@pytest.mark.parametrize("move, lags", [("move_forward", "distance"), ("move_turn", "heading")])
def test_either_lag_alone_makes_a_stalled_base_stuck_within_the_stuck_time(base, executor, move,  # noqa: F811
                                                                           lags):
    """Wheel motors too weak to move the base (a stalled drive): a long move forward lags in
    distance only, a turn in place in heading only. Each must be Stuck soon after its lag
    passes the limit, not when the move is about to end (8-10 s later)."""
    for joint in WHEEL_JOINTS:
        executor.world.limits[joint] = replace(executor.world.limits[joint], effort=0.05)
    ready(base)
    assert getattr(base, move)(3000.0 if move == "move_forward" else 360.0).ok
    took = run_until(executor, lambda: state(base) == VehicleState.STUCK, 3.0)
    assert took < 1.5, took
    said = base.alarms.active()[-1].source                # "… (190 mm, 0.0° off): stopped"
    mm, degree = (float(v.split()[0].rstrip("°")) for v in said.split("(")[1].split(",")[:2])
    c = base.config
    assert (mm > c.stuck_error, abs(degree) > c.stuck_angle) == (lags == "distance", lags == "heading"), said


def test_a_contact_while_another_thread_plans_a_move_does_not_deadlock(base, executor):  # noqa: F811
    """The simulation thread raised the contact under the core's lock and queued its brake
    through submit, which waited for the planning thread; that plan waited for the core's lock:
    neither went on, and the base was never stepped again."""
    import threading
    ready(base)
    assert base.set_digital_sensor_lock(True).ok
    in_plan, sim_has_lock, out = threading.Event(), threading.Event(), {}
    submit, raise_ = base.device.submit, base.alarms.raise_

    def held_submit(plan, label):            # the service thread's plan waits for the contact
        def held(start):
            in_plan.set()
            assert sim_has_lock.wait(30.0)
            return plan(start)
        return submit(held, label)

    def raising(code, *args, **kwargs):      # raised under the core's lock
        raise_(code, *args, **kwargs)
        if code == AlarmCode.CONTACT:
            sim_has_lock.set()
    base.device.submit, base.alarms.raise_ = held_submit, raising
    service = threading.Thread(target=lambda: out.setdefault("move", base.move_forward(200.0)),
                               daemon=True)
    service.start()
    assert in_plan.wait(30.0)
    executor.world.bumper_in_contact = lambda: True
    simulation = threading.Thread(target=executor.step, daemon=True)
    simulation.start()
    simulation.join(10.0)
    service.join(10.0)
    assert not simulation.is_alive() and not service.is_alive(), "deadlock"
    assert not out["move"].ok and "Locked" in out["move"].comment
    assert state(base) == VehicleState.LOCKED


def test_enabling_the_sensor_while_the_bumper_touches_locks_the_base(base, executor, wall):  # noqa: F811
    """有効時に接触を検出すると…停止し: armed only once the bumper came free, a base enabled
    against a box pushed it 590 mm with the sensor on and no alarm."""
    ready(base)
    base.set_velocity((200.0, 45.0))
    base.move_forward(1000.0)
    run_until(executor, lambda: state(base) == VehicleState.STUCK, 8.0)
    settle(executor, base, 2.0)
    assert base.get_input(1).values["input"] == 1                          # touching
    assert base.set_digital_sensor_lock(True).ok
    run_until(executor, lambda: state(base) == VehicleState.LOCKED, 0.1)
    assert base.unlock().ok and state(base) == VehicleState.STUCK          # as before the lock
    assert base.move_continuous_rel((-200.0, 0.0, 0.0)).ok                  # backs away unlocked
    settle(executor, base)
    assert state(base) == VehicleState.READY


def test_switching_the_sensor_on_again_while_locked_lets_the_base_back_away(base, executor, wall):  # noqa: F811
    """A client re-sending its "sensor on" re-armed it against the obstacle: unlock locked again
    at the next step, and the base could not back away."""
    ready(base)
    base.set_velocity((200.0, 45.0))
    assert base.set_digital_sensor_lock(True).ok
    base.move_forward(1000.0)
    run_until(executor, lambda: state(base) == VehicleState.LOCKED, 5.0)
    settle(executor, base, 2.0)
    assert base.set_digital_sensor_lock(True).ok
    assert base.unlock().ok
    steps(executor, 0.1)
    assert state(base) == VehicleState.READY and base.move_forward(-200.0).ok


def brush_at_full_speed(base, executor) -> None:  # noqa: F811
    """A contact at 800 mm/s (the bumper brushed past something light): Locked, braking."""
    ready(base)
    base.set_velocity((800.0, 45.0))
    assert base.set_digital_sensor_lock(True).ok
    base.move_forward(5000.0)
    run_until(executor, lambda: base.odometry.v > 0.79, 5.0)
    touching = iter([True])
    executor.world.bumper_in_contact = lambda: next(touching, False)
    executor.step()
    assert state(base) == VehicleState.LOCKED


def test_a_pause_during_the_brake_after_a_contact_brings_the_base_to_rest(base, executor):  # noqa: F811
    """1.4.22 pause: 動作中の場合は，まず設定された最大加速度で停止し，完全停止後に一時停止状態.
    A brush of the bumper at 800 mm/s, unlocked at once, then a pause: the pause froze the
    brake's clock, so its wheels kept turning at the speed they had (272 mm/s for ever) while
    the state said Paused."""
    brush_at_full_speed(base, executor)
    assert base.unlock().ok and base.pause().ok
    steps(executor, 1.5)                                        # 0.8 s to rest at 1000 mm/s²
    assert state(base) == VehicleState.PAUSED and abs(base.odometry.v) < 5e-3
    x = position(base)[0]
    steps(executor, 1.0)
    assert position(base)[0] == pytest.approx(x, abs=1.0)
    assert base.resume().ok
    settle(executor, base, 2.0)
    assert state(base) == VehicleState.READY and position(base)[0] == pytest.approx(x, abs=5.0)


def test_a_move_given_during_the_brake_starts_where_the_brake_ends(base, executor):  # noqa: F811
    """1.4.19 moveLinearAbs: 現在位置・姿勢から…直線的に移動. Accepted while the brake after a
    contact ran (unlocked at once), it was planned from where the base was then, 320 mm short
    of where the brake ended: the base could not follow and went Stuck."""
    brush_at_full_speed(base, executor)
    assert base.unlock().ok
    motion = base.move_linear_abs((3000.0, 0.0, 0.0)).values["motion_id"]
    settle(executor, base, 10.0)
    assert not base.device.was_discarded(motion), base.device.discard_reason(motion)
    assert state(base) == VehicleState.READY
    x, y, theta = position(base)
    assert x == pytest.approx(3000.0, abs=5.0) and abs(y) < 5.0 and abs(theta) < 0.5


def test_a_stop_during_a_paused_brake_ends_the_pause(base, executor):  # noqa: F811
    """1.4.33 stop: 停止後は全ての動作指令を廃棄し，待機状態に移行します. A stop while the brake after a
    contact was paused discarded the queue but kept the pause: the base stayed Paused, and the
    next move waited for a resume."""
    brush_at_full_speed(base, executor)
    assert base.unlock().ok and base.pause().ok
    steps(executor, 0.2)
    assert base.stop().ok
    settle(executor, base, 2.0)
    assert state(base) == VehicleState.READY and abs(base.odometry.v) < 5e-3
    motion = base.move_forward(100.0).values["motion_id"]
    settle(executor, base, 3.0)
    assert base.device.is_over(motion) and not base.device.was_discarded(motion)
