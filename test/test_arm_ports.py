"""Every operation of the common and middle-level ports on ArmCore, without ROS: the ids each may
answer (exactly the spec's), normal cases, and bad inputs → the right id with the queue intact."""
import math

import numpy as np
import pytest

from acti_middle_node.operations import COMMON_PORT, EXTENSIONS, MIDDLE_PORT, OPERATIONS
from acti_motion.arm.core import ArmConfig, ArmCore
from acti_motion.replies import ReturnCode as R
from sim_fixtures import executor, run_until  # noqa: F401

START = list(ArmConfig().initial_joints_deg)
IDENTITY = [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]
START_HG = [0.8660254037844388, 0.0, 0.5, 163.0, 0.0, 1.0, 0.0, 0.0,
            -0.5, 0.0, 0.8660254037844388, 1341.9395239043904]
NAN, INF = math.nan, math.inf

MOVE = {R.OK, R.STATUS_ERR, R.VALUE_ERR, R.FULL_MOTION_QUEUE_ERR, R.NOT_SV_ON_ERR, R.NG}
SETTER = {R.OK, R.VALUE_ERR, R.NG}
OK_NG = {R.OK, R.NG}
# Chapter 5's return-value table of every operation, and the common port's.
SPEC_RETURNS = {
    "close_gripper": {R.OK, R.STATUS_ERR, R.FULL_MOTION_QUEUE_ERR, R.NOT_SV_ON_ERR, R.NG},
    "open_gripper": MOVE,
    "move_gripper": {R.OK, R.STATUS_ERR, R.VALUE_ERR, R.NOT_SV_ON_ERR, R.NG},
    **{f"move_{k}": MOVE for k in ("linear_cartesian_abs", "linear_cartesian_rel",
                                   "ptp_cartesian_abs", "ptp_cartesian_rel", "ptp_joint_abs",
                                   "ptp_joint_rel", "circular_cartesian_abs",
                                   "circular_cartesian_rel")},
    "go_home": MOVE,
    **{f"get_{k}": OK_NG for k in ("base_offset", "feedback_pos_cartesian", "max_speed_cartesian",
                                   "max_speed_joint", "min_accel_time_cartesian",
                                   "min_accel_time_joint", "soft_limit_cartesian", "home",
                                   "active_alarm", "feedback_pos_joint", "manip_info",
                                   "soft_limit_joint", "state")},
    "pause": OK_NG, "resume": OK_NG, "stop": OK_NG, "clear_alarms": OK_NG, "servo_off": OK_NG,
    "servo_on": {R.OK, R.STATUS_ERR, R.NG},
    **{f"set_{k}": SETTER for k in ("accel_time_cartesian", "accel_time_joint", "base_offset",
                                    "max_speed_cartesian", "max_speed_joint",
                                    "min_accel_time_cartesian", "min_accel_time_joint",
                                    "soft_limit_cartesian", "speed_cartesian", "speed_joint",
                                    "home")},
    "set_control_point_offset": {R.OK, R.STATUS_ERR, R.NG},
    "set_soft_limit_joint": {R.OK, R.STATUS_ERR, R.VALUE_ERR, R.NG},
}


@pytest.fixture
def arm(executor):  # noqa: F811
    return ArmCore(executor, ArmConfig(queue_size=3))


def ready(arm):
    for r in (arm.servo_on(), arm.set_speed_joint(50), arm.set_speed_cartesian(50)):
        assert r.ok


def car(hg=START_HG, elbow=0.0, flag=0):
    return (list(hg), elbow, flag)


def moved(hg, dx=0.0, dy=0.0, dz=0.0):
    out = list(hg)
    out[3] += dx
    out[7] += dy
    out[11] += dz
    return out


def rel(dx=0.0, dy=0.0, dz=0.0, elbow=0.0):
    return car(moved(IDENTITY, dx, dy, dz), elbow)


