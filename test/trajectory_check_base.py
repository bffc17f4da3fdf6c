"""A trajectory checker for the mobile base: what the code commands, step by step.

`BaseTrace` steps a real MotionExecutor and records, every control period, the base's set-point:
the reference pose and the feed-forward twist (the path's twist times the device's time rate),
as `TrackedBaseMotion.apply` commands them. `check` then fails on what a person would call a
jerk: a set-point that jumps, a commanded acceleration beyond the setting, and a rest that is
not where the code announced it (a stop's rest point).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

from acti_motion.vehicle.paths import BrakeMotion, Pose2D, wrap_angle


@dataclass(frozen=True)
class SetPoint:
    time: float                  # simulated s
    pose: Pose2D                 # reference pose (odometry frame)
    v: float                     # commanded forward speed (m/s)
    w: float                     # commanded yaw rate (rad/s)
    motion_id: int               # 0: at rest, no motion
    braking: bool                # a BrakeMotion (no reference: the odometry is the set-point)


class BaseTrace:
    """Steps the executor and records the base's set-points."""

    def __init__(self, executor, base) -> None:
        self.executor, self.base = executor, base
        self.points: list[SetPoint] = []
        self.record()

    def record(self) -> None:
        device = self.base.device
        with device.lock:
            cur, t, rate, hold = device.current, device.t, device.rate, device.hold
            if cur is None:
                point = SetPoint(self.executor.world.time, hold, 0.0, 0.0, 0, False)
            elif isinstance(cur.motion, BrakeMotion):
                point = SetPoint(self.executor.world.time, cur.motion.at(t), 0.0, 0.0, cur.id, True)
            else:
                v, w = cur.motion.reference_twist(t)
                v, w = (v * rate, w * rate) if t < cur.motion.path_end else (0.0, 0.0)
                point = SetPoint(self.executor.world.time, cur.motion.at(t), v, w, cur.id, False)
        self.points.append(point)

    def step(self, seconds: float) -> None:
        for _ in range(round(seconds / self.executor.dt)):
            self.executor.step()
            self.record()

    def until(self, predicate, max_seconds: float = 30.0) -> float:
        """Step until predicate() holds; simulated seconds it took."""
        t0 = self.executor.world.time
        while not predicate():
            assert self.executor.world.time - t0 <= max_seconds, f"not reached in {max_seconds} s"
            self.executor.step()
            self.record()
        return self.executor.world.time - t0

    def until_idle(self, max_seconds: float = 30.0) -> float:
        return self.until(lambda: not self.base.device.busy, max_seconds)

    def check(self, accel: tuple[float, float] | None = None, tolerance: float = 1.05,
              rest: Pose2D | None = None) -> None:
        """No set-point jumps; commanded accelerations within `accel` (m/s², rad/s²; default:
        the unit's maximum, which pause and stop use); and, given `rest`, the last set-point is
        that pose with no speed."""
        c = self.base.config
        a_max, alpha_max = accel or (c.accel_limit_translation / 1000.0,
                                     math.radians(c.accel_limit_rotation))
        dt = self.executor.dt
        for p, q in zip(self.points, self.points[1:]):
            if p.braking or q.braking:
                continue
            where = f"at {q.time:.3f} s (motion {p.motion_id} → {q.motion_id})"
            dv, dw = abs(q.v - p.v) / dt, abs(q.w - p.w) / dt
            assert dv <= a_max * tolerance + 1e-9, f"forward acceleration {dv:.3f} m/s² {where}"
            assert dw <= alpha_max * tolerance + 1e-9, f"yaw acceleration {dw:.3f} rad/s² {where}"
            # the set-point moves no farther than its speed carries it (plus one step of accel)
            reach = (max(abs(p.v), abs(q.v)) + a_max * dt) * dt * (1 + tolerance) + 1e-6
            turn = (max(abs(p.w), abs(q.w)) + alpha_max * dt) * dt * (1 + tolerance) + 1e-6
            assert p.pose.distance(q.pose) <= reach, f"set-point jump {p.pose.distance(q.pose):.4f} m {where}"
            assert abs(wrap_angle(q.pose.theta - p.pose.theta)) <= turn, f"heading jump {where}"
        if rest is not None:
            last = self.points[-1]
            assert (last.v, last.w) == (0.0, 0.0), f"still commanded {last.v, last.w}"
            assert last.pose.distance(rest) < 1e-6, f"rests at {last.pose}, announced {rest}"
            assert abs(wrap_angle(last.pose.theta - rest.theta)) < 1e-6

    def max_speed(self) -> float:
        return max(abs(p.v) for p in self.points)
