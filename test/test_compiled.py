"""The compiled kernels (acti_motion/arm/compiled.py) against the numpy formulas they replaced
(kept here as the reference), on tables of random postures and poses, near-singular ones (θ2,
θ4, θ6 near 0, a stretched arm) and ones near the joint limits; and their start-up: loaded from
numba's cache when imported, never compiled in a request."""
import math
import subprocess
import sys

import numpy as np
import pinocchio as pin
import pytest

from acti_motion.arm import compiled
from acti_motion.arm.core import shared_kinematics
from acti_motion.arm.trajectories import STRAY_COS, STRAY_M2, unit_grid

TWO_PI = 2.0 * math.pi
CLEAR = compiled.CLEAR


@pytest.fixture(scope="module")
def kin():
    return shared_kinematics()


# --- the numpy formulas the kernels replaced ------------------------------------------------------
def rot_zy_many(a, b):
    ca, sa, cb, sb = np.cos(a), np.sin(a), np.cos(b), np.sin(b)
    return np.array([ca * cb, -sa, ca * sb, sa * cb, ca, sa * sb, -sb, np.zeros_like(ca),
                     cb]).T.reshape(-1, 3, 3)


def rot_z_many(a):
    c, s = np.cos(a), np.sin(a)
    zero, one = np.zeros_like(c), np.ones_like(c)
    return np.array([c, -s, zero, s, c, zero, zero, zero, one]).T.reshape(-1, 3, 3)


def flange_many(kin, qs):
    R = rot_zy_many(qs[:, 0], qs[:, 1])
    p = kin.shoulder + kin.upper_arm * R[:, :, 2]
    R = R @ rot_zy_many(qs[:, 2], qs[:, 3])
    p = p + kin.forearm * R[:, :, 2]
    R = R @ rot_zy_many(qs[:, 4], qs[:, 5])
    p = p + kin.hand * R[:, :, 2]
    out = np.zeros((len(qs), 4, 4))
    out[:, :3, :3] = R @ rot_z_many(qs[:, 6])
    out[:, :3, 3] = p
    out[:, 3, 3] = 1.0
    return out


def reproduces(got, want):
    d = np.abs(got[..., :3, :] - want[..., :3, :])
    return (d[..., 3].max(axis=-1) <= 1e-7) & (d[..., :3].max(axis=(-2, -1)) <= 1e-6)


def branch_many(kin, elbow, wrist, R, signs, ref):
    s2, s4, s6 = signs.T
    ua = (elbow - kin.shoulder) / kin.upper_arm
    t2 = np.arccos(np.clip(ua[:, 2], -1.0, 1.0))
    t1 = np.where(np.sin(t2) < 1e-9, ref[..., 0],
                  np.arctan2(ua[:, 1], ua[:, 0]) + np.where(s2 < 0, math.pi, 0.0))
    t2 = s2 * t2
    f = (wrist - elbow) / kin.forearm
    r12 = rot_zy_many(t1, t2)
    f2 = np.einsum("nji,nj->ni", r12, f)
    t4 = s4 * np.arccos(np.clip(f2[:, 2], -1.0, 1.0))
    t3 = np.where(np.abs(np.sin(t4)) < 1e-9, ref[..., 2],
                  np.arctan2(s4 * f2[:, 1], s4 * f2[:, 0]))
    rw = (r12 @ rot_zy_many(t3, t4)).transpose(0, 2, 1) @ R
    t6 = s6 * np.arccos(np.clip(rw[:, 2, 2], -1.0, 1.0))
    wrist_free = np.abs(np.sin(t6)) < 1e-9
    t5 = np.where(wrist_free, ref[..., 4], np.arctan2(s6 * rw[:, 1, 2], s6 * rw[:, 0, 2]))
    t7 = np.where(wrist_free, np.arctan2(rw[:, 1, 0], rw[:, 0, 0]) - ref[..., 4],
                  np.arctan2(s6 * rw[:, 2, 1], -s6 * rw[:, 2, 0]))
    return np.array([t1, t2, t3, t4, t5, t6, t7]).T


def rows_dot(a, b):
    return np.einsum("ij,ij->i", a, b)


