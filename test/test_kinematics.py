"""Pinocchio kinematics of the SRS arm: IK round trips, the arm angle, reach, branch choice."""
import math

import numpy as np
import pytest

from acti_motion.arm.core import shared_kinematics
from acti_motion.arm.kinematics import Unreachable, wrap

START = np.radians([0.0, 30.0, 0.0, -60.0, 0.0, 60.0, 0.0])


@pytest.fixture(scope="module")
def kin():
    return shared_kinematics()


def test_geometry_is_read_off_the_urdf(kin):
    assert np.allclose(kin.shoulder, [0.10, 0.0, 0.54])
    assert (kin.upper_arm, kin.forearm, kin.hand) == pytest.approx((0.4, 0.4, 0.126))


def test_ik_reproduces_random_postures_with_their_arm_angle(kin):
    rng = np.random.default_rng(7)
    for _ in range(300):
        q = rng.uniform(kin.lower * 0.95, kin.upper * 0.95)
        got = kin.solve(kin.flange(q), q + rng.normal(0.0, 0.03, 7), psi=kin.arm_angle(q))
        assert np.max(np.abs(got - q)) < 1e-6


@pytest.mark.parametrize("psi_deg", [-150.0, -60.0, 0.0, 45.0, 120.0, 180.0])
def test_ik_honours_the_arm_angle_and_keeps_the_pose(kin, psi_deg):
    target = kin.flange(START)
    q = kin.solve(target, START, psi=math.radians(psi_deg))
    assert np.allclose(kin.flange(q), target, atol=1e-9)
    assert abs(wrap(kin.arm_angle(q) - math.radians(psi_deg))) < 1e-8


@pytest.mark.parametrize("taught", [
    (0, 30, 0, -60, 30, -2, -20),     # J6 just below 0 (the start's is +60)
    (0, 30, 20, 2, -30, 60, 0),       # J4 just above 0 (the start's is −60)
    (30, -2, -20, -90, 0, 45, 0),     # J2 just below 0 (the start's is +30)
])
def test_the_nearest_solution_is_taken_across_a_branch_boundary(kin, taught):
    """A pose taught with J2, J4 or J6 near 0 on the other side of the start's sign: its twin
    with the start's sign has the joints beside it half a turn away (a wrist or shoulder flip)."""
    q = np.radians(taught)
    start = np.radians([0, 30, 0, -60, 0, 60, 0])
    got = kin.solve(kin.flange(q), start, psi=kin.arm_angle(q))
    assert np.degrees(np.max(np.abs(got - q))) < 1e-6, np.round(np.degrees(got), 3)


def test_start_posture_reports_elbow_zero_and_flags(kin):
    assert math.degrees(kin.arm_angle(START)) == pytest.approx(0.0, abs=1e-9)
    assert kin.flags(START) == 0
    assert kin.flags(np.radians([0, -30, 0, 60, 0, -60, 0])) == 0x7


def test_unreachable_targets_say_why(kin):
    far = kin.flange(START)
    far[:3, 3] = kin.shoulder + [1.2, 0.0, 0.0]
    with pytest.raises(Unreachable, match="out of reach"):
        kin.solve(far, START)
    near = kin.flange(START)
    near[:3, 3] = kin.shoulder + near[:3, 2] * kin.hand + [0.05, 0.0, 0.0]
    with pytest.raises(Unreachable, match="too close"):
        kin.solve(near, START)


def test_soft_joint_limits_restrict_the_solutions(kin):
    target = kin.flange(START)
    lower, upper = kin.lower.copy(), kin.upper.copy()
    lower[5] = math.radians(70.0)          # J6 must be >= 70°, but this pose needs 60° or -60°
    with pytest.raises(Unreachable, match="joint limits"):
        kin.solve(target, START, psi=0.0, lower=lower, upper=upper)


def test_transport_keeps_the_elbow_normal_to_the_new_line(kin):
    u0, n0 = kin.elbow_direction(START)
    u1 = np.array([1.0, 0.0, 1.0]) / math.sqrt(2)
    n1 = kin.transport(n0, u0, u1)
    assert abs(np.dot(n1, u1)) < 1e-12 and np.linalg.norm(n1) == pytest.approx(1.0)


