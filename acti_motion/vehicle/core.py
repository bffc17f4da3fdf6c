"""The mobile-base core: the VehicleService operations, without ROS.

Each public method is one IDL operation, named as the ROS service, taking the IDL parameters by
their snake-case names (nested structs as tuples in field order) and returning a `Reply`: a
refusal is `success = false` with the reason as the message, and raises a warning (state
Warning-###) until clearAlarm or the next accepted command. Units are the spec's: mm, degree,
mm/s, degree/s, mm/s², degree/s², ms; the motion layer below works in m, rad, s.
"""
from __future__ import annotations

import functools
import math
import threading
from dataclasses import dataclass
from enum import IntEnum
from typing import Any, Callable

from acti_motion.vehicle.paths import (BrakeMotion, Odometry, Path, Pose2D, TrackedBaseMotion, arc, line,
                              straight_to, turn, velocity_path)
from acti_motion.vehicle.cruise import CruiseMotion, transition_to
from acti_motion.executor import Device, MotionExecutor
from acti_motion.replies import Refused, ReturnCode, answers, finite_number
from acti_motion.vehicle.alarms import AlarmCode, Alarms, AlarmType, Kind
from acti_sim.battery import Battery, BatteryModel
from acti_sim.io_module import IoModule
from acti_sim.world import World

IF_VERSION = "RTC VehicleService interface: ver.2.0.0"
FIRMWARE_VERSION = "Ver.1.0.0.1"
WHEEL_AXES = (0, 1)                      # getServoStatus ids: left, right wheel motor
VELOCITY_DRIVEN = ("move_jog", "joystick")  # motions driven by a velocity, not a target


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
# "Ready only" moves (moveForward, moveTurn, moveLinearRel, moveCircularRel) run from an idle base;
# Paused is idle too, and the pause operation says commands given then are kept for resume.
IDLE = (VehicleState.READY, VehicleState.WARNING, VehicleState.STUCK, VehicleState.PAUSED)
# "Servo on only" moves (moveLinearAbs, moveContinuousRel, moveCruiseAbs, moveJog) also queue
# behind a moving base; Alarm and Locked refuse every motion until clearAlarm / unlock.
SERVO_ON = IDLE + (VehicleState.BUSY, VehicleState.AVOID)


@dataclass
class VehicleConfig:
    """Start-up settings and limits of the base (spec units); the node's parameters."""
    queue_size: int = 32                         # motion queue capacity
    velocity_limit_translation: float = 1000.0   # velocity limit, translation [mm/s]
    velocity_limit_rotation: float = 90.0        # velocity limit, rotation [degree/s]
    accel_limit_translation: float = 1000.0      # acceleration limit, translation [mm/s²]
    accel_limit_rotation: float = 180.0          # acceleration limit, rotation [degree/s²]
    default_velocity_translation: float = 300.0  # velocity at start-up [mm/s]
    default_velocity_rotation: float = 45.0      # turn rate at start-up [degree/s]
    default_accel_translation: float = 500.0     # acceleration at start-up [mm/s²]
    default_accel_rotation: float = 90.0         # turn acceleration at start-up [degree/s²]
    jog_timeout: int = 500                       # ms from the last jog command to the stop
    joy_axis_linear: int = 1                     # sensor_msgs/Joy axis for forward speed …
    joy_axis_angular: int = 0                    # … and for the yaw rate (left stick)
    joy_enable_button: int = -1                  # a button that must be held (-1: none)
    io_config: str = ""                          # I/O ids (YAML); "" = config/vehicle_io.yaml
    battery_capacity_wh: float = 960.0           # battery capacity [Wh]
    battery_charge: float = 1.0                  # state of charge at start-up, 0 … 1
    battery_low_voltage: float = 46.0            # V: warning 110 below
    battery_cutoff_voltage: float = 44.0         # V: fault 201 below (servo off)
    stuck_error: float = 100.0                   # mm of tracking error …
    stuck_angle: float = 20.0                    # … or degrees of heading error …
    stuck_time: float = 0.3                      # … held this long (s): the base is Stuck


