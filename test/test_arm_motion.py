"""Arm motion in the real simulation, without ROS: composition of queued Rel moves, CP and PTP
accuracy, TOPP-RA near a singularity, pause / resume / stop, gripper order, soft-limit alarms."""
import math

import numpy as np
import pinocchio as pin
import pytest

from acti_motion.arm.core import ArmConfig, ArmCore
from acti_motion.arm.kinematics import wrap
from acti_motion.arm.poses import hg_to_pose, orientation_error_deg, position_error_mm, pose_to_hg
from acti_motion.replies import ReturnCode as R
from acti_motion.arm.trajectories import ConstAccelTiming, Trapezoid
from arm_fixtures import IDENTITY, WORK, arm, rest  # noqa: F401
from sim_fixtures import executor, run_until  # noqa: F401
from trajectory_check import ArmTrace

def rel(dx=0.0, dy=0.0, dz=0.0, rot=None, elbow=0.0):
    m = np.eye(4)
    if rot is not None:
        m[:3, :3] = pin.exp3(np.radians(rot))
    m[:3, 3] = [dx / 1000, dy / 1000, dz / 1000]
    return (pose_to_hg(m), elbow, 0)


def measured(arm, executor):  # noqa: F811
    return arm.tool_pose(executor.world.arm_positions())


def feedback(arm):
    hg, elbow, _ = arm.get_feedback_pos_cartesian().values["pos"]
    return hg_to_pose(hg, "pos"), elbow


# --- composition -----------------------------------------------------------------------------------
def test_queued_joint_rel_moves_compose(arm, executor):  # noqa: F811
    assert arm.move_ptp_joint_rel([5.0] * 7).ok and arm.move_ptp_joint_rel([7.0] * 7).ok
    rest(executor, arm)
    pos = arm.get_feedback_pos_joint().values["pos"][:7]
    assert np.max(np.abs(np.subtract(pos, np.add(WORK, 12.0)))) < 0.01


def test_queued_cartesian_rel_moves_compose_in_the_robot_frame(arm, executor):  # noqa: F811
    P0, elbow0 = feedback(arm)
    assert arm.move_linear_cartesian_rel(rel(dx=40.0, rot=[0, 0, 15.0])).ok
    assert arm.move_ptp_cartesian_rel(rel(dx=40.0, dy=-30.0, rot=[0, 0, 15.0])).ok
    want = np.eye(4)
    want[:3, :3] = pin.exp3(np.radians([0, 0, 30.0])) @ P0[:3, :3]   # R' = ΔR·R, twice
    want[:3, 3] = P0[:3, 3] + [0.08, -0.03, 0.0]                       # p' = p + Δp, twice
    end = arm.tool_pose(arm.device.queued_end.joints)
    assert position_error_mm(end, want) < 1e-6 and orientation_error_deg(end, want) < 1e-6
    rest(executor, arm)
    got, elbow = feedback(arm)
    assert position_error_mm(got, want) < 0.1 and orientation_error_deg(got, want) < 0.05
    assert elbow == pytest.approx(elbow0, abs=0.05)        # Rel with Δelbow 0 keeps the elbow


def test_move_to_where_it_already_is_finishes_at_once(arm, executor):  # noqa: F811
    P0, elbow0 = feedback(arm)
    for op in (arm.move_linear_cartesian_abs, arm.move_ptp_cartesian_abs):
        assert op((pose_to_hg(P0), elbow0, 0)).ok
        assert run_until(executor, lambda: not arm.device.busy, 1.0) < 0.02
    assert arm.move_ptp_joint_rel([0.0] * 7).ok and arm.move_linear_cartesian_rel(rel()).ok
    assert run_until(executor, lambda: not arm.device.busy, 1.0) < 0.02


# --- accuracy ------------------------------------------------------------------------------------------
def follow(arm, executor, check, max_seconds=15.0):  # noqa: F811
    """Run until idle, calling check(measured pose, commanded set-point) every step."""
    def step():
        cur = arm.device.current
        check(measured(arm, executor), cur.motion.at(arm.device.t) if cur else None)
        return not arm.device.busy
    return run_until(executor, step, max_seconds)


