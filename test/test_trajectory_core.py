"""The ROS-free trajectory core: joint_trajectory_controller's rules, interpolation, limit checks,
tolerances, and a trajectory run on a real arm's queue (stop, pause, preemption, busy)."""
from __future__ import annotations

import math

import numpy as np
import pytest

from acti_motion.trajectory.follow import PREEMPTED, ArmTrajectories
from acti_motion.trajectory.interpolation import Knot, PiecewisePolynomial
from acti_motion.trajectory.tolerances import RequestedTolerance, Tolerances
from acti_motion.trajectory.validation import (INVALID_GOAL, INVALID_JOINTS, OLD_HEADER_TIMESTAMP,
                                               InvalidTrajectory, RequestedPoint,
                                               RequestedTrajectory, validate)
from acti_motion.replies import Refused
from acti_sim.world import ARM_JOINTS
from arm_fixtures import WORK, arm, rest  # noqa: F401
from sim_fixtures import executor, run_until  # noqa: F401

Q0 = np.radians(WORK)


def request(*offsets_times, names=ARM_JOINTS, velocities=False, start=0.0):
    """Points at Q0 + offset (rad, on every joint) at the given times."""
    pts = []
    for offset, t in offsets_times:
        q = (Q0 + offset)[:len(names)].tolist()
        v = [0.0] * len(names) if velocities else []
        pts.append(RequestedPoint(t, q, v, v))
    return RequestedTrajectory(list(names), pts, start)


# --- interpolation -------------------------------------------------------------------------------
@pytest.mark.parametrize("order", [1, 2, 3])
def test_each_segment_meets_its_knots(order):
    a = Knot(0.0, np.array([0.0, 1.0]), *(([np.array([0.5, -1.0])] if order > 1 else [None])
                                          + ([np.array([0.2, 0.0])] if order > 2 else [None])))
    b = Knot(2.0, np.array([1.0, -1.0]), *(([np.zeros(2)] if order > 1 else [None])
                                           + ([np.array([0.0, 0.3])] if order > 2 else [None])))
    poly = PiecewisePolynomial([a, b])
    q, qd, qdd = poly.sample_many(np.array([0.0, 2.0 - 1e-12]))
    assert np.allclose(q[0], a.positions) and np.allclose(q[1], b.positions)
    if order == 1:
        assert np.allclose(qd, 0.5 * (b.positions - a.positions))
    else:
        assert np.allclose(qd[0], a.velocities) and np.allclose(qd[1], b.velocities, atol=1e-9)
    if order == 3:
        assert np.allclose(qdd[0], a.accelerations) and np.allclose(qdd[1], b.accelerations)
    assert np.all(poly.sample_many(np.array([5.0]))[1] == 0)        # at rest past the end


# --- validation: joint_trajectory_controller's rules ------------------------------------------------
@pytest.mark.parametrize("req, code, words", [
    (request((0.0, 1.0), names=("joint1", "wrist")), INVALID_JOINTS, "unknown joint(s) wrist"),
    (request((0.0, 1.0), names=ARM_JOINTS[:6]), INVALID_JOINTS, "joint(s) missing: joint7"),
    (RequestedTrajectory(list(ARM_JOINTS), []), INVALID_GOAL, "no points"),
    (request((0.0, 1.0), (0.1, 1.0)), INVALID_GOAL, "not strictly increasing"),
    (request((0.0, 1.0), start=5.0), OLD_HEADER_TIMESTAMP, "ends in the past"),
    (RequestedTrajectory(list(ARM_JOINTS), [RequestedPoint(1.0, list(Q0), [0.1] * 7)]),
     INVALID_GOAL, "velocity is not zero: joint1"),
    (RequestedTrajectory(list(ARM_JOINTS), [RequestedPoint(1.0, list(Q0)[:3])]), INVALID_GOAL,
     "3 positions for 7 joint names"),
    (RequestedTrajectory(list(ARM_JOINTS), [RequestedPoint(1.0, list(Q0), effort=[1.0] * 7)]),
     INVALID_GOAL, "effort"),
])
def test_a_goal_the_controller_rejects_says_why(req, code, words):
    with pytest.raises(InvalidTrajectory) as e:
        validate(req, ARM_JOINTS, now=100.0)
    assert e.value.code == code and words in str(e.value)


def test_partial_goals_when_allowed_hold_the_rest():
    valid = validate(request((0.1, 1.0), names=ARM_JOINTS[:2]), ARM_JOINTS, 0.0,
                     allow_partial_joints_goal=True)
    assert valid.given.tolist() == [True, True] + [False] * 5
    assert np.isnan(valid.knots[0].positions[2])


