"""Arm motions: joint paths, their timing, and Cartesian lines and arcs turned into joint paths.

A motion is a joint path q(s), s ∈ [0, 1], timed by s(t): a synchronized trapezoid (PTP, and CP
where it keeps every joint limit) or TOPP-RA's time-optimal timing under the same limits (CP
near singularities). The finger moves linearly in s, so gripper commands are motions too and
queue with the moves.

CP moves sample the exact Cartesian path with the analytic IK (one solution per sample, each the
nearest to the one before), refine the sampling until the joint spline reproduces the path
within `PATH_TOLERANCE_MM` / `PATH_TOLERANCE_DEG`, and check the soft limits on the result.
Planning runs on the service thread before a move is accepted, so its arithmetic on the
samples is compiled (`acti_motion.arm.compiled`, a call per stage): the IK of all samples at
once where the branch is beyond doubt (`ArmKinematics.solve_many`), one by one near a branch
boundary; the same samples and joints either way. Its cost is bounded: at most
200 first samples, refinement to `MAX_SAMPLES`, a TOPP-RA grid sized by the path (at most
`TOPPRA_GRID` points), and paths longer than any within the arm's reach refused before they are
sampled (`CartesianPlanner.check_length`).
"""
from __future__ import annotations

import functools
import logging
import math
from dataclasses import dataclass
from typing import Callable, Protocol, TypeGuard

import numpy as np
import pinocchio as pin
import toppra as ta     # at start-up: the import takes most of a second, never in a request
from scipy.interpolate import PPoly
from scipy.linalg import lapack

from acti_motion.arm import compiled
from acti_motion.arm.kinematics import ArmKinematics, Unreachable, wrap
from acti_motion.arm.poses import Frames
from acti_motion.profiles import Trapezoid
from acti_sim.world import World

logging.getLogger("toppra").setLevel(logging.WARNING)
# Every TOPPRA(...) asks importlib whether qpoases and cvxpy are installed (~0.25 ms of a plan,
# more with a long sys.path): the answer cannot change within a process.
ta.solverwrapper.available_solvers = functools.lru_cache(maxsize=None)(
    ta.solverwrapper.available_solvers)

PATH_TOLERANCE_MM = 0.02
PATH_TOLERANCE_DEG = 0.01
STRAY_M2 = (PATH_TOLERANCE_MM / 1000.0) ** 2      # the tolerances as `compiled.strays` takes them
STRAY_COS = math.cos(math.radians(PATH_TOLERANCE_DEG))
MAX_JOINT_STEP = math.radians(2.0)   # between IK samples of a CP path
MAX_SAMPLES = 4000
TOPPRA_GRID = 201         # most grid points of TOPP-RA (`toppra_grid` sizes it by the path)
GRID_FLOOR = 25           # least intervals of TOPP-RA's grid
GRID_STEP_MM = 15.0       # TOPP-RA grid intervals: at most this much of the path apart,
GRID_STEP_RAD = math.radians(3.0)   # and of a turn or of the joints' travel
SAMPLE_FLOOR = 4          # least intervals of the IK samples of a CP path (more where it strays)
ELBOW_GRID_FLOOR = 4      # least intervals of the grid the elbow is carried on along a CP path
UNIT_GRID_MAPS = 32       # splines through up to this many evenly spaced samples: by a kept map
NO_TURN = 1e-12           # rad: a line's rotation below this is rounding (R1·R0ᵀ of equal R)


@dataclass(frozen=True)
class ArmSetpoint:
    """What the arm is commanded to hold: joints (rad) and the finger position (m)."""
    joints: np.ndarray
    finger: float


# --- joint paths ----------------------------------------------------------------------------------
class JointPath(Protocol):
    def q(self, s: float) -> np.ndarray: ...

    def dq(self, s: float) -> np.ndarray: ...


