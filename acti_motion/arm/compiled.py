"""The CP plan's arithmetic on a few poses, compiled (numba): the analytic IK of the SRS arm with
its forward-kinematics self-check, the elbow carried along a path, a line's poses, and the
joint spline's checks.

Why compiled: each stage is a dozen numpy calls on arrays of 4 to 8 rows, and a numpy call costs
1 … 3 µs whatever its size, so a 20 mm CP accept spent ~0.3 ms in call overheads
(docs/experiments.md). A kernel does a stage in one call of ~1 µs.

The signatures are given, so the kernels are compiled (or loaded from numba's cache beside this
file) when this module is imported, at start-up, never in a request, and a call with other
types fails instead of compiling. `make setup` fills the cache (`python -m
acti_motion.arm.compiled`). Inputs are read-only views of any layout; rows of an input with one
row serve every row of the others (a broadcast).
"""
from __future__ import annotations

import math

import numpy as np
from numba import boolean, float64, njit, types

CLEAR = 0.2                   # rad: θ2, θ4, θ6 this far from 0 leave no doubt about the branch
TWO_PI = 2.0 * math.pi

_A1 = types.Array(float64, 1, "A", readonly=True)
_A2 = types.Array(float64, 2, "A", readonly=True)
_A3 = types.Array(float64, 3, "A", readonly=True)
# The GIL kept: a kernel runs ~1 µs, and releasing it would let another thread (the simulation's)
# take the GIL in the middle of an accept.
_KERNEL = {"cache": True, "error_model": "numpy"}


def _kernel(signature):
    return njit(signature, **_KERNEL)


# --- rotations ------------------------------------------------------------------------------------
@njit(cache=True, inline="always")
def _rzy(a: float, b: float) -> np.ndarray:
    """Rotation about z by a, then about the new y by b."""
    ca, sa, cb, sb = math.cos(a), math.sin(a), math.cos(b), math.sin(b)
    return np.array([[ca * cb, -sa, ca * sb], [sa * cb, ca, sa * sb], [-sb, 0.0, cb]])


@njit(cache=True, inline="always")
def _mat3(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    out = np.empty((3, 3))
    for i in range(3):
        for j in range(3):
            out[i, j] = A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j]
    return out


@njit(cache=True, inline="always")
def _mat4(A: np.ndarray, B: np.ndarray) -> np.ndarray:
    out = np.empty((4, 4))
    for i in range(4):
        for j in range(4):
            out[i, j] = (A[i, 0] * B[0, j] + A[i, 1] * B[1, j] + A[i, 2] * B[2, j]
                         + A[i, 3] * B[3, j])
    return out


@njit(cache=True, inline="always")
def _clip_unit(x: float) -> float:
    return min(max(x, -1.0), 1.0)


@_kernel(float64[:, ::1](_A2, _A1, _A2))
def rotate_rows(axes: np.ndarray, angles: np.ndarray, v: np.ndarray) -> np.ndarray:
    """Each vector v[i] turned by angles[i] about the unit axes[i] (Rodrigues)."""
    n = len(angles)
    out = np.empty((n, 3))
    for i in range(n):
        k, x = axes[i % len(axes)], v[i % len(v)]
        c, s = math.cos(angles[i]), math.sin(angles[i])
        kx = (k[1] * x[2] - k[2] * x[1], k[2] * x[0] - k[0] * x[2], k[0] * x[1] - k[1] * x[0])
        along = (k[0] * x[0] + k[1] * x[1] + k[2] * x[2]) * (1.0 - c)
        for j in range(3):
            out[i, j] = x[j] * c + kx[j] * s + k[j] * along
    return out