def test_the_ports_have_9_and_30_operations_and_5_extensions():
    assert (len(COMMON_PORT), len(MIDDLE_PORT), len(EXTENSIONS)) == (9, 30, 5)


@pytest.mark.parametrize("op", [op.name for op in OPERATIONS])
def test_each_operation_answers_exactly_the_ids_the_spec_lists(arm, op):
    assert getattr(arm, op).return_codes == SPEC_RETURNS[op]


# --- getters -------------------------------------------------------------------------------------
def test_getters_at_start(arm):
    info = arm.get_manip_info().values["manip_info"]
    assert info[2:] == (7, 4, True) and info[0]       # 250 Hz: exactly 4 ms
    assert arm.get_active_alarm().values == {"alarms": []}
    limits = arm.get_soft_limit_joint().values["soft_limit"]
    assert len(limits) == 7 and all(u > lo for u, lo in limits)
    assert limits[0] == pytest.approx((170.0, -170.0), abs=1e-3)
    assert arm.get_soft_limit_cartesian().values == {
        "x_limit": (1200.0, -1000.0), "y_limit": (1000.0, -1000.0), "z_limit": (1600.0, -100.0)}
    assert arm.get_base_offset().values["offset"] == IDENTITY
    assert arm.get_max_speed_joint().values["speed"][0] == pytest.approx(85.0, abs=0.01)
    assert arm.get_max_speed_cartesian().values["speed"] == (500.0, 90.0)
    assert arm.get_min_accel_time_joint().values["acl_time"] == 0.1
    assert arm.get_min_accel_time_cartesian().values["acl_time"] == 0.1
    assert arm.get_home().values["joint_point"] == START
    hg, elbow, flag = arm.get_feedback_pos_cartesian().values["pos"]
    assert np.allclose(hg, START_HG, atol=1e-6) and elbow == pytest.approx(0.0, abs=1e-6)
    assert flag == 0
    assert arm.get_state().values["state"] == 0


# --- settings ---------------------------------------------------------------------------------------
@pytest.mark.parametrize("setter", ["set_speed_joint", "set_speed_cartesian"])
@pytest.mark.parametrize("ratio, code", [(0, R.OK), (100, R.OK), (101, R.VALUE_ERR),
                                         (4294967295, R.VALUE_ERR)])
def test_speed_ratios(arm, setter, ratio, code):
    r = getattr(arm, setter)(ratio)
    assert r.code == code and (code == R.OK or "100" in r.comment)


@pytest.mark.parametrize("kind", ["joint", "cartesian"])
def test_accel_times_and_their_minimums(arm, kind):
    set_acc = getattr(arm, f"set_accel_time_{kind}")
    set_min = getattr(arm, f"set_min_accel_time_{kind}")
    for bad in (0.05, NAN, INF, -1.0):
        r = set_acc(bad)
        assert r.code == R.VALUE_ERR and r.comment
    assert set_acc(0.1).ok and set_acc(2.0).ok
    for bad in (0.0, -0.2, NAN, INF, 0.001):
        assert set_min(bad).code == R.VALUE_ERR
    r = set_min(0.5)
    assert r.ok and getattr(arm, f"get_min_accel_time_{kind}")().values["acl_time"] == 0.5
    r = set_min(3.0)
    assert r.ok and "now 3 s" in r.comment
    assert getattr(arm, f"accel_time_{kind}") == 3.0          # raised to the new minimum
    assert set_acc(2.9).code == R.VALUE_ERR


@pytest.mark.parametrize("speed, words", [
    ([80.0] * 6, "7 values"), ([80.0] * 8, "7 values"), ([NAN] + [80.0] * 6, "finite"),
    ([0.0] + [80.0] * 6, "at least"), ([-5.0] + [80.0] * 6, "at least"),
    ([200.0] + [80.0] * 6, "rated"), ([5e-324] * 7, "at least 0.1"), ([1e308] * 7, "rated"),
    ([INF] * 7, "finite"),
])
def test_max_speed_joint_refusals(arm, speed, words):
    r = arm.set_max_speed_joint(speed)
    assert r.code == R.VALUE_ERR and words in r.comment