def test_flange_many_matches_pinocchio(kin):
    qs = np.random.default_rng(3).uniform(kin.lower, kin.upper, (200, 7))
    got = kin.flange_many(qs)
    assert max(np.max(np.abs(F - kin.flange(q))) for F, q in zip(got, qs)) < 1e-12


def test_solve_many_gives_solve_s_answers_where_it_says_it_solved(kin):
    rng = np.random.default_rng(11)
    qs = rng.uniform(kin.lower * 0.95, kin.upper * 0.95, (300, 7))
    refs = qs + rng.normal(0.0, 0.03, qs.shape)
    dirs = np.array([kin.elbow_direction(q)[1] for q in qs])
    flanges = kin.flange_many(qs)
    got, solved = kin.solve_many(flanges, dirs, refs, chained=False)
    clear = np.all(np.abs(qs[:, 1::2]) > 0.25, axis=1) & np.all(np.abs(refs[:, 1::2]) > 0.25,
                                                                   axis=1)
    assert np.all(solved[clear]) and not np.all(solved)       # boundaries are left to solve()
    for F, d, ref, q in zip(flanges[solved], dirs[solved], refs[solved], got[solved]):
        assert np.max(np.abs(q - kin.solve(F, ref, elbow_dir=d))) < 1e-9


def test_solve_many_chained_follows_the_turns_and_stops_at_the_first_doubt(kin):
    q0 = np.radians([-100.0, -50.0, 20.0, -80.0, 30.0, 60.0, 10.0])   # θ2 < 0: raw θ1 is +260°
    qs = q0 + np.linspace(0.0, 1.0, 12)[:, None] * np.radians([20.0, 0, 0, 0, 0, -58.0, 0])
    dirs = np.array([kin.elbow_direction(q)[1] for q in qs])
    got, solved = kin.solve_many(kin.flange_many(qs), dirs, q0, chained=True)
    k = int(np.sum(solved))
    assert 0 < k < len(qs) and np.all(solved[:k])             # J6 nears 0: the rest is solve()'s
    assert np.max(np.abs(got[:k] - qs[:k])) < 1e-9             # θ1 a whole turn from the raw one
    seq = [q0]
    for F, d in zip(kin.flange_many(qs[:k]), dirs[:k]):
        seq.append(kin.solve(F, seq[-1], elbow_dir=d))
    assert np.max(np.abs(got[:k] - np.array(seq[1:]))) < 1e-9


def test_the_elbow_direction_and_arm_angle_in_plain_floats_are_the_vectors_of_the_points(kin):
    """elbow_direction, angle_of and wrist_direction (plain floats) against the same quantities
    from the posture's points and flange with numpy, on random postures and a stretched arm;
    a second call with the same posture answers the kept result, another posture a new one."""
    rng = np.random.default_rng(11)
    postures = [*rng.uniform(kin.lower * 0.95, kin.upper * 0.95, (100, 7)), np.zeros(7)]
    for q in postures:
        pts = kin.points(q)
        u = (pts.wrist - pts.shoulder) / np.linalg.norm(pts.wrist - pts.shoulder)
        v = pts.elbow - pts.shoulder
        n = v - np.dot(v, u) * u
        n = kin.reference(u)[0] if np.linalg.norm(n) < 1e-9 else n / np.linalg.norm(n)
        got_u, got_n = kin.elbow_direction(q)
        assert np.allclose(got_u, u, atol=1e-14) and np.allclose(got_n, n, atol=1e-12)
        assert kin.elbow_direction(q.copy())[1] is got_n
        e1, e2 = kin.reference(u)
        assert kin.angle_of(u, n) == pytest.approx(math.atan2(np.dot(n, e2), np.dot(n, e1)),
                                                   abs=1e-14)
        w = kin.wrist_of(kin.flange(q)) - kin.shoulder
        assert np.allclose(kin.wrist_direction(kin.flange(q)), w / np.linalg.norm(w), atol=1e-14)
    assert kin.elbow_direction(START)[1] is not kin.elbow_direction(postures[0])[1]