def solve_many(kin, flanges, elbow_dirs, reference, chained):
    a, b = kin.upper_arm, kin.forearm
    w = flanges[:, :3, 3] - kin.hand * flanges[:, :3, 2]
    v = w - kin.shoulder
    dist = np.maximum(np.sqrt(rows_dot(v, v)), 1e-12)
    u = v / dist[:, None]
    h = (a * a - b * b + dist * dist) / (2 * dist)
    rho = np.sqrt(np.maximum(a * a - h * h, 0.0))
    n = elbow_dirs - rows_dot(elbow_dirs, u)[:, None] * u
    n /= np.maximum(np.sqrt(rows_dot(n, n)), 1e-12)[:, None]
    elbow = kin.shoulder + h[:, None] * u + rho[:, None] * n
    q = branch_many(kin, elbow, w, flanges[:, :3, :3], np.sign(reference[..., 1::2]), reference)
    if chained:
        steps = q - np.concatenate([reference[None], q[:-1]])
        q = q - TWO_PI * np.rint(steps / TWO_PI).cumsum(axis=0)
    else:
        q = q + TWO_PI * np.rint((reference - q) / TWO_PI)
    ok = ((dist <= kin.reach + 1e-9) & (dist >= kin.min_reach - 1e-9)
          & (np.abs(q[:, 1::2]).min(axis=1) > CLEAR)
          & (np.abs(reference[..., 1::2]).min(axis=-1) > CLEAR)
          & ((q >= kin.lower - 1e-9) & (q <= kin.upper + 1e-9)).all(axis=1)
          & reproduces(flange_many(kin, q), flanges))
    return q, np.logical_and.accumulate(ok) if chained else ok


def units(v):
    return v / np.sqrt(rows_dot(v, v))[:, None]


def rotate_many(axes, angles, v):
    c, s = np.cos(angles)[:, None], np.sin(angles)[:, None]
    return v * c + np.cross(axes, v) * s + axes * ((axes * v).sum(axis=1)[:, None] * (1.0 - c))


def exp3_many(w):
    return np.array([pin.exp3(x) for x in w])


# --- tables ---------------------------------------------------------------------------------------
def postures(kin, n=200, seed=5):
    """Random postures within the limits, near-singular ones (θ2, θ4 or θ6 within 1e-10 … 0.3
    of 0, a stretched arm) and ones at the joint limits."""
    rng = np.random.default_rng(seed)
    qs = [rng.uniform(kin.lower * 0.95, kin.upper * 0.95, (n, 7))]
    for j in (1, 3, 5):
        near = rng.uniform(kin.lower * 0.9, kin.upper * 0.9, (30, 7))
        near[:, j] = rng.choice([-1.0, 1.0], 30) * 10.0 ** rng.uniform(-10, math.log10(0.3), 30)
        qs.append(near)
    stretched = rng.uniform(kin.lower * 0.9, kin.upper * 0.9, (10, 7))
    stretched[:, 3] = 0.0
    edge = rng.uniform(kin.lower * 0.9, kin.upper * 0.9, (20, 7))
    k = rng.integers(0, 7, 20)
    edge[np.arange(20), k] = np.where(rng.random(20) < 0.5, kin.lower[k], kin.upper[k])
    return np.vstack(qs + [stretched, edge])


def test_flange_poses_are_the_numpy_formula_s_and_pinocchio_s(kin):
    qs = postures(kin)
    got = kin.flange_many(qs)
    assert np.max(np.abs(got - flange_many(kin, qs))) < 1e-14
    assert max(np.max(np.abs(F - kin.flange(q))) for F, q in zip(got, qs)) < 1e-12


@pytest.mark.parametrize("chained", [False, True])
def test_the_batch_ik_is_the_numpy_formula_s(kin, chained):
    """Same joints (to rounding) and the same verdicts, far from and near the branch
    boundaries, near the limits, out of reach (a flange moved away) and with the reference a
    whole turn away."""
    rng = np.random.default_rng(8)
    qs = postures(kin)
    flanges = kin.flange_many(qs)
    flanges[::17, :3, 3] *= 3.0                        # out of reach
    dirs = np.array([kin.elbow_direction(q)[1] for q in qs]) + rng.normal(0, 0.05, (len(qs), 3))
    if chained:
        path = qs[:12] + np.linspace(0, 1, 12)[:, None] * np.radians([5.0] * 7)
        cases = [(kin.flange_many(path), dirs[:12], path[0] + TWO_PI * np.array([1, 0, -1, 0,
                                                                                    0, 0, 2]))]
        cases += [(flanges[i:i + 8], dirs[i:i + 8], qs[i]) for i in range(0, len(qs) - 8, 8)]
    else:
        refs = qs + rng.normal(0.0, 0.05, qs.shape)
        refs[::5] += TWO_PI * rng.integers(-1, 2, refs[::5].shape)
        cases = [(flanges, dirs, refs)]
    verdicts = []
    for F, d, ref in cases:
        got, ok = kin.solve_many(F, d, ref, chained=chained)
        want, want_ok = solve_many(kin, F, d, ref, chained)
        assert np.array_equal(ok, want_ok)
        assert np.max(np.abs(got[ok] - want[ok]), initial=0.0) < 1e-12   # others: `solve`
        verdicts.extend(ok)
    assert any(verdicts) and not all(verdicts)