def test_max_speeds_round_trip(arm):
    assert arm.set_max_speed_joint([40.0] * 7).ok
    assert arm.get_max_speed_joint().values["speed"] == [40.0] * 7
    rated = list(arm.hard_max_speed_joint)               # J6, J7: 134.9997°/s (2.35619 rad/s)
    assert arm.set_max_speed_joint([round(x, 3) for x in rated]).ok   # as shown: the rating
    assert arm.get_max_speed_joint().values["speed"] == pytest.approx(
        [min(round(x, 3), x) for x in rated], abs=1e-9)            # never above the rating
    assert arm.set_max_speed_joint(rated[:5] + [135.01, 135.0]).code == R.VALUE_ERR
    assert arm.set_max_speed_cartesian((250.0, 45.0)).ok
    assert arm.get_max_speed_cartesian().values["speed"] == (250.0, 45.0)
    for bad in ((NAN, 45.0), (250.0, INF), (0.0, 45.0), (250.0, -1.0)):
        assert arm.set_max_speed_cartesian(bad).code == R.VALUE_ERR
    assert arm.get_max_speed_cartesian().values["speed"] == (250.0, 45.0)


def test_soft_limit_cartesian(arm):
    assert arm.set_soft_limit_cartesian((500.0, -500.0), (400.0, -400.0), (1500.0, 0.0)).ok
    assert arm.get_soft_limit_cartesian().values["z_limit"] == (1500.0, 0.0)
    for bad in [((-500.0, 500.0), (1, 0), (1, 0)), ((NAN, 0.0), (1, 0), (1, 0)),
                ((1, 0), (1, 0), (INF, 0.0))]:
        r = arm.set_soft_limit_cartesian(*bad)
        assert r.code == R.VALUE_ERR and r.comment
    assert arm.get_soft_limit_cartesian().values["x_limit"] == (500.0, -500.0)


@pytest.mark.parametrize("limits, words", [
    ([(90.0, -90.0)] * 6, "7 limits"), ([(90.0, -90.0)] * 8, "7 limits"),
    ([(-90.0, 90.0)] + [(90.0, -90.0)] * 6, "above lower"),
    ([(NAN, -90.0)] + [(90.0, -90.0)] * 6, "finite"),
    ([(90.0, -90.0)] * 6 + [(180.0, -90.0)], "hardware"),
])
def test_soft_limit_joint_refusals(arm, limits, words):
    r = arm.set_soft_limit_joint(limits)
    assert r.code == R.VALUE_ERR and words in r.comment
    assert arm.get_soft_limit_joint().values["soft_limit"][0][0] == pytest.approx(170.0, abs=1e-3)


def test_a_joint_soft_limit_may_pin_a_joint(arm):
    """setSoftLimitJoint (common port) is VALUE_ERR for upper < lower, not for upper = lower:
    a joint held at one value (J7 at 0°) was refused with "upper must be above lower"."""
    ready(arm)
    limits = [(90.0, -90.0)] * 6 + [(0.0, 0.0)]
    assert arm.set_soft_limit_joint(limits).ok
    assert arm.get_soft_limit_joint().values["soft_limit"][6] == (0.0, 0.0)
    assert arm.move_ptp_joint_rel([5.0] + [0.0] * 6).ok
    r = arm.move_ptp_joint_rel([0.0] * 6 + [0.5])
    assert r.code == R.VALUE_ERR and "J7" in r.comment, r.comment


