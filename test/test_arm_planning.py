"""CP planning without the simulation: the batch IK plans exactly what one-by-one IK plans, the
paths' batch poses, the length bound that keeps every plan's cost bounded."""
import math
import sys
import time

import numpy as np
import pinocchio as pin
import pytest
from scipy.interpolate import CubicSpline

from acti_motion.arm import compiled
from acti_motion.arm.core import ArmConfig, ArmCore, shared_kinematics
from acti_motion.arm.poses import Frames, pose_to_hg
from acti_motion.arm.trajectories import (TOPPRA_GRID, ArcPath, CartesianLimits, CartesianPlanner,
                                          LinePath, bounds_keep_limits, convex_checkpoints,
                                          keeps_limits, not_a_knot_coefficients,
                                          not_a_knot_on_unit_grid,
                                          not_a_knot_spline, poses_along, positions_along,
                                          samples_keep_limits, spline_within, time_optimal,
                                          toppra_grid, unit_grid)
from acti_motion.profiles import Trapezoid
from acti_motion.replies import ReturnCode as R
from sim_fixtures import executor  # noqa: F401

WORK = np.radians([0.0, 45.0, 0.0, -90.0, 0.0, 45.0, 0.0])
SINGULAR_FROM = np.radians([20.0, 40.0, 10.0, -70.0, 30.0, 25.0, 0.0])
SINGULAR_TO = np.radians([-20.0, 40.0, -10.0, -70.0, -30.0, -25.0, 8.0])   # the wrist passes J6 = 0


@pytest.fixture(scope="module")
def kin():
    return shared_kinematics()


def limits(kin) -> CartesianLimits:
    return CartesianLimits(speed=0.5, angular_speed=math.radians(90.0), ramp=0.3,
                           joint_velocity=kin.velocity, joint_accel=kin.velocity / 0.1)


def moved(P: np.ndarray, dp=(0.0, 0.0, 0.0), rot=(0.0, 0.0, 0.0)) -> np.ndarray:
    out = P.copy()
    out[:3, 3] += dp
    out[:3, :3] = pin.exp3(np.radians(rot)) @ P[:3, :3]
    return out


def one_by_one(flanges, elbow_dirs, reference, *, chained):
    """solve_many that solves nothing: every sample goes through ArmKinematics.solve."""
    return np.zeros((len(flanges), 7)), np.zeros(len(flanges), bool)


CASES = {
    "200 mm line with a 30° turn": (WORK, lambda P: LinePath(P, moved(P, (0.1, 0.15, -0.1),
                                                                      (0.0, 0.0, 30.0))), {}),
    "arc": (WORK, lambda P: ArcPath(P, P[:3, 3] + [0.1, 0.1, 0.0], moved(P, (0.2, 0.0, 0.0))), {}),
    "elbow turn": (WORK, lambda P: LinePath(P, P), {"turn": math.radians(60.0)}),
    "elbow to an arm angle": (WORK, lambda P: LinePath(P, moved(P, (0.05, 0.0, -0.1))),
                              {"psi": math.radians(25.0)}),
    "near the wrist singularity": (SINGULAR_FROM, None, {}),
}


@pytest.mark.parametrize("name", CASES)
def test_batch_ik_plans_what_one_by_one_ik_plans(kin, monkeypatch, name):
    start, path_of, elbow = CASES[name]
    P0 = kin.flange(start)
    path = LinePath(P0, kin.flange(SINGULAR_TO)) if path_of is None else path_of(P0)
    planner, frames = CartesianPlanner(kin), Frames()
    fast = planner.plan(path, frames, start, limits(kin), **elbow)
    with monkeypatch.context() as m:
        m.setattr(kin, "solve_many", one_by_one)
        slow = planner.plan(path, frames, start, limits(kin), **elbow)
    assert len(fast.path.ss) == len(slow.path.ss) and np.allclose(fast.path.ss, slow.path.ss)
    assert np.max(np.abs(fast.path.qs - slow.path.qs)) < 1e-9
    assert fast.retimed == slow.retimed
    assert fast.retimed or path_of is not None          # the singular one needs TOPP-RA
    assert fast.timing.duration == pytest.approx(slow.timing.duration, rel=1e-9)


