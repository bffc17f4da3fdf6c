"""Bad input on every arm setting and move, without ROS: 1e308, 5e-324, inf and NaN get VALUE_ERR
(NG where the spec lists no VALUE_ERR) with a comment, the setting and the queue stay as they
were, the arm stays stoppable, and what cannot be done is refused before any planning."""
import math
import time

import numpy as np
import pytest

from acti_motion.arm.core import MAX_ACCEL_TIME_S, ArmConfig, ArmCore
from acti_motion.replies import ReturnCode as R
from arm_fixtures import IDENTITY, WORK, arm  # noqa: F401
from sim_fixtures import executor, run_until  # noqa: F401
from trajectory_check import ArmTrace

HUGE, TINY, INF, NAN = 1e308, 5e-324, math.inf, math.nan
NON_FINITE = (INF, -INF, NAN)
ABSURD = (HUGE, -HUGE, *NON_FINITE)



def hg(dx=0.0, dy=0.0, dz=0.0):
    m = list(IDENTITY)
    m[3], m[7], m[11] = dx, dy, dz
    return m


def settings(arm):
    """Everything a setter can change, as comparable values."""
    return (arm.accel_time_joint, arm.accel_time_cartesian, arm.min_accel_time_joint,
            arm.min_accel_time_cartesian, tuple(arm.max_speed_joint), arm.max_speed_cartesian,
            arm.soft_limit_cartesian.tobytes(), arm.soft_limit_joint.tobytes(),
            arm.frames.base.tobytes(), arm.frames.tool.tobytes(), tuple(arm.home))


# --- settings --------------------------------------------------------------------------------
def setting_calls(x):
    """(operation, kwargs) that put the number x into every numeric field of every setting."""
    joint_limits = [(170.0, -170.0)] * 7
    return [
        ("set_accel_time_joint", dict(acl_time=x)),
        ("set_accel_time_cartesian", dict(acl_time=x)),
        ("set_min_accel_time_joint", dict(acl_time=x)),
        ("set_min_accel_time_cartesian", dict(acl_time=x)),
        ("set_max_speed_joint", dict(speed=[x] * 7)),
        ("set_max_speed_joint", dict(speed=[50.0] * 6 + [x])),
        ("set_max_speed_cartesian", dict(speed=(x, 45.0))),
        ("set_max_speed_cartesian", dict(speed=(250.0, x))),
        ("set_soft_limit_cartesian", dict(x_limit=(x, -1000.0), y_limit=(1000.0, -1000.0),
                                          z_limit=(1600.0, -100.0))),
        ("set_soft_limit_cartesian", dict(x_limit=(1200.0, -1000.0), y_limit=(1000.0, -1000.0),
                                          z_limit=(1600.0, -x))),
        ("set_soft_limit_joint", dict(soft_limit=[(x, -170.0)] + joint_limits[1:])),
        ("set_soft_limit_joint", dict(soft_limit=joint_limits[:6] + [(170.0, -x)])),
        ("set_base_offset", dict(offset=hg(dx=x))),
        ("set_base_offset", dict(offset=[x] + IDENTITY[1:])),
        ("set_control_point_offset", dict(offset=hg(dz=x))),
        ("set_home", dict(joint_point=[x] + list(WORK[1:]))),
    ]


@pytest.mark.parametrize("x", ABSURD, ids=["1e308", "-1e308", "inf", "-inf", "nan"])
def test_every_setting_refuses_absurd_numbers_and_keeps_its_value(arm, x):
    for op, kwargs in setting_calls(x):
        before = settings(arm)
        r = getattr(arm, op)(**kwargs)
        want = R.NG if op == "set_control_point_offset" else R.VALUE_ERR
        assert r.code == want and r.comment, (op, kwargs, r)
        assert settings(arm) == before, op


@pytest.mark.parametrize("op", ["set_accel_time_joint", "set_accel_time_cartesian",
                                "set_min_accel_time_joint", "set_min_accel_time_cartesian"])
def test_accel_times_are_bounded_so_stop_stays_quick(arm, op):
    for bad in (TINY, 0.0, -1.0, MAX_ACCEL_TIME_S + 0.01, 600.0, HUGE):
        r = getattr(arm, op)(bad)
        assert r.code == R.VALUE_ERR and "s" in r.comment, (bad, r)
    assert getattr(arm, op)(MAX_ACCEL_TIME_S).ok