# --- poses ---------------------------------------------------------------------------------------
@_kernel(float64[:, ::1](_A2, _A2))
def relative_pose(start: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """The Cartesian Rel rule: the pose with R = ΔR·R₀ and p = p₀ + Δp (4×4 each)."""
    out = np.eye(4)
    out[:3, :3] = _mat3(delta[:3, :3], start[:3, :3])
    for r in range(3):
        out[r, 3] = start[r, 3] + delta[r, 3]
    return out


# --- forward kinematics ---------------------------------------------------------------------------
@_kernel(float64[:, :, ::1](_A2, _A1, float64, float64, float64))
def flange_poses(qs: np.ndarray, shoulder: np.ndarray, upper_arm: float, forearm: float,
                 hand: float) -> np.ndarray:
    """Flange poses (N×4×4) of the postures qs (N×7) of the SRS arm: shoulder point, link
    lengths along z (read off the model by ArmKinematics)."""
    out = np.zeros((len(qs), 4, 4))
    for i in range(len(qs)):
        q = qs[i]
        R = _rzy(q[0], q[1])
        p = shoulder + upper_arm * R[:, 2]
        R = _mat3(R, _rzy(q[2], q[3]))
        p = p + forearm * R[:, 2]
        R = _mat3(R, _rzy(q[4], q[5]))
        p = p + hand * R[:, 2]
        c, s = math.cos(q[6]), math.sin(q[6])
        for r in range(3):
            out[i, r, 0] = R[r, 0] * c + R[r, 1] * s
            out[i, r, 1] = -R[r, 0] * s + R[r, 1] * c
            out[i, r, 2] = R[r, 2]
            out[i, r, 3] = p[r]
        out[i, 3, 3] = 1.0
    return out


@_kernel(boolean[::1](_A3, _A3))
def reproduces(got: np.ndarray, want: np.ndarray) -> np.ndarray:
    """Whether each pose of `got` is `want`'s (N×4×4) up to rounding: the IK's self-check
    (position within 1e-7 m, each rotation element within 1e-6)."""
    ok = np.empty(len(got), dtype=np.bool_)
    for i in range(len(got)):
        pos = rot = 0.0
        for r in range(3):
            pos = max(pos, abs(got[i, r, 3] - want[i, r, 3]))
            for c in range(3):
                rot = max(rot, abs(got[i, r, c] - want[i, r, c]))
        ok[i] = pos <= 1e-7 and rot <= 1e-6
    return ok


# --- inverse kinematics ---------------------------------------------------------------------------
@_kernel(float64[:, ::1](_A2, _A2, _A3, _A2, _A2, _A1, float64, float64))
def branches(elbow: np.ndarray, wrist: np.ndarray, flanges: np.ndarray, signs: np.ndarray,
             ref: np.ndarray, shoulder: np.ndarray, upper_arm: float,
             forearm: float) -> np.ndarray:
    """Joint angles (N×7) of the branches with the signs (of θ2, θ4, θ6) for elbow and wrist
    points and flange rotations. Where a branch is singular (sin θ2, θ4 or θ6 near 0) the free
    angle is the reference's."""
    n = max(len(elbow), len(wrist), len(flanges), len(signs), len(ref))
    out = np.empty((n, 7))
    for i in range(n):
        e, w = elbow[i % len(elbow)], wrist[i % len(wrist)]
        F, sg, r = flanges[i % len(flanges)], signs[i % len(signs)], ref[i % len(ref)]
        s2, s4, s6 = sg[0], sg[1], sg[2]
        ua = (e - shoulder) / upper_arm
        t2 = math.acos(_clip_unit(ua[2]))
        if math.sin(t2) < 1e-9:
            t1 = r[0]
        else:
            t1 = math.atan2(ua[1], ua[0]) + (math.pi if s2 < 0 else 0.0)
        t2 = s2 * t2
        f = (w - e) / forearm
        r12 = _rzy(t1, t2)
        f2 = np.empty(3)
        for k in range(3):
            f2[k] = r12[0, k] * f[0] + r12[1, k] * f[1] + r12[2, k] * f[2]
        t4 = s4 * math.acos(_clip_unit(f2[2]))
        if abs(math.sin(t4)) < 1e-9:
            t3 = r[2]
        else:
            t3 = math.atan2(s4 * f2[1], s4 * f2[0])
        r14 = _mat3(r12, _rzy(t3, t4))
        rw = np.empty((3, 3))                  # r14ᵀ · R
        for a in range(3):
            for b in range(3):
                rw[a, b] = r14[0, a] * F[0, b] + r14[1, a] * F[1, b] + r14[2, a] * F[2, b]
        t6 = s6 * math.acos(_clip_unit(rw[2, 2]))
        if abs(math.sin(t6)) < 1e-9:
            t5 = r[4]
            t7 = math.atan2(rw[1, 0], rw[0, 0]) - r[4]
        else:
            t5 = math.atan2(s6 * rw[1, 2], s6 * rw[0, 2])
            t7 = math.atan2(s6 * rw[2, 1], -s6 * rw[2, 0])
        out[i, 0], out[i, 1], out[i, 2], out[i, 3] = t1, t2, t3, t4
        out[i, 4], out[i, 5], out[i, 6] = t5, t6, t7
    return out


@njit(cache=True, inline="always")
def _wrist(F: np.ndarray, hand: float) -> np.ndarray:
    return np.array([F[0, 3] - hand * F[0, 2], F[1, 3] - hand * F[1, 2],
                     F[2, 3] - hand * F[2, 2]])


@_kernel(types.Tuple((float64[:, ::1], boolean[::1]))(
    _A3, _A2, _A2, boolean, _A1, float64, float64, float64, float64, float64, _A1, _A1))
def solve_poses(flanges: np.ndarray, elbow_dirs: np.ndarray, reference: np.ndarray,
                chained: bool, shoulder: np.ndarray, upper_arm: float, forearm: float,
                hand: float, reach: float, min_reach: float, lower: np.ndarray,
                upper: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """ArmKinematics.solve_many's answer (see there): joints (N×7) of the flange poses with the
    elbows towards elbow_dirs, in the reference's branch (reference: one row, or one per pose),
    and which it solved exactly as `solve` would: the arm's geometry, reach and limits as
    ArmKinematics reads them off the model."""
    a, b = upper_arm, forearm
    n = len(flanges)
    elbow, wrist = np.empty((n, 3)), np.empty((n, 3))
    dist = np.empty(n)
    for i in range(n):
        w = _wrist(flanges[i], hand)
        v = w - shoulder
        d = max(math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]), 1e-12)
        u = v / d
        h = (a * a - b * b + d * d) / (2 * d)
        rho = math.sqrt(max(a * a - h * h, 0.0))
        e = elbow_dirs[i % len(elbow_dirs)]
        along = e[0] * u[0] + e[1] * u[1] + e[2] * u[2]
        m = e - along * u
        m = m / max(math.sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2]), 1e-12)
        elbow[i] = shoulder + h * u + rho * m
        wrist[i] = w
        dist[i] = d
    signs = np.sign(reference[:, 1::2]).copy()
    q = branches(elbow, wrist, flanges, signs, reference, shoulder, a, b)
    if chained:     # each nearest the one before: whole turns that add up along the poses
        turns = np.zeros(7)
        previous = reference[0].copy()
        for i in range(n):
            raw = q[i].copy()
            for j in range(7):
                turns[j] += np.rint((raw[j] - previous[j]) / TWO_PI)
                q[i, j] = raw[j] - TWO_PI * turns[j]
            previous = raw
    else:
        for i in range(n):
            r = reference[i % len(reference)]
            for j in range(7):
                q[i, j] = q[i, j] + TWO_PI * np.rint((r[j] - q[i, j]) / TWO_PI)
    same = reproduces(flange_poses(q, shoulder, a, b, hand), flanges)
    ok = np.empty(n, dtype=np.bool_)
    for i in range(n):
        r = reference[i % len(reference)]
        good = dist[i] <= reach + 1e-9 and dist[i] >= min_reach - 1e-9 and same[i]
        good = good and min(abs(q[i, 1]), abs(q[i, 3]), abs(q[i, 5])) > CLEAR
        good = good and min(abs(r[1]), abs(r[3]), abs(r[5])) > CLEAR
        for j in range(7):
            good = good and lower[j] - 1e-9 <= q[i, j] <= upper[j] + 1e-9
        ok[i] = good and (not chained or i == 0 or ok[i - 1])
    return q, ok