def test_linear_move_stays_on_the_line_and_ends_on_target(arm, executor):  # noqa: F811
    P0, elbow0 = feedback(arm)
    target = P0.copy()
    target[:3, 3] += [0.15, 0.20, -0.25]
    target[:3, :3] = pin.exp3(np.radians([20.0, -10.0, 30.0])) @ P0[:3, :3]
    assert arm.move_linear_cartesian_abs((pose_to_hg(target), 25.0, 0)).ok
    line = target[:3, 3] - P0[:3, 3]
    length, angle = np.linalg.norm(line), orientation_error_deg(P0, target)
    deviation, sync = [], []

    def check(P, setpoint):
        v = P[:3, 3] - P0[:3, 3]
        deviation.append(np.linalg.norm(v - np.dot(v, line) / length ** 2 * line) * 1000)
        if setpoint is not None:       # translation and rotation progress together
            C = arm.tool_pose(setpoint.joints)
            sync.append(np.linalg.norm(C[:3, 3] - P0[:3, 3]) / length
                        - orientation_error_deg(P0, C) / angle)
    follow(arm, executor, check)
    for _ in range(60):
        executor.step()
    got, elbow = feedback(arm)
    assert max(deviation) <= 0.5
    assert max(np.abs(sync)) < 1e-3
    assert position_error_mm(got, target) <= 0.1 and orientation_error_deg(got, target) <= 0.05
    assert elbow == pytest.approx(25.0, abs=0.05)


def test_ptp_cartesian_reaches_the_pose_and_the_elbow(arm, executor):  # noqa: F811
    P0, _ = feedback(arm)
    target = P0.copy()
    target[:3, 3] += [0.25, -0.15, -0.15]
    assert arm.move_ptp_cartesian_abs((pose_to_hg(target), -40.0, 0)).ok
    rest(executor, arm)
    got, elbow = feedback(arm)
    assert position_error_mm(got, target) <= 0.1 and orientation_error_deg(got, target) <= 0.05
    assert elbow == pytest.approx(-40.0, abs=0.05)


def test_circular_move_stays_on_the_circle(arm, executor):  # noqa: F811
    P0, _ = feedback(arm)
    p0 = P0[:3, 3]
    via, end = p0 + [0.1, 0.1, 0.0], p0 + [0.2, 0.0, 0.0]        # centre p0 + 0.1 x, r 100 mm
    assert arm.move_circular_cartesian_rel(rel(dx=100.0, dy=100.0), rel(dx=200.0)).ok
    centre, off_circle, near_via = p0 + [0.1, 0.0, 0.0], [], []

    def check(P, _):
        off_circle.append(abs(np.linalg.norm(P[:3, 3] - centre) - 0.1) * 1000
                          + abs(P[2, 3] - p0[2]) * 1000)
        near_via.append(np.linalg.norm(P[:3, 3] - via) * 1000)
    follow(arm, executor, check)
    for _ in range(60):
        executor.step()
    got, _ = feedback(arm)
    assert max(off_circle) <= 0.5 and min(near_via) <= 0.5
    assert np.linalg.norm(got[:3, 3] - end) * 1000 <= 0.1


def test_near_a_singularity_toppra_keeps_the_joint_limits_and_the_line(executor):  # noqa: F811
    arm = ArmCore(executor, ArmConfig(initial_joints_deg=(20, 40, 10, -70, 30, 25, 0)))
    arm.servo_on()
    arm.set_speed_cartesian(100)
    qb = np.radians([-20, 40, -10, -70, -30, -25, 8])             # the wrist passes J6 = 0
    target, P0 = arm.tool_pose(qb), arm.tool_pose(arm.device.hold.joints)
    r = arm.move_linear_cartesian_abs((pose_to_hg(target), math.degrees(arm.kin.arm_angle(qb)), 0))
    assert r.ok
    motion = arm.device.queue[0].motion
    assert isinstance(motion.timing, ConstAccelTiming)
    nominal = Trapezoid.for_axes(
        [np.linalg.norm(target[:3, 3] - P0[:3, 3]), orientation_error_deg(P0, target)],
        [0.5, 90.0], 0.3)
    assert motion.duration > nominal.duration            # slowed where the joints need it
    ts = np.linspace(0.0, motion.duration, 2000)
    qs = np.array([motion.at(t).joints for t in ts])
    qd = np.diff(qs, axis=0) / np.diff(ts)[:, None]
    assert np.max(np.abs(qd) / arm.kin.velocity) < 1.01
    qdd = np.diff(qd, axis=0) / np.diff(ts)[1:, None]
    assert np.max(np.abs(qdd) / (arm.kin.velocity / arm.min_accel_time_joint)) < 1.05
    line, deviation = target[:3, 3] - P0[:3, 3], []

    def check(P, _):
        v = P[:3, 3] - P0[:3, 3]
        deviation.append(np.linalg.norm(v - np.dot(v, line) / np.dot(line, line) * line) * 1000)
    follow(arm, executor, check)
    assert max(deviation) <= 0.5