class LinearJointPath:
    """The joint-space straight line of PTP moves (and a standing path for gripper moves)."""

    def __init__(self, q0: np.ndarray, q1: np.ndarray) -> None:
        self.q0 = np.asarray(q0, float)
        self._delta: np.ndarray | None = np.asarray(q1, float) - self.q0
        self._delta_floats: list[float] | None = None
        self.end: np.ndarray | None = None      # q(1.0), when made in advance (`from_floats`)

    @classmethod
    def from_floats(cls, q0: np.ndarray, delta: list[float], end: list[float]) -> "LinearJointPath":
        """The line from q0 (an array) by `delta`, ending at `end` = q0 + delta in floats (the
        very values numpy's q(1.0) gives): one numpy call where the constructor and q(1.0)
        take six, 1 … 3 µs each on the cold core of a PTP accept. Its `delta` array is made
        when first read: by the run, on the simulation thread, not by the accept."""
        path = cls.__new__(cls)
        path.q0, path._delta, path._delta_floats, path.end = q0, None, delta, np.array(end)
        return path

    @property
    def delta(self) -> np.ndarray:
        delta = self._delta
        if delta is None:
            delta = self._delta = np.array(self._delta_floats)
        return delta

    def q(self, s: float) -> np.ndarray:
        if s == 1.0 and self.end is not None:
            return self.end
        return self.q0 + s * self.delta

    def dq(self, s: float) -> np.ndarray:
        return self.delta


def not_a_knot_spline(xs: np.ndarray, ys: np.ndarray) -> PPoly:
    """The cubic spline through (xs[i], ys[i]) (ys: N×dof, N ≥ 4) with not-a-knot ends: the
    one scipy's CubicSpline(xs, ys, axis=0) builds, by the same equations, without its input
    checks (a sixth of a short CP plan)."""
    return PPoly.construct_fast(not_a_knot_coefficients(xs, ys), np.asarray(xs, float))


