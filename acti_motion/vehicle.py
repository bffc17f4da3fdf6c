"""The mobile-base core: the VehicleService operations, without ROS.

Each public method is one IDL operation, named as the ROS service, taking the IDL parameters by
their snake-case names and returning a `Reply` (any refusal becomes `success = false` with the
comment as the message). Units are the spec's: mm, degree, mm/s, degree/s.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from enum import IntEnum

from acti_motion.base import LinePath, Odometry, Pose2D, TrackedBaseMotion
from acti_motion.executor import MotionExecutor
from acti_motion.replies import Refused, ReturnCode, answers, finite_number
from acti_sim.world import World


class VehicleState(IntEnum):
    """Table 7 of the VehicleService spec: state code → the state string's stem."""
    READY = 0x010
    BUSY = 0x011
    WARNING = 0x012
    ALARM = 0x013
    STUCK = 0x014
    PAUSED = 0x015
    AVOID = 0x016
    LOCKED = 0x017
    POWERED = 0x018
    UNPOWERED = 0x019


STATE_STRINGS = {
    VehicleState.READY: "Ready", VehicleState.BUSY: "Busy", VehicleState.WARNING: "Warning",
    VehicleState.ALARM: "Alarm", VehicleState.STUCK: "Stuck", VehicleState.PAUSED: "Paused",
    VehicleState.AVOID: "Avoid", VehicleState.LOCKED: "Locked", VehicleState.POWERED: "Powered",
    VehicleState.UNPOWERED: "Unpowered",
}


@dataclass
class VehicleConfig:
    """Start-up settings and limits of the base (spec units)."""
    queue_size: int = 32
    velocity_limit_translation: float = 1000.0   # mm/s
    velocity_limit_rotation: float = 90.0        # degree/s
    accel_limit_translation: float = 1000.0      # mm/s²
    accel_limit_rotation: float = 180.0          # degree/s²
    default_velocity_translation: float = 300.0
    default_velocity_rotation: float = 45.0
    default_accel_translation: float = 500.0
    default_accel_rotation: float = 90.0


def refuse(message: str) -> Refused:
    return Refused(ReturnCode.NG, message)


class VehicleCore:
    """Power, servo, state, odometry and the motion queue of the differential-drive base."""

    def __init__(self, executor: MotionExecutor, config: VehicleConfig | None = None) -> None:
        self.config = c = config or VehicleConfig()
        world = executor.world
        self.odometry = Odometry(world.wheel_radius, world.wheel_separation, world.wheel_positions())
        self.device = executor.add_device("base", c.queue_size, self.odometry.pose)
        self.power = False
        self.servo = False
        self.velocity = (c.default_velocity_translation, c.default_velocity_rotation)
        self.acceleration = (c.default_accel_translation, c.default_accel_rotation)
        self._dt = executor.dt
        executor.before_step(self._update_odometry)

    def _update_odometry(self, world: World) -> None:
        self.odometry.update(world.wheel_positions(), self._dt)

    # --- state ------------------------------------------------------------------------------
    def state(self) -> VehicleState:
        if not self.power:
            return VehicleState.UNPOWERED
        if not self.servo:
            return VehicleState.POWERED
        if self.device.paused:
            return VehicleState.PAUSED
        if self.device.busy:
            return VehicleState.BUSY
        return VehicleState.READY

    @answers
    def get_state(self) -> dict:
        s = self.state()
        return {"state": int(s), "msg": STATE_STRINGS[s]}

    @answers
    def set_power(self, on_off: bool) -> None:
        """Main power; switching it off stops the base and drops the servo."""
        if not on_off:
            self.device.stop(self._stop_ramp())
            self.servo = False
        self.power = bool(on_off)

    @answers
    def set_servo(self, on_off: bool) -> None:
        """Table 8: refused without power; switching off stops a moving base first."""
        if not self.power:
            raise refuse("main power is off: call set_power(true) first")
        if not on_off:
            self.device.stop(self._stop_ramp())
        self.servo = bool(on_off)

    @answers
    def get_position(self) -> dict:
        p = self.odometry.pose
        return {"pos": (1000.0 * p.x, 1000.0 * p.y, math.degrees(p.theta))}

    # --- motion -----------------------------------------------------------------------------
    @answers
    def move_forward(self, x: float) -> dict:
        distance = finite_number(x, "x") / 1000.0
        self._require(VehicleState.READY)
        speed, accel = self.velocity[0] / 1000.0, self.acceleration[0] / 1000.0
        odometry = self.odometry

        def plan(start: Pose2D) -> TrackedBaseMotion:
            return TrackedBaseMotion(odometry, LinePath(start, distance, speed, accel))
        return self._submit(plan, "move_forward")

    # --- helpers ----------------------------------------------------------------------------
    def _require(self, *allowed: VehicleState) -> None:
        s = self.state()
        if s not in allowed:
            wanted = " or ".join(STATE_STRINGS[a] for a in allowed)
            raise refuse(f"the base is {STATE_STRINGS[s]}: this command needs {wanted}")

    def _submit(self, plan, label: str) -> dict:
        motion_id = self.device.submit(plan, label)
        if motion_id is None:
            raise refuse(f"the motion queue is full ({self.device.capacity} motions)")
        return {"motion_id": motion_id}

    def _stop_ramp(self) -> float:
        """Time to stop from the set speed at the maximum acceleration."""
        c = self.config
        return max(self.velocity[0] / c.accel_limit_translation,
                   self.velocity[1] / c.accel_limit_rotation)