# --- pause, resume, stop ------------------------------------------------------------------------------------
def speed(executor):  # noqa: F811
    return float(np.max(np.abs(executor.world.arm_velocities())))


def test_pause_decelerates_holds_keeps_the_queue_and_resume_finishes(arm, executor):  # noqa: F811
    trace = ArmTrace(executor, arm)
    goal = np.add(WORK, [30.0, -20.0, 20.0, 30.0, 20.0, 20.0, 40.0])
    assert arm.move_ptp_joint_abs(list(goal)).ok and arm.move_ptp_joint_rel([-5.0] * 7).ok
    run_until(executor, lambda: executor.world.time > 0.8, 2.0)
    cruising = speed(executor)
    assert arm.pause().ok and arm.pause().comment == "ignored: already paused"
    executor.step()
    assert speed(executor) > 0.5 * cruising                      # decelerates, no instant halt
    took = run_until(executor, lambda: not arm.state_word() & 0x02, 2.0)
    assert took <= arm.accel_time_joint + 0.02
    for _ in range(120):
        executor.step()
    assert speed(executor) < 1e-3
    assert arm.state_word() == 0x11 and arm.device.queue_length == 1
    assert arm.move_ptp_joint_rel([1.0] * 7).ok                  # queued while paused
    assert arm.resume().ok
    rest(executor, arm)
    pos = arm.get_feedback_pos_joint().values["pos"][:7]
    assert np.max(np.abs(np.subtract(pos, goal - 4.0))) < 0.01
    assert arm.device.completed == 3 and arm.state_word() == 0x01
    trace.check()
    trace.check_rest(np.radians(goal - 4.0))


@pytest.mark.parametrize("kind", ["ptp", "linear"])
def test_stop_decelerates_within_the_accel_time_and_flushes(arm, executor, kind):  # noqa: F811
    trace = ArmTrace(executor, arm)
    if kind == "ptp":
        assert arm.move_ptp_joint_rel([40.0, -20.0, 30.0, 20.0, 30.0, 20.0, 40.0]).ok
        ramp = arm.accel_time_joint
    else:
        assert arm.move_linear_cartesian_rel(rel(dx=300.0, dy=-100.0)).ok
        ramp = arm.accel_time_cartesian
    first = arm.device.last_id
    assert arm.move_ptp_joint_rel([5.0] * 7).ok and arm.move_ptp_joint_rel([5.0] * 7).ok
    run_until(executor, lambda: executor.world.time > 0.7, 2.0)
    assert speed(executor) > 0.1
    assert arm.stop().ok
    rest_at = arm.device.queued_end.joints.copy()
    assert arm.device.queue_length == 0 and arm.state_word() & 0x08 == 0
    took = run_until(executor, lambda: not arm.device.busy, 2.0)
    assert took <= ramp + 0.01
    assert all(arm.device.was_discarded(i) for i in range(first, first + 3))
    for _ in range(60):
        executor.step()
    trace.check_rest(rest_at)
    assert speed(executor) < 1e-2
    here = arm.get_feedback_pos_joint().values["pos"][:7]
    assert arm.move_ptp_joint_rel([2.0] * 7).ok                  # continues from the rest point
    rest(executor, arm)
    assert np.max(np.abs(np.subtract(arm.get_feedback_pos_joint().values["pos"][:7],
                                     np.add(here, 2.0)))) < 0.02
    trace.check()


def test_stop_while_paused_flushes_and_clears_the_pause(arm, executor):  # noqa: F811
    trace = ArmTrace(executor, arm)
    assert arm.move_ptp_joint_rel([20.0] * 7).ok and arm.move_ptp_joint_rel([5.0] * 7).ok
    run_until(executor, lambda: executor.world.time > 0.5, 2.0)
    assert arm.pause().ok
    run_until(executor, lambda: not arm.state_word() & 0x02, 2.0)
    held = trace.last.copy()
    assert arm.stop().ok
    assert arm.state_word() & 0x10 == 0 and arm.device.queue_length == 0
    assert run_until(executor, lambda: not arm.device.busy, 0.1) < 0.02
    assert arm.resume().comment == "ignored: the arm is not paused"
    assert arm.state_word() == 0x01
    for _ in range(10):
        executor.step()
    trace.check()
    trace.check_rest(held)                       # rests where the pause held it