# --- the elbow along a path -----------------------------------------------------------------------
@njit(cache=True, inline="always")
def _unit_to_wrist(F: np.ndarray, shoulder: np.ndarray, hand: float) -> np.ndarray:
    """The unit direction from the shoulder to the wrist of the flange pose F."""
    v = _wrist(F, hand) - shoulder
    return v / math.sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])


@_kernel(types.Tuple((float64[:, ::1], float64[:, ::1]))(_A3, _A1, _A1, float64))
def carry_elbow(flanges: np.ndarray, n0: np.ndarray, shoulder: np.ndarray,
                hand: float) -> tuple[np.ndarray, np.ndarray]:
    """(us, ns): the unit shoulder-wrist directions of the flange poses (N×4×4) along a path,
    and the elbow direction n0 carried along them without twist (each projected normal to
    its u and scaled to length 1)."""
    us, ns = np.empty((len(flanges), 3)), np.empty((len(flanges), 3))
    n = n0.copy()
    for i in range(len(flanges)):
        u = _unit_to_wrist(flanges[i], shoulder, hand)
        d = n[0] * u[0] + n[1] * u[1] + n[2] * u[2]
        n = n - d * u
        n = n / math.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2])
        us[i], ns[i] = u, n
    return us, ns


@_kernel(float64[:, ::1](_A3, _A1, _A1, _A2, float64, _A1, float64))
def elbow_directions(flanges: np.ndarray, ss: np.ndarray, grid: np.ndarray, base: np.ndarray,
                     turn: float, shoulder: np.ndarray, hand: float) -> np.ndarray:
    """The elbow direction at each s of a path (flange poses at ss: N×4×4): the carried
    directions `base` on the even `grid` interpolated, made normal to the shoulder-wrist
    direction there and turned about it by turn·s."""
    last = len(grid) - 1
    n = len(ss)
    us, out = np.empty((n, 3)), np.empty((n, 3))
    for k in range(n):
        u = _unit_to_wrist(flanges[k], shoulder, hand)
        i = min(int(ss[k] * last), last - 1)
        f = (ss[k] - grid[i]) / (grid[i + 1] - grid[i])
        m = (1 - f) * base[i] + f * base[i + 1]
        m = m - (m[0] * u[0] + m[1] * u[1] + m[2] * u[2]) * u
        us[k] = u
        out[k] = m / math.sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2])
    if turn:
        return rotate_rows(us, turn * ss, out)
    return out


