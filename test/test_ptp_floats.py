"""A PTP accept's plain-float arithmetic gives what the numpy formulas it replaced gave, exactly:
the request's check, degrees and radians, the goal, the joint line's control-point positions
(a few posture by posture, more at once; with and without offsets) and the queued motion."""
import math

import numpy as np
import pinocchio as pin
import pytest

from acti_motion.arm.core import shared_kinematics
from acti_motion.arm.kinematics import FEW_POSTURES
from acti_motion.arm.planning import _line_positions_mm
from acti_motion.arm.poses import Frames
from acti_motion.profiles import Trapezoid
from acti_motion.replies import Refused, finite_floats
from arm_fixtures import WORK, arm  # noqa: F401
from sim_fixtures import executor  # noqa: F401

STEPS = [[0.5] * 7, [-0.5] * 7, [-60.0] + [0.0] * 6, [30.0] * 7, [0.0] * 7,
         [1e-9, -3.3, 7.123456789, 0.1, -0.1, 45.0, -12.5], [5.0, -60.0, 0.0, 40.0, 0.0, 10.0, 0.0]]
STARTS = [WORK, (0.0,) * 7, (20.0, 40.0, 10.0, -70.0, 30.0, 25.0, 0.0),
          (-93.0, -1.0, 21.0, 7.0, 76.0, 36.0, 27.0)]


def finite_vector_before(values, length, name):
    """finite_vector as it was before the plain-float check (numpy all the way)."""
    v = np.asarray(values if isinstance(values, list) else list(values), dtype=float).reshape(-1)
    if len(v) != length:
        raise Refused(3, f"{name} needs {length} values, got {len(v)}")
    floats = v.tolist()
    if not all(map(math.isfinite, floats)):
        bad = [i for i, x in enumerate(floats) if not math.isfinite(x)]
        raise Refused(3, f"{name}[{bad[0]}] is {v[bad[0]]}: every value must be a finite number")
    return v


@pytest.mark.parametrize("values", STEPS + [
    [1, 2, 3, 4, 5, 6, 7], (0.5,) * 7, np.full(7, 0.25), [True] + [0.0] * 6, [0.5] * 6,
    [0.5] * 8, [math.nan] + [0.0] * 6, [0.0, math.inf] + [0.0] * 5, [0.0] * 6 + [-math.inf],
    [np.float64(0.5)] * 7, [1e308, 5e-324, -0.0, 0.0, 1.0, 2.0, 3.0]])
def test_the_request_check_answers_as_numpy_did(values):
    try:
        want = finite_vector_before(values, 7, "joint_points").tolist()
    except Refused as r:
        with pytest.raises(Refused) as got:
            finite_floats(values, 7, "joint_points")
        assert got.value.comment == r.comment
    else:
        got = finite_floats(values, 7, "joint_points")
        assert got == want and all(type(x) is float for x in got)


@pytest.mark.parametrize("step", STEPS)
@pytest.mark.parametrize("start", STARTS)
def test_degrees_radians_and_the_goal_are_numpy_s(start, step):
    q = np.radians(start)
    goal = [a + math.radians(d) for a, d in zip(q.tolist(), step)]
    assert goal == (q + np.radians(step)).tolist()
    assert [math.degrees(g) for g in goal] == np.degrees(q + np.radians(step)).tolist()
    delta = [g - a for g, a in zip(goal, q.tolist())]
    assert delta == (np.array(goal) - q).tolist()


def positions_before(kin, frames, q0, delta, ss):
    """The joint line's positions as they were computed before: every sample through numpy,
    a few postures' flanges by Pinocchio one by one, more at once (`flange_many`)."""
    qs = np.asarray(q0) + np.asarray(ss)[:, None] * np.asarray(delta)
    flanges = (np.array([kin.flange(q) for q in qs]) if len(qs) <= FEW_POSTURES
               else kin.flange_many(qs))
    return frames.tool_of(flanges)[:, :3, 3] * 1000.0


@pytest.mark.parametrize("offsets", [False, True])
@pytest.mark.parametrize("count", [2, 3, 16, 24, 25, 61])
@pytest.mark.parametrize("step", STEPS)
@pytest.mark.parametrize("start", STARTS)
def test_the_line_s_positions_are_numpy_s(start, step, count, offsets):
    kin, frames = shared_kinematics(), Frames()
    if offsets:
        base, tool = np.eye(4), np.eye(4)
        base[:3, :3] = pin.exp3(np.radians([3.0, -4.0, 30.0]))
        base[:3, 3] = [0.01, -0.02, 0.005]
        tool[:3, :3] = pin.exp3(np.radians([0.0, 10.0, 0.0]))
        tool[:3, 3] = [0.0, 0.015, 0.12]
        frames = Frames(base, tool)
    q0 = np.radians(start).tolist()
    delta = np.radians(step).tolist()
    ss = [k / (count - 1) for k in range(count)]
    assert ss == (np.arange(count) / (count - 1)).tolist()
    want = positions_before(kin, frames, q0, delta, ss)
    assert np.array_equal(np.asarray(_line_positions_mm(kin, frames, q0, delta, ss)), want)
    odd = np.linspace(0.1, 0.9, count)              # the refinement's parameters (an array)
    assert np.array_equal(np.asarray(_line_positions_mm(kin, frames, q0, delta, odd)),
                          positions_before(kin, frames, q0, delta, odd))