def test_soft_limit_joint_round_trip_and_check(arm):
    limits = [(90.0, -90.0)] * 7
    assert arm.set_soft_limit_joint(limits).ok
    assert arm.get_soft_limit_joint().values["soft_limit"] == limits
    ready(arm)
    r = arm.move_ptp_joint_abs([95.0, 30.0, 0.0, -60.0, 0.0, 60.0, 0.0])
    assert r.code == R.VALUE_ERR and "J1" in r.comment


@pytest.mark.parametrize("offset, words", [
    (IDENTITY[:11], "12 values"), ([NAN] + IDENTITY[1:], "finite"),
    ([2.0] + IDENTITY[1:], "rotation"), ([-1.0] + IDENTITY[1:5] + [1.0] + IDENTITY[6:], "rotation"),
])
def test_offsets_refuse_non_transforms(arm, offset, words):
    r = arm.set_base_offset(offset)
    assert r.code == R.VALUE_ERR and words in r.comment
    r = arm.set_control_point_offset(offset)         # the spec lists no VALUE_ERR here
    assert r.code == R.NG and words in r.comment
    assert arm.get_base_offset().values["offset"] == IDENTITY


def test_base_offset_moves_the_robot_frame(arm):
    # the robot frame is 100 mm ahead of the arm frame and turned 90° about z
    offset = [0.0, -1.0, 0.0, 100.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]
    before = arm.get_feedback_pos_cartesian().values["pos"][0]    # same joint sample as below
    assert arm.set_base_offset(offset).ok
    assert arm.get_base_offset().values["offset"] == offset
    hg = arm.get_feedback_pos_cartesian().values["pos"][0]
    # arm-frame (163, 0) is robot-frame R⁻¹(p − t) = (0, -63)
    assert (hg[3], hg[7], hg[11]) == pytest.approx((0.0, -63.0, 1341.9395), abs=1e-3)
    assert (before[3], before[7]) == pytest.approx((163.0, 0.0), abs=1e-3)


def test_get_base_offset_answers_the_offset_as_it_was_set(arm):
    """5.4.2/5.4.22: getBaseOffset gets the offset setBaseOffset set. A translation of
    -1023.3 mm came back as -1023.2999999999998 (mm → m → mm), and an exact rotation
    (cos 45° = 0.7071067811865476) as 0.7071067811865475; a rounded rotation comes back as the
    rotation in force."""
    c = math.sqrt(0.5)
    offset = [c, -c, 0.0, -1023.3, c, c, 0.0, 0.7, 0.0, 0.0, 1.0, 1500.9]
    assert arm.set_base_offset(offset).ok
    assert arm.get_base_offset().values["offset"] == offset
    rounded = [0.7071, -0.7071, 0.0, 10.0, 0.7071, 0.7071, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0]
    assert arm.set_base_offset(rounded).ok
    got = arm.get_base_offset().values["offset"]
    assert got[0] == pytest.approx(c, abs=1e-12) and got[3::4] == [10.0, 0.0, 0.0]


def test_control_point_offset_moves_the_control_point(arm):
    tool = moved(IDENTITY, dz=100.0)
    assert arm.set_control_point_offset(tool).ok
    hg = arm.get_feedback_pos_cartesian().values["pos"][0]
    # the flange z axis is (0.5, 0, 0.866): 100 mm along it
    assert (hg[3], hg[11]) == pytest.approx((213.0, 1341.9395 + 86.6025), abs=1e-3)


def test_home(arm, executor):  # noqa: F811
    for bad in ([0.0] * 6, [NAN] * 7, [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 200.0]):
        assert arm.set_home(bad).code == R.VALUE_ERR
    home = [10.0, 20.0, 0.0, -50.0, 0.0, 40.0, 0.0]
    assert arm.set_home(home).ok and arm.get_home().values["joint_point"] == home
    assert arm.go_home().code == R.NOT_SV_ON_ERR
    ready(arm)
    assert arm.go_home().ok
    run_until(executor, lambda: not arm.device.busy, 10.0)
    assert np.allclose(np.degrees(arm.device.hold.joints), home)