POWER_IDLE_W = 30.0          # electronics while the main power is on
POWER_SERVO_W = 20.0         # wheel servos holding
DRIVE_LOSS_N = 150.0         # rolling and drive-train resistance of the moving base
DRIVE_EFFICIENCY = 0.8


class VehicleRefused(Refused):
    """A refusal with the warning code it raises."""

    def __init__(self, alarm: AlarmCode, comment: str) -> None:
        super().__init__(ReturnCode.NG, comment)
        self.alarm = alarm


WARNING_FOR = {ReturnCode.VALUE_ERR: AlarmCode.INVALID_VALUE,
               ReturnCode.STATUS_ERR: AlarmCode.WRONG_STATE,
               ReturnCode.FULL_MOTION_QUEUE_ERR: AlarmCode.QUEUE_FULL}


def invalid(message: str) -> VehicleRefused:
    return VehicleRefused(AlarmCode.INVALID_VALUE, message)


def _operation(clears_warnings: bool) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    def decorate(fn: Callable[..., Any]) -> Callable[..., Any]:
        @functools.wraps(fn)
        def recorded(self: "VehicleCore", *args: Any, **kwargs: Any) -> Any:
            with self.lock:
                try:
                    out = fn(self, *args, **kwargs)
                except Refused as r:
                    code = getattr(r, "alarm", None) or WARNING_FOR.get(r.code, AlarmCode.INVALID_VALUE)
                    self.alarms.raise_(code, f"{fn.__name__}: {r.comment}", Kind.COMMAND)
                    raise
                if clears_warnings:
                    self.alarms.clear(Kind.COMMAND)
                return out
        return answers(recorded)
    return decorate


command = _operation(clears_warnings=True)    # changes something: success clears command warnings
query = _operation(clears_warnings=False)     # reads: a refusal (unknown id) still warns


def positive_pair(values: Any, limits: tuple[float, float], name: str, unit: tuple[str, str]) -> tuple[float, float]:
    """(translation, rotation), each finite, > 0 and within its limit."""
    out = []
    for value, limit, part, u in zip(values, limits, ("translation", "rotation"), unit):
        v = finite_number(value, f"{name}.{part}")
        if not 0.0 < v <= limit:
            raise invalid(f"{name}.{part} is {v:g} {u}: it must be > 0 and at most {limit:g} {u}")
        out.append(v)
    return out[0], out[1]


def finite_pose(pos: Any, name: str = "pos") -> Pose2D:
    """A Position (mm, mm, degree) as a Pose2D (m, m, rad)."""
    x, y, theta = (finite_number(v, f"{name}.{f}") for v, f in zip(pos, ("x", "y", "theta")))
    return Pose2D(x / 1000.0, y / 1000.0, math.radians(theta))