def test_the_eight_branches_are_the_numpy_formula_s(kin):
    """`solve`'s eight branches at once, the reference broadcast, near-singular poses too."""
    from acti_motion.arm.kinematics import BRANCH_SIGNS
    for q in postures(kin, n=40)[::3]:
        F = kin.flange(q)
        w = F[:3, 3] - kin.hand * F[:3, 2]
        elbow = kin.points(q).elbow
        got = compiled.branches(elbow[None], w[None], F[None], BRANCH_SIGNS, q[None],
                                kin.shoulder, kin.upper_arm, kin.forearm)
        want = branch_many(kin, np.broadcast_to(elbow, (8, 3)), np.broadcast_to(w, (8, 3)),
                           np.broadcast_to(F[:3, :3], (8, 3, 3)), BRANCH_SIGNS, q)
        # rounding grows as 1/sin near a singular θ2, θ4, θ6 (acos near ±1); within ~1e-7 of
        # one, the last bit of cos θ decides which free angle takes the turn: the same pose
        clearance = float(np.min(np.abs(np.sin(q[1::2]))))
        if clearance > 1e-6:
            assert np.max(np.abs(got - want)) < 1e-13 / min(1e-2, clearance)
        else:
            assert np.max(np.abs(kin.flange_many(got) - kin.flange_many(want))) < 1e-7


def test_the_elbow_kernels_are_the_numpy_formula_s(kin):
    rng = np.random.default_rng(4)
    for q in postures(kin, n=20)[::4]:
        path = q + np.linspace(0, 1, 9)[:, None] * rng.normal(0, 0.2, 7)
        flanges = kin.flange_many(path)
        n0 = kin.elbow_direction(q)[1]
        us_want = units(flanges[:, :3, 3] - kin.hand * flanges[:, :3, 2] - kin.shoulder)
        ns_want, n = [], n0
        for u in us_want:
            n = n - np.dot(n, u) * u
            n = n / np.linalg.norm(n)
            ns_want.append(n)
        us, ns = compiled.carry_elbow(flanges, n0, kin.shoulder, kin.hand)
        assert np.max(np.abs(us - us_want)) < 1e-14 and np.max(np.abs(ns - ns_want)) < 1e-14
        grid = unit_grid(9)
        ss = np.sort(rng.uniform(0, 1, 7))
        at = kin.flange_many(q + ss[:, None] * (path[-1] - q))
        u = units(at[:, :3, 3] - kin.hand * at[:, :3, 2] - kin.shoulder)
        for turn in (0.0, 0.7, -2.0):
            i = np.minimum((ss * 8).astype(int), 7)
            f = ((ss - grid[i]) / (grid[i + 1] - grid[i]))[:, None]
            m = (1 - f) * ns[i] + f * ns[i + 1]
            want = units(m - rows_dot(m, u)[:, None] * u)
            want = rotate_many(u, turn * ss, want) if turn else want
            got = compiled.elbow_directions(at, ss, grid, ns, turn, kin.shoulder, kin.hand)
            assert np.max(np.abs(got - want)) < 1e-14


def test_the_path_kernels_are_the_numpy_formula_s():
    rng = np.random.default_rng(2)
    for _ in range(20):
        R0 = pin.exp3(rng.normal(0, 1.5, 3))
        w = rng.normal(0, 1.0, 3) * 10.0 ** rng.uniform(-13, 0)
        ss, p0, dp = np.sort(rng.uniform(0, 1, 9)), rng.normal(0, 1, 3), rng.normal(0, 1, 3)
        positions = compiled.line_positions(p0, dp, ss)
        assert np.max(np.abs(positions - (p0 + ss[:, None] * dp))) < 1e-15
        got = compiled.geodesic_poses(R0, w, True, ss, positions)
        assert np.max(np.abs(got[:, :3, :3] - exp3_many(ss[:, None] * w) @ R0)) < 1e-14
        assert np.array_equal(got[:, :3, 3], positions)
        assert np.array_equal(got[:, 3], np.broadcast_to([0.0, 0.0, 0.0, 1.0], (9, 4)))
        assert np.array_equal(compiled.geodesic_poses(R0, w, False, ss, positions)[:, :3, :3],
                              np.broadcast_to(R0, (9, 3, 3)))
        axes, angles = units(rng.normal(0, 1, (9, 3))), rng.uniform(-7, 7, 9)
        v = rng.normal(0, 1, 3)
        assert np.max(np.abs(compiled.rotate_rows(axes, angles, v[None])
                             - rotate_many(axes, angles, v))) < 1e-14