# --- tolerances ----------------------------------------------------------------------------------
def test_tolerances_zero_default_negative_none():
    defaults = Tolerances.uniform(7, 0.05, 0.0)
    got = defaults.with_requested([RequestedTolerance("joint2", 0.2), RequestedTolerance("joint3", -1),
                                   RequestedTolerance("joint4", 0.0)], ARM_JOINTS, "path_tolerance")
    assert got.position[0] == 0.05 and got.position[1] == 0.2 and math.isinf(got.position[2])
    assert got.position[3] == 0.05 and math.isinf(got.velocity[0])
    off = np.zeros(7)
    off[1] = 0.3
    assert "joint2 position error +0.3000 rad" in got.violation(ARM_JOINTS, np.zeros(7), off,
                                                                 np.zeros(7), np.zeros(7))
    with pytest.raises(InvalidTrajectory, match="names 'elbow'"):
        defaults.with_requested([RequestedTolerance("elbow", 1.0)], ARM_JOINTS, "goal_tolerance")


# --- on the arm's queue --------------------------------------------------------------------------
def four_points(step=0.2, dt=1.0):
    return request((0.0, 0.0), (step / 3, dt), (2 * step / 3, 2 * dt), (step, 3 * dt),
                   velocities=True)


def test_a_trajectory_runs_as_one_motion_and_ends_at_its_last_point(executor, arm):  # noqa: F811
    follower = ArmTrajectories(arm)
    motion_id, _ = follower.follow(validate(four_points(), ARM_JOINTS, follower.now()), "t")
    assert arm.device.current is None and arm.device.queue[0].id == motion_id
    executor.step()
    assert arm.state_word() & 0x02                              # moving, in the state word
    took = rest(executor, arm)
    assert 2.98 <= took < 3.2
    assert np.max(np.abs(arm.feedback_joints - (Q0 + 0.2))) < 0.01
    assert not arm.device.was_discarded(motion_id)


def test_a_limit_violation_names_joint_point_and_limit(executor, arm):  # noqa: F811
    follower = ArmTrajectories(arm)
    fast = request((0.0, 0.0), (0.5, 0.1), velocities=True)       # 0.5 rad in 0.1 s
    with pytest.raises(InvalidTrajectory, match=r"joint1 breaks its max speed between where the "
                                                r"arm is and point 1 .*limit ±"):
        follower.follow(validate(fast, ARM_JOINTS, follower.now()), "t")
    far = RequestedTrajectory(list(ARM_JOINTS), [RequestedPoint(0.0, list(Q0)),
                                                 RequestedPoint(20.0, [4.0] + list(Q0[1:]))])
    with pytest.raises(InvalidTrajectory, match="joint1 breaks its soft limit"):
        follower.follow(validate(far, ARM_JOINTS, follower.now()), "t")
    assert not arm.device.busy


def test_a_first_point_away_from_the_arm_is_refused(executor, arm):  # noqa: F811
    follower = ArmTrajectories(arm)
    with pytest.raises(InvalidTrajectory, match="point 0 is where the trajectory begins"):
        follower.follow(validate(request((0.1, 0.0), (0.2, 1.0)), ARM_JOINTS, 0.0), "t")


def test_stop_pause_and_busy_govern_it(executor, arm):  # noqa: F811
    follower = ArmTrajectories(arm)
    motion_id, _ = follower.follow(validate(four_points(), ARM_JOINTS, follower.now()), "t")
    run_until(executor, lambda: arm.device.t > 0.5, 5.0)
    assert arm.pause().ok
    run_until(executor, lambda: arm.device.rate == 0.0, 5.0)
    t = arm.device.t
    for _ in range(50):
        executor.step()
    assert arm.device.t == t and arm.state_word() & 0x10
    assert arm.resume().ok and arm.stop().ok
    rest(executor, arm)
    assert arm.device.discard_reason(motion_id) == "stop"
    # an ACT move queued: a trajectory is refused, saying so
    assert arm.move_ptp_joint_rel([5.0] + [0.0] * 6).ok
    q = arm.device.hold.joints
    req = RequestedTrajectory(list(ARM_JOINTS), [RequestedPoint(1.0, list(q))])
    with pytest.raises(Refused, match=r"motion\(s\) \(ACT moves, gripper commands\) running"):
        follower.follow(validate(req, ARM_JOINTS, follower.now()), "t")


def test_a_new_trajectory_replaces_the_running_one(executor, arm):  # noqa: F811
    follower = ArmTrajectories(arm)
    first, _ = follower.follow(validate(four_points(0.3, 2.0), ARM_JOINTS, follower.now()), "t")
    run_until(executor, lambda: arm.device.t > 1.0, 5.0)
    q = arm.device.current.motion.at(arm.device.t).joints
    back = RequestedTrajectory(list(ARM_JOINTS), [RequestedPoint(1.5, list(Q0), [0.0] * 7)])
    second, _ = follower.follow(validate(back, ARM_JOINTS, follower.now()), "u")
    assert second > first and arm.device.discard_reason(first) == PREEMPTED
    assert np.max(np.abs(arm.device.current.motion.at(arm.device.t).joints - q)) < 0.02
    rest(executor, arm)
    assert np.max(np.abs(arm.feedback_joints - Q0)) < 0.01
    assert not arm.device.was_discarded(second)


