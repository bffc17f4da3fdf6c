"""Differential-drive base: wheel odometry, reference paths and pose-tracking motions (SI: m, rad, s).

A *path* is a reference in its own time from 0: `duration`, `pose(t)` (odometry frame),
`twist(t)` = (forward speed, yaw rate) and `peak(t0, t1)`, the largest of each over a span. A `TrackedBaseMotion` follows one on the odometry with
Kanayama's tracking law; while it runs, the rest of its path can be replaced (`splice`), which is
how a jog, a continuous move or a cruise take a new target without stopping.
"""
from __future__ import annotations

import bisect
import math
import threading
from dataclasses import dataclass
from typing import Callable, Iterable, Protocol, Sequence

import numpy as np

from acti_sim.world import World


@dataclass(frozen=True)
class Pose2D:
    x: float
    y: float
    theta: float

    def forward(self, distance: float) -> "Pose2D":
        return Pose2D(self.x + distance * math.cos(self.theta),
                      self.y + distance * math.sin(self.theta), self.theta)

    def compose(self, rel: "Pose2D") -> "Pose2D":
        """`rel`, given in this pose's frame, in the frame this pose is given in."""
        c, s = math.cos(self.theta), math.sin(self.theta)
        return Pose2D(self.x + c * rel.x - s * rel.y, self.y + s * rel.x + c * rel.y,
                      self.theta + rel.theta)

    def inverse(self) -> "Pose2D":
        c, s = math.cos(self.theta), math.sin(self.theta)
        return Pose2D(-c * self.x - s * self.y, s * self.x - c * self.y, -self.theta)

    def distance(self, other: "Pose2D") -> float:
        return math.hypot(other.x - self.x, other.y - self.y)