@pytest.mark.parametrize("grid", [None, 26, TOPPRA_GRID])
def test_toppra_timing_keeps_the_joint_limits_between_its_grid_points(kin, grid):
    """Near the wrist singularity (a fast, bending joint path), on the path's own grid, a coarse
    one and the finest: the joints' velocity and acceleration, exact from the spline and the
    timing's s(t), ṡ(t) at 20,000 instants, keep the limits (TOPP-RA alone looks only at its
    grid points: 7e-5 over at 201 points, 4e-3 at 26)."""
    P0 = kin.flange(SINGULAR_FROM)
    plan = CartesianPlanner(kin).plan(LinePath(P0, kin.flange(SINGULAR_TO)), Frames(),
                                      SINGULAR_FROM, limits(kin))
    assert plan.retimed
    ss, qs, lim = plan.path.ss, plan.path.qs, limits(kin)
    extents = np.array([np.linalg.norm(kin.flange(SINGULAR_TO)[:3, 3] - P0[:3, 3]), 0.0, 0.0])
    assert 26 <= toppra_grid(ss, qs, extents) <= TOPPRA_GRID
    timing = time_optimal(ss, qs, extents, lim, grid)
    ts = np.linspace(0.0, timing.duration, 20001)
    s, sd = np.array([timing.sample(t) for t in ts]).T
    qd = plan.path.d1(s) * sd[:, None]
    assert np.max(np.abs(qd) / lim.joint_velocity) <= 1.0 + 1e-6    # as the nominal profile
    dt = ts[1] - ts[0]
    qdd = np.diff(qd, axis=0) / dt
    assert np.max(np.abs(qdd) / lim.joint_accel) <= 1.0 + 1e-3


def test_batch_poses_are_the_poses_along_the_path(kin):
    P0 = kin.flange(WORK)
    ss = np.linspace(0.0, 1.0, 7)
    line = LinePath(P0, moved(P0, (0.1, -0.2, 0.05), (10.0, -20.0, 30.0)))
    for s, T in zip(ss, line.poses(ss)):
        assert np.allclose(T[:3, :3], pin.exp3(s * line.w) @ line.R0, atol=1e-12)
        assert np.allclose(T[:3, 3], line.p0 + s * line.dp, atol=1e-12)
    arc = ArcPath(P0, P0[:3, 3] + [0.1, 0.1, 0.0], moved(P0, (0.2, 0.0, 0.0)))
    ps = arc.positions(np.linspace(0.0, 1.0, 101))
    assert np.allclose(np.linalg.norm(ps - arc.center, axis=1), arc.radius, atol=1e-12)
    assert np.min(np.linalg.norm(ps - (P0[:3, 3] + [0.1, 0.1, 0.0]), axis=1)) < 0.002
    assert np.allclose(ps[-1], P0[:3, 3] + [0.2, 0.0, 0.0], atol=1e-12)
    assert np.allclose(arc.pose(0.3), arc.poses(np.array([0.3]))[0])


def test_paths_of_other_modules_are_taken_one_by_one(kin):
    class Shifted:                        # like the programs' paths: only pose and position
        def __init__(self, path):
            self.path, self.length, self.angle = path, path.length, path.angle

        def pose(self, s):
            return moved(self.path.pose(s), (0.0, 0.0, 0.01))

        def position(self, s):
            return self.pose(s)[:3, 3]
    line = LinePath(kin.flange(WORK), moved(kin.flange(WORK), (0.1, 0.0, 0.0)))
    ss = np.array([0.0, 0.5, 1.0])
    assert np.allclose(poses_along(Shifted(line), ss)[:, :3, 3],
                       line.positions(ss) + [0.0, 0.0, 0.01])
    assert np.allclose(positions_along(Shifted(line), ss), line.positions(ss) + [0.0, 0.0, 0.01])


def test_a_path_longer_than_any_within_reach_is_refused_before_sampling(executor):  # noqa: F811
    arm = ArmCore(executor, ArmConfig(initial_joints_deg=tuple(np.degrees(WORK))))
    arm.servo_on()
    arm.set_speed_cartesian(50)

    def rel(dx, dy):
        m = np.eye(4)
        m[:3, 3] = [dx / 1000, dy / 1000, 0.0]
        return pose_to_hg(m), 0.0, 0
    t0 = time.perf_counter()
    # the via point is 0.4 µm off the line, beyond the end: the arc runs round a 50 km circle
    r = arm.move_circular_cartesian_rel(rel(200.0, 0.0004), rel(100.0, 0.0))
    assert time.perf_counter() - t0 < 1.0
    assert r.code == R.VALUE_ERR and "out of reach" in r.comment and "mm long" in r.comment
    assert arm.device.queue_length == 0
    assert arm.move_circular_cartesian_rel(rel(100.0, 100.0), rel(200.0, 0.0)).ok