def test_pause_while_stopping_is_ignored(arm, executor):  # noqa: F811
    trace = ArmTrace(executor, arm)
    assert arm.move_ptp_joint_rel([20.0] * 7).ok
    run_until(executor, lambda: executor.world.time > 0.5, 2.0)
    assert arm.stop().ok
    assert arm.pause().comment == "ignored: it is stopping"
    run_until(executor, lambda: not arm.state_word() & 0x02, 1.0)
    assert arm.state_word() == 0x01 and not arm.device.busy
    assert arm.move_ptp_joint_rel([1.0] * 7).ok
    assert run_until(executor, lambda: not arm.device.busy, 2.0) > 0.2
    trace.check()


# --- gripper -------------------------------------------------------------------------------------------------
def test_gripper_commands_queue_in_order_with_the_moves(arm, executor):  # noqa: F811
    assert arm.move_ptp_joint_rel([10.0] * 7).ok
    assert arm.open_gripper().ok
    assert arm.move_ptp_joint_rel([-10.0] * 7).ok
    labels = []

    def record():
        cur = arm.device.current
        labels.append((cur.label if cur else "", executor.world.gripper_position()))
        return not arm.device.busy
    run_until(executor, record, 10.0)
    order = [lab for i, (lab, _) in enumerate(labels) if lab and (i == 0 or labels[i - 1][0] != lab)]
    assert order == ["move_ptp_joint_rel", "open_gripper", "move_ptp_joint_rel"]
    during_first = [f for lab, f in labels[:20]]
    assert max(during_first) < 1e-3                               # still closed while moving
    rest(executor, arm, settle=120)
    assert arm.get_feedback_pos_joint().values["pos"][7] == pytest.approx(80.0, abs=0.5)
    assert arm.move_gripper(25).ok
    rest(executor, arm, settle=120)
    assert arm.get_feedback_pos_joint().values["pos"][7] == pytest.approx(20.0, abs=0.5)
    assert arm.close_gripper().ok
    rest(executor, arm, settle=120)
    assert arm.get_feedback_pos_joint().values["pos"][7] == pytest.approx(0.0, abs=0.5)


# --- soft limits watched while moving --------------------------------------------------------------------
def test_cartesian_soft_limit_crossed_while_moving_stops_with_alarm_5(arm, executor):  # noqa: F811
    trace = ArmTrace(executor, arm)
    P0, _ = feedback(arm)
    x0 = P0[0, 3] * 1000
    assert arm.move_linear_cartesian_rel(rel(dx=200.0)).ok and arm.move_ptp_joint_rel([1.0] * 7).ok
    run_until(executor, lambda: arm.device.current is not None, 0.1)
    assert arm.set_soft_limit_cartesian((x0 + 60.0, -1000.0), (1000.0, -1000.0),
                                        (1600.0, -100.0)).ok
    run_until(executor, lambda: arm.alarms, 5.0)
    assert [a.code for a in arm.alarms] == [0x5] and "x =" in arm.alarms[0].description
    assert arm.state_word() & 0x04 and arm.device.queue_length == 0
    took = run_until(executor, lambda: not arm.device.busy, 2.0)
    assert took <= arm.min_accel_time_cartesian + 0.01
    r = arm.move_ptp_joint_rel([1.0] * 7)
    assert r.code == R.STATUS_ERR
    assert arm.stop().comment == "ignored: an alarm is active"
    run_until(executor, lambda: not arm.state_word() & 0x02, 0.2)     # the joints settled
    assert arm.clear_alarms().ok and arm.state_word() == 0x01
    assert arm.move_linear_cartesian_rel(rel(dx=-50.0)).ok        # back inside: allowed
    rest(executor, arm)
    assert not arm.alarms
    trace.check()