def test_a_new_trajectory_replaces_one_accepted_and_not_started_yet(executor, arm):  # noqa: F811
    """A goal sent right after another, before the simulation picked that one up (an idle
    loop lets 1 ms pass first), replaces it as it would a running one: it was refused as
    'the arm is busy' (test_moveit_ros's preemption failed so once in CI)."""
    follower = ArmTrajectories(arm)
    first, _ = follower.follow(validate(four_points(0.3, 2.0), ARM_JOINTS, follower.now()), "t")
    assert arm.device.current is None and arm.device.queue_length == 1      # not started
    back = RequestedTrajectory(list(ARM_JOINTS), [RequestedPoint(1.0, list(Q0), [0.0] * 7)])
    second, _ = follower.follow(validate(back, ARM_JOINTS, follower.now()), "u")
    assert second > first and arm.device.discard_reason(first) == PREEMPTED
    assert arm.device.queue_length == 1
    rest(executor, arm)
    assert np.max(np.abs(arm.feedback_joints - Q0)) < 0.01
    assert not arm.device.was_discarded(second)


def test_servo_off_refuses_a_trajectory(executor, arm):  # noqa: F811
    follower = ArmTrajectories(arm)
    arm.servo_off()
    with pytest.raises(Refused, match="servo is off"):
        follower.follow(validate(four_points(), ARM_JOINTS, follower.now()), "t")


# --- stamps and jogs -------------------------------------------------------------------------------
def test_a_stamp_in_the_future_holds_and_one_in_the_past_joins_the_rest():
    from acti_motion.trajectory.interpolation import State
    from acti_motion.trajectory.limits import follow_plan
    start = State(Q0, np.zeros(7), np.zeros(7))
    req = request((0.0, 0.0), (0.1, 1.0), (0.2, 2.0), velocities=True, start=10.0)
    valid = validate(req, ARM_JOINTS, now=9.0)
    ahead = follow_plan(valid, start, 9.5, ARM_JOINTS)        # starts in 0.5 s: hold till then
    assert [k.time for k in ahead.knots] == [0.0, 0.5, 1.5, 2.5] and ahead.points == [-1, -1, 1, 2]
    assert np.allclose(ahead.knots[1].positions, Q0)
    late = follow_plan(valid, start, 11.5, ARM_JOINTS)        # 1.5 s in: point 2 is left
    assert [k.time for k in late.knots] == [0.0, 0.5] and late.points == [-1, 2]


def test_a_jog_ramps_holds_and_stops_inside_the_soft_limit(executor, arm):  # noqa: F811
    from acti_motion.trajectory.interpolation import State
    from acti_motion.trajectory.jog import SOFT_LIMIT_MARGIN_RAD, jog_plan
    from acti_motion.trajectory.limits import check_limits
    limits = ArmTrajectories(arm).limits()
    start = State(Q0, np.zeros(7), np.zeros(7))
    v = np.zeros(7)
    v[0] = 0.5
    plan = jog_plan(v, 1.0, 0.3, limits)(start, 0.0)
    poly = check_limits(plan, limits)
    assert poly.duration == pytest.approx(1.6) and poly.state(0.8).velocities[0] == pytest.approx(0.5)
    assert poly.state(poly.duration).positions[0] == pytest.approx(Q0[0] + 0.5 * 1.3)
    v[0] = 100.0                                               # far too fast, toward the limit
    near = State(np.r_[limits.upper[0] - 0.05, Q0[1:]], np.zeros(7), np.zeros(7))
    poly = check_limits(jog_plan(v, 5.0, 0.3, limits)(near, 0.0), limits)
    end = poly.state(poly.duration).positions[0]
    assert limits.upper[0] - 0.01 < end <= limits.upper[0] - SOFT_LIMIT_MARGIN_RAD + 1e-9


def test_the_soft_limit_watch_stops_a_trajectory_with_an_alarm(executor, arm):  # noqa: F811
    """A joint soft limit narrowed while the trajectory is paused (ACT 5.4.8): on resume the
    watch stops it at the limit and raises alarm 0x4, as for any move."""
    follower = ArmTrajectories(arm)
    motion_id, _ = follower.follow(validate(four_points(0.3, 1.0), ARM_JOINTS, follower.now()), "t")
    run_until(executor, lambda: arm.device.t > 0.5, 5.0)
    assert arm.pause().ok
    run_until(executor, lambda: arm.device.rate == 0.0, 5.0)
    limits = arm.get_soft_limit_joint().values["soft_limit"]
    here = math.degrees(arm.device.current.motion.at(arm.device.t).joints[0])
    limits[0] = (here + 2.0, limits[0][1])                     # (upper, lower), degree
    assert arm.set_soft_limit_joint(limits).ok
    assert arm.resume().ok
    rest(executor, arm)
    assert [a.code for a in arm.alarms] == [0x4]
    assert arm.device.discard_reason(motion_id).startswith("alarm 0x4")
    assert math.degrees(arm.feedback_joints[0]) < here + 2.0 + 0.1