def test_a_1000_mm_line_is_planned_from_a_bounded_number_of_postures(executor, monkeypatch):  # noqa: F811
    """Issue 35's 1,000 mm CP line checked in <= 5 ms of CPU (`bench_arm.py` measures it): what
    keeps it there is the work, bounded here. Its joint spline is solved at a fixed grid (128
    postures at either speed), and the line keeps to the convex soft-limit box and reach
    if and only if its two ends do (two positions, not a sample per few mm)."""
    arm = ArmCore(executor, ArmConfig(initial_joints_deg=tuple(np.degrees(WORK))))
    arm.servo_on()
    arm.set_speed_joint(100)
    forward = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]])

    def across(y: float) -> tuple:
        pose = np.eye(4)
        pose[:3, :3], pose[:3, 3] = forward, (0.45, y, 0.9)
        return pose_to_hg(pose), 90.0, 0
    assert arm.move_ptp_cartesian_abs(across(-0.5)).ok
    while arm.device.busy:
        executor.step()
    postures = []
    kin = type(arm.kin)
    for name in ("solve", "solve_many", "flange", "flange_many"):
        def counted(self, first, *args, _method=getattr(kin, name), _many=name.endswith("many"),
                    **kwargs):
            postures.append(len(first) if _many else 1)
            return _method(self, first, *args, **kwargs)
        monkeypatch.setattr(kin, name, counted)
    for ratio in (5, 100):
        arm.set_speed_cartesian(ratio)
        postures.clear()
        r = arm.move_linear_cartesian_abs(across(0.5 if ratio == 5 else -0.5))
        assert r.ok, r.comment
        assert sum(postures) <= 160, (ratio, postures)
    line = LinePath(np.eye(4), moved(np.eye(4), (1.0, 0.0, 0.0)))
    assert convex_checkpoints(line, 500).shape == (2, 3)


@pytest.mark.parametrize("n", [4, 9, 57])
def test_the_joint_spline_is_scipy_s_not_a_knot_cubic_spline(n):
    rng = np.random.default_rng(n)
    xs = np.concatenate([[0.0], np.sort(rng.random(n - 2)), [1.0]])
    ys = rng.normal(size=(n, 7))
    ours, theirs = not_a_knot_spline(xs, ys), CubicSpline(xs, ys, axis=0)
    assert np.allclose(ours.c, theirs.c, rtol=1e-12, atol=1e-12)
    ts = np.linspace(-0.01, 1.01, 301)                 # extrapolates like CubicSpline too
    assert np.allclose(ours(ts), theirs(ts), rtol=1e-12, atol=1e-12)
    mids = (xs[:-1] + xs[1:]) / 2                      # the pieces at their middles at once
    assert np.allclose(compiled.spline_middles(not_a_knot_coefficients(xs, ys), xs),
                       theirs(mids), rtol=1e-12, atol=1e-12)


def test_toppra_is_imported_with_the_planner():
    assert "toppra" in sys.modules            # at start-up, never inside the first request


def _plans_and_profiles(kin):
    """CP plans of a table of paths (short and long lines, turns, an arc, near the wrist
    singularity) under nominal profiles from slow to fast, with short and long ramps."""
    P0 = kin.flange(WORK)
    paths = [LinePath(P0, moved(P0, (0.02, 0.0, 0.0))), LinePath(P0, moved(P0, (0.0, 0.2, 0.0))),
             LinePath(P0, moved(P0, (0.1, 0.15, -0.1), (0.0, 0.0, 30.0))),
             ArcPath(P0, P0[:3, 3] + [0.1, 0.1, 0.0], moved(P0, (0.2, 0.0, 0.0)))]
    plans = [CartesianPlanner(kin).plan(p, Frames(), WORK, limits(kin)) for p in paths]
    plans.append(CartesianPlanner(kin).plan(LinePath(kin.flange(SINGULAR_FROM),
                                                     kin.flange(SINGULAR_TO)),
                                            Frames(), SINGULAR_FROM, limits(kin)))
    for plan in plans:
        for duration in (0.05, 0.2, 0.5, 1.0, 3.0, 20.0):
            for ramp in (0.01, 0.1, 0.3):
                yield plan.path, Trapezoid(max(duration, 2 * ramp), ramp)