def wrap_angle(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


# Each wheel's travel error is modelled as random with a variance growing with the distance it
# rolled (Chong & Kleeman's model): σ² = WHEEL_VARIANCE_PER_M · |travel|. 1e-7 m²/m (0.32 mm
# after 1 m) puts the errors bench/bench_vehicle_odometry.py measures against the ground truth
# (0.25 mm after 500 mm, 4.8 mm after a 20 m square) within about 1.5 σ.
WHEEL_VARIANCE_PER_M = 1e-7


class Odometry:
    """Dead reckoning from wheel rotation, as a real base would have it (not the ground truth).

    `pose` is the spec's position: `reset` redefines it (setPosition). The dead reckoning itself
    stays continuous (REP 105's odom frame): `frame` is the odom frame's pose in the position
    frame, which each reset moves, so pose = frame ∘ (pose in odom). `covariance` (x, y, θ in
    the odom frame) grows with the wheels' travel; `twist_variance` is that of (v, w), from the
    last step's travel. `lock` makes a reset atomic with the updates.
    """

    def __init__(self, wheel_radius: float, wheel_separation: float, wheels: np.ndarray) -> None:
        self.r, self.b = wheel_radius, wheel_separation
        self._last = tuple(map(float, wheels))
        self.pose = Pose2D(0.0, 0.0, 0.0)
        self.frame = Pose2D(0.0, 0.0, 0.0)
        self._cov = (0.0,) * 6          # the covariance's upper triangle: xx xy xθ yy yθ θθ
        self.v = 0.0
        self.w = 0.0
        self.twist_variance = (0.0, 0.0)
        self.lock = threading.Lock()

    def update(self, wheels: np.ndarray, dt: float) -> None:
        left, right = map(float, wheels)        # floats: numpy scalars cost ~5x a step here
        dl, dr = (left - self._last[0]) * self.r, (right - self._last[1]) * self.r
        self._last = (left, right)
        ds, dth = (dl + dr) / 2, (dr - dl) / self.b
        with self.lock:
            p = self.pose
            mid = p.theta + dth / 2
            self.pose = Pose2D(p.x + ds * math.cos(mid), p.y + ds * math.sin(mid),
                               wrap_angle(p.theta + dth))
            if dl or dr:
                self._propagate(mid - self.frame.theta, ds, dl, dr)
        self.v, self.w = ds / dt, dth / dt
        wheels_var = WHEEL_VARIANCE_PER_M * (abs(dl) + abs(dr)) / (dt * dt)
        self.twist_variance = (wheels_var / 4, wheels_var / (self.b * self.b))

    @property
    def covariance(self) -> np.ndarray:
        """x, y, θ (3×3, odom frame)."""
        xx, xy, xt, yy, yt, tt = self._cov
        return np.array([[xx, xy, xt], [xy, yy, yt], [xt, yt, tt]])

    def _propagate(self, heading: float, ds: float, dl: float, dr: float) -> None:
        """First-order propagation of the covariance over one step (heading: mid-step, odom):
        F P Fᵀ + G Q Gᵀ with F = [[1, 0, -ds sin], [0, 1, ds cos], [0, 0, 1]], G the pose's
        change by each wheel's travel and Q their variances, written out in floats (it runs
        every step the wheels turn, and 3×3 numpy products cost ~10x as much)."""
        c, s, k = math.cos(heading), math.sin(heading), ds / (2 * self.b)
        a, b = -ds * s, ds * c
        xx, xy, xt, yy, yt, tt = self._cov
        r0 = (xx + a * xt, xy + a * yt, xt + a * tt)       # rows of F P
        r1 = (xy + b * xt, yy + b * yt, yt + b * tt)
        g = ((c / 2 - k * s, c / 2 + k * s), (s / 2 + k * c, s / 2 - k * c),
             (1 / self.b, -1 / self.b))
        q = (WHEEL_VARIANCE_PER_M * abs(dr), WHEEL_VARIANCE_PER_M * abs(dl))

        def wheels(i: int, j: int) -> float:
            return g[i][0] * g[j][0] * q[0] + g[i][1] * g[j][1] * q[1]
        self._cov = (r0[0] + a * r0[2] + wheels(0, 0), r0[1] + b * r0[2] + wheels(0, 1),
                     r0[2] + wheels(0, 2), r1[1] + b * r1[2] + wheels(1, 1),
                     r1[2] + wheels(1, 2), tt + wheels(2, 2))

    def reset(self, pose: Pose2D) -> Pose2D:
        """Redefine the pose (its heading wrapped to ±π, as every pose odometry reports: 200°
        read 200 until the next step made it −160); returns the transform from the old frame
        to the new one."""
        pose = Pose2D(pose.x, pose.y, wrap_angle(pose.theta))
        with self.lock:
            old, self.pose = self.pose, pose
            moved = pose.compose(old.inverse())
            self.frame = moved.compose(self.frame)
        return moved

    def continuous(self) -> tuple[Pose2D, Pose2D]:
        """(the dead-reckoned pose in the odom frame, which never jumps; the odom frame's pose in
        the position frame): their composition is `pose`."""
        with self.lock:
            odom = self.frame.inverse().compose(self.pose)
            return Pose2D(odom.x, odom.y, wrap_angle(odom.theta)), self.frame


# --- paths -----------------------------------------------------------------------------------
class Path(Protocol):
    duration: float

    def pose(self, t: float) -> Pose2D:
        """Reference pose at t (clamped to [0, duration])."""

    def twist(self, t: float) -> tuple[float, float]:
        """(forward speed m/s, yaw rate rad/s) at t; (0, 0) outside [0, duration]."""

    def peak(self, t0: float, t1: float) -> tuple[float, float]:
        """The largest |forward speed| and |yaw rate| over [t0, t1], exactly: every path's
        twist is piecewise linear in t, so it peaks at an end of the span or at a corner."""

    def retimed(self, t: float, limits: "Limits") -> "Path | None":
        """The rest of the path from t on, timed for new limits from the speed at t (same
        geometry, same end); None when this kind of path keeps its timing."""


Limits = tuple[float, float, float, float]      # (v_max, w_max, a_max, alpha_max) in m, rad, s


class Ramp:
    """Time-optimal 1-D profile over `length` >= 0 from speed `v0` >= 0 to rest: accelerate (or
    decelerate) to `vmax`, cruise, decelerate, all at `amax`. A start too fast to stop within
    `length` decelerates harder, just enough."""

    def __init__(self, length: float, vmax: float, amax: float, v0: float = 0.0) -> None:
        self.length = length = max(0.0, length)
        self.segments: list[tuple[float, float, float, float]] = []   # (t0, s0, v0, a)
        t = s = 0.0
        v = max(0.0, v0)

        def push(a: float, dt: float) -> None:
            nonlocal t, s, v
            if dt > 0.0:
                self.segments.append((t, s, v, a))
                s += v * dt + a * dt * dt / 2
                v += a * dt
                t += dt
        if length <= 0.0:
            self.duration = 0.0
            self.segments.append((0.0, 0.0, 0.0, 0.0))
            self._starts = [0.0]
            return
        if v * v / (2 * amax) >= length:                  # cannot stop in time: brake harder
            push(-v * v / (2 * length), 2 * length / v)
        else:
            peak = min(vmax, math.sqrt(amax * length + v * v / 2)) if v <= vmax else vmax
            d_change = abs(peak * peak - v * v) / (2 * amax)
            d_stop = peak * peak / (2 * amax)
            push(math.copysign(amax, peak - v), abs(peak - v) / amax)
            push(0.0, max(0.0, length - d_change - d_stop) / peak)
            push(-amax, peak / amax)
        self.duration = t
        self.segments.append((t, length, 0.0, 0.0))
        self._starts = [seg[0] for seg in self.segments]

    def sample(self, t: float) -> tuple[float, float]:
        """(s, ds/dt) at t, clamped to the ends."""
        if t >= self.duration:
            return self.length, 0.0
        if t <= 0.0:
            return 0.0, self.segments[0][2]
        t0, s0, v0, a = self.segments[bisect.bisect_right(self._starts, t) - 1]
        dt = t - t0
        return s0 + v0 * dt + a * dt * dt / 2, v0 + a * dt

    def peak_rate(self, t0: float, t1: float) -> float:
        """The largest ds/dt over [t0, t1]: at an end or at a corner between them (the rate is
        linear between corners)."""
        corners = self._starts[bisect.bisect_right(self._starts, t0):
                               bisect.bisect_left(self._starts, t1)]
        return max(self.sample(t)[1] for t in (t0, t1, *corners))


class CurvePath:
    """A curve of constant shape driven by a `Ramp` on its parameter s: a straight line (s in m),
    a turn in place (s in rad) or an arc about a point (s in rad of rotation about it).

    `unit` = (forward speed, yaw rate) per unit ds/dt, signed; the curve is the rigid motion
    generated by that body twist from `start`.
    """

    def __init__(self, start: Pose2D, unit: tuple[float, float], length: float,
                 limits: tuple[float, float, float, float], v0: float = 0.0) -> None:
        """`limits` = (v_max, w_max, a_max, alpha_max) of the base; `v0` the start ds/dt."""
        self.start, self.unit = start, unit
        u_v, u_w = abs(unit[0]), abs(unit[1])
        v_max, w_max, a_max, alpha_max = limits
        sd_max = min(v_max / u_v if u_v > 0 else math.inf, w_max / u_w if u_w > 0 else math.inf)
        sdd_max = min(a_max / u_v if u_v > 0 else math.inf, alpha_max / u_w if u_w > 0 else math.inf)
        self.ramp = Ramp(length, sd_max, sdd_max, v0)
        self.duration = self.ramp.duration

    def at_parameter(self, s: float) -> Pose2D:
        v, w = self.unit[0] * s, self.unit[1] * s
        if abs(w) < 1e-12:
            return self.start.forward(v)
        r = v / w                                         # the body twist integrated exactly
        return self.start.compose(Pose2D(r * math.sin(w), r * (1 - math.cos(w)), w))

    def pose(self, t: float) -> Pose2D:
        return self.at_parameter(self.ramp.sample(t)[0])

    def twist(self, t: float) -> tuple[float, float]:
        if t < 0.0 or t >= self.duration:
            return 0.0, 0.0
        sd = self.ramp.sample(t)[1]
        return self.unit[0] * sd, self.unit[1] * sd

    def peak(self, t0: float, t1: float) -> tuple[float, float]:
        t0, t1 = max(t0, 0.0), min(t1, self.duration)
        if t0 > t1 or t0 >= self.duration:
            return 0.0, 0.0
        sd = self.ramp.peak_rate(t0, t1)
        return abs(self.unit[0]) * sd, abs(self.unit[1]) * sd

    def retimed(self, t: float, limits: Limits) -> "CurvePath":
        s, sd = self.ramp.sample(t) if t < self.duration else (self.ramp.length, 0.0)
        return CurvePath(self.at_parameter(s), self.unit, self.ramp.length - s, limits, sd)


def line(start: Pose2D, distance: float, limits: tuple[float, float, float, float]) -> CurvePath:
    """Straight `distance` m along the heading (negative: backwards)."""
    return CurvePath(start, (math.copysign(1.0, distance), 0.0), abs(distance), limits)


def turn(start: Pose2D, angle: float, limits: tuple[float, float, float, float]) -> CurvePath:
    """Turn in place by `angle` rad, counter-clockwise positive."""
    return CurvePath(start, (0.0, math.copysign(1.0, angle)), abs(angle), limits)


def arc(start: Pose2D, centre_y: float, angle: float,
        limits: tuple[float, float, float, float]) -> CurvePath:
    """Rotate the base rigidly by `angle` rad about the point `centre_y` m to its left (on the
    wheel axle): forward speed = centre_y · yaw rate."""
    sign = math.copysign(1.0, angle)
    return CurvePath(start, (centre_y * sign, sign), abs(angle), limits)


class Chain:
    """Paths one after the other (each starts where the previous one ends, with its speed)."""

    def __init__(self, paths: Sequence[Path], start: Pose2D) -> None:
        self.paths = [p for p in paths if p.duration > 0.0]
        self.start = start
        self.starts = list(np.cumsum([0.0] + [p.duration for p in self.paths]))
        self.duration = self.starts[-1]

    def _index(self, t: float) -> int:
        return min(max(bisect.bisect_right(self.starts, t) - 1, 0), len(self.paths) - 1)

    def _find(self, t: float) -> tuple[Path | None, float]:
        if not self.paths:
            return None, 0.0
        i = self._index(t)
        return self.paths[i], t - self.starts[i]

    def pose(self, t: float) -> Pose2D:
        path, tau = self._find(t)
        return self.start if path is None else path.pose(tau)

    def twist(self, t: float) -> tuple[float, float]:
        if t < 0.0 or t >= self.duration:
            return 0.0, 0.0
        path, tau = self._find(t)
        return path.twist(tau)

    def peak(self, t0: float, t1: float) -> tuple[float, float]:
        if not self.paths or t1 < 0.0 or t0 >= self.duration:
            return 0.0, 0.0
        first, last = self._index(t0), self._index(t1)
        return peak_of(self.paths[i].peak(t0 - self.starts[i], t1 - self.starts[i])
                       for i in range(first, last + 1))

    def head(self, t: float) -> "list[Path] | None":
        """The parts that make the path up to time t (the last one cut there), or None when
        the part running at t cannot be cut."""
        if not self.paths or not 0.0 < t < self.duration:
            return None
        i = self._index(t)
        cut = getattr(self.paths[i], "head", None)
        return None if cut is None else self.paths[:i] + [cut(t - self.starts[i])]

    def retimed(self, t: float, limits: Limits) -> "Chain":
        """The running part re-timed from its present speed, the parts after it from rest."""
        if not self.paths:
            return self
        i = self._index(t)
        head = self.paths[i]
        parts = [retimed_or_kept(head, t - self.starts[i], limits)]
        parts += [retimed_or_kept(p, 0.0, limits) for p in self.paths[i + 1:]]
        return Chain(parts, self.pose(t))


class Tail:
    """A path from time `start` on (the part of a path that keeps its timing)."""

    def __init__(self, path: Path, start: float) -> None:
        self.path, self.start = path, start
        self.duration = max(0.0, path.duration - start)

    def pose(self, t: float) -> Pose2D:
        return self.path.pose(self.start + min(max(t, 0.0), self.duration))

    def twist(self, t: float) -> tuple[float, float]:
        return self.path.twist(self.start + t) if 0.0 <= t < self.duration else (0.0, 0.0)

    def peak(self, t0: float, t1: float) -> tuple[float, float]:
        t0, t1 = max(t0, 0.0), min(t1, self.duration)
        if t0 > t1 or t0 >= self.duration:
            return 0.0, 0.0
        return self.path.peak(self.start + t0, self.start + t1)


def retimed_or_kept(path: Path, t: float, limits: Limits) -> Path:
    new = getattr(path, "retimed", lambda *_: None)(t, limits)
    if new is not None:
        return new
    return path if t <= 0.0 else Tail(path, t)


class Moved:
    """A path seen from another frame: pose' = frame ∘ pose (setPosition moves the odometry frame)."""

    def __init__(self, path: Path, frame: Pose2D) -> None:
        self.path, self.frame = path, frame
        self.duration = path.duration

    def pose(self, t: float) -> Pose2D:
        return self.frame.compose(self.path.pose(t))

    def twist(self, t: float) -> tuple[float, float]:
        return self.path.twist(t)

    def peak(self, t0: float, t1: float) -> tuple[float, float]:
        return self.path.peak(t0, t1)

    def retimed(self, t: float, limits: Limits) -> "Moved | None":
        inner = getattr(self.path, "retimed", lambda *_: None)(t, limits)
        return None if inner is None else Moved(inner, self.frame)


def straight_to(start: Pose2D, goal: Pose2D, limits: tuple[float, float, float, float],
                wrap_final: bool) -> Chain:
    """A differential drive's straight move: turn toward the goal, drive, turn to its heading.
    A goal behind the base is reached backwards (the smaller turn). `wrap_final` turns the
    shorter way to an absolute heading; otherwise the heading change is taken as given."""
    dx, dy = goal.x - start.x, goal.y - start.y
    dist = math.hypot(dx, dy)
    paths: list[Path] = []
    here = start
    if dist > 1e-5:
        bearing = wrap_angle(math.atan2(dy, dx) - start.theta)
        if abs(bearing) > math.pi / 2:
            bearing, dist = wrap_angle(bearing - math.pi), -dist
        paths.append(turn(here, bearing, limits))
        here = Pose2D(here.x, here.y, here.theta + bearing)
        paths.append(line(here, dist, limits))
        here = here.forward(dist)
    final = goal.theta - here.theta
    paths.append(turn(here, wrap_angle(final) if wrap_final else final, limits))
    return Chain(paths, start)


class SampledPath:
    """A path given as samples (t, x, y, theta, v, w), linearly interpolated (theta unwrapped)."""

    def __init__(self, t: np.ndarray, x: np.ndarray, y: np.ndarray, theta: np.ndarray,
                 v: np.ndarray, w: np.ndarray) -> None:
        self.t, self.x, self.y, self.theta, self.v, self.w = t, x, y, theta, v, w
        self.duration = float(t[-1])

    def _index(self, t: float) -> tuple[int, float]:
        ts = self.t
        i = min(max(int(ts.searchsorted(t, "right")) - 1, 0), len(ts) - 2)
        t_i = float(ts[i])
        span = float(ts[i + 1]) - t_i
        return i, 0.0 if span <= 0 else min(1.0, max(0.0, (t - t_i) / span))

    def pose(self, t: float) -> Pose2D:
        if len(self.t) == 1:
            return Pose2D(float(self.x[0]), float(self.y[0]), float(self.theta[0]))
        i, f = self._index(t)
        lerp = lambda a: float(a[i] + f * (a[i + 1] - a[i]))  # noqa: E731
        return Pose2D(lerp(self.x), lerp(self.y), lerp(self.theta))

    def twist(self, t: float) -> tuple[float, float]:
        if t < 0.0 or t >= self.duration or len(self.t) == 1:
            return 0.0, 0.0
        i, f = self._index(t)
        return (float(self.v[i] + f * (self.v[i + 1] - self.v[i])),
                float(self.w[i] + f * (self.w[i + 1] - self.w[i])))

    def peak(self, t0: float, t1: float) -> tuple[float, float]:
        t0, t1 = max(t0, 0.0), min(t1, self.duration)
        if t0 > t1 or t0 >= self.duration or len(self.t) == 1:
            return 0.0, 0.0
        inside = slice(int(self.t.searchsorted(t0, "right")), int(self.t.searchsorted(t1, "left")))
        # at the end itself the path has stopped: its last sample is what it reaches
        end = self.twist(t1) if t1 < self.duration else (float(self.v[-1]), float(self.w[-1]))
        return peak_of((self.twist(t0), end, (float(np.abs(self.v[inside]).max(initial=0.0)),
                                              float(np.abs(self.w[inside]).max(initial=0.0)))))


    def head(self, t: float) -> "SampledPath":
        """The path up to time t (0 < t < duration), ending with the state there."""
        i, f = self._index(t)
        cut = lambda a: np.append(a[:i + 1], a[i] + f * (a[i + 1] - a[i]))  # noqa: E731
        return SampledPath(*(cut(a) for a in (self.t, self.x, self.y, self.theta, self.v, self.w)))


class ConstantTwist:
    """Driving at a constant (forward speed, yaw rate) for `duration` s: a line, an arc or a turn."""

    def __init__(self, start: Pose2D, twist: tuple[float, float], duration: float) -> None:
        self.start, (self.v, self.w), self.duration = start, twist, max(0.0, duration)

    def pose(self, t: float) -> Pose2D:
        t = min(max(t, 0.0), self.duration)
        v, w = self.v * t, self.w * t
        if abs(w) < 1e-12:
            return self.start.forward(v)
        r = v / w
        return self.start.compose(Pose2D(r * math.sin(w), r * (1 - math.cos(w)), w))

    def twist(self, t: float) -> tuple[float, float]:
        return (self.v, self.w) if 0.0 <= t < self.duration else (0.0, 0.0)

    def peak(self, t0: float, t1: float) -> tuple[float, float]:
        inside = t0 < self.duration and t1 >= 0.0 and t0 <= t1
        return (abs(self.v), abs(self.w)) if inside else (0.0, 0.0)


def peak_of(twists: "Iterable[tuple[float, float]]") -> tuple[float, float]:
    """The largest |forward speed| and |yaw rate| among `twists`."""
    v = w = 0.0
    for tv, tw in twists:
        v, w = max(v, abs(tv)), max(w, abs(tw))
    return v, w


SLEW_SAMPLES = 2000          # at most this many samples per speed change of a velocity drive
SLEW_DT = 0.005              # s between them, unless that would need more


def slew(start: Pose2D, v0: float, w0: float, goal: tuple[float, float],
         accel: tuple[float, float], longest: float = math.inf) -> SampledPath:
    """Change speed from (v0, w0) to `goal` at `accel` (a, alpha), for at most `longest` s."""
    a, alpha = accel
    span = min(longest, max(abs(goal[0] - v0) / a, abs(goal[1] - w0) / alpha))
    dt = max(SLEW_DT, span / SLEW_SAMPLES)
    ts, xs, ys, ths, vs, ws = [0.0], [start.x], [start.y], [start.theta], [v0], [w0]
    t, x, y, th, v, w = 0.0, start.x, start.y, start.theta, v0, w0

    def toward(cur: float, target: float, rate: float) -> float:
        step = rate * dt
        return target if abs(target - cur) <= step else cur + math.copysign(step, target - cur)
    while t < span - 1e-12 and (v, w) != tuple(goal):
        v1, w1 = toward(v, goal[0], a), toward(w, goal[1], alpha)
        vm, wm = (v + v1) / 2, (w + w1) / 2
        mid = th + wm * dt / 2
        x, y, th = x + vm * dt * math.cos(mid), y + vm * dt * math.sin(mid), th + wm * dt
        t += dt
        v, w = v1, w1
        ts.append(t)
        xs.append(x)
        ys.append(y)
        ths.append(th)
        vs.append(v)
        ws.append(w)
    return SampledPath(*(np.array(a_) for a_ in (ts, xs, ys, ths, vs, ws)))


def velocity_path(start: Pose2D, v0: float, w0: float, target: tuple[float, float], hold: float,
                  accel: tuple[float, float]) -> Chain:
    """Drive like a jog: from speed (v0, w0) slew to `target` (v, w) at `accel` (a, alpha), keep it
    until `hold` s, then slew to rest. With hold = 0 and target (0, 0) it is a brake. Its cost
    does not grow with `hold` or with how slow the acceleration is."""
    up = slew(start, v0, w0, target, accel, hold)
    end = up.pose(up.duration)
    v, w = (float(up.v[-1]), float(up.w[-1])) if len(up.t) > 1 else (v0, w0)
    keep = ConstantTwist(end, (v, w), hold - up.duration)
    down = slew(keep.pose(keep.duration), v, w, (0.0, 0.0), accel)
    return Chain([up, keep, down], start)


# --- motions ---------------------------------------------------------------------------------
class TrackedBaseMotion:
    """A base motion along a reference path: feed-forward twist plus feedback on the odometry
    error (Kanayama's tracking law), then a short settle so the base ends on the target.

    The reference is a list of (motion time, path) segments: `splice(t, path)` makes `path` the
    reference from t on, also from a time still ahead (a plan made outside the device's lock
    takes over a little after now; until then the old reference runs). `error` is the latest
    tracking error (m, rad), for blocked-base detection.
    """

    SETTLE = 0.4
    K_X, K_Y, K_TH = 3.0, 30.0, 6.0

    def __init__(self, odometry: Odometry, path: Path, kind: str = "") -> None:
        self.odometry = odometry
        self.segments: list[tuple[float, Path]] = [(0.0, path)]
        self.kind = kind
        self.error = (0.0, 0.0)
        self._settle = self.SETTLE if path.duration > 0.0 else 0.0   # a move of no length: none

    @property
    def path(self) -> Path:
        """The last reference: the one the motion ends on."""
        return self.segments[-1][1]

    @property
    def t0(self) -> float:
        return self.segments[-1][0]

    @property
    def duration(self) -> float:
        return self.t0 + self.path.duration + self._settle

    @property
    def path_end(self) -> float:
        """Motion time at which the reference stops (the settle follows)."""
        return self.t0 + self.path.duration

    def _segment(self, t: float) -> tuple[float, Path]:
        for t0, path in reversed(self.segments):
            if t >= t0:
                return t0, path
        return self.segments[0]

    def at(self, t: float) -> Pose2D:
        t0, path = self._segment(t)
        return path.pose(min(max(t - t0, 0.0), path.duration))

    def reference_twist(self, t: float) -> tuple[float, float]:
        t0, path = self._segment(t)
        return path.twist(t - t0)

    def reference_peak(self, t0: float, t1: float) -> tuple[float, float]:
        """The reference's largest |forward speed| and |yaw rate| over motion times [t0, t1]:
        each segment's path over the part of the span it is the reference for."""
        ends = [start for start, _ in self.segments[1:]] + [math.inf]
        return peak_of(path.peak(max(t0, start) - start, min(t1, end) - start)
                       for (start, path), end in zip(self.segments, ends)
                       if start <= t1 and end > t0)

    def splice(self, t: float, path: Path) -> None:
        """Follow `path` (which starts at the reference state at t) from motion time t on."""
        self.segments = [s for s in self.segments if s[0] < t] + [(t, path)]
        if path.duration > 0.0:
            self._settle = self.SETTLE

    def handover(self, t: float, path: Path, kind: str) -> "TrackedBaseMotion":
        """A plain tracked motion of another kind that follows this one's reference until t and
        `path` from then on (a continuous move or a jog taking over a running move)."""
        other = TrackedBaseMotion(self.odometry, path, kind)
        other.segments, other._settle = list(self.segments), self._settle
        other.splice(t, path)
        return other

    def move_frame(self, frame: Pose2D) -> None:
        self.segments = [(t0, Moved(path, frame)) for t0, path in self.segments]

    def replan(self, t: float, limits: Limits) -> "Callable[[], None] | None":
        """New velocity or acceleration settings from motion time t on (0: not started): the
        new timing, planned now; calling the result applies it (under the device's lock)."""
        local = max(0.0, t - self.t0)
        if local >= self.path.duration:
            return None
        new = getattr(self.path, "retimed", lambda *_: None)(local, limits)
        if new is None:
            return None
        at = max(t, self.t0)
        return lambda: self.splice(at, new)

    def apply(self, world: World, t: float, rate: float) -> None:
        if len(self.segments) > 1 and t >= self.segments[1][0]:      # forget what is behind
            self.segments = [s for i, s in enumerate(self.segments)
                             if i + 1 == len(self.segments) or self.segments[i + 1][0] > t]
        if t >= self.duration:
            world.set_wheel_velocities(0.0, 0.0)
            return
        ref = self.at(t)
        v_d, w_d = self.reference_twist(t)
        v_d, w_d = v_d * rate, w_d * rate
        p = self.odometry.pose
        dx, dy = ref.x - p.x, ref.y - p.y
        ex = math.cos(p.theta) * dx + math.sin(p.theta) * dy
        ey = -math.sin(p.theta) * dx + math.cos(p.theta) * dy
        eth = wrap_angle(ref.theta - p.theta)
        self.error = (math.hypot(ex, ey), eth)
        v = v_d * math.cos(eth) + self.K_X * ex
        w = w_d + v_d * self.K_Y * ey + self.K_TH * math.sin(eth)
        r, b = self.odometry.r, self.odometry.b
        world.set_wheel_velocities((v - w * b / 2) / r, (v + w * b / 2) / r)


class BrakeMotion:
    """Stop the wheels from their measured speeds at the given decelerations, without a reference
    pose (after a contact or a blockage); the set-point is wherever odometry says the base is.

    The brake runs on the world's clock, not the device's: a pause slows the device's clock to
    a halt, which froze the brake with its wheels still turning (pause: 最大加速度で停止し)."""

    SETTLE = 0.1

    def __init__(self, odometry: Odometry, decel: tuple[float, float]) -> None:
        self.odometry = odometry
        self.kind = "brake"
        self.v0, self.w0 = odometry.v, odometry.w
        self.ramp = max(abs(self.v0) / decel[0], abs(self.w0) / decel[1], 1e-3)
        self.duration = self.ramp + self.SETTLE
        self.error = (0.0, 0.0)
        self._began: float | None = None     # world time at which the brake's clock was 0
        self._now: float | None = None       # world time of the last step applied

    def at(self, t: float) -> Pose2D:
        """Where the base comes to rest: the measured pose moved on by what is left of the brake
        (an arc: both speeds fall together). A move queued behind the brake starts there; from
        the pose at its planning it started short by the braking distance and went Stuck."""
        k = self._left(self._now)
        left = self.ramp * k * k / 2
        return ConstantTwist(self.odometry.pose, (self.v0 * left, self.w0 * left), 1.0).pose(1.0)

    def _left(self, now: float | None) -> float:
        """The fraction of the start speeds commanded at world time `now` (None: not begun)."""
        return 1.0 if now is None else max(0.0, 1.0 - (now - self._began) / self.ramp)

    def move_frame(self, frame: Pose2D) -> None:
        """Nothing to move: the set-point is the odometry itself."""

    def apply(self, world: World, t: float, rate: float) -> None:
        if self._began is None:
            self._began = world.time - t
        self._now = world.time
        k = self._left(self._now)
        v, w = self.v0 * k, self.w0 * k
        r, b = self.odometry.r, self.odometry.b
        world.set_wheel_velocities((v - w * b / 2) / r, (v + w * b / 2) / r)