@pytest.mark.parametrize("step", STEPS[:4])
def test_the_queued_ptp_motion_is_the_numpy_formula_s(arm, step):  # noqa: F811
    start = arm.device.queued_end.joints.copy()
    r = arm.move_ptp_joint_rel(step)
    assert r.ok, r.comment
    motion = arm.device.queue[-1].motion
    goal = start + np.radians(step)
    assert np.array_equal(motion.path.q0, start)
    assert np.array_equal(motion.path.delta, goal - start)
    speed = np.radians(arm.max_speed_joint) * arm.speed_joint / 100.0
    want = Trapezoid.for_axes((goal - start).tolist(), speed.tolist(), arm.accel_time_joint)
    assert motion.duration == want.duration


def test_the_kept_posture_is_the_next_move_s_start_and_gives_the_same_position(arm):  # noqa: F811
    """A PTP plan that computes its line's postures keeps the last one (`_position_at`): its
    end, where the next move starts (`path.q(1.0)`, the same floats); its position is what
    Pinocchio gives. A move near the kept posture, well inside the box, computes none."""
    kin, frames = shared_kinematics(), arm.frames
    x, y, z = _line_positions_mm(kin, frames, arm.device.queued_end.joints.tolist(),
                                 [0.0] * 7, [0.0])[0]
    assert arm.set_soft_limit_box((x - 150, x + 150, y - 150, y + 150, z - 150, z + 150)).ok
    frames = arm.frames
    for step in ([0.5] * 7, [3.0, -2.0, 1.0, 0.0, 0.5, -0.25, 7.0]):  # near the box: computed
        assert arm.move_ptp_joint_rel(step).ok
        end = arm.device.queued_end.joints.tolist()
        kept_frames, joints, position, _ = arm._posture_memo
        assert kept_frames is frames and joints == end
        assert position == _line_positions_mm(kin, frames, end, [0.0] * 7, [0.0])[0]
    assert arm.move_ptp_joint_rel([-0.01] * 7).ok          # within 1 mm of the kept posture
    assert arm._posture_memo[1] == end


def short_moves_near_a_box(arm, seed: int) -> list:
    """The replies (code, comment) and queued ends of 400 random short PTP moves (-0.3 … 0.5°
    each joint: a drift) from the arm's posture, inside a box 240 mm wide around its control
    point: near the kept posture at first, then into the box's sides."""
    kin = shared_kinematics()
    x, y, z = _line_positions_mm(kin, arm.frames, arm.device.queued_end.joints.tolist(),
                                 [0.0] * 7, [0.0])[0]
    assert arm.set_soft_limit_box((x - 120, x + 120, y - 120, y + 120, z - 120, z + 120)).ok
    rng = np.random.default_rng(seed)
    out = []
    for _ in range(400):
        r = arm.move_ptp_joint_rel(rng.uniform(-0.3, 0.5, 7).tolist())
        out.append((r.code, r.comment, arm.device.queued_end.joints.tolist()))
    return out


@pytest.mark.parametrize("seed", [1, 2])
def test_a_line_near_the_kept_posture_is_answered_as_its_samples_would_be(seed):
    """The shortcut past the line's forward kinematics (`_line_near_kept_posture_inside`)
    answers every move as the samples' check does: the same replies and queued ends as an arm
    without it, over moves that often reach the box."""
    from acti_motion.arm.core import ArmConfig, ArmCore
    from acti_motion.executor import MotionExecutor
    from acti_sim.world import World
    runs, taken = [], []
    for shortcut in (True, False):
        world = World()
        try:
            a = ArmCore(MotionExecutor(world, real_time_factor=0.0),
                        ArmConfig(queue_size=1000, initial_joints_deg=WORK))
            assert a.servo_on().ok and a.set_speed_joint(50).ok
            near = a._line_near_kept_posture_inside
            a._line_near_kept_posture_inside = (
                (lambda *args: taken.append(near(*args)) or taken[-1]) if shortcut
                else (lambda *args: False))
            runs.append(short_moves_near_a_box(a, seed))
        finally:
            world.close()
    with_it, without = runs
    assert with_it == without
    assert 50 < sum(code == 0 for code, _, _ in with_it) < 350      # both kinds of answer
    assert sum(taken) >= 10 and not all(taken)                       # both ways of checking