# --- a line's poses -------------------------------------------------------------------------------
@_kernel(float64[:, ::1](_A1, _A1, _A1))
def line_positions(p0: np.ndarray, dp: np.ndarray, ss: np.ndarray) -> np.ndarray:
    """p0 + s·dp at each s (N×3)."""
    out = np.empty((len(ss), 3))
    for i in range(len(ss)):
        out[i] = p0 + ss[i] * dp
    return out


@_kernel(float64[:, :, ::1](_A2, _A1, boolean, _A1, _A2))
def geodesic_poses(R0: np.ndarray, w: np.ndarray, turns: bool, ss: np.ndarray,
                   positions: np.ndarray) -> np.ndarray:
    """Poses (N×4×4) at the positions, turned from R0 by exp(s·w) (pin.exp3 of the rotation
    vector s·w, Rodrigues' formula) where `turns`, else R0's."""
    out = np.zeros((len(ss), 4, 4))
    K = np.zeros((3, 3))
    for i in range(len(ss)):
        if turns:
            x, y, z = ss[i] * w[0], ss[i] * w[1], ss[i] * w[2]
            angle = math.sqrt(x * x + y * y + z * z)
            norm = max(angle, 1e-300)
            x, y, z = x / norm, y / norm, z / norm
            K[0, 1], K[0, 2], K[1, 2] = -z, y, -x
            K[1, 0], K[2, 0], K[2, 1] = z, -y, x
            s, c = math.sin(angle), 1.0 - math.cos(angle)
            KK = _mat3(K, K)
            E = s * K + c * KK
            for r in range(3):
                E[r, r] += 1.0
            out[i, :3, :3] = _mat3(E, R0)
        else:
            out[i, :3, :3] = R0
        out[i, :3, 3] = positions[i]
        out[i, 3, 3] = 1.0
    return out