# --- moves: refusals ------------------------------------------------------------------------------
MOVES = {
    "move_ptp_joint_abs": dict(joint_points=START),
    "move_ptp_joint_rel": dict(joint_points=[1.0] * 7),
    "move_ptp_cartesian_abs": dict(car_point=car(moved(START_HG, dx=50.0))),
    "move_ptp_cartesian_rel": dict(car_point=rel(dx=20.0)),
    "move_linear_cartesian_abs": dict(car_point=car(moved(START_HG, dx=50.0))),
    "move_linear_cartesian_rel": dict(car_point=rel(dz=-20.0)),
    "move_circular_cartesian_abs": dict(car_point_r=car(moved(START_HG, dx=50.0, dz=-50.0)),
                                        car_point_t=car(moved(START_HG, dz=-100.0))),
    "move_circular_cartesian_rel": dict(car_point_r=rel(dx=50.0, dz=-50.0),
                                        car_point_t=rel(dz=-100.0)),
    "go_home": {},
}
GRIPPER = {"open_gripper": {}, "close_gripper": {}, "move_gripper": dict(angle_ratio=50)}


@pytest.mark.parametrize("op", [*MOVES, *GRIPPER])
def test_servo_off_refuses_every_motion(arm, op):
    r = getattr(arm, op)(**{**MOVES, **GRIPPER}[op])
    assert r.code == R.NOT_SV_ON_ERR and "servo_on" in r.comment


@pytest.mark.parametrize("op", list(MOVES))
def test_every_move_accepted_when_ready(arm, op):
    ready(arm)
    r = getattr(arm, op)(**MOVES[op])
    assert r.ok, r.comment
    assert r.values["motion_id"] == 1


@pytest.mark.parametrize("op", list(MOVES))
def test_zero_speed_ratio_refuses_with_status_err(arm, op):
    arm.servo_on()
    r = getattr(arm, op)(**MOVES[op])
    setter = "set_speed_cartesian" if "linear" in op or "circular" in op else "set_speed_joint"
    assert r.code == R.STATUS_ERR and setter in r.comment


@pytest.mark.parametrize("op", [*MOVES, *GRIPPER])
def test_alarm_refuses_every_motion_until_cleared(arm, op):
    ready(arm)
    arm._alarms.append(arm_alarm())
    assert arm.get_state().values["state"] == 0x05
    r = getattr(arm, op)(**{**MOVES, **GRIPPER}[op])
    assert r.code == R.STATUS_ERR and "clear_alarms" in r.comment
    assert arm.get_active_alarm().values["alarms"] == [(0x5, 1, "test")]
    assert arm.clear_alarms().ok and arm.get_state().values["state"] == 0x01
    assert getattr(arm, op)(**{**MOVES, **GRIPPER}[op]).ok


def test_move_gripper_answers_its_state_error_before_its_argument(arm):
    """5.4.9 lists NOT_SV_ON_ERR, STATUS_ERR and VALUE_ERR; the arm answers a motion command's
    state error first (README: servo off, an alarm), as every move and the other gripper
    commands do: moveGripper(101) with the servo off or an alarm active was VALUE_ERR."""
    r = arm.move_gripper(101)
    assert r.code == R.NOT_SV_ON_ERR and "servo_on" in r.comment, r
    ready(arm)
    arm._alarms.append(arm_alarm())
    r = arm.move_gripper(101)
    assert r.code == R.STATUS_ERR and "clear_alarms" in r.comment, r
    assert arm.clear_alarms().ok and arm.move_gripper(101).code == R.VALUE_ERR


def arm_alarm():
    from acti_motion.arm.core import Alarm, AlarmType
    return Alarm(0x5, AlarmType.WARNING, "test")


