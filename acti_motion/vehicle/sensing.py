"""What the base's simulation thread does each step before the devices move: odometry, battery
(drain and its alarms, with hysteresis), the contact sensor, blockage (Stuck) and the jog
deadman. A part of VehicleCore (its state, locks and device), kept apart for its one job."""
from __future__ import annotations

import math
from typing import Any

from acti_motion.executor import Device
from acti_motion.vehicle.alarms import AlarmCode, Kind
from acti_motion.vehicle.paths import BrakeMotion, Chain, velocity_path
from acti_motion.vehicle.refusals import si_pair
from acti_sim.world import World

VELOCITY_DRIVEN = ("move_jog", "joystick")  # motions driven by a velocity, not a target
POWER_IDLE_W = 30.0          # electronics while the main power is on
POWER_SERVO_W = 20.0         # wheel servos holding
DRIVE_LOSS_N = 150.0         # rolling and drive-train resistance of the moving base
DRIVE_EFFICIENCY = 0.8


class Sensing:
    """The simulation-thread half of VehicleCore (mixed in; uses its attributes)."""

    config: Any
    device: Device

    def _sense(self, world: World) -> None:
        """Each step before the devices move: odometry, battery, contact, blockage, deadman."""
        self.odometry.update(world.wheel_positions(), self._dt)
        if self.device.current is None:
            world.hold_wheels()
        self._drain_battery()
        self._contact = contact = world.bumper_in_contact()
        if not contact:
            self._contact_armed = True
        elif self._contact_trips():
            with self.lock:
                if self._contact_trips():       # again under the lock: not switched off meanwhile
                    self._contact_armed = False
                    self.locked = True
                    self.alarms.raise_(AlarmCode.CONTACT,
                                       "contact sensor: the bumper touched something", Kind.CONTACT)
                    self._halt("a contact (the base is Locked)")
        self._watch_tracking(world.time)
        self._watch_obstacles(world)
        self._watch_deadman(world)

    def _contact_trips(self) -> bool:
        return self.digital_sensor_lock and self._contact_armed and not self.locked

    def _watch_deadman(self, world: World) -> None:
        """A jog or joystick drive not renewed within its timeout decelerates at the
        acceleration setting, or ends where it is when it is held at rest. The timeout counts
        the job's clock (the world's, /clock), not the path's, so a pause does not extend it,
        and a recording replays it: a simulation that lags the wall clock drives as far."""
        cur, device = self.device.current, self.device
        if (cur is None or cur.label not in VELOCITY_DRIVEN or self._deadman_fired == cur.id
                or world.time < self._drive_deadline or device.stopping):
            return
        accel = si_pair(self.acceleration)

        def look(device: Device, attempt: int):
            if device.current is not cur:
                return None
            return device.t, device.rate == 0.0

        def plan(seen):
            if seen is None:
                return lambda device: None
            t, held = seen
            here = cur.motion.at(t)
            path = Chain([], here) if held else velocity_path(here, *cur.motion.reference_twist(t),
                                                              (0.0, 0.0), 0.0, accel)

            def commit(device: Device) -> None:
                if world.time < self._drive_deadline:
                    return          # renewed meanwhile (its commit holds this lock too)
                cur.motion.splice(t, path)
                self._deadman_fired = cur.id
            return commit
        device.edit_planned(look, plan)

    def _watch_tracking(self, now: float) -> None:
        """Stuck (table 7): the base lags its path too far for too long, or a move is about to
        end farther from its target than the arrival tolerance (however short the move)."""
        device, c = self.device, self.config
        cur = device.current
        if cur is None or isinstance(cur.motion, BrakeMotion) or device.paused:
            self._stuck_since = None
            return
        dist, angle = cur.motion.error
        ending = device.t >= cur.motion.path_end and device.t + self._dt >= cur.motion.duration
        if ending and (dist * 1000.0 > c.arrival_error or abs(math.degrees(angle)) > c.arrival_angle):
            self._declare_stuck(dist, angle, "did not reach its target")
            return
        if dist * 1000.0 < c.stuck_error and abs(math.degrees(angle)) < c.stuck_angle:
            self._stuck_since = None
            return
        if self._stuck_since is None:
            self._stuck_since = now
        elif now - self._stuck_since >= c.stuck_time:
            self._declare_stuck(dist, angle, "could not follow its path")

    def _declare_stuck(self, dist: float, angle: float, what: str) -> None:
        """Stop at once: the motion is discarded, not completed."""
        with self.lock:
            self._stuck_since = None
            self.stuck = True
            self.alarms.raise_(AlarmCode.STUCK,
                               f"the base {what} ({1000 * dist:.0f} mm, "
                               f"{math.degrees(angle):.1f}° off): stopped", Kind.STUCK)
            self._halt(f"a blockage: the base {what}")

    def _check_battery(self, voltage: float) -> None:
        """Raise the battery alarms whose level is tripped (with hysteresis); the cut-off one
        also turns the servo off."""
        if self._battery_low.update(voltage) and not self.alarms.has(AlarmCode.BATTERY_LOW):
            self.alarms.raise_(AlarmCode.BATTERY_LOW,
                               f"battery low: {self._battery_low.describe(voltage)}",
                               Kind.CONDITION)
        if self._battery_empty.update(voltage) and not self.alarms.has(AlarmCode.BATTERY_EMPTY):
            with self.lock:
                self.alarms.raise_(AlarmCode.BATTERY_EMPTY,
                                   f"battery exhausted: {self._battery_empty.describe(voltage)}: "
                                   "servo off", Kind.CONDITION)
                if self.servo:
                    self.servo = False
                    self._stop("the battery cut-off (servo off)")

    def _drain_battery(self) -> None:
        if not self.power:
            self.battery.drain(0.0, self._dt)
            return
        v, w, b = self.odometry.v, self.odometry.w, self.odometry.b
        wheels = abs(v - w * b / 2) + abs(v + w * b / 2)
        drive = DRIVE_LOSS_N * wheels / 2 / DRIVE_EFFICIENCY
        self.battery.drain(POWER_IDLE_W + (POWER_SERVO_W if self.servo else 0.0) + drive, self._dt)
        self._check_battery(self.battery.voltage)