@_kernel(float64[:, :, ::1](_A1, _A1, _A2, _A1, boolean, _A1))
def line_poses(p0: np.ndarray, dp: np.ndarray, R0: np.ndarray, w: np.ndarray, turns: bool,
               ss: np.ndarray) -> np.ndarray:
    """A line's poses at each s: `geodesic_poses` at `line_positions`."""
    return geodesic_poses(R0, w, turns, ss, line_positions(p0, dp, ss))


# --- the joint spline and its checks --------------------------------------------------------------------
@_kernel(boolean[::1](_A3, _A3, float64, float64))
def strays(want: np.ndarray, got: np.ndarray, max_m2: float, min_cos: float) -> np.ndarray:
    """Which poses of `got` miss those of `want` (N×4×4 each): by more than √max_m2 in
    position, or turned by more than the angle whose cosine is min_cos ((trace(got·wantᵀ) − 1)
    / 2, the trace being the sum of the elements' products)."""
    out = np.empty(len(want), dtype=np.bool_)
    for i in range(len(want)):
        d2 = trace = 0.0
        for r in range(3):
            d = want[i, r, 3] - got[i, r, 3]
            d2 += d * d
            for c in range(3):
                trace += got[i, r, c] * want[i, r, c]
        out[i] = d2 > max_m2 or (trace - 1.0) / 2 < min_cos
    return out


@_kernel(float64[:, :, ::1](_A3, _A2))
def unit_grid_coefficients(unit_map: np.ndarray, ys: np.ndarray) -> np.ndarray:
    """The not-a-knot spline's coefficients (4 × pieces × dof, highest power first) through ys
    on an even grid, by its linear map (3 × pieces × points, the spline of each unit vector):
    the map applied to ys less its first row, and the pieces starting at the samples."""
    n, dof = ys.shape
    c = np.empty((4, n - 1, dof))
    for k in range(n - 1):
        for j in range(dof):
            for p in range(3):
                total = 0.0
                for i in range(n):
                    total += unit_map[p, k, i] * (ys[i, j] - ys[0, j])
                c[p, k, j] = total
            c[3, k, j] = ys[k, j]
    return c


@_kernel(float64[:, ::1](_A3, _A1))
def spline_middles(c: np.ndarray, ss: np.ndarray) -> np.ndarray:
    """The cubic spline (coefficients c, breakpoints ss) at the middle of each piece."""
    out = np.empty((c.shape[1], c.shape[2]))
    for k in range(c.shape[1]):
        t = (ss[k] + ss[k + 1]) / 2 - ss[k]
        for j in range(c.shape[2]):
            out[k, j] = c[3, k, j] + t * (c[2, k, j] + t * (c[1, k, j] + t * c[0, k, j]))
    return out


@_kernel(float64[::1](_A3, _A1, float64))
def spline_at(c: np.ndarray, ss: np.ndarray, s: float) -> np.ndarray:
    """The cubic spline (coefficients c, breakpoints ss) at s, as scipy's PPoly evaluates it
    (the same floats): the piece with ss[i] <= s < ss[i + 1] (the last one at its end and
    beyond, the first before it), its power series summed from the constant term up."""
    n = len(ss)
    if s >= ss[n - 1]:
        i = n - 2
    elif s < ss[0]:
        i = 0
    else:
        lo, hi = 0, n - 2
        while lo < hi:
            mid = (lo + hi + 1) // 2
            if s >= ss[mid]:
                lo = mid
            else:
                hi = mid - 1
        i = lo
    x = s - ss[i]
    out = np.empty(c.shape[2])
    for j in range(c.shape[2]):
        total, z = 0.0, 1.0
        for k in range(c.shape[0]):
            total = total + c[c.shape[0] - k - 1, i, j] * z
            z *= x
        out[j] = total
    if s != s:                            # NaN: PPoly's answer
        out[:] = np.nan
    return out