def test_servo_off_during_a_soft_limit_stop_keeps_its_braking(arm, executor):  # noqa: F811
    """servo_off stops at the motion's accel time (1 s here); during the alarm's fastest stop
    that must not lengthen the braking (it ended 95.8 mm past the limit instead of 15.8)."""
    trace = ArmTrace(executor, arm)
    arm.set_speed_cartesian(100)
    assert arm.set_accel_time_cartesian(1.0).ok
    P0, _ = feedback(arm)
    x0 = P0[0, 3] * 1000
    assert arm.move_linear_cartesian_rel(rel(dx=250.0)).ok
    run_until(executor, lambda: arm.device.rate >= 1.0 and arm.device.t > 1.0, 5.0)
    x_now = arm.tool_pose(arm.device.current.motion.at(arm.device.t).joints)[0, 3] * 1000
    limit = x_now + 30.0
    assert arm.set_soft_limit_cartesian((limit, -1000.0), (1000.0, -1000.0), (1600.0, -100.0)).ok
    run_until(executor, lambda: arm.alarms, 5.0)
    executor.step()
    assert arm.device.stopping and arm.servo_off().ok
    run_until(executor, lambda: not arm.device.busy, 3.0)
    assert arm.tool_pose(arm.device.hold.joints)[0, 3] * 1000 <= limit + 1e-3
    trace.check()


def test_joint_soft_limit_narrowed_while_paused_raises_alarm_4_on_resume(arm, executor):  # noqa: F811
    trace = ArmTrace(executor, arm)
    assert arm.move_ptp_joint_rel([40.0, 0, 0, 0, 0, 0, 0]).ok
    run_until(executor, lambda: executor.world.time > 0.4, 2.0)
    assert arm.pause().ok
    run_until(executor, lambda: not arm.state_word() & 0x02, 2.0)
    j1 = arm.get_feedback_pos_joint().values["pos"][0]
    limits = arm.get_soft_limit_joint().values["soft_limit"]
    limits[0] = (j1 + 5.0, -170.0)
    assert arm.set_soft_limit_joint(limits).ok                    # paused is not moving
    assert arm.resume().ok
    run_until(executor, lambda: arm.alarms, 5.0)
    assert arm.alarms[0].code == 0x4 and "J1" in arm.alarms[0].description
    run_until(executor, lambda: not arm.device.busy, 1.0)
    assert arm.get_active_alarm().values["alarms"][0][:2] == (0x4, 1)
    # the watch looked ahead by the braking distance: the arm rests at the limit (was 0.876°
    # past it), commanded and measured
    assert abs(math.degrees(arm.device.hold.joints[0]) - (j1 + 5.0)) < 1e-3
    run_until(executor, lambda: not arm.state_word() & 0x02, 1.0)
    assert arm.get_feedback_pos_joint().values["pos"][0] <= j1 + 5.0 + 0.01
    trace.check()


def test_a_cartesian_soft_limit_set_while_moving_stops_the_arm_at_it(arm, executor):  # noqa: F811
    """The limit is 60 mm ahead of a 200 mm line at full speed: the stop begins a braking
    distance before it, and the control point rests on it (was: the stop began at the
    crossing and ended past it)."""
    trace = ArmTrace(executor, arm)
    arm.set_speed_cartesian(100)
    P0, _ = feedback(arm)
    x0 = P0[0, 3] * 1000
    assert arm.move_linear_cartesian_rel(rel(dx=200.0)).ok
    run_until(executor, lambda: arm.device.current is not None, 0.1)
    assert arm.set_soft_limit_cartesian((x0 + 60.0, -1000.0), (1000.0, -1000.0),
                                        (1600.0, -100.0)).ok
    run_until(executor, lambda: arm.alarms, 5.0)
    assert arm.alarms[0].code == 0x5 and "x =" in arm.alarms[0].description
    run_until(executor, lambda: not arm.device.busy, 2.0)
    rest_x = arm.tool_pose(arm.device.hold.joints)[0, 3] * 1000
    assert x0 + 59.9 <= rest_x <= x0 + 60.0 + 1e-3
    run_until(executor, lambda: not arm.state_word() & 0x02, 1.0)
    assert feedback(arm)[0][0, 3] * 1000 <= x0 + 60.0 + 0.1
    trace.check()


def test_elbow_turns_without_moving_the_control_point(arm, executor):  # noqa: F811
    P0, elbow0 = feedback(arm)
    worst = []
    assert arm.move_linear_cartesian_rel(rel(elbow=60.0)).ok
    follow(arm, executor, lambda P, _: worst.append(position_error_mm(P, P0)))
    for _ in range(60):
        executor.step()
    got, elbow = feedback(arm)
    assert max(worst) <= 0.5 and orientation_error_deg(got, P0) <= 0.05
    assert abs(wrap(math.radians(elbow - elbow0 - 60.0))) < math.radians(0.05)