def test_the_stray_check_is_the_numpy_formula_s(kin):
    rng = np.random.default_rng(6)
    qs = postures(kin, n=50)
    want = kin.flange_many(qs)
    moved = qs + rng.normal(0, 1, qs.shape) * 10.0 ** rng.uniform(-9, -3, (len(qs), 1))
    got = kin.flange_many(moved)
    d = want[:, :3, 3] - got[:, :3, 3]
    cos = (np.einsum("nij,nij->n", got[:, :3, :3], want[:, :3, :3]) - 1.0) / 2
    expect = (rows_dot(d, d) > STRAY_M2) | (cos < STRAY_COS)
    assert expect.any() and not expect.all()
    assert np.array_equal(compiled.strays(want, got, STRAY_M2, STRAY_COS), expect)


def test_the_spline_bounds_are_the_numpy_formula_s():
    """bounds_keep and within against their numpy forms, on random splines and limits set
    just above and below each bound (both answers occur)."""
    rng = np.random.default_rng(9)
    for _ in range(60):
        pieces = int(rng.integers(1, 12))
        ss = np.concatenate([[0.0], np.sort(rng.uniform(0, 1, pieces - 1)), [1.0]])
        c = rng.normal(0, 1, (4, pieces, 7))
        a = np.abs(c)
        h = (ss[1:] - ss[:-1])[:, None]
        m1 = (a[2] + h * (2.0 * a[1] + 3.0 * h * a[0])).max(axis=0)
        m2 = (2.0 * a[1] + 6.0 * h * a[0]).max(axis=0)
        peak, ramp = rng.uniform(0.1, 3.0), rng.uniform(0.05, 1.0)
        scale = rng.choice([0.999999, 1.000001], 7)
        vel, acc = m1 * peak * scale, (m2 * peak * peak + m1 * peak / ramp) * scale[::-1]
        want = bool((m1 * peak <= vel).all()
                    and (m2 * peak * peak + m1 * peak / ramp <= acc).all())
        assert compiled.bounds_keep(c, ss, peak, ramp, vel, acc) == want
        bend = h * h * (a[1] + h * a[0])
        end = c[3] + h * c[2]
        low = (np.minimum(c[3], end) - bend).min(axis=0)
        high = (np.maximum(c[3], end) + bend).max(axis=0)
        lower, upper = low - rng.choice([-1e-9, 1e-9], 7), high + rng.choice([-1e-9, 1e-9, 1e-9], 7)
        want = bool((np.minimum(c[3], end) - bend >= lower).all()
                    and (np.maximum(c[3], end) + bend <= upper).all())
        assert compiled.within(c, ss, lower, upper) == want