@_kernel(boolean[::1](_A3, _A1, _A3, _A2, _A2, _A1, float64, float64, float64, float64,
                      float64))
def spline_strays(c: np.ndarray, ss: np.ndarray, want: np.ndarray, to_robot: np.ndarray,
                  tool: np.ndarray, shoulder: np.ndarray, upper_arm: float, forearm: float,
                  hand: float, max_m2: float, min_cos: float) -> np.ndarray:
    """Which pieces of a joint spline miss the path at their middles (`want`: the path's
    control-point poses there) by more than `strays` lets through: the flange poses of the
    middles (`flange_poses`) as control-point poses, to_robot · F · tool (the frames' offsets:
    a product with identities is exact)."""
    flanges = flange_poses(spline_middles(c, ss), shoulder, upper_arm, forearm, hand)
    got = np.empty_like(flanges)
    for i in range(len(flanges)):
        got[i] = _mat4(_mat4(to_robot, flanges[i]), tool)
    return strays(want, got, max_m2, min_cos)


@_kernel(types.int64[::1](_A2, float64))
def long_steps(qs: np.ndarray, largest: float) -> np.ndarray:
    """The intervals between the rows of qs in which some joint steps by more than `largest`."""
    out = np.empty(len(qs) - 1, dtype=np.int64)
    count = 0
    for k in range(len(qs) - 1):
        step = 0.0
        for j in range(qs.shape[1]):
            step = max(step, abs(qs[k + 1, j] - qs[k, j]))
        if step > largest:
            out[count] = k
            count += 1
    return out[:count].copy()


@_kernel(boolean(_A3, _A1, float64, float64, _A1, _A1))
def bounds_keep(c: np.ndarray, ss: np.ndarray, peak: float, ramp: float, velocity: np.ndarray,
                accel: np.ndarray) -> bool:
    """trajectories.bounds_keep_limits's test (see there) on the spline's coefficients c
    (4 × pieces × dof, highest power first) and breakpoints ss: per joint, the bounds M1 of
    |q'| and M2 of |q''| over the pieces, M1·peak within the velocity and M2·peak² +
    M1·peak / ramp within the acceleration limit."""
    for j in range(c.shape[2]):
        m1 = m2 = 0.0
        for k in range(c.shape[1]):
            h = ss[k + 1] - ss[k]
            c0, c1, c2 = abs(c[0, k, j]), abs(c[1, k, j]), abs(c[2, k, j])
            m1 = max(m1, c2 + h * (2.0 * c1 + 3.0 * h * c0))
            m2 = max(m2, 2.0 * c1 + 6.0 * h * c0)
        if not (m1 * peak <= velocity[j] and m2 * peak * peak + m1 * peak / ramp <= accel[j]):
            return False
    return True


@_kernel(boolean(_A3, _A1, _A1, _A1))
def within(c: np.ndarray, ss: np.ndarray, lower: np.ndarray, upper: np.ndarray) -> bool:
    """trajectories.spline_within's test (see there): each piece's chord c₃ + c₂x widened by
    h²(|c₁| + h|c₀|) within [lower, upper] per joint."""
    for k in range(c.shape[1]):
        h = ss[k + 1] - ss[k]
        for j in range(c.shape[2]):
            bend = h * h * (abs(c[1, k, j]) + h * abs(c[0, k, j]))
            start, end = c[3, k, j], c[3, k, j] + h * c[2, k, j]
            if not (min(start, end) - bend >= lower[j] and max(start, end) + bend <= upper[j]):
                return False
    return True


if __name__ == "__main__":        # `make setup`: importing compiled (or loaded) every kernel
    print("acti_motion.arm.compiled: the kernels are in numba's cache")