def test_offsets_apply_to_cp_targets_and_feedback(arm, executor):  # noqa: F811
    base = np.eye(4)                               # robot frame: 100 mm ahead, turned 90° about z
    base[:3, :3] = pin.exp3(np.radians([0.0, 0.0, 90.0]))
    base[:3, 3] = [0.1, 0.0, 0.0]
    tool = np.eye(4)                               # control point 120 mm out, tilted 20° about x
    tool[:3, :3] = pin.exp3(np.radians([20.0, 0.0, 0.0]))
    tool[:3, 3] = [0.0, 0.0, 0.12]
    assert arm.set_base_offset(pose_to_hg(base)).ok
    assert arm.set_control_point_offset(pose_to_hg(tool)).ok
    P0, elbow0 = feedback(arm)
    flange = arm.kin.flange(executor.world.arm_positions())
    want0 = np.linalg.inv(base) @ flange @ tool
    assert position_error_mm(P0, want0) < 1e-6 and orientation_error_deg(P0, want0) < 1e-6
    target = P0.copy()
    target[:3, 3] += [-0.1, 0.2, -0.1]             # robot-frame axes
    target[:3, :3] = pin.exp3(np.radians([0.0, 25.0, 0.0])) @ P0[:3, :3]
    assert arm.move_linear_cartesian_abs((pose_to_hg(target), elbow0, 0)).ok
    line, deviation = target[:3, 3] - P0[:3, 3], []

    def check(P, _):
        v = P[:3, 3] - P0[:3, 3]
        deviation.append(np.linalg.norm(v - np.dot(v, line) / np.dot(line, line) * line) * 1000)
    follow(arm, executor, check)
    for _ in range(60):
        executor.step()
    got, _ = feedback(arm)
    assert max(deviation) <= 0.5
    assert position_error_mm(got, target) <= 0.1 and orientation_error_deg(got, target) <= 0.05


@pytest.mark.parametrize("limit", ["joint", "cartesian"])
def test_a_move_queued_before_a_limit_changed_stops_where_it_is_outside_it(arm, executor, limit):  # noqa: F811
    """5.4.8 範囲を超える場合は停止してアラーム: a move accepted before the limit was set, and
    starting outside it, ran to its end with no alarm (only crossings were watched)."""
    P0, _ = feedback(arm)
    assert arm.move_linear_cartesian_rel(rel(dx=200.0)).ok        # accepted, not yet started
    assert arm.pause().ok                                         # … and held: not moving
    if limit == "joint":
        j1 = arm.get_feedback_pos_joint().values["pos"][0]
        limits = arm.get_soft_limit_joint().values["soft_limit"]
        limits[0] = (170.0, j1 + 0.5)                             # J1 already below its lower
        assert arm.set_soft_limit_joint(limits).ok                # paused is not moving
    else:
        x0 = P0[0, 3] * 1000.0
        assert arm.set_soft_limit_cartesian((x0 - 50.0, -1000.0), (1000.0, -1000.0),
                                            (1600.0, -100.0)).ok
    assert arm.resume().ok
    run_until(executor, lambda: arm.alarms, 1.0)
    assert [a.code for a in arm.alarms] == [0x4 if limit == "joint" else 0x5]
    run_until(executor, lambda: not arm.device.busy, 2.0)
    P1, _ = feedback(arm)
    assert np.linalg.norm(P1[:3, 3] - P0[:3, 3]) * 1000.0 < 20.0  # stopped at once, not 200 mm on


def test_setting_limits_again_does_not_stop_a_move_back_inside(arm, executor):  # noqa: F811
    """A move back inside a limit may run; re-sending the same limits, or changing another
    axis's, while it runs stopped it with the alarm (every setting counted as a change)."""
    P0, _ = feedback(arm)
    z0 = P0[2, 3] * 1000.0
    box = ((1000.0, -1000.0), (1000.0, -1000.0), (z0 - 40.0, -100.0))
    assert arm.set_soft_limit_cartesian(*box).ok                   # the arm 40 mm above it
    assert arm.move_linear_cartesian_rel(rel(dz=-80.0)).ok         # back inside: allowed
    run_until(executor, lambda: arm.device.current is not None, 0.1)
    assert arm.set_soft_limit_cartesian(*box).ok                   # the same again
    wider_x = ((1100.0, -1000.0),) + box[1:]
    assert arm.set_soft_limit_cartesian(*wider_x).ok               # another axis's
    run_until(executor, lambda: not arm.device.busy, 5.0)
    assert not arm.alarms, arm.alarms
