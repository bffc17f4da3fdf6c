"""The control path of the base: state, power and servo, alarms, the sensor lock, the getters and
the plain settings, pause, resume and stop. Each operation runs on the caller's thread (the
node's control plane) under the short state lock `lock` (`@command`, `@query`), which the
simulation thread takes too: none of them plans, so none makes stop, pause or a step wait for
more than a moment. `_stop` and `_halt` are also called under that lock by the simulation
thread (sensing) and by power and servo off. A part of VehicleCore (its state, locks and
device), mixed in."""
from __future__ import annotations

import math
from typing import Any

from acti_motion.executor import STOPPED, Device
from acti_motion.replies import Reply
from acti_motion.vehicle.alarms import Alarm, AlarmCode, Alarms, AlarmType, Kind
from acti_motion.vehicle.paths import BrakeMotion, Odometry
from acti_motion.vehicle.refusals import VehicleRefused, command, invalid, query, si_pair
from acti_motion.vehicle.states import SERVO_ON, STATE_STRINGS, VehicleState

IF_VERSION = "RTC VehicleService interface: ver.2.0.0"
FIRMWARE_VERSION = "Ver.1.0.0.1"
WHEEL_AXES = (0, 1)                      # getServoStatus ids: left, right wheel motor


class Control:
    """The control-path part of VehicleCore (mixed in; uses its attributes)."""

    config: Any
    device: Device
    alarms: Alarms
    odometry: Odometry

    # --- state ------------------------------------------------------------------------------
    def state(self) -> VehicleState:
        if not self.power:
            return VehicleState.UNPOWERED
        if self.alarms.first(AlarmType.FAULT, Kind.CONTACT):
            return VehicleState.ALARM
        if self.locked:
            return VehicleState.LOCKED
        if not self.servo:
            return VehicleState.POWERED
        if self.device.paused:        # Paused once at rest; Busy while it decelerates
            return VehicleState.BUSY if self.device.moving and self.device.rate > 0.0 else VehicleState.PAUSED
        if self.stuck:
            return VehicleState.STUCK
        if self.avoiding:             # stopping for a detour, or on it (acti_motion.vehicle.obstacles)
            return VehicleState.AVOID
        if self.device.busy:
            return VehicleState.BUSY
        if self._latest_warning() is not None:
            return VehicleState.WARNING
        return VehicleState.READY

    def state_string(self, s: VehicleState) -> str:
        """Table 7's string: Warning-### and Alarm-### carry the code."""
        alarm = (self.alarms.first(AlarmType.FAULT, Kind.CONTACT) if s == VehicleState.ALARM else
                 self._latest_warning() if s == VehicleState.WARNING else None)
        if alarm is None:                  # also when it was cleared meanwhile by another thread
            return STATE_STRINGS[s]
        return f"{STATE_STRINGS[s]}-{alarm.code:03d}"

    def _latest_warning(self) -> Alarm | None:
        warnings = [a for a in self.alarms.active() if a.type == AlarmType.WARNING]
        return warnings[-1] if warnings else None

    @query
    def get_state(self) -> dict:
        s = self.state()
        return {"state": int(s), "msg": self.state_string(s)}

    @command
    def set_power(self, on_off: bool) -> None:
        """Main power; switching it off stops the base and drops the servo. Switching on is
        refused while the battery is below its cut-off (with the hysteresis band); power that
        is on already stays on, true (偽 = 主回路電源投入に失敗: nothing failed)."""
        if on_off and not self.power and self._battery_empty.update(self.battery.voltage):
            raise VehicleRefused(AlarmCode.WRONG_STATE,
                                 f"the battery is at {self.battery.voltage:.1f} V, below the cut-off "
                                 f"{self.config.battery_cutoff_voltage:g} V + "
                                 f"{self.config.battery_hysteresis:g} V: power stays off")
        if not on_off:
            self.servo = False       # before the stop: a plan that commits after it sees it
            self._stop("power off")
        self.power = bool(on_off)

    @command
    def set_servo(self, on_off: bool) -> None:
        """Table 8: refused without power, and switching on is refused while an alarm is active;
        switching off stops a moving base first."""
        if not self.power:
            raise VehicleRefused(AlarmCode.WRONG_STATE,
                                 "main power is off: call set_power(true) first")
        if on_off and not self.servo and self.alarms.first(AlarmType.FAULT):
            alarm = self.alarms.first(AlarmType.FAULT)
            raise VehicleRefused(AlarmCode.WRONG_STATE,
                                 f"alarm {alarm.code} is active ({alarm.source}): the servo stays "
                                 f"off until {self._remedy(alarm.code)}")
        if not on_off:
            self.servo = False       # before the stop: a plan that commits after it sees it
            self._stop("servo off")
        self.servo = bool(on_off)

    def _remedy(self, code: int) -> str:
        """What ends an alarm: unlock for a contact, a charged battery for the battery's."""
        if code == AlarmCode.CONTACT:
            return "unlock"
        level = {AlarmCode.BATTERY_EMPTY: self._battery_empty,
                 AlarmCode.BATTERY_LOW: self._battery_low}.get(code)
        if level is not None:
            return f"the battery is back at {level.level + level.band:g} V and clear_alarm is called"
        return "clear_alarm"

    @query
    def get_servo_status(self, axisid: int) -> dict:
        if axisid not in WHEEL_AXES:
            raise VehicleRefused(AlarmCode.UNKNOWN_ID,
                                 f"axis {axisid} does not exist: the wheel motors are 0 (left) and 1 (right)")
        return {"status": self.servo}

    # --- alarms -----------------------------------------------------------------------------
    @command
    def clear_alarm(self) -> Reply | None:
        """Clear every alarm, the contact fault 301 too (1.4.1: 発生した全てのアラームを解除します).
        One whose cause is still there is raised again at once: a battery still within its
        hysteresis band of the level. Stuck ends. Locked is a state, not an alarm, and stays:
        table 7 keeps it "解除指令受信まで", and its release command is unlock (1.4.34:
        接触検出停止状態から復帰します), as clearAlarm is the Alarm state's. The reply (always true)
        says which alarms are still active and what ends each, and that the base stays Locked."""
        self.alarms.clear(*Kind)
        self.stuck = False
        self._check_battery(self.battery.voltage)
        left = [f"{a.code} until {self._remedy(a.code)}" for a in self.alarms.active()]
        if self.locked:
            left.append("Locked until unlock (a contact)")
        return Reply(comment="still active: " + "; ".join(left)) if left else None

    @query
    def get_active_alarm(self, num_of_alarm: int) -> dict:
        active = self.alarms.active()
        return {"num_of_active_alarm": len(active),
                "active_alarms": [(a.code, int(a.type), a.source)
                                  for a in active[:max(0, num_of_alarm)]]}

    @command
    def unlock(self) -> None:
        """Leave Locked; the contact sensor re-arms once the bumper is free."""
        self.locked = False
        self.alarms.clear(Kind.CONTACT)

    @command
    def set_digital_sensor_lock(self, on_off: bool) -> None:
        """Switched on, the sensor is armed at once: a bumper already touching something locks
        the base (有効時に接触を検出すると…停止し). Once it has locked, it re-arms only when the
        bumper is free, however often it is switched on again, so that an unlocked base can
        back away."""
        switched_on = bool(on_off) and not self.digital_sensor_lock
        self.digital_sensor_lock = bool(on_off)
        if switched_on and not self.locked:
            self._contact_armed = True

    # --- versions, limits, settings ---------------------------------------------------------
    @query
    def get_if_version(self) -> dict:
        return {"version": IF_VERSION}

    @query
    def get_version(self) -> dict:
        return {"ver": FIRMWARE_VERSION}

    @query
    def get_velocity_limit(self) -> dict:
        c = self.config
        return {"vel_limit_t": c.velocity_limit_translation, "vel_limit_r": c.velocity_limit_rotation}

    @query
    def get_acceleration_limit(self) -> dict:
        c = self.config
        return {"acc_limit_t": c.accel_limit_translation, "acc_limit_r": c.accel_limit_rotation}

    @query
    def get_default_velocity(self) -> dict:
        c = self.config
        return {"default_vel": (c.default_velocity_translation, c.default_velocity_rotation)}

    @query
    def get_default_acceleration(self) -> dict:
        c = self.config
        return {"default_accel": (c.default_accel_translation, c.default_accel_rotation)}

    @command
    def set_jog_timeout(self, timeout: int) -> None:
        if timeout <= 0:
            raise invalid(f"timeout is {timeout} ms: it must be > 0")
        self.jog_timeout = int(timeout)

    # --- position, battery, I/O -------------------------------------------------------------
    @query
    def get_position(self) -> dict:
        p = self.odometry.pose
        return {"pos": (1000.0 * p.x, 1000.0 * p.y, math.degrees(p.theta))}

    @query
    def get_battery_voltage(self) -> dict:
        """In the spec's unit, 0.1 V: 55.0 V reads 550.0."""
        return {"voltage": round(10.0 * self.battery.voltage, 1)}

    @query
    def get_input(self, ioid: int) -> dict:
        value = self.io.read(ioid)
        if value is None:
            raise VehicleRefused(AlarmCode.UNKNOWN_ID,
                                 f"input {ioid} is not declared (inputs: {sorted(self.io.inputs)})")
        return {"input": value}

    @command
    def set_output(self, ioid: int, output: int, mask: int) -> None:
        if ioid == 0:
            raise VehicleRefused(AlarmCode.UNKNOWN_ID, "output 0 is reserved for the unit")
        if not self.io.write(ioid, output, mask):
            raise VehicleRefused(AlarmCode.UNKNOWN_ID,
                                 f"output {ioid} is not declared (outputs: {sorted(self.io.outputs)})")

    # --- pause, resume, stop ----------------------------------------------------------------
    @command
    def pause(self) -> Reply | None:
        """Decelerate at the maximum acceleration and hold; the queue stays, new motions queue.
        Given while a stop decelerates, it holds once the base is at rest (完全停止後に一時停止
        状態). Ignored (still true, with a comment) where no motion can run: Unpowered, Powered,
        Alarm, Locked; switching the servo off ends a pause."""
        s = self.state()
        if s not in SERVO_ON:
            return Reply(comment=f"ignored: the base is {STATE_STRINGS[s]}, there is nothing to pause")
        self.device.pause(self._stop_ramp(), after_stop=True)
        return None

    @command
    def resume(self) -> Reply | None:
        """Leave a pause (the spec: always true); one that finds no pause says so, as pause does."""
        if not self.device.resume(self._resume_ramp()):
            return Reply(comment="ignored: the base is not paused")
        return None

    @command
    def stop(self) -> None:
        """Decelerate at the maximum acceleration and discard every motion, also those given
        until the base is at rest; then Ready (停止後は…待機状態に移行): Stuck ends too."""
        self._stop()
        self._accepted_motion()

    # --- ramps and stops --------------------------------------------------------------------
    def _ramp(self, accel: tuple[float, float], up: bool) -> float:
        """Time for the device's rate to ramp from 1 to 0 (pause, stop) or from 0 to 1 (`up`,
        resume) at `accel` (mm/s², degree/s²). Speed = rate × path speed, so where the path
        itself slows down (or, ramping up, speeds up) just now, its own acceleration adds to the
        ramp's: the ramp takes only what is left of `accel` beside it (at least a quarter); and
        stopping takes down the highest speed the path reaches meanwhile (`reference_peak`:
        exact, where nine samples of the span could miss it between them, at half their cost
        to the control plane)."""
        device, dt = self.device, self._dt
        cur = device.current
        motion = cur.motion if cur is not None and hasattr(cur.motion, "reference_twist") else None
        t = device.t
        if motion is None:
            now = later = (self.odometry.v, self.odometry.w)
        else:
            now, later = motion.reference_twist(t), motion.reference_twist(t + dt)
        ramp = 0.02
        for i, a in enumerate(si_pair(accel)):
            change = (abs(later[i]) - abs(now[i])) / dt
            adds = max(0.0, change if up else -change)
            speed = abs(now[i])
            if not up and change > 0.0:            # the path still speeds up while it stops
                span = speed * (1.0 + change / a) / a
                speed = max(speed, motion.reference_peak(t, t + span)[i])
            ramp = max(ramp, speed / max(a - adds, a / 4))
        return ramp

    def _stop_ramp(self) -> float:
        """Time to stop from the present speed at the maximum acceleration. A brake does so
        already: pause and stop keep its pace (infinite, the device's rate stays). Time-scaled,
        its clock froze in a pause and so did the wheel speeds it commands: the base rolled on,
        Paused, and stop and servo off, which only discarded the queue, could not end it."""
        cur = self.device.current
        if cur is not None and isinstance(cur.motion, BrakeMotion):
            return math.inf
        c = self.config
        return self._ramp((c.accel_limit_translation, c.accel_limit_rotation), up=False)

    def _resume_ramp(self) -> float:
        return self._ramp(self.acceleration, up=True)

    def _stop(self, reason: str = STOPPED) -> None:
        """Decelerate at the maximum acceleration and discard everything, `reason` given to
        the waits on what is discarded (all that comes until the base is at rest, also while
        a brake runs)."""
        self.device.stop(self._stop_ramp(), reason)

    def _halt(self, reason: str) -> None:
        """Give up the plan at once and brake the wheels at the maximum acceleration."""
        c = self.config
        decel = si_pair((c.accel_limit_translation, c.accel_limit_rotation))
        self.device.halt(self.odometry.pose, reason,
                         then=(BrakeMotion(self.odometry, decel), "brake"))