def test_speeds_have_a_floor_and_a_ceiling(arm):
    for speed in ([TINY] * 7, [0.05] * 7):
        r = arm.set_max_speed_joint(speed)
        assert r.code == R.VALUE_ERR and "at least 0.1" in r.comment
    for speed in ((TINY, 45.0), (0.5, 45.0), (250.0, TINY), (20000.0, 45.0)):
        r = arm.set_max_speed_cartesian(speed)
        assert r.code == R.VALUE_ERR and "within" in r.comment
    assert arm.set_max_speed_joint([0.1] * 7).ok and arm.set_max_speed_cartesian((1.0, 0.1)).ok


def test_tiny_positions_and_offsets_are_fine(arm):
    assert arm.set_base_offset(hg(dx=TINY)).ok
    assert arm.set_control_point_offset(hg(dz=TINY)).ok
    assert arm.move_ptp_joint_rel([TINY] * 7).ok


@pytest.mark.parametrize("limits", [((0.0, 0.0), (0.0, 0.0), (0.0, 0.0)),
                                    ((100.0, 100.0), (1000.0, -1000.0), (1600.0, -100.0)),
                                    ((1200.0, -1000.0), (-1000.0, 1000.0), (1600.0, -100.0))])
def test_cartesian_soft_limit_needs_lower_below_upper(arm, limits):
    r = arm.set_soft_limit_cartesian(*limits)
    assert r.code == R.VALUE_ERR and "must be above lower" in r.comment
    assert arm.get_soft_limit_cartesian().values["x_limit"] == (1200.0, -1000.0)


def test_start_settings_are_checked_by_the_setters(executor):  # noqa: F811
    for field, value in (("accel_time_joint", 600.0), ("min_accel_time_cartesian", HUGE),
                         ("max_speed_rotation", TINY), ("soft_limit_cartesian", (0.0,) * 6)):
        with pytest.raises(ValueError, match=field):
            ArmCore(executor, ArmConfig(**{field: value}))


# --- moves ------------------------------------------------------------------------------------
def move_calls(x):
    """(operation, kwargs) that put the number x into every numeric field of every move."""
    def car(m, elbow=0.0):
        return (m, elbow, 0)
    return [
        ("move_ptp_joint_abs", dict(joint_points=[x] + list(WORK[1:]))),
        ("move_ptp_joint_rel", dict(joint_points=[0.0] * 6 + [x])),
        ("move_ptp_cartesian_abs", dict(car_point=car(hg(dx=x)))),
        ("move_ptp_cartesian_abs", dict(car_point=car(hg(), elbow=x))),
        ("move_ptp_cartesian_rel", dict(car_point=car(hg(dz=x)))),
        ("move_linear_cartesian_abs", dict(car_point=car(hg(dy=x)))),
        ("move_linear_cartesian_rel", dict(car_point=car(hg(dx=x)))),
        ("move_linear_cartesian_rel", dict(car_point=car(hg(), elbow=x))),
        ("move_linear_cartesian_rel", dict(car_point=car([x] + IDENTITY[1:]))),
        ("move_circular_cartesian_abs", dict(car_point_r=car(hg(dx=x)), car_point_t=car(hg()))),
        ("move_circular_cartesian_rel", dict(car_point_r=car(hg(dx=50.0, dz=-50.0)),
                                             car_point_t=car(hg(dz=x)))),
    ]


@pytest.mark.parametrize("x", ABSURD, ids=["1e308", "-1e308", "inf", "-inf", "nan"])
def test_every_move_refuses_absurd_numbers_at_once_and_keeps_the_queue(arm, x):
    assert arm.move_ptp_joint_rel([1.0] * 7).ok
    for op, kwargs in move_calls(x):
        t0 = time.monotonic()
        r = getattr(arm, op)(**kwargs)
        assert r.code == R.VALUE_ERR and r.comment, (op, kwargs, r)
        assert "Error" not in r.comment, r.comment               # no internal failure
        assert time.monotonic() - t0 < 2.0, (op, "refused only after planning")
        assert [m.id for m in arm.device.queue] == [1]


def test_every_move_takes_5e_324_as_the_tiny_number_it_is(arm):
    """Denormal inputs: a move to where it is (or through a denormal via point) is queued or
    refused with VALUE_ERR and a comment, never an internal failure."""
    for op, kwargs in move_calls(TINY):
        r = getattr(arm, op)(**kwargs)
        assert r.code in (R.OK, R.VALUE_ERR) and (r.ok or r.comment), (op, kwargs, r)