@pytest.mark.parametrize("op, kwargs, words", [
    ("move_ptp_joint_abs", dict(joint_points=[1.0] * 6), "7 values"),
    ("move_ptp_joint_abs", dict(joint_points=[1.0] * 8), "7 values"),
    ("move_ptp_joint_abs", dict(joint_points=[0, 0, NAN, 0, 0, 0, 0]), "finite"),
    ("move_ptp_joint_rel", dict(joint_points=[0, INF, 0, 0, 0, 0, 0]), "finite"),
    ("move_ptp_joint_rel", dict(joint_points=[0, 0, 0, 0, 0, 0, 200.0]), "soft limit"),
    ("move_ptp_cartesian_abs", dict(car_point=car(moved(START_HG, dx=2000.0))), "soft limit"),
    ("move_ptp_cartesian_abs", dict(car_point=car(moved(START_HG, dx=900.0, dz=-500))), "reach"),
    ("move_ptp_cartesian_abs", dict(car_point=car([NAN] + START_HG[1:])), "finite"),
    ("move_ptp_cartesian_abs", dict(car_point=car(START_HG, elbow=INF)), "elbow"),
    ("move_ptp_cartesian_abs", dict(car_point=car(START_HG[:11])), "12 values"),
    ("move_ptp_cartesian_rel", dict(car_point=car([1.1] + IDENTITY[1:])), "rotation"),
    ("move_linear_cartesian_abs", dict(car_point=car(moved(START_HG, dx=900.0, dz=-500))),
     "reach"),
    ("move_linear_cartesian_abs", dict(car_point=car(moved(START_HG, dz=-1500.0))), "soft limit"),
    ("move_linear_cartesian_rel", dict(car_point=rel(dx=NAN)), "finite"),
    ("move_linear_cartesian_rel", dict(car_point=rel(dz=-1500.0)), "soft limit"),
    ("move_circular_cartesian_abs", dict(car_point_r=car(moved(START_HG, dx=50.0)),
                                         car_point_t=car(moved(START_HG, dx=50.0))), "one line"),
    ("move_circular_cartesian_rel", dict(car_point_r=rel(), car_point_t=rel(dz=-50.0)),
     "one line"),
    ("move_circular_cartesian_rel", dict(car_point_r=rel(dx=NAN), car_point_t=rel(dz=-50.0)),
     "finite"),
    ("move_gripper", dict(angle_ratio=101), "100"),
])
def test_bad_move_inputs_get_value_err_and_keep_the_queue(arm, op, kwargs, words):
    ready(arm)
    assert arm.move_ptp_joint_rel([1.0] * 7).ok
    r = getattr(arm, op)(**kwargs)
    assert r.code == R.VALUE_ERR and words in r.comment, r.comment
    assert arm.device.queue_length == 1 and arm.device.last_id == 1


@pytest.mark.parametrize("op, code", [("move_ptp_joint_rel", R.FULL_MOTION_QUEUE_ERR),
                                      ("move_linear_cartesian_rel", R.FULL_MOTION_QUEUE_ERR),
                                      ("open_gripper", R.FULL_MOTION_QUEUE_ERR),
                                      ("close_gripper", R.FULL_MOTION_QUEUE_ERR),
                                      ("move_gripper", R.STATUS_ERR)])
def test_full_queue_refuses_and_keeps_what_is_queued(arm, op, code):
    ready(arm)
    for _ in range(3):
        assert arm.move_ptp_joint_rel([1.0] * 7).ok
    assert arm.get_state().values["state"] & 0x08
    r = getattr(arm, op)(**{**MOVES, **GRIPPER}[op])
    assert r.code == code and "full" in r.comment
    assert [m.id for m in arm.device.queue] == [1, 2, 3]