class VehicleCore:
    """Power, servo, state, alarms, I/O, battery, odometry and the motion queue of the base."""

    def __init__(self, executor: MotionExecutor, config: VehicleConfig | None = None) -> None:
        self.config = c = config or VehicleConfig()
        world = executor.world
        self.lock = threading.RLock()
        self.odometry = Odometry(world.wheel_radius, world.wheel_separation, world.wheel_positions())
        self.device: Device = executor.add_device("base", c.queue_size, self.odometry.pose)
        self.alarms = Alarms()
        self.battery = Battery(BatteryModel(capacity_wh=c.battery_capacity_wh), c.battery_charge)
        self._contact = False
        self.io = IoModule.load(c.io_config, {"bumper": lambda: int(self._contact)})
        self.power = False
        self.servo = False
        self.locked = False
        self.stuck = False
        self.digital_sensor_lock = False
        self._contact_armed = True
        self._stuck_since: float | None = None
        try:                          # the start-up settings obey the rules of the setters
            self.velocity = positive_pair(
                (c.default_velocity_translation, c.default_velocity_rotation),
                (c.velocity_limit_translation, c.velocity_limit_rotation), "default velocity",
                ("mm/s", "degree/s"))
            self.acceleration = positive_pair(
                (c.default_accel_translation, c.default_accel_rotation),
                (c.accel_limit_translation, c.accel_limit_rotation), "default acceleration",
                ("mm/s²", "degree/s²"))
        except Refused as r:
            raise ValueError(f"vehicle configuration: {r.comment}") from None
        if c.jog_timeout <= 0:
            raise ValueError(f"vehicle configuration: jog_timeout is {c.jog_timeout} ms, it must be > 0")
        self.jog_timeout = c.jog_timeout
        self.joystick = False
        self._dt = executor.dt
        executor.before_step(self._sense)

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
        if self.stuck:
            return VehicleState.STUCK
        if self.device.paused:        # Paused once at rest; Busy while it decelerates
            return VehicleState.BUSY if self.device.moving and self.device.rate > 0.0 else VehicleState.PAUSED
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

    def _latest_warning(self):
        warnings = [a for a in self.alarms.active() if a.type == AlarmType.WARNING]
        return warnings[-1] if warnings else None

    @query
    def get_state(self) -> dict:
        s = self.state()
        return {"state": int(s), "msg": self.state_string(s)}

    @command
    def set_power(self, on_off: bool) -> None:
        """Main power; switching it off stops the base and drops the servo."""
        if on_off and self.battery.voltage < self.config.battery_cutoff_voltage:
            raise VehicleRefused(AlarmCode.WRONG_STATE,
                                 f"the battery is at {self.battery.voltage:.1f} V, below the "
                                 f"cut-off {self.config.battery_cutoff_voltage:g} V: power stays off")
        if not on_off:
            self._stop()
            self.servo = False
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
                                 "off until clear_alarm / unlock")
        if not on_off:
            self._stop()
        self.servo = bool(on_off)

    @query
    def get_servo_status(self, axisid: int) -> dict:
        if axisid not in WHEEL_AXES:
            raise VehicleRefused(AlarmCode.UNKNOWN_ID,
                                 f"axis {axisid} does not exist: the wheel motors are 0 (left) and 1 (right)")
        return {"status": self.servo}

    # --- alarms -----------------------------------------------------------------------------
    @command
    def clear_alarm(self) -> None:
        """Clear every alarm whose cause is gone; a contact lock needs unlock."""
        self.alarms.clear(Kind.COMMAND, Kind.STUCK)
        self.stuck = False
        v = self.battery.voltage
        if v >= self.config.battery_cutoff_voltage:
            self.alarms.clear(code=AlarmCode.BATTERY_EMPTY)
        if v >= self.config.battery_low_voltage:
            self.alarms.clear(code=AlarmCode.BATTERY_LOW)

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
        self.digital_sensor_lock = bool(on_off)
        self._contact_armed = not self._contact

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
    def set_velocity(self, vel: Any) -> None:
        """Within the unit's limits, > 0. A moving base changes speed smoothly (at the
        acceleration setting) to match; queued moves take it too. Jogs keep their velocities."""
        c = self.config
        self.velocity = positive_pair(vel, (c.velocity_limit_translation, c.velocity_limit_rotation),
                                      "vel", ("mm/s", "degree/s"))
        self._retime()

    @command
    def set_acceleration(self, accel: Any) -> None:
        """Within the unit's limits, > 0; refused while moving (Busy, Avoid)."""
        c = self.config
        value = positive_pair(accel, (c.accel_limit_translation, c.accel_limit_rotation),
                              "accel", ("mm/s²", "degree/s²"))
        s = self.state()
        if s in (VehicleState.BUSY, VehicleState.AVOID):
            raise VehicleRefused(AlarmCode.WRONG_STATE,
                                 f"the base is {STATE_STRINGS[s]}: set_acceleration is refused while moving")
        self.acceleration = value
        self._retime()

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

    @command
    def set_position(self, pos: Any) -> None:
        """Redefine the odometry pose; accepted motions keep their path on the floor."""
        new = finite_pose(pos)

        def move_frame(device: Device) -> None:
            frame = self.odometry.reset(new)
            running = [device.current] if device.current is not None else []
            for queued in running + list(device.queue):
                queued.motion.move_frame(frame)
            device.hold = frame.compose(device.hold)
        self.device.edit(move_frame)

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
    def pause(self) -> None:
        """Decelerate at the maximum acceleration and hold; the queue stays, new motions queue."""
        self.device.pause(self._stop_ramp())

    @command
    def resume(self) -> None:
        self.device.resume(self._resume_ramp())

    @command
    def stop(self) -> None:
        """Decelerate at the maximum acceleration and discard every motion."""
        self._stop()

    # --- motion -----------------------------------------------------------------------------
    @command
    def move_forward(self, x: float) -> dict:
        distance = finite_number(x, "x") / 1000.0
        self._require(IDLE, "move_forward")
        limits = self._limits()
        return self._submit(lambda start: line(start, distance, limits), "move_forward")

    @command
    def move_turn(self, theta: float) -> dict:
        angle = math.radians(finite_number(theta, "theta"))
        self._require(IDLE, "move_turn")
        limits = self._limits()
        return self._submit(lambda start: turn(start, angle, limits), "move_turn")

    @command
    def move_linear_rel(self, pos: Any) -> dict:
        rel = finite_pose(pos)
        self._require(IDLE, "move_linear_rel")
        limits = self._limits()
        return self._submit(lambda start: straight_to(start, start.compose(rel), limits, False),
                            "move_linear_rel")

    @command
    def move_linear_abs(self, pos: Any) -> dict:
        goal = finite_pose(pos)
        self._require(SERVO_ON, "move_linear_abs")
        limits = self._limits()
        return self._submit(lambda start: straight_to(start, goal, limits, True), "move_linear_abs")

    @command
    def move_circular_rel(self, center_point: Any, theta: float) -> dict:
        cx, cy = (finite_number(v, f"center_point.{f}") for v, f in zip(center_point, "xy"))
        angle = math.radians(finite_number(theta, "theta"))
        if cx != 0.0:
            raise VehicleRefused(AlarmCode.NOT_HOLONOMIC,
                                 f"center_point.x is {cx:g} mm: a differential drive turns only "
                                 "about a point on its wheel axle (x = 0)")
        self._require(IDLE, "move_circular_rel")
        limits = self._limits()
        return self._submit(lambda start: arc(start, cy / 1000.0, angle, limits), "move_circular_rel")

    @command
    def move_cruise_abs(self, cruise_point: Any) -> dict:
        """Pass cruise_point (odometry frame) smoothly: points given while the base cruises are
        appended to its path, so it stops only at the last; TOPP-RA times the path within the
        velocity and acceleration settings."""
        px, py = (finite_number(v, f"cruise_point.{f}") for v, f in zip(cruise_point, "xy"))
        self._require(SERVO_ON, "move_cruise_abs")
        point, limits, odometry = (px / 1000.0, py / 1000.0), self._limits(), self.odometry

        def extend(device: Device) -> int | None:
            last = device.queue[-1] if device.queue else device.current
            if last is None or last.label != "move_cruise_abs":
                return None
            running = last is device.current
            if running and device.stopping:
                return None
            last.motion.limits = limits
            return last.id if last.motion.add_point(point, device.t if running else 0.0) else None
        motion_id = self.device.edit(extend)
        if motion_id is not None:
            self._accepted_motion()
            return {"motion_id": motion_id}
        return self._submit_motion(lambda start: CruiseMotion(odometry, start, point, limits),
                                   "move_cruise_abs")

    @command
    def move_continuous_rel(self, pos: Any) -> dict:
        """Go to pos relative to the base. Given again while the base is on its way, the new
        target (relative to where the base is then) replaces the old one and the base turns onto
        it with continuous velocity; behind other queued moves it waits its turn."""
        rel = finite_pose(pos)
        self._require(SERVO_ON, "move_continuous_rel")
        limits, label = self._limits(), "move_continuous_rel"

        def retarget(device: Device) -> int | None:
            last = device.queue[-1] if device.queue else device.current
            if last is None or last.label != label:
                return None
            if last is not device.current:                       # queued: plan it again
                start = last.motion.at(0.0)
                last.motion.splice(0.0, straight_to(start, start.compose(rel), limits, False))
                return last.id
            if device.stopping:
                return None
            t, motion = device.t, last.motion
            here = motion.at(t)
            motion.splice(t, transition_to(here, *motion.reference_twist(t), here.compose(rel), limits))
            return last.id
        motion_id = self.device.edit(retarget)
        if motion_id is not None:
            self._accepted_motion()
            return {"motion_id": motion_id}
        return self._submit(lambda start: straight_to(start, start.compose(rel), limits, False), label)

    @command
    def move_jog(self, x_vel: float, y_vel: float, theta_vel: float) -> dict:
        """Drive at (x_vel, theta_vel) until jog_timeout ms after the last call, then decelerate.
        Each velocity is signed (backwards, clockwise) and at most the unit's limit; y_vel must
        be 0 on a differential drive. A jog starts on an idle base or updates the running jog."""
        c = self.config
        vx, vy, vth = (finite_number(v, n) for v, n in zip((x_vel, y_vel, theta_vel),
                                                            ("x_vel", "y_vel", "theta_vel")))
        if vy != 0.0:
            raise VehicleRefused(AlarmCode.NOT_HOLONOMIC,
                                 f"y_vel is {vy:g} mm/s: a differential drive cannot move sideways")
        for value, limit, name, unit in ((vx, c.velocity_limit_translation, "x_vel", "mm/s"),
                                         (vth, c.velocity_limit_rotation, "theta_vel", "degree/s")):
            if abs(value) > limit:
                raise invalid(f"{name} is {value:g} {unit}: the unit's limit is {limit:g} {unit}")
        self._require(SERVO_ON, "move_jog")
        (at, ar) = self.acceleration
        return self._drive((vx / 1000.0, math.radians(vth)), self.jog_timeout / 1000.0,
                           (at / 1000.0, math.radians(ar)), "move_jog")

    @command
    def set_joystick(self, on_off: bool) -> None:
        """Joystick on: its input drives the base (within the velocity and acceleration settings).
        Off while it drives: decelerate at the maximum acceleration, then Ready."""
        self.joystick = bool(on_off)
        cur = self.device.current
        if not on_off and cur is not None and cur.label == "joystick":
            c = self.config
            self._drive((0.0, 0.0), 0.0, (c.accel_limit_translation / 1000.0,
                                          math.radians(c.accel_limit_rotation)), "joystick")

    def joy_input(self, axes: list[float], buttons: list[int]) -> bool:
        """A sensor_msgs/Joy sample (not an IDL operation): full stick = the velocity setting.
        Ignored (False) with the joystick off, the servo off, an alarm, or moves in the queue."""
        c = self.config
        with self.lock:
            if not self.joystick or self.state() not in SERVO_ON:
                return False
            if c.joy_enable_button >= 0 and not (c.joy_enable_button < len(buttons)
                                                 and buttons[c.joy_enable_button]):
                axes = []

            def axis(i: int) -> float:
                value = axes[i] if 0 <= i < len(axes) else 0.0
                return min(1.0, max(-1.0, value)) if math.isfinite(value) else 0.0
            (vt, vr), (at, ar) = self.velocity, self.acceleration
            target = (axis(c.joy_axis_linear) * vt / 1000.0, math.radians(axis(c.joy_axis_angular) * vr))
            try:
                self._drive(target, self.jog_timeout / 1000.0, (at / 1000.0, math.radians(ar)),
                            "joystick")
            except Refused:
                return False
            return True

    # --- helpers ----------------------------------------------------------------------------
    def _require(self, allowed: tuple[VehicleState, ...], operation: str) -> None:
        s = self.state()
        if s not in allowed:
            need = "Ready" if allowed == IDLE else "the servo on"
            raise VehicleRefused(AlarmCode.WRONG_STATE,
                                 f"the base is {STATE_STRINGS[s]}: {operation} needs {need}"
                                 + self._how_to_leave(s))

    @staticmethod
    def _how_to_leave(s: VehicleState) -> str:
        return {VehicleState.UNPOWERED: " (call set_power(true), then set_servo(true))",
                VehicleState.POWERED: " (call set_servo(true))",
                VehicleState.ALARM: " (call clear_alarm)",
                VehicleState.LOCKED: " (call unlock)",
                VehicleState.BUSY: " (wait, or call stop)"}.get(s, "")

    def _limits(self) -> tuple[float, float, float, float]:
        """The velocity and acceleration settings in SI: (v, w, a, alpha)."""
        (vt, vr), (at, ar) = self.velocity, self.acceleration
        return vt / 1000.0, math.radians(vr), at / 1000.0, math.radians(ar)

    def _submit(self, plan: Callable[[Pose2D], Path], label: str) -> dict:
        """Queue a tracked motion along plan(start of the motion)."""
        odometry = self.odometry
        return self._submit_motion(lambda start: TrackedBaseMotion(odometry, plan(start), label),
                                   label)

    def _submit_motion(self, make: Callable[[Pose2D], Any], label: str) -> dict:
        motion_id = self.device.submit(make, label)
        if motion_id is None:
            raise VehicleRefused(AlarmCode.QUEUE_FULL,
                                 f"the motion queue is full ({self.device.capacity} motions)")
        self._accepted_motion()
        return {"motion_id": motion_id}

    def _drive(self, target: tuple[float, float], hold: float, accel: tuple[float, float],
               label: str) -> dict:
        """Velocity drive: re-plan the running jog/joystick motion from where its reference is
        now (speed continuous), or start one on an idle base; refused behind queued moves."""
        def plan(start: Pose2D, v0: float = 0.0, w0: float = 0.0) -> Path:
            return velocity_path(start, v0, w0, target, hold, accel)

        def update(device: Device) -> int | None:
            cur = device.current
            if cur is not None and not device.queue and not device.stopping \
                    and cur.label in VELOCITY_DRIVEN:
                t = device.t
                cur.motion.splice(t, plan(cur.motion.at(t), *cur.motion.reference_twist(t)))
                cur.label = label
                return cur.id
            if device.busy and not (cur is not None and device.stopping and not device.queue):
                raise VehicleRefused(AlarmCode.WRONG_STATE,
                                     f"the base is busy with queued moves: {label} drives only an "
                                     "idle base (wait, or call stop)")
            return None
        motion_id = self.device.edit(update)
        if motion_id is None and target == (0.0, 0.0):
            return {"motion_id": 0}                  # standing still already: nothing to queue
        if motion_id is None:
            return self._submit(plan, label)
        self._accepted_motion()
        return {"motion_id": motion_id}

    def _accepted_motion(self) -> None:
        self.stuck = False
        self.alarms.clear(Kind.STUCK)

    def _retime(self) -> None:
        """Apply new settings to the running motion (from now on) and to the queued ones."""
        limits = self._limits()

        def retime(device: Device) -> None:
            cur = device.current
            if cur is not None and not device.stopping and hasattr(cur.motion, "retime"):
                cur.motion.retime(device.t, limits)
            for queued in device.queue:
                if hasattr(queued.motion, "retime"):
                    queued.motion.retime(0.0, limits)
        self.device.edit(retime)

    def _reference_twist(self) -> tuple[float, float]:
        cur = self.device.current
        if cur is None or not hasattr(cur.motion, "reference_twist"):
            return self.odometry.v, self.odometry.w
        return cur.motion.reference_twist(self.device.t)

    def _stop_ramp(self) -> float:
        """Time to stop from the present speed at the maximum acceleration."""
        c = self.config
        v, w = self._reference_twist()
        return max(abs(v) * 1000.0 / c.accel_limit_translation,
                   math.degrees(abs(w)) / c.accel_limit_rotation, 0.02)

    def _resume_ramp(self) -> float:
        v, w = self._reference_twist()
        (at, ar) = self.acceleration
        return max(abs(v) * 1000.0 / at, math.degrees(abs(w)) / ar, 0.02)

    def _stop(self) -> None:
        cur = self.device.current
        if cur is not None and isinstance(cur.motion, BrakeMotion):
            return
        self.device.stop(self._stop_ramp())

    def _halt(self) -> None:
        """Give up the plan at once and brake the wheels at the maximum acceleration."""
        c = self.config
        self.device.halt(self.odometry.pose)
        decel = (c.accel_limit_translation / 1000.0, math.radians(c.accel_limit_rotation))
        self.device.submit(lambda start: BrakeMotion(self.odometry, decel), "brake")

    # --- the simulation thread --------------------------------------------------------------
    def _sense(self, world: World) -> None:
        """Each step before the devices move: odometry, battery, contact and blockage."""
        self.odometry.update(world.wheel_positions(), self._dt)
        if self.device.current is None:
            world.set_wheel_velocities(0.0, 0.0)
        self._drain_battery()
        self._contact = contact = world.bumper_in_contact()
        if not contact:
            self._contact_armed = True
        elif self.digital_sensor_lock and self._contact_armed and not self.locked:
            with self.lock:
                self._contact_armed = False
                self.locked = True
                self.alarms.raise_(AlarmCode.CONTACT, "contact sensor: the bumper touched something",
                                   Kind.CONTACT)
                self._halt()
        self._watch_tracking(world.time)

    def _watch_tracking(self, now: float) -> None:
        cur = self.device.current
        c = self.config
        if cur is None or isinstance(cur.motion, BrakeMotion) or self.device.paused:
            self._stuck_since = None
            return
        dist, angle = cur.motion.error
        if dist * 1000.0 < c.stuck_error and abs(math.degrees(angle)) < c.stuck_angle:
            self._stuck_since = None
            return
        if self._stuck_since is None:
            self._stuck_since = now
        elif now - self._stuck_since >= c.stuck_time:
            with self.lock:
                self._stuck_since = None
                self.stuck = True
                self.alarms.raise_(AlarmCode.STUCK,
                                   f"the base could not follow its path ({1000 * dist:.0f} mm, "
                                   f"{math.degrees(angle):.1f}° off): stopped", Kind.STUCK)
                self._halt()

    def _drain_battery(self) -> None:
        if not self.power:
            self.battery.drain(0.0, self._dt)
            return
        v, w, b = self.odometry.v, self.odometry.w, self.odometry.b
        wheels = abs(v - w * b / 2) + abs(v + w * b / 2)
        drive = DRIVE_LOSS_N * wheels / 2 / DRIVE_EFFICIENCY
        self.battery.drain(POWER_IDLE_W + (POWER_SERVO_W if self.servo else 0.0) + drive, self._dt)
        voltage, c = self.battery.voltage, self.config
        if voltage < c.battery_low_voltage and not self.alarms.has(AlarmCode.BATTERY_LOW):
            self.alarms.raise_(AlarmCode.BATTERY_LOW,
                               f"battery low: {voltage:.1f} V (below {c.battery_low_voltage:g} V)",
                               Kind.CONDITION)
        if voltage < c.battery_cutoff_voltage and not self.alarms.has(AlarmCode.BATTERY_EMPTY):
            with self.lock:
                self.alarms.raise_(AlarmCode.BATTERY_EMPTY,
                                   f"battery exhausted: {voltage:.1f} V (below "
                                   f"{c.battery_cutoff_voltage:g} V): servo off", Kind.CONDITION)
                self._stop()
                self.servo = False