def test_the_kernels_load_from_the_cache_and_never_compile_again():
    """Importing the module loads every kernel (signatures given: compiled or loaded then), from
    numba's cache (`make setup` fills it); a call with other types fails instead of compiling."""
    code = ("import time; t = time.process_time(); from acti_motion.arm import compiled; "
            "import numba; ks = [v for v in vars(compiled).values() "
            "if isinstance(v, numba.core.registry.CPUDispatcher)]; "
            "ks = [k for k in ks if k.signatures]; "
            "print(len(ks), all(k._can_compile is False for k in ks), "
            "sum(k.stats.cache_misses.__len__() for k in ks), time.process_time() - t)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout.split()
    assert int(out[0]) == 19 and out[1] == "True" and out[2] == "0", out
    with pytest.raises(TypeError):
        compiled.line_positions(np.zeros(3, dtype=np.float32), np.zeros(3), np.zeros(2))


def test_the_spline_s_middles_and_steps_are_the_numpy_formula_s(kin):
    """spline_strays: the middles' flange poses, as control-point poses with and without
    offsets, against the path's poses there; long_steps: the intervals with a joint step
    beyond the bound; line_poses: a line's positions and rotations in one call."""
    from acti_motion.arm.trajectories import not_a_knot_coefficients
    rng = np.random.default_rng(12)
    base, tool = np.eye(4), np.eye(4)
    base[:3, :3], base[:3, 3] = pin.exp3(np.radians([3.0, -4.0, 30.0])), [0.01, -0.02, 0.005]
    tool[:3, :3], tool[:3, 3] = pin.exp3(np.radians([0.0, 10.0, 0.0])), [0.0, 0.015, 0.12]
    seen = set()
    for q in postures(kin, n=30)[::3]:
        ss = np.concatenate([[0.0], np.sort(rng.uniform(0, 1, 5)), [1.0]])
        bend = rng.choice([0.0, 1e-3])            # off the line between the samples, or not
        qs = q + ss[:, None] * rng.normal(0, 0.3, 7) + bend * np.sin(7 * ss)[:, None]
        c = not_a_knot_coefficients(ss, qs)
        mids = (ss[:-1] + ss[1:]) / 2
        t = (mids - ss[:-1])[:, None]
        middles = c[3] + t * (c[2] + t * (c[1] + t * c[0]))
        assert np.max(np.abs(compiled.spline_middles(c, ss) - middles)) < 1e-15
        for to_robot, flange_to_tool in ((np.eye(4), np.eye(4)), (np.linalg.inv(base), tool)):
            got = to_robot @ flange_many(kin, middles) @ flange_to_tool
            want = to_robot @ flange_many(kin, q + mids[:, None] * (qs[-1] - q)) @ flange_to_tool
            d = want[:, :3, 3] - got[:, :3, 3]
            cos = (np.einsum("nij,nij->n", got[:, :3, :3], want[:, :3, :3]) - 1.0) / 2
            expect = (rows_dot(d, d) > STRAY_M2) | (cos < STRAY_COS)
            assert np.array_equal(compiled.spline_strays(
                c, ss, want, to_robot, flange_to_tool, kin.shoulder, kin.upper_arm,
                kin.forearm, kin.hand, STRAY_M2, STRAY_COS), expect)
            seen.update(expect.tolist())
        steps = np.abs(qs[1:] - qs[:-1])
        for bound in (0.0, float(np.median(steps)), 10.0):
            assert np.array_equal(compiled.long_steps(qs, bound),
                                  np.flatnonzero(steps.max(axis=1) > bound))
        p0, dp, R0, w = rng.normal(0, 1, 3), rng.normal(0, 1, 3), pin.exp3(q[:3]), q[3:6]
        assert np.array_equal(compiled.line_poses(p0, dp, R0, w, True, ss),
                              compiled.geodesic_poses(R0, w, True, ss,
                                                      compiled.line_positions(p0, dp, ss)))
    assert seen == {False, True}


def test_the_rel_rule_s_kernel_is_the_numpy_formula():
    rng = np.random.default_rng(13)
    for _ in range(60):
        start, delta = np.eye(4), np.eye(4)
        start[:3, :3], start[:3, 3] = pin.exp3(rng.normal(0, 2, 3)), rng.normal(0, 1, 3)
        delta[:3, :3], delta[:3, 3] = pin.exp3(rng.normal(0, 2, 3)), rng.normal(0, 1, 3)
        got = compiled.relative_pose(start, delta)
        assert np.max(np.abs(got[:3, :3] - delta[:3, :3] @ start[:3, :3])) < 1e-15
        assert np.array_equal(got[:3, 3], start[:3, 3] + delta[:3, 3])
        assert np.array_equal(got[3], [0.0, 0.0, 0.0, 1.0])


def test_the_spline_at_a_point_is_ppoly_s_to_the_last_bit():
    """spline_at (SplineJointPath.q) against scipy's PPoly: at the breakpoints, between them,
    before and beyond the ends, and at NaN."""
    from scipy.interpolate import PPoly

    from acti_motion.arm.trajectories import not_a_knot_coefficients
    rng = np.random.default_rng(1)
    for n in (4, 5, 9, 30, 200):
        ss = np.concatenate([[0.0], np.sort(rng.uniform(0, 1, n - 2)), [1.0]])
        c = not_a_knot_coefficients(ss, np.cumsum(rng.normal(size=(n, 7)), axis=0))
        spline = PPoly.construct_fast(c, ss)
        points = [*ss, *rng.uniform(-0.1, 1.1, 200), np.nextafter(1.0, 0.0),
                  np.nextafter(1.0, 2.0), -0.0, math.nan]
        for s in points:
            assert np.array_equal(compiled.spline_at(c, ss, s), spline(s), equal_nan=True)