# --- control: the spec's "ignored" cases ------------------------------------------------------------
def test_pause_resume_stop_ignored_when_the_spec_says(arm):
    for op in ("pause", "stop"):
        r = getattr(arm, op)()
        assert r.ok and "ignored: servo is off" in r.comment
    ready(arm)
    r = arm.pause()
    assert r.ok and "not moving" in r.comment and not arm.device.paused
    r = arm.resume()
    assert r.ok and "not paused" in r.comment
    arm._alarms.append(arm_alarm())
    assert "alarm" in arm.pause().comment and "alarm" in arm.stop().comment
    assert arm.get_state().values["state"] == 0x05


def test_settings_refused_while_moving(arm, executor):  # noqa: F811
    ready(arm)
    assert arm.move_ptp_joint_rel([10.0] * 7).ok
    executor.step()
    r = arm.set_soft_limit_joint([(90.0, -90.0)] * 7)
    assert r.code == R.STATUS_ERR and "moves" in r.comment
    r = arm.set_control_point_offset(IDENTITY)
    assert r.code == R.STATUS_ERR
    r = arm.set_base_offset(IDENTITY)                 # the spec lists no STATUS_ERR for it: NG
    assert r.code == R.NG and "queued" in r.comment


@pytest.mark.parametrize("field, value", [
    ("queue_size", 0), ("initial_speed_ratio", 101), ("accel_time_joint", 0.0),
    ("max_speed_translation", NAN), ("soft_limit_cartesian", (1.0, 0.0, 0, 1, 0, 1)),
    ("soft_limit_cartesian", (0.0, 1.0)), ("initial_joints_deg", (0.0,) * 6),
    ("home_joints_deg", (0.0, 200.0, 0, 0, 0, 0, 0)),
])
def test_bad_start_settings_are_refused_at_start(executor, field, value):  # noqa: F811
    with pytest.raises(ValueError, match=field):
        ArmCore(executor, ArmConfig(**{field: value}))


def test_ptp_path_that_leaves_the_cartesian_box_is_refused(arm):
    ready(arm)
    assert arm.set_soft_limit_cartesian((1200.0, -1000.0), (1000.0, -1000.0), (1400.0, -100.0)).ok
    mirror = [0.0, -30.0, 0.0, 60.0, 0.0, -60.0, 0.0]      # same height, but straight up between
    r = arm.move_ptp_joint_abs(mirror)
    assert r.code == R.VALUE_ERR and "the path leaves the Cartesian soft limit: z" in r.comment
    assert arm.set_soft_limit_cartesian((1200.0, -1000.0), (1000.0, -1000.0), (1500.0, -100.0)).ok
    assert arm.move_ptp_joint_abs(mirror).ok


def test_feedback_pose_is_kept_at_rest_and_follows_a_move(arm, executor):  # noqa: F811
    """At rest the sensed joints drift by ~1e-10 rad a step: the pose is not computed again
    (same object); a move gives a new pose every sample."""
    ready(arm)
    for _ in range(500):                # settled after servo on
        executor.step()
    rest = arm.get_feedback_pos_cartesian().values["pos"]
    for _ in range(20):
        executor.step()
        assert arm.get_feedback_pos_cartesian().values["pos"] is rest
    assert arm.move_ptp_joint_rel([5.0] + [0.0] * 6).ok
    poses = []
    for _ in range(20):
        executor.step()
        poses.append(arm.get_feedback_pos_cartesian().values["pos"][0])
    assert all(a != b for a, b in zip(poses, poses[1:]))
    assert poses[-1][7] != pytest.approx(rest[0][7], abs=1e-3)      # y: J1 turned


def test_a_refusal_shows_the_value_as_given_not_rounded_into_the_limit(arm):
    """J1 = 170.0001 read "J1 = 170° is outside the soft limit [-170, 170]°"."""
    ready(arm)
    hi = float(arm.soft_limit_joint[0, 1])
    r = arm.move_ptp_joint_abs([hi + 1e-4, 30.0, 0.0, -60.0, 0.0, 60.0, 0.0])
    assert r.code == R.VALUE_ERR and f"J1 = {hi + 1e-4:.10g}°" in r.comment, r.comment