def test_the_limits_bound_says_keeps_only_where_every_sample_keeps(kin):
    """`keeps_limits` decides as the 401 samples do, on a table of plans and profiles; its
    bounds decide alone in part of them (the short lines), never against the samples."""
    lim, by_bound, answers = limits(kin), 0, set()
    for spline, nominal in _plans_and_profiles(kin):
        sampled = samples_keep_limits(spline, nominal, lim)
        assert keeps_limits(spline, nominal, lim) == sampled
        if bounds_keep_limits(spline, nominal, lim):
            assert sampled
            by_bound += 1
        answers.add(sampled)
    assert answers == {True, False} and by_bound > 10


def test_the_spline_bound_says_within_only_where_every_point_is(kin):
    """`spline_within` (the CP path's joint soft-limit check at once) on the table's joint
    splines against limits around their range sampled finely: never within where a point is
    outside; within for the short line with room to spare."""
    splines = {id(s): s for s, _ in _plans_and_profiles(kin)}.values()
    for spline in splines:
        fine = spline.spline(np.linspace(0.0, 1.0, 20001))
        low, high = fine.min(axis=0), fine.max(axis=0)
        assert not spline_within(spline, low + 1e-9, high + 1.0)
        assert not spline_within(spline, low - 1.0, high - 1e-9)
    short = next(iter(splines))
    fine = short.spline(np.linspace(0.0, 1.0, 20001))
    assert spline_within(short, fine.min(axis=0) - 1e-3, fine.max(axis=0) + 1e-3)


def test_the_unit_grid_is_linspace_to_the_last_bit():
    for n in range(2, 400):
        assert np.array_equal(unit_grid(n), np.linspace(0.0, 1.0, n))


def test_the_spline_on_a_unit_grid_by_its_kept_map_is_the_solved_one():
    """A CP plan's first samples (evenly spaced): the coefficients by the map kept per number
    of points are those the system's solve gives, to rounding (within and beyond the kept
    sizes)."""
    rng = np.random.default_rng(5)
    for n in range(4, 41):
        ys = np.cumsum(rng.normal(size=(n, 7)), axis=0)
        got, want = not_a_knot_on_unit_grid(ys), not_a_knot_coefficients(unit_grid(n), ys)
        assert np.allclose(got, want, rtol=1e-10, atol=1e-10 * np.max(np.abs(want)))
        assert np.array_equal(got[3], ys[:-1])                     # through the samples
        still = not_a_knot_on_unit_grid(np.tile(ys[0], (n, 1)))      # a move that stays
        assert not still[:3].any() and np.array_equal(still[3], np.tile(ys[0], (n - 1, 1)))


def test_a_cp_plan_follows_each_setting_change(executor):  # noqa: F811
    """A CP move's limits are kept between accepts (`_cartesian_limits`): each setting's change
    is in the next plan, and its return gives the first plan's timing again."""
    arm = ArmCore(executor, ArmConfig(initial_joints_deg=tuple(np.degrees(WORK))))
    arm.servo_on()
    assert arm.set_accel_time_cartesian(0.1).ok
    sign = [1.0]

    def duration() -> float:
        sign[0] = -sign[0]
        m = np.eye(4)
        m[0, 3] = 0.1 * sign[0]
        assert arm.move_linear_cartesian_rel((pose_to_hg(m), 0.0, 0)).ok
        return arm.device.queue[-1].motion.timing.duration
    changes = [(arm.set_speed_cartesian, 20, 60), (arm.set_max_speed_cartesian, (100.0, 90.0),
                                                   (400.0, 90.0)),
               (arm.set_accel_time_cartesian, 0.3, 0.1)]
    for setter, first, second in changes:
        assert setter(first).ok
        before = duration()
        assert setter(second).ok
        assert duration() != pytest.approx(before)
        assert setter(first).ok
        assert duration() == before
    assert arm.set_max_speed_joint([1.0] * 7).ok      # the joints' limits: time-optimal, slower
    slow = duration()
    assert slow > before and arm.set_max_speed_joint(list(arm.hard_max_speed_joint)).ok
    assert duration() == before