@pytest.mark.parametrize("via_mm", [1e6, 5000.0])
def test_a_far_via_point_is_refused_before_planning(arm, via_mm):
    """Was: a circular move through a via point 1 km away took 5-17 s to be refused."""
    for limits in (None, (1e5, -1e5)):
        if limits:     # also with a soft-limit box that does not stop it: the reach does
            assert arm.set_soft_limit_cartesian(limits, limits, limits).ok
        t0 = time.monotonic()
        r = arm.move_circular_cartesian_rel(((hg(dx=via_mm)), 0.0, 0), (hg(dz=-50.0), 0.0, 0))
        assert r.code == R.VALUE_ERR and ("reach" in r.comment or "soft limit" in r.comment)
        assert time.monotonic() - t0 < 1.0
    r = arm.move_ptp_cartesian_rel((hg(dx=via_mm), 0.0, 0))
    assert r.code == R.VALUE_ERR and ("out of" in r.comment or "soft limit" in r.comment)


def test_a_planning_failure_is_ng_with_a_comment_and_queues_nothing(arm, monkeypatch):
    """Fault injection: whatever fails inside planning answers NG; nothing escapes."""
    def broken(*args, **kwargs):
        raise AssertionError("internal check failed")
    monkeypatch.setattr(arm.planner, "plan", broken)
    r = arm.move_linear_cartesian_rel((hg(dx=20.0), 0.0, 0))
    assert r.code == R.NG and "AssertionError: internal check failed" in r.comment
    assert arm.device.last_id == 0 and not arm.device.busy


# --- the arm stays stoppable at the bounds -----------------------------------------------------
def test_stop_rests_within_the_longest_accel_time(arm, executor):  # noqa: F811
    assert arm.set_accel_time_joint(MAX_ACCEL_TIME_S).ok and arm.set_speed_joint(100).ok
    trace = ArmTrace(executor, arm)
    assert arm.move_ptp_joint_rel([60.0, -30.0, 40.0, 30.0, 40.0, 30.0, 60.0]).ok
    run_until(executor, lambda: executor.world.time > 3.0, 5.0)
    assert arm.stop().ok
    rest_at = arm.device.queued_end.joints.copy()
    took = run_until(executor, lambda: not arm.device.busy, MAX_ACCEL_TIME_S + 1.0)
    assert took <= MAX_ACCEL_TIME_S + 2 * executor.dt
    for _ in range(10):
        executor.step()
    trace.check()
    trace.check_rest(rest_at)


def test_the_slowest_joint_speed_still_moves_and_stops(arm, executor):  # noqa: F811
    """Was: 5e-324 °/s was accepted and a small move then killed the process."""
    assert arm.set_max_speed_joint([0.1] * 7).ok
    trace = ArmTrace(executor, arm)
    r = arm.move_ptp_joint_rel([1.0] * 7)
    assert r.ok and np.isfinite(arm.device.queue[0].motion.duration)
    run_until(executor, lambda: executor.world.time > 1.0, 2.0)
    assert arm.stop().ok
    run_until(executor, lambda: not arm.device.busy, arm.accel_time_joint + 0.1)
    trace.check()


def _accepted_then_run(arm, executor, reply):  # noqa: F811
    """A move is refused, or it runs to its end without the soft-limit watch's alarm."""
    if reply.code == R.VALUE_ERR:
        return "refused"
    assert reply.ok, reply
    run_until(executor, lambda: not arm.device.busy, 60.0)
    assert not arm.alarms, arm.alarms
    return "ran"


def test_a_ptp_move_accepted_never_trips_the_cartesian_limit_watch(arm, executor):  # noqa: F811
    """A far control point bulges between the accept check's samples (one per degree): a limit
    on the samples' extreme was accepted, then the run crossed it by 0.12 mm (alarm 0x5)."""
    start = [-85.5, 40.0, 0.0, -40.0, 0.0, 90.0, 90.0]
    assert arm.move_ptp_joint_abs(start).ok
    run_until(executor, lambda: not arm.device.busy, 30.0)
    assert arm.set_control_point_offset(hg(dx=2000.0, dz=2000.0)).ok
    step = np.radians([91.0] + [0.0] * 6)
    qs = np.radians(start) + np.linspace(0.0, 1.0, 92)[:, None] * step
    sampled = arm.frames.tool_of(arm.kin.flange_many(qs))[:, 0, 3].max() * 1000.0
    assert arm.set_soft_limit_cartesian((sampled, -10000.0), (10000.0, -10000.0),
                                        (10000.0, -10000.0)).ok
    assert _accepted_then_run(arm, executor, arm.move_ptp_joint_rel(list(np.degrees(step)))) \
        == "refused"