def not_a_knot_coefficients(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """The coefficients (4 × pieces × dof, highest power first, as PPoly's) of
    `not_a_knot_spline`. The tridiagonal system goes to LAPACK's banded solver (gbsv) as
    scipy.linalg.solve_banded hands it over, without that function's checks (most of its
    cost on a short line's few points)."""
    dx = xs[1:] - xs[:-1]
    slope = (ys[1:] - ys[:-1]) / dx[:, None]
    h = dx.tolist()
    n = len(xs)
    band = np.zeros((4, n))       # gbsv's layout: a row for its fill-in, upper, main, lower
    A = band[1:]
    A[1, 1:-1] = 2.0 * (dx[:-1] + dx[1:])
    A[0, 2:] = dx[:-1]
    A[2, :-2] = dx[1:]
    b = np.empty_like(ys)
    b[1:-1] = 3.0 * (dx[1:, None] * slope[:-1] + dx[:-1, None] * slope[1:])
    d = h[0] + h[1]
    A[1, 0], A[0, 1] = h[1], d
    b[0] = ((h[0] + 2 * d) * h[1] * slope[0] + h[0] ** 2 * slope[1]) / d
    d = h[-1] + h[-2]
    A[1, -1], A[2, -2] = h[-2], d
    b[-1] = (h[-1] ** 2 * slope[-2] + (2 * d + h[-1]) * h[-2] * slope[-1]) / d
    _, _, ds, info = lapack.dgbsv(1, 1, band, b, overwrite_ab=True, overwrite_b=True)
    if info:
        raise np.linalg.LinAlgError(f"singular spline system (gbsv info {info})")
    dxc = dx[:, None]
    t = (ds[:-1] + ds[1:] - 2.0 * slope) / dxc
    c = np.empty((4, n - 1, ys.shape[1]))
    c[0] = t / dxc
    c[1] = (slope - ds[:-1]) / dxc - t
    c[2] = ds[:-1]
    c[3] = ys[:-1]
    return c


def not_a_knot_on_unit_grid(ys: np.ndarray) -> np.ndarray:
    """`not_a_knot_coefficients(unit_grid(len(ys)), ys)` (a CP plan's first samples): the
    coefficients are linear in ys, so for up to UNIT_GRID_MAPS points by one product with
    that map, solved once per number of points. The map takes ys less its first row (a
    constant's derivatives are 0 then to the last bit, as the solve gives them: a move that
    stays ends exactly where it starts) and the pieces start exactly at the samples."""
    n = len(ys)
    if n > UNIT_GRID_MAPS:
        return not_a_knot_coefficients(unit_grid(n), ys)
    return compiled.unit_grid_coefficients(_unit_grid_map(n), ys)


@functools.lru_cache(maxsize=None)
def _unit_grid_map(n: int) -> np.ndarray:
    """(3 × n−1 × n): the x³, x², x coefficients of the splines through each unit vector on
    unit_grid(n)."""
    return not_a_knot_coefficients(unit_grid(n), np.eye(n))[:3].copy()


@functools.lru_cache(maxsize=256)
def unit_grid(n: int) -> np.ndarray:
    """np.linspace(0.0, 1.0, n) for n ≥ 2, the same values (its arithmetic), without the cost
    of its general form; kept per n, read-only (twice in every CP plan, a few sizes)."""
    grid = np.arange(n, dtype=float) * (1.0 / (n - 1))
    grid[-1] = 1.0
    grid.flags.writeable = False
    return grid


_D1 = np.array([3.0, 2.0, 1.0])[:, None, None]    # a cubic's coefficients → its derivatives
_D2 = np.array([6.0, 2.0])[:, None, None]


class SplineJointPath:
    """A cubic spline through IK samples (s_i, q_i) of a Cartesian path."""

    def __init__(self, ss: np.ndarray, qs: np.ndarray, c: np.ndarray | None = None) -> None:
        """`c`: the spline's coefficients when the caller has them (`not_a_knot_coefficients`);
        kept, as PPoly's `c` property converts its array on every reading."""
        self.ss, self.qs = ss, qs
        self.c = not_a_knot_coefficients(ss, qs) if c is None else c
        self.spline = PPoly.construct_fast(self.c, ss)
        self._d1: PPoly | None = None
        self._d2: PPoly | None = None

    @property
    def d1(self) -> PPoly:
        """q'(s), built when first asked for (by the run, or by a timing check the bounds did
        not settle): PPoly.derivative's coefficients, without its checks."""
        if self._d1 is None:
            self._d1 = PPoly.construct_fast(self.c[:-1] * _D1, self.ss)
        return self._d1

    @property
    def d2(self) -> PPoly:
        """q''(s), as `d1`."""
        if self._d2 is None:
            self._d2 = PPoly.construct_fast(self.c[:-2] * _D2, self.ss)
        return self._d2

    def q(self, s: float) -> np.ndarray:
        """q(s): PPoly's floats, in one compiled call (the run asks every control period, an
        accept for the end)."""
        return compiled.spline_at(self.c, self.ss, s)

    def dq(self, s: float) -> np.ndarray:
        return self.d1(s)


# --- timing ---------------------------------------------------------------------------------------
class Timing(Protocol):
    duration: float

    def sample(self, t: float) -> tuple[float, float]: ...


class _PathParameter:
    """s itself as a one-axis path: ParametrizeConstAccel over it yields s(t) and ds/dt."""
    dof = 1

    def __call__(self, ss: float | np.ndarray, order: int = 0) -> np.ndarray:
        ss = np.atleast_1d(np.asarray(ss, float))
        return (ss if order == 0 else np.full(len(ss), 1.0 if order == 1 else 0.0))[:, None]


class ConstAccelTiming:
    """TOPP-RA's path velocities at its grid points, constant path acceleration in between
    (toppra's ParametrizeConstAccel, which keeps the acceleration limits between grid points)."""

    def __init__(self, gridpoints: np.ndarray, velocities: np.ndarray) -> None:
        v = np.maximum(np.asarray(velocities, float), 0.0)
        if np.any(v[:-1] + v[1:] <= 0.0):
            raise Unreachable("the time-optimal timing stops inside the path")
        self._p = ta.parametrizer.ParametrizeConstAccel(_PathParameter(), gridpoints, v)
        self.duration = float(self._p.duration)

    def sample(self, t: float) -> tuple[float, float]:
        if t >= self.duration:
            return 1.0, 0.0
        t = max(t, 0.0)
        return float(self._p(t)[0]), float(self._p(t, 1)[0])


# --- the motion the executor runs -------------------------------------------------------------------
class ArmMotion:
    """A joint path timed by a profile; the finger goes from finger0 to finger1 along s.
    `ramp` is the accel time pause and stop use for it; `kind` is "joint", "cartesian", "gripper"."""

    def __init__(self, path: JointPath, timing: Timing, finger0: float, finger1: float,
                 ramp: float, kind: str) -> None:
        self.path, self.timing, self.ramp, self.kind = path, timing, ramp, kind
        self.finger0, self.dfinger = finger0, finger1 - finger0
        self.duration = timing.duration
        self.limits_checked: np.ndarray | None = None   # the soft limits its plan was checked with
        self._applied: tuple[float, ArmSetpoint] | None = None
        self._end: ArmSetpoint | None = None

    def at(self, t: float) -> ArmSetpoint:
        applied = self._applied
        if applied is not None and applied[0] == t:     # the soft-limit watch, after `apply`
            return applied[1]
        if t >= self.duration:      # every timing is at s = 1 there; the queue asks it twice
            if self._end is None:
                self._end = ArmSetpoint(self.path.q(1.0), self.finger0 + self.dfinger)
            return self._end
        s, _ = self.timing.sample(t)
        return ArmSetpoint(self.path.q(s), self.finger0 + s * self.dfinger)

    def apply(self, world: World, t: float, rate: float) -> None:
        s, ds = self.timing.sample(t)
        point = ArmSetpoint(self.path.q(s), self.finger0 + s * self.dfinger)
        self._applied = (t, point)
        world.set_arm_targets(point.joints, rate * ds * self.path.dq(s))
        if self.dfinger:
            world.set_gripper_target(point.finger)


# --- Cartesian paths of the control point (robot frame, m) ---------------------------------------
class CartesianPath(Protocol):
    """What the planner takes as a path: the pose (4×4) and the position at progress s ∈ [0, 1],
    its length (m) and its rotation angle (rad). `LinePath` and `ArcPath`, or a program's path."""
    length: float
    angle: float

    def pose(self, s: float) -> np.ndarray: ...

    def position(self, s: float) -> np.ndarray: ...


class LinePath:
    """Straight line and rotation geodesic, both linear in s."""

    def __init__(self, P0: np.ndarray, P1: np.ndarray) -> None:
        self.p0, self.dp = P0[:3, 3].copy(), P1[:3, 3] - P0[:3, 3]
        self.R0 = P0[:3, :3].copy()
        self.w = pin.log3(P1[:3, :3] @ self.R0.T)
        self.length = math.hypot(*self.dp.tolist())
        self.angle = math.hypot(*self.w.tolist())

    def positions(self, ss: np.ndarray) -> np.ndarray:
        """Positions at each s (N×3)."""
        return compiled.line_positions(self.p0, self.dp, np.asarray(ss, float))

    def poses(self, ss: np.ndarray) -> np.ndarray:
        """Poses at each s (N×4×4)."""
        return compiled.line_poses(self.p0, self.dp, self.R0, self.w, self.angle > NO_TURN,
                                   np.asarray(ss, float))

    def position(self, s: float) -> np.ndarray:
        return self.positions(np.array([s]))[0]

    def pose(self, s: float) -> np.ndarray:
        return self.poses(np.array([s]))[0]


class ArcPath(LinePath):
    """Circular arc from P0 through the point `via` to P1; the orientation follows the geodesic
    from P0's to P1's, linearly in arc length."""

    def __init__(self, P0: np.ndarray, via: np.ndarray, P1: np.ndarray) -> None:
        super().__init__(P0, P1)
        a, b, c = P0[:3, 3], np.asarray(via, float), P1[:3, 3]
        ab, ac = b - a, c - a
        normal = np.cross(ab, ac)
        scale = np.linalg.norm(ab) * np.linalg.norm(ac)
        if scale < 1e-12 or np.linalg.norm(normal) < 1e-6 * scale:
            raise ValueError("the start, via and end points are on one line (or coincide): "
                             "no circle passes through them")
        n2 = float(np.dot(normal, normal))
        self.center = a + (np.dot(ab, ab) * np.cross(ac, normal)
                           + np.dot(ac, ac) * np.cross(normal, ab)) / (2 * n2)
        self.normal = normal / math.sqrt(n2)
        self.radius = float(np.linalg.norm(a - self.center))
        r0, r1 = a - self.center, c - self.center
        self.sweep = math.atan2(float(np.dot(np.cross(r0, r1), self.normal)),
                                float(np.dot(r0, r1))) % (2 * math.pi)
        self.length = self.radius * self.sweep
        self._r0 = r0

    def positions(self, ss: np.ndarray) -> np.ndarray:
        ss = np.asarray(ss, float)
        return self.center + compiled.rotate_rows(self.normal[None], ss * self.sweep,
                                                  self._r0[None])

    def poses(self, ss: np.ndarray) -> np.ndarray:
        ss = np.asarray(ss, float)
        return compiled.geodesic_poses(self.R0, self.w, self.angle > NO_TURN, ss,
                                       self.positions(ss))


def _own(path: CartesianPath) -> TypeGuard[LinePath]:
    """A path of this module: poses at once, and `length` is the control point's path length
    (the programs' paths define only `pose`, and their length is the tool point's)."""
    return type(path) in (LinePath, ArcPath)


def poses_along(path: CartesianPath, ss: np.ndarray) -> np.ndarray:
    """Poses of `path` at each s: at once for the paths of this module, one by one for others."""
    if _own(path):
        return path.poses(ss)
    return np.array([path.pose(s) for s in ss])


def positions_along(path: CartesianPath, ss: np.ndarray) -> np.ndarray:
    """Positions of `path` at each s (N×3), as `poses_along`."""
    if _own(path):
        return path.positions(ss)
    return np.array([path.position(s) for s in ss])


def convex_checkpoints(path: CartesianPath, intervals: int) -> np.ndarray:
    """Positions of `path` (N×3) that tell whether it keeps to a convex region (the soft-limit
    box, the reach's ball) and where it first leaves one: a line's two ends (a line leaves a
    convex region at most once, so its end is outside if and only if it does), else the
    positions at `intervals` + 1 evenly spaced points."""
    if isinstance(path, LinePath):
        return positions_along(path, np.array([0.0, 1.0]))
    return positions_along(path, np.linspace(0.0, 1.0, intervals + 1))


# --- planning ---------------------------------------------------------------------------------------
@dataclass(frozen=True)
class CartesianLimits:
    """Nominal CP profile (control point speeds, accel time) and the joint limits it must keep."""
    speed: float              # m/s
    angular_speed: float      # rad/s (orientation and elbow)
    ramp: float               # s
    joint_velocity: np.ndarray  # rad/s
    joint_accel: np.ndarray     # rad/s²


@dataclass
class CartesianPlan:
    path: SplineJointPath
    timing: Timing
    retimed: bool             # TOPP-RA timing instead of the nominal trapezoid


class CartesianPlanner:
    """Turns a control-point path into a joint spline and a timing (see the module notes)."""

    def __init__(self, kin: ArmKinematics) -> None:
        self.kin = kin

    def plan(self, path: CartesianPath, frames: Frames, start_q: np.ndarray,
             limits: CartesianLimits, *, psi: float | None = None,
             turn: float = 0.0) -> CartesianPlan:
        """Joint spline and timing that move the control point along `path` (robot frame) while
        the elbow, carried along without twist, turns by `turn` (rad) or, when `psi` is given,
        by what it takes to end at the arm angle `psi`."""
        elbow = self._elbow_plan(path, frames.flange_of, start_q, psi, turn)
        turn = elbow.turn
        spline = self._sample(path, frames, start_q, elbow)
        extents = [path.length, path.angle, abs(turn)]
        speeds = [limits.speed, limits.angular_speed, limits.angular_speed]
        nominal = Trapezoid.for_axes(extents, speeds, limits.ramp)
        if keeps_limits(spline, nominal, limits):
            return CartesianPlan(spline, nominal, False)
        timing = time_optimal(spline.ss, spline.qs, np.array(extents), limits)
        return CartesianPlan(spline, timing, True)

    def reach_radius(self, frames: Frames) -> float:
        """Radius (m) of the ball about the shoulder that holds every control point the arm
        reaches: arm, hand and the control-point offset."""
        return self.kin.reach + self.kin.hand + frames.tool_reach

    def check_length(self, path: CartesianPath, frames: Frames) -> None:
        """Unreachable when `path` (a line or arc of this module) is longer than any path within
        the arm's reach: every control point lies within reach + hand + the control-point
        offset of the shoulder, and no line or arc inside a ball of radius r is longer than 2πr.
        This bounds every sampling of what is accepted (an arc through a via point almost on
        the line runs the long way round a huge circle)."""
        radius = self.reach_radius(frames)
        if _own(path) and path.length > 2 * math.pi * radius:
            raise Unreachable(f"out of reach: the path is {path.length * 1e3:.0f} mm long, and no "
                              f"path within the arm's reach is longer than "
                              f"{2 * math.pi * radius * 1e3:.0f} mm")

    # --- the elbow along the path: transported without twist, plus an even turn to the target ---
    def _elbow_plan(self, path: CartesianPath, to_flange: Callable[[np.ndarray], np.ndarray],
                    start_q: np.ndarray, psi: float | None, turn: float) -> "_ElbowPlan":
        kin = self.kin
        grid = unit_grid(1 + min(128, max(ELBOW_GRID_FLOOR, math.ceil(path.length / 0.005),
                                          math.ceil(path.angle / 0.02))))
        us, ns = compiled.carry_elbow(to_flange(poses_along(path, grid)),
                                      kin.elbow_direction(start_q)[1], kin.shoulder, kin.hand)
        if psi is not None:
            turn = wrap(psi - kin.angle_of(us[-1], ns[-1]))
        return _ElbowPlan(grid, ns, turn)

    def _sample(self, path: CartesianPath, frames: Frames, start_q: np.ndarray,
                elbow: _ElbowPlan) -> SplineJointPath:
        kin, ik = self.kin, _PathIK(self.kin, path, frames, elbow)
        count = 1 + max(SAMPLE_FLOOR, math.ceil(path.length / 0.02), math.ceil(path.angle / 0.1),
                        math.ceil(abs(elbow.turn) / 0.1))
        ss = first = unit_grid(min(count, 200))
        qs = ik.chain(ss, np.asarray(start_q, float))
        # refine where a joint steps too far (a fast joint near a singularity, or a branch jump)
        for _ in range(40):
            todo = compiled.long_steps(qs, MAX_JOINT_STEP)
            if not len(todo):
                break
            ss, qs = _insert(ss, qs, todo, ik.between)
            if len(ss) > MAX_SAMPLES or np.min(np.diff(ss)) < 1e-7:
                raise Unreachable("the path runs through a singularity (a joint would jump)")
        # refine where the spline strays from the path
        for _ in range(8):
            c = not_a_knot_on_unit_grid(qs) if ss is first else not_a_knot_coefficients(ss, qs)
            strays = compiled.spline_strays(
                c, ss, poses_along(path, (ss[:-1] + ss[1:]) / 2), frames.base_inverse,
                frames.tool, kin.shoulder, kin.upper_arm, kin.forearm, kin.hand, STRAY_M2,
                STRAY_COS)
            if not strays.any():
                return SplineJointPath(ss, qs, c)
            ss, qs = _insert(ss, qs, np.flatnonzero(strays), ik.between)
        return SplineJointPath(ss, qs)


def keeps_limits(spline: SplineJointPath, nominal: Trapezoid, limits: CartesianLimits) -> bool:
    """Whether the joints keep their velocity and acceleration limits along `spline` timed by
    the nominal profile: at 401 instants (`samples_keep_limits`), decided at once where bounds
    over the whole path already say so (`bounds_keep_limits`, a short CP line's usual case)."""
    return (nominal.duration <= 0.0 or bounds_keep_limits(spline, nominal, limits)
            or samples_keep_limits(spline, nominal, limits))


def samples_keep_limits(spline: SplineJointPath, nominal: Trapezoid,
                        limits: CartesianLimits) -> bool:
    """The joints' velocity and acceleration at 401 instants of the profile within the limits."""
    s, sd, sdd = nominal.sample_many(np.linspace(0.0, nominal.duration, 401))
    d1, d2 = spline.d1(s), spline.d2(s)
    qd = d1 * sd[:, None]
    qdd = d2 * (sd ** 2)[:, None] + d1 * sdd[:, None]
    return bool(np.all(np.abs(qd) <= limits.joint_velocity * (1 + 1e-6))
                and np.all(np.abs(qdd) <= limits.joint_accel * (1 + 1e-3)))


def bounds_keep_limits(spline: SplineJointPath, nominal: Trapezoid,
                       limits: CartesianLimits) -> bool:
    """A sufficient condition for `samples_keep_limits`, in a few numpy calls: with |q'(s)| ≤ M1
    and |q''(s)| ≤ M2 over the whole cubic spline (bounds per piece: q' is a quadratic, q''
    linear, on [0, h]), ṡ ≤ the profile's peak v and |s̈| ≤ v / ramp, the joint velocity q'ṡ is
    within M1·v and the acceleration q''ṡ² + q's̈ within M2·v² + M1·v / ramp. Where these
    bounds keep the limits, so does every sample the full check would take."""
    return nominal.ramp > 0.0 and compiled.bounds_keep(
        spline.c, spline.ss, nominal.peak, nominal.ramp, limits.joint_velocity,
        limits.joint_accel)


def spline_within(spline: SplineJointPath, lower: np.ndarray, upper: np.ndarray) -> bool:
    """Whether a cubic spline stays within [lower, upper] (per axis) between its first and last
    breakpoints, by a bound per piece: q(x) = c₃ + c₂x + x²(c₁ + c₀x) on [0, h] is within
    h²(|c₁| + h|c₀|) of the chord c₃ + c₂x. A sufficient condition: False says nothing."""
    return compiled.within(spline.c, spline.ss, lower, upper)


@dataclass
class _ElbowPlan:
    grid: np.ndarray
    base: np.ndarray     # transported elbow directions on the grid
    turn: float

    def directions(self, ss: np.ndarray, flanges: np.ndarray, kin: ArmKinematics) -> np.ndarray:
        """The elbow direction at each s (flange poses there: N×4×4), normal to the
        shoulder-wrist direction there."""
        return compiled.elbow_directions(flanges, ss, self.grid, self.base, self.turn,
                                         kin.shoulder, kin.hand)


class _PathIK:
    """The joints along a Cartesian path: each sample the IK solution nearest to a reference
    (the sample before it). Many samples are solved at once where `ArmKinematics.solve_many`
    decides alone, else one by one with `ArmKinematics.solve` (same answers, and the reason
    when there is none)."""

    def __init__(self, kin: ArmKinematics, path: CartesianPath, frames: Frames,
                 elbow: _ElbowPlan) -> None:
        self.kin, self.path, self.frames, self.elbow = kin, path, frames, elbow

    def _targets(self, ss: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        flanges = self.frames.flange_of(poses_along(self.path, ss))
        return flanges, self.elbow.directions(ss, flanges, self.kin)

    def _one(self, s: float, flange: np.ndarray, elbow_dir: np.ndarray,
             ref: np.ndarray) -> np.ndarray:
        try:
            return self.kin.solve(flange, ref, elbow_dir=elbow_dir)
        except Unreachable as e:
            raise Unreachable(f"at {100 * s:.1f} % of the path: {e}") from None

    def chain(self, ss: np.ndarray, start_q: np.ndarray) -> np.ndarray:
        """Joints at ss (ss[0] = 0 is start_q), each solved from the one before."""
        flanges, dirs = self._targets(ss[1:])
        batch, ok = self.kin.solve_many(flanges, dirs, start_q, chained=True)
        if ok[-1]:                  # a leading run: all of them (a short line's usual case)
            return np.concatenate([start_q[None], batch])
        qs = [start_q, *batch[ok]]
        for i in range(int(np.sum(ok)), len(flanges)):
            qs.append(self._one(ss[i + 1], flanges[i], dirs[i], qs[-1]))
        return np.array(qs)

    def between(self, ss: np.ndarray, refs: np.ndarray) -> np.ndarray:
        """Joints at ss, each solved from refs[i]."""
        flanges, dirs = self._targets(ss)
        qs, ok = self.kin.solve_many(flanges, dirs, refs, chained=False)
        for i in np.flatnonzero(~ok):
            qs[i] = self._one(ss[i], flanges[i], dirs[i], refs[i])
        return qs


def toppra_grid(ss: np.ndarray, qs: np.ndarray, extents: np.ndarray) -> int:
    """Grid points of TOPP-RA for a joint path through (ss, qs) along Cartesian `extents`
    (length m, angle rad, elbow turn rad): one interval per `GRID_STEP_MM` of the path, per
    `GRID_STEP_RAD` of its turns and of its joints' travel (the IK samples lie denser where the
    joints bend), between `GRID_FLOOR` and `TOPPRA_GRID` - 1. TOPP-RA's cost grows with the grid
    (~20 µs a point); what a coarser grid lets through between its points is caught and
    scaled away by `_kept_between` (a 1,000 mm line: 68 points, 0.1 % slower than 201)."""
    travel = float(np.sum(np.max(np.abs(np.diff(qs, axis=0)), axis=1))) if len(qs) > 1 else 0.0
    intervals = max(GRID_FLOOR, math.ceil(extents[0] * 1000.0 / GRID_STEP_MM),
                    math.ceil(max(extents[1], extents[2], travel) / GRID_STEP_RAD))
    return 1 + min(TOPPRA_GRID - 1, intervals)


def time_optimal(ss: np.ndarray, qs: np.ndarray, extents: np.ndarray,
                 limits: CartesianLimits, grid: int | None = None) -> ConstAccelTiming:
    """TOPP-RA timing of the joint spline under the joint limits and the nominal Cartesian
    speed and acceleration (as three extra axes that grow linearly in s), on `grid` points
    (None: `toppra_grid`'s), checked between them (`_kept_between`)."""
    way = np.hstack([qs, ss[:, None] * extents[None, :]])
    path = ta.SplineInterpolator(ss, way)
    cart_v = np.array([limits.speed, limits.angular_speed, limits.angular_speed])
    vlim = np.concatenate([limits.joint_velocity, cart_v])
    alim = np.concatenate([limits.joint_accel, cart_v / limits.ramp])
    constraints = _limit_constraints(tuple(vlim), tuple(alim))
    gridpoints = np.linspace(ss[0], ss[-1], toppra_grid(ss, qs, extents) if grid is None else grid)
    instance = ta.algorithm.TOPPRA(constraints, path, gridpoints=gridpoints,
                                   solver_wrapper="seidel", parametrizer="ParametrizeConstAccel")
    sd = instance.compute_parameterization(0.0, 0.0)[1]
    if sd is None or np.any(np.isnan(sd)):
        raise Unreachable("no timing keeps the joint limits along this path")
    sd = np.maximum(sd, 0.0)
    return ConstAccelTiming(gridpoints, sd * _kept_between(path, gridpoints, sd, vlim, alim))


def _kept_between(path: Callable[..., np.ndarray], gridpoints: np.ndarray, sd: np.ndarray,
                  vlim: np.ndarray, alim: np.ndarray, per_interval: int = 8) -> float:
    """The factor (≤ 1) by which to scale the path velocities `sd` at `gridpoints` so that
    the velocity and acceleration limits hold between the grid points too, where TOPP-RA does
    not look: constant path acceleration in each interval (ParametrizeConstAccel), so sd² is
    linear in s there; checked at `per_interval` points of each. Scaling the path velocity by
    k scales the joints' velocities by k and their accelerations by k²."""
    h = np.diff(gridpoints)
    u = (sd[1:] ** 2 - sd[:-1] ** 2) / (2 * h)                 # path acceleration per interval
    t = np.linspace(0.0, 1.0, per_interval + 1)[:-1]
    ds = (h[:, None] * t).ravel()
    i = np.repeat(np.arange(len(h)), per_interval)
    s = gridpoints[i] + ds
    v = np.sqrt(np.maximum(sd[i] ** 2 + 2 * u[i] * ds, 0.0))
    d1, d2 = path(s, 1), path(s, 2)
    velocity = float(np.max(np.abs(d1 * v[:, None]) / vlim))
    accel = float(np.max(np.abs(d2 * (v ** 2)[:, None] + d1 * u[i][:, None]) / alim))
    return 1.0 / max(1.0, velocity, math.sqrt(accel))


@functools.lru_cache(maxsize=16)
def _limit_constraints(vlim: tuple[float, ...], alim: tuple[float, ...]) -> list:
    """TOPP-RA's symmetric velocity and acceleration constraints, built once per set of limits
    (building one formats its limits as text, a good part of a plan's cost; they keep no
    state of a plan, so plans on any thread share them)."""
    v, a = np.array(vlim), np.array(alim)
    return [ta.constraint.JointVelocityConstraint(np.stack([-v, v], axis=1)),
            ta.constraint.JointAccelerationConstraint(np.stack([-a, a], axis=1))]


def _insert(ss: np.ndarray, qs: np.ndarray, where: np.ndarray,
            solve: Callable[[np.ndarray, np.ndarray], np.ndarray]
            ) -> tuple[np.ndarray, np.ndarray]:
    """Insert the midpoints of the intervals `where`, solved from their left samples."""
    mids = (ss[where] + ss[where + 1]) / 2
    return np.insert(ss, where + 1, mids), np.insert(qs, where + 1, solve(mids, qs[where]), axis=0)

