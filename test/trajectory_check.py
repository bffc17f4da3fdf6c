"""Trajectory checker for tests: the arm's commanded joint set-points, recorded every control
step, checked for jumps, for accelerations beyond the setting and for rest where announced.

It records what the executor commands the world (`World.set_arm_targets`: positions and their
feed-forward velocities) after every step of a real `MotionExecutor`, so a wrong rest point, an
instant resume or a seam that skips shows as a set-point that jumps, and a profile whose velocity
jumps (at a move's start, say) as a feed-forward velocity that is not the set-points' own,
whatever the test looks at otherwise.
"""
from __future__ import annotations

import numpy as np

from acti_motion.executor import MotionExecutor

SPEED_MARGIN = 1.02        # discretisation of the rate ramps
ACCEL_MARGIN = 2.05        # a stop's ramp adds its own deceleration to the move's (≤ 2× the limit)


class ArmTrace:
    """Commanded joint set-points (rad) of `arm` after every step of `executor`."""

    def __init__(self, executor: MotionExecutor, arm) -> None:
        world = executor.world
        self.arm = arm
        self.dt = world.time_step
        self._last = np.array(arm.device.hold.joints, float)
        self._last_velocity = np.zeros_like(self._last)
        self.setpoints: list[np.ndarray] = [self._last.copy()]
        self.velocities: list[np.ndarray] = [self._last_velocity]
        command = world.set_arm_targets

        def record(q, qd=None) -> None:
            self._last = np.array(q, float)
            self._last_velocity = np.zeros_like(self._last) if qd is None else np.array(qd, float)
            command(q, qd)
        world.set_arm_targets = record

        def sample(_world) -> None:
            self.setpoints.append(self._last.copy())
            self.velocities.append(self._last_velocity)
        executor.after_step(sample)

    @property
    def last(self) -> np.ndarray:
        return self.setpoints[-1]

    def check(self) -> None:
        """No step faster than the joint's maximum speed and no acceleration beyond
        max speed / min accel time (the arm's settings now), on every joint."""
        q = np.array(self.setpoints)
        v = np.diff(q, axis=0) / self.dt
        speed = np.radians(self.arm.max_speed_joint)
        over = np.abs(v) / speed
        k, j = np.unravel_index(int(np.argmax(over)), over.shape)
        assert over[k, j] <= SPEED_MARGIN, (
            f"set-point jump at step {k + 1}: J{j + 1} moved {np.degrees(q[k + 1, j] - q[k, j]):.4f}°"
            f" in one step ({over[k, j]:.2f}× its maximum speed)")
        if len(v) < 2:
            return
        a = np.diff(v, axis=0) / self.dt
        limit = speed / self.arm.min_accel_time_joint
        over = np.abs(a) / limit
        k, j = np.unravel_index(int(np.argmax(over)), over.shape)
        assert over[k, j] <= ACCEL_MARGIN, (
            f"acceleration at step {k + 1}: J{j + 1} {np.degrees(a[k, j]):.1f}°/s² "
            f"({over[k, j]:.2f}× max speed / min accel time)")
        self._check_feed_forward(q, limit)

    def _check_feed_forward(self, q: np.ndarray, accel_limit: np.ndarray) -> None:
        """The commanded velocity is the set-points' own: within what the acceleration limit
        changes in one step of their central difference (a profile's velocity that jumped at a
        move's start while its positions crept on was 10× that)."""
        qd = np.array(self.velocities)[1:-1]
        moved = (q[2:] - q[:-2]) / (2 * self.dt)
        off = np.abs(qd - moved) / (accel_limit * self.dt)
        k, j = np.unravel_index(int(np.argmax(off)), off.shape)
        assert off[k, j] <= ACCEL_MARGIN, (
            f"feed-forward velocity at step {k + 1}: J{j + 1} commanded "
            f"{np.degrees(qd[k, j]):.3f}°/s while its set-points moved at "
            f"{np.degrees(moved[k, j]):.3f}°/s ({off[k, j]:.2f}× a step of max acceleration)")

    def check_rest(self, announced: np.ndarray, steps: int = 10) -> None:
        """The last `steps` set-points hold still at the announced rest point (rad)."""
        tail = np.array(self.setpoints[-steps:])
        assert np.max(np.abs(tail - tail[-1])) < 1e-12, "the set-point still moves"
        off = np.degrees(np.max(np.abs(tail[-1] - np.asarray(announced))))
        assert off < 1e-9, f"at rest {off:.6f}° away from the announced rest point"