def test_a_cp_move_accepted_never_trips_the_joint_limit_watch(arm, executor):  # noqa: F811
    """The accept check samples the joint spline 4× per knot: a limit just past the samples'
    extreme was accepted, then the run crossed it by 1e-6° (alarm 0x4)."""
    assert arm.set_speed_cartesian(100).ok
    assert arm.move_ptp_joint_abs([0.0, 40.0, 0.0, -80.0, 0.0, 40.0, 0.0]).ok
    run_until(executor, lambda: not arm.device.busy, 30.0)
    move = (hg(dy=400.0, dz=-300.0), 0.0, 0)
    assert arm.move_linear_cartesian_rel(move).ok               # planned once, to learn its path
    spline = arm.device.queue[-1].motion.path
    dense = np.degrees(spline.spline(np.linspace(0.0, 1.0, 4 * len(spline.ss))))
    fine = np.degrees(spline.spline(np.linspace(0.0, 1.0, 200001)))
    assert arm.stop().ok
    run_until(executor, lambda: not arm.device.busy, 5.0)
    assert dense[:, 3].min() - fine[:, 3].min() > 2e-6          # the samples miss the extreme
    limits = [tuple(x) for x in arm.get_soft_limit_joint().values["soft_limit"]]
    limits[3] = (limits[3][0], dense[:, 3].min() - 1e-10)
    assert arm.set_soft_limit_joint(limits).ok
    assert _accepted_then_run(arm, executor, arm.move_linear_cartesian_rel(move)) == "refused"


@pytest.mark.parametrize("call", [
    lambda a: a.move_ptp_joint_abs([999.0] + [0.0] * 6),
    lambda a: a.move_ptp_cartesian_abs((hg(dx=5000.0), 0.0, 0)),
    lambda a: a.move_linear_cartesian_abs((hg(dx=5000.0), 0.0, 0)),
    lambda a: a.move_circular_cartesian_abs((hg(dx=5000.0), 0.0, 0), (hg(dx=300.0), 0.0, 0))])
def test_a_bad_absolute_target_is_value_err_on_a_full_queue_too(arm, call):
    """Known without the start: said before the queue is looked at (as a relative step that
    no start can take; FULL_MOTION_QUEUE_ERR hid it)."""
    while arm.move_ptp_joint_rel([0.0] * 6 + [0.1]).ok:
        pass
    assert arm.device.full
    r = call(arm)
    assert r.code == R.VALUE_ERR and r.comment, r


def test_a_relative_step_back_into_moved_soft_limits_is_accepted(arm, executor):  # noqa: F811
    """5.4.15 refuses (VALUE_ERR) only a bad value: with J1's soft limit set to 50 … 60° while it
    rests at 0°, +55° ends inside it, as movePTPJointAbs to 55° does. The check made before the
    queue called a step wider than the limit's span (10°) one that "leaves it from any start";
    a step no start within the hardware range can take is still refused there (full queue)."""
    limits = [tuple(x) for x in arm.get_soft_limit_joint().values["soft_limit"]]
    limits[0] = (60.0, 50.0)
    assert arm.set_soft_limit_joint(limits).ok
    r = arm.move_ptp_joint_rel([55.0] + [0.0] * 6)
    assert r.ok, r.comment
    run_until(executor, lambda: not arm.device.busy, 30.0)
    assert arm.get_feedback_pos_joint().values["pos"][0] == pytest.approx(55.0, abs=0.05)
    while arm.move_ptp_joint_rel([0.0] * 6 + [0.1]).ok:
        pass
    r = arm.move_ptp_joint_rel([-250.0] + [0.0] * 6)         # from +170 at most: -80 < 50
    assert r.code == R.VALUE_ERR and "from any start" in r.comment, r


@pytest.mark.parametrize("call", [
    lambda a: a.move_ptp_cartesian_rel((hg(dx=5000.0), 0.0, 0)),
    lambda a: a.move_linear_cartesian_rel((hg(dz=-5000.0), 0.0, 0)),
    lambda a: a.move_circular_cartesian_rel((hg(dy=5000.0), 0.0, 0), (hg(dx=100.0), 0.0, 0)),
    lambda a: a.move_circular_cartesian_rel((hg(dy=100.0), 0.0, 0), (hg(dx=5000.0), 0.0, 0))])
def test_a_cartesian_step_longer_than_the_reach_is_value_err_on_a_full_queue_too(arm, call):
    """5.4.11/5.4.13 (VALUE_ERR: a bad value): a relative step longer than the diameter of the
    ball the control point reaches ends out of reach from any start, as a joint step no start
    can take; on a full queue it was FULL_MOTION_QUEUE_ERR."""
    while arm.move_ptp_joint_rel([0.0] * 6 + [0.1]).ok:
        pass
    assert arm.device.full
    r = call(arm)
    assert r.code == R.VALUE_ERR and "reach" in r.comment, r


def test_go_home_outside_the_soft_limits_is_value_err_on_a_full_queue_too(arm):
    """goHome (2014) is a move to an absolute target: a home that soft limits set since leave
    out is VALUE_ERR before the queue is looked at, as movePTPJointAbs's (it was
    FULL_MOTION_QUEUE_ERR on a full queue)."""
    limits = [tuple(x) for x in arm.get_soft_limit_joint().values["soft_limit"]]
    limits[0] = (60.0, -60.0)
    assert arm.set_home([90.0] + list(WORK[1:])).ok
    assert arm.set_soft_limit_joint(limits).ok
    while arm.move_ptp_joint_rel([0.0] * 6 + [0.1]).ok:
        pass
    assert arm.device.full
    r = arm.go_home()
    assert r.code == R.VALUE_ERR and "J1 = 90° is outside the soft limit" in r.comment, r


@pytest.mark.parametrize("op", ["move_ptp_cartesian_abs", "move_linear_cartesian_abs"])
def test_an_absolute_pose_no_joints_reach_is_value_err_on_a_full_queue_too(arm, op):
    """5.4.10/5.4.12 (VALUE_ERR: a bad value): whether a joint solution within the soft limits
    reaches an absolute pose with its elbow does not depend on the start (all eight branches are
    tried); the flange turned half a turn about z here has none (J7's ±175°). On a full queue
    it was FULL_MOTION_QUEUE_ERR."""
    here = arm.get_feedback_pos_cartesian().values["pos"][0]
    turned = [-1.0, 0.0, 0.0, here[3], 0.0, -1.0, 0.0, here[7], 0.0, 0.0, 1.0, here[11]]
    while arm.move_ptp_joint_rel([0.0] * 6 + [0.1]).ok:
        pass
    assert arm.device.full
    r = getattr(arm, op)((turned, 0.0, 0))
    assert r.code == R.VALUE_ERR and "no joint solution" in r.comment, r


def test_a_short_ptp_move_is_checked_between_its_two_samples_too(arm, executor):  # noqa: F811
    """A move under a degree has two samples, its ends, checked in plain floats when both lie
    well inside the box: ends within the limit's margin are still checked between them (the
    control point bulges past the ends' extreme), and a box the ends lie well inside accepts."""
    start = [-85.5, 40.0, 0.0, -40.0, 0.0, 90.0, 90.0]
    assert arm.move_ptp_joint_abs(start).ok
    run_until(executor, lambda: not arm.device.busy, 30.0)
    assert arm.set_control_point_offset(hg(dx=2000.0, dz=2000.0)).ok

    def x_mm(j1_deg):                        # the control point's x over J1 (degree)
        qs = np.radians(np.array(start)[None, :].repeat(len(j1_deg), 0))
        qs[:, 0] = np.radians(j1_deg)
        return arm.frames.tool_of(arm.kin.flange_many(qs))[:, 0, 3] * 1000.0
    j1 = np.arange(-85.5, -85.5 + 91.0, 0.01)
    peak = float(j1[np.argmax(x_mm(j1))])          # x is largest there: a bulge between ends
    assert -85.0 < peak < 5.0
    wide = (10000.0, -10000.0)
    assert arm.set_soft_limit_cartesian(wide, wide, wide).ok
    assert arm.move_ptp_joint_abs([peak - 0.45] + start[1:]).ok
    run_until(executor, lambda: not arm.device.busy, 30.0)
    ends = float(x_mm(np.array([peak - 0.45, peak + 0.45])).max())
    assert float(x_mm(np.array([peak]))[0]) > ends + 0.05
    assert arm.set_soft_limit_cartesian((ends + 0.01, -10000.0), wide, wide).ok
    step = [0.9] + [0.0] * 6
    assert _accepted_then_run(arm, executor, arm.move_ptp_joint_rel(step)) == "refused"
    assert arm.set_soft_limit_cartesian((ends + 100.0, -10000.0), wide, wide).ok
    assert _accepted_then_run(arm, executor, arm.move_ptp_joint_rel(step)) == "ran"
