"""The planning path of the base: every move, the settings that re-time or re-frame the motions
(set_velocity's re-plan, set_acceleration, set_position), the joystick and its input. Each operation runs
on the caller's thread (the node's motion plane) under the `planning` lock (`@planned`;
joy_input takes it itself), one at a time, and plans under no lock that the control operations
or the simulation take, so that a plan taking milliseconds never delays stop, pause, a getter
or a step. It takes the short state lock `lock` only to check the state, and commits through
the device's edits, which plan again when the device changed meanwhile. A part of VehicleCore
(its state, locks and device), mixed in."""
from __future__ import annotations

import math
from contextlib import contextmanager
from typing import Any, Callable, Iterator

from acti_motion.executor import STALE, Device
from acti_motion.replies import Refused, Reply, finite_number
from acti_motion.vehicle.alarms import AlarmCode
from acti_motion.vehicle.cruise import CruiseMotion, transition_to
from acti_motion.vehicle.paths import (Path, Pose2D, TrackedBaseMotion, arc, line, straight_to, turn,
                                       velocity_path)
from acti_motion.vehicle.refusals import (Discarded, VehicleRefused, bounded_pair, command, finite_pose, invalid,
                                          planned, si_pair)
from acti_motion.vehicle.sensing import VELOCITY_DRIVEN
from acti_motion.vehicle.states import READY_ONLY, SERVO_ON, STATE_STRINGS, VehicleState

LOOKAHEAD_STEPS = 2          # control periods ahead of now that an edit planned off-lock splices in …
LOOKAHEAD_GROWTH = 4         # … times this for each attempt the device outran
RETIME_TRIES = 3             # re-plans of a new velocity setting before the moves keep their timing


PAUSED = object()       # look of a take-over: the base is paused, the command queues for resume
# a velocity drive given while paused: taking over would discard what the pause keeps for
# resume (pause: 動作指令は廃棄されません), and queued, its deadman would end it before it ran
PAUSED_DRIVE = ("the base is Paused: {} would discard the moves kept for resume "
                "(resume or stop first)")


class Planning:
    """The planning-path part of VehicleCore (mixed in; uses its attributes)."""

    config: Any
    device: Device

    # --- settings that re-time or re-frame the motions --------------------------------------
    def set_velocity(self, vel: Any) -> Reply:
        """Within [velocity_min, limit]; answered once the value is checked and set, as 1.4.32
        answers (真：引数で指定した値が正常に設定された). A moving base then changes speed smoothly
        (at the acceleration setting) to match; queued moves take it too (移動中に実行すると，
        移動速度を連続かつ動的に変化させて設定値に一致させます): the re-plan runs after the answer
        (`retiming`), so the caller never waits for it. Jogs keep their velocities (the command's
        own); a joystick drive scales to it (full stick = the setting)."""
        reply = self._set_velocity(vel)
        if reply.ok:
            self.retimer.request()
        return reply

    @command
    def _set_velocity(self, vel: Any) -> None:
        self.velocity = bounded_pair(vel, *self.velocity_bounds, "vel", ("mm/s", "degree/s"))

    def _retime_to_settings(self) -> None:
        """The re-plan a new velocity setting asks (the retimer's): the running and queued moves
        re-timed to the settings as they are now (a move that outran the plan is planned again),
        and a joystick drive rescaled."""
        with self.planning_operation():
            for _ in range(RETIME_TRIES):
                try:
                    self._retime(self.velocity, self.acceleration)
                    break
                except VehicleRefused:
                    continue            # the base outran the plan: plan again from where it is
            else:
                raise RuntimeError(f"the base outran {RETIME_TRIES} re-plans")
            self._rescale_joystick()

    @planned
    def set_acceleration(self, accel: Any) -> None:
        """Within [accel_min, limit]; refused while moving (Busy, Avoid)."""
        value = bounded_pair(accel, *self.accel_bounds, "accel", ("mm/s²", "degree/s²"))
        s = self.state()
        if s in (VehicleState.BUSY, VehicleState.AVOID):
            raise VehicleRefused(AlarmCode.WRONG_STATE,
                                 f"the base is {STATE_STRINGS[s]}: set_acceleration is refused while moving")
        self._retime(self.velocity, value)
        self.acceleration = value

    @planned
    def set_position(self, pos: Any) -> None:
        """Redefine the odometry pose (within the work area); accepted motions keep their path
        on the floor. A planning operation: no plan can start from the old frame meanwhile."""
        new = finite_pose(pos)
        self._check_rotation(new.theta, "pos.theta")
        self._check_goal(new, "pos")

        def move_frame(device: Device) -> None:
            frame = self.odometry.reset(new)
            running = [device.current] if device.current is not None else []
            for queued in running + list(device.queue):
                queued.motion.move_frame(frame)
            device.hold = frame.compose(device.hold)
        self.device.edit(move_frame)

    # --- motion -----------------------------------------------------------------------------
    @planned
    def move_forward(self, x: float) -> dict:
        distance = finite_number(x, "x") / 1000.0
        self._check_step(distance, 0.0, "x")
        self._require(READY_ONLY, "move_forward")
        limits = self._limits()

        def plan(start: Pose2D) -> Path:
            self._check_goal(start.forward(distance), "the target")
            return line(start, distance, limits)
        return self._submit(plan, "move_forward", READY_ONLY)

    @planned
    def move_turn(self, theta: float) -> dict:
        angle = math.radians(finite_number(theta, "theta"))
        self._check_rotation(angle, "theta")
        self._require(READY_ONLY, "move_turn")
        limits = self._limits()
        return self._submit(lambda start: turn(start, angle, limits), "move_turn", READY_ONLY)

    @planned
    def move_linear_rel(self, pos: Any) -> dict:
        rel = finite_pose(pos)
        self._check_rotation(rel.theta, "pos.theta")
        self._check_step(rel.x, rel.y, "pos")
        self._require(READY_ONLY, "move_linear_rel")
        limits = self._limits()

        def plan(start: Pose2D) -> Path:
            goal = self._check_goal(start.compose(rel), "the target")
            return straight_to(start, goal, limits, False)
        return self._submit(plan, "move_linear_rel", READY_ONLY)

    @planned
    def move_linear_abs(self, pos: Any) -> dict:
        goal = finite_pose(pos)
        self._check_rotation(goal.theta, "pos.theta")
        self._check_goal(goal, "pos")
        self._require(SERVO_ON, "move_linear_abs")
        limits = self._limits()
        return self._submit(lambda start: straight_to(start, goal, limits, True), "move_linear_abs",
                            SERVO_ON)

    @planned
    def move_circular_rel(self, center_point: Any, theta: float) -> dict:
        cx, cy = (finite_number(v, f"center_point.{f}") for v, f in zip(center_point, "xy"))
        angle = math.radians(finite_number(theta, "theta"))
        if cx != 0.0:
            raise VehicleRefused(AlarmCode.NOT_HOLONOMIC,
                                 f"center_point.x is {cx:.10g} mm: a differential drive turns only "
                                 "about a point on its wheel axle (x = 0)")
        self._check_rotation(angle, "theta")
        if abs(cy) > self.config.work_area:
            raise invalid(f"center_point.y is {cy:.10g} mm: the centre must lie within the work area "
                          f"(±{self.config.work_area:g} mm)")
        self._require(READY_ONLY, "move_circular_rel")
        limits = self._limits()

        def plan(start: Pose2D) -> Path:
            path = arc(start, cy / 1000.0, angle, limits)
            self._check_goal(path.pose(path.duration), "the target")
            return path
        return self._submit(plan, "move_circular_rel", READY_ONLY)

    @planned
    def move_cruise_abs(self, cruise_point: Any) -> dict:
        """Pass cruise_point (odometry frame) smoothly: points given while the base cruises are
        appended to its path, so it stops only at the last; TOPP-RA times the path within the
        velocity and acceleration settings. Each point costs the same to add, however many
        came before (only the path after the last point but one is planned again)."""
        px, py = (finite_number(v, f"cruise_point.{f}") for v, f in zip(cruise_point, "xy"))
        point = (px / 1000.0, py / 1000.0)
        self._check_goal(Pose2D(*point, 0.0), "cruise_point")
        self._require(SERVO_ON, "move_cruise_abs")
        limits, odometry = self._limits(), self.odometry

        def look(device: Device, attempt: int):
            last = device.queue[-1] if device.queue else device.current
            if last is None or last.label != "move_cruise_abs" or not isinstance(last.motion, CruiseMotion):
                return None
            running = last is device.current
            if running and device.stopping:
                return None
            return last, running, self._splice_time(device, last.motion, attempt) if running else 0.0

        def plan(seen):
            if seen is None:
                return lambda device: None
            last, running, t = seen
            update = last.motion.plan(t, [point], limits)

            def commit(device: Device) -> int | None:
                if update is None:
                    return None
                if running and device.t > t:
                    return STALE
                self._admit(SERVO_ON, "move_cruise_abs", device)
                last.motion.commit(update)
                return last.id
            return commit
        motion_id = self._edit(look, plan)
        if motion_id is not None:
            self._accepted_motion()
            return {"motion_id": motion_id}
        return self._submit_motion(lambda start: CruiseMotion(odometry, start, point, limits),
                                   "move_cruise_abs", SERVO_ON)

    @planned
    def move_continuous_rel(self, pos: Any) -> dict:
        """Go to pos relative to the base. Given while the base moves (any move but a brake),
        the new target (relative to where the base is then) takes over: the base turns onto it
        with continuous velocity and every move queued behind is discarded (1.4.15: 連続実行
        した場合，最後に設定された目標点以外は消去; 移動中に実行すると…新たな経路へと移行)."""
        rel = finite_pose(pos)
        self._check_rotation(rel.theta, "pos.theta")
        self._check_step(rel.x, rel.y, "pos")
        self._require(SERVO_ON, "move_continuous_rel")
        limits, label = self._limits(), "move_continuous_rel"

        def look(device: Device, attempt: int):
            if device.paused:
                return PAUSED
            cur = self._running(device)
            if cur is None:
                return None
            return cur, cur.motion.at(device.t), self._splice_time(device, cur.motion, attempt)

        def plan(seen):
            if seen is PAUSED:          # kept for resume (一時停止状態で入力された動作指令は蓄積)
                return lambda device: None
            if seen is None:
                return self._discard_not_started
            cur, here, t = seen
            goal = self._check_goal(here.compose(rel), "the target")
            motion = cur.motion
            path = transition_to(motion.at(t), *motion.reference_twist(t), goal, limits)
            return lambda device: self._take_over(device, cur, t, path, label)
        motion_id = self._edit(look, plan)
        if motion_id is not None:
            self._accepted_motion()
            return {"motion_id": motion_id}

        def from_rest(start: Pose2D) -> Path:
            return straight_to(start, self._check_goal(start.compose(rel), "the target"), limits, False)
        return self._submit(from_rest, label, SERVO_ON)

    @planned
    def move_jog(self, x_vel: float, y_vel: float, theta_vel: float) -> dict:
        """Drive at (x_vel, theta_vel) until jog_timeout ms (wall time) after the last call, then
        decelerate. Each velocity is signed (backwards, clockwise) and at most the unit's limit;
        y_vel must be 0 on a differential drive. Servo on: a jog starts on an idle base, updates
        the running jog, or takes over a running move (discarding the moves queued behind)."""
        c = self.config
        vx, vy, vth = (finite_number(v, n) for v, n in zip((x_vel, y_vel, theta_vel),
                                                            ("x_vel", "y_vel", "theta_vel")))
        if vy != 0.0:
            raise VehicleRefused(AlarmCode.NOT_HOLONOMIC,
                                 f"y_vel is {vy:.10g} mm/s: a differential drive cannot move sideways")
        for value, limit, name, unit in ((vx, c.velocity_limit_translation, "x_vel", "mm/s"),
                                         (vth, c.velocity_limit_rotation, "theta_vel", "degree/s")):
            if abs(value) > limit:
                raise invalid(f"{name} is {value:.10g} {unit}: the unit's limit is {limit:g} {unit}")
        self._require(SERVO_ON, "move_jog")
        return self._drive(si_pair((vx, vth)), self.jog_timeout / 1000.0,
                           si_pair(self.acceleration), "move_jog", take_over=True)

    def clamp_velocity(self, x_vel: float, theta_vel: float) -> tuple[float, float, bool] | None:
        """(x_vel mm/s, theta_vel degree/s) clamped to the unit's limits, and whether they were:
        cmd_vel is clamped, as ROS base drivers do, where move_jog refuses. None for a NaN, which
        is no velocity at all (min and max would have made it full speed in reverse)."""
        if math.isnan(x_vel) or math.isnan(theta_vel):
            return None
        c = self.config
        x = min(c.velocity_limit_translation, max(-c.velocity_limit_translation, x_vel))
        th = min(c.velocity_limit_rotation, max(-c.velocity_limit_rotation, theta_vel))
        return x, th, (x, th) != (x_vel, theta_vel)

    @planned
    def set_joystick(self, on_off: bool) -> None:
        """Joystick on: its input drives the base (within the velocity and acceleration settings).
        Off while it drives: decelerate at the maximum acceleration, then Ready (while paused it
        stays held, and its deadman ends it after resume)."""
        self.joystick = bool(on_off)
        cur = self.device.current
        if not on_off and cur is not None and cur.label == "joystick" and not self.device.paused:
            c = self.config
            try:
                self._drive((0.0, 0.0), 0.0,
                            si_pair((c.accel_limit_translation, c.accel_limit_rotation)), "joystick",
                            take_over=False, brake=True)
            except VehicleRefused:
                pass    # the base outran every plan of the brake: the drive's deadman ends it

    def joy_input(self, axes: list[float], buttons: list[int]) -> bool:
        """A sensor_msgs/Joy sample (not an IDL operation): full stick = the velocity setting.
        Ignored (False) with the joystick off, the servo off, an alarm, or other moves running
        or queued."""
        c = self.config
        with self.planning_operation():
            if not self.joystick or self.state() not in SERVO_ON:
                return False
            if c.joy_enable_button >= 0 and not (c.joy_enable_button < len(buttons)
                                                 and buttons[c.joy_enable_button]):
                axes = []

            def axis(i: int) -> float:
                value = axes[i] if 0 <= i < len(axes) else 0.0
                return min(1.0, max(-1.0, value)) if math.isfinite(value) else 0.0
            stick = (axis(c.joy_axis_linear), axis(c.joy_axis_angular))
            try:
                self._drive(self._stick_target(stick), self.jog_timeout / 1000.0,
                            si_pair(self.acceleration), "joystick", take_over=False)
            except Refused:
                return False
            self._stick = stick
            return True

    def _stick_target(self, stick: tuple[float, float]) -> tuple[float, float]:
        """The joystick's (v, w) in SI for stick deflections in −1 … 1: full stick = the setting."""
        return si_pair((stick[0] * self.velocity[0], stick[1] * self.velocity[1]))

    def _rescale_joystick(self) -> None:
        """A joystick drive takes a new velocity setting at once, not at the next Joy sample
        (1.4.27: its speed is limited by setVelocity; 1.4.32: a moving base changes speed to
        match), keeping its deadman's deadline."""
        cur, left = self.device.current, self._drive_deadline - self._world.time
        if cur is None or cur.label != "joystick" or self._deadman_fired == cur.id \
                or not 0.0 < left < math.inf:
            return
        try:
            self._drive(self._stick_target(self._stick), left, si_pair(self.acceleration),
                        "joystick", take_over=False)
        except Refused:
            pass    # held by a pause, or moves queued behind it: its next sample or its deadman

    # --- helpers ----------------------------------------------------------------------------
    @contextmanager
    def planning_operation(self) -> Iterator[None]:
        """The planning lock for one operation, which arrives when it is called: a stop that
        comes after that (also while it waits for another's plan) or decelerates then discards
        what it commands (`_admit`); one that waited was run after the stop."""
        arrived = self.device.arrival()
        with self.planning:
            self._op_generation, self._op_arrival = self.device.generation, arrived
            yield

    def _require(self, allowed: tuple[VehicleState, ...], operation: str) -> None:
        """The state check before planning. A move given while a stop decelerates is true and
        discarded, as at its commit (`_admit`): a Ready-only one was refused as Busy instead,
        and left the stopped base in Warning-102."""
        with self.lock:
            s = self.state()
            if self.device.stopped_since(self._op_arrival) and s in SERVO_ON:
                raise Discarded(operation)
            self._refuse_unless(s, allowed, operation)

    def _admit(self, allowed: tuple[VehicleState, ...], operation: str, device: Device) -> None:
        """The check a planned motion passes when it is committed (after planning): still in
        an allowed state; and if a stop decelerated when the operation arrived or came since,
        or a halt came since it began, it is discarded (stop discards every motion command).
        Takes no lock, so that it can run inside the device's."""
        s = self.state()
        if (device.stopped_since(self._op_arrival) or device.generation != self._op_generation) \
                and s in SERVO_ON:
            raise Discarded(operation)
        self._refuse_unless(s, allowed, operation)

    def _refuse_unless(self, s: VehicleState, allowed: tuple[VehicleState, ...], operation: str) -> None:
        if s not in allowed:
            need = ("Ready (a Ready-only move)"
                    if allowed == READY_ONLY else "it unlocked" if s == VehicleState.LOCKED
                    else "no active alarm" if s == VehicleState.ALARM else "the servo on")
            raise VehicleRefused(AlarmCode.WRONG_STATE,
                                 f"the base is {self.state_string(s)}: {operation} needs {need}"
                                 + self._how_to_leave(s))

    def _how_to_leave(self, s: VehicleState) -> str:
        if s in (VehicleState.WARNING, VehicleState.STUCK):
            warning = self._latest_warning() if s == VehicleState.WARNING else None
            return (f" (it lasts until {self._remedy(warning.code)})" if warning is not None
                    else " (call clear_alarm or stop)")
        return {VehicleState.UNPOWERED: " (call set_power(true), then set_servo(true))",
                VehicleState.POWERED: " (call set_servo(true))",
                VehicleState.ALARM: " (call clear_alarm)",
                VehicleState.LOCKED: " (call unlock)",
                VehicleState.BUSY: " (wait, or call stop)"}.get(s, "")

    def _check_goal(self, goal: Pose2D, what: str) -> Pose2D:
        """Refuse a target outside the work area (a plan there could not be made quickly)."""
        area = self.config.work_area
        if not (abs(goal.x) <= area / 1000.0 and abs(goal.y) <= area / 1000.0):
            raise invalid(f"{what} ({1000.0 * goal.x:.10g}, {1000.0 * goal.y:.10g}) mm is outside "
                          f"the work area (±{area:g} mm in x and y)")
        return goal

    def _check_step(self, dx: float, dy: float, what: str) -> None:
        """Refuse a relative step (m) longer than the work area's diagonal: it ends outside from
        any start, so it is wrong in every state (checked before the state, as absolute targets
        are; during a stop's deceleration it was true and discarded)."""
        length, diagonal = math.hypot(dx, dy), 2.0 * math.sqrt(2.0) * self.config.work_area
        if not 1000.0 * length <= diagonal:
            raise invalid(f"{what} is a step of {1000.0 * length:.10g} mm: longer than the work "
                          f"area's diagonal ({diagonal:.0f} mm), it ends outside it from any start")

    def _check_rotation(self, angle: float, what: str) -> None:
        limit = self.config.turn_limit
        if not abs(math.degrees(angle)) <= limit:
            raise invalid(f"{what} is {math.degrees(angle):.10g} degree: at most ±{limit:g} degree")

    def _limits(self, velocity: tuple[float, float] | None = None,
                acceleration: tuple[float, float] | None = None) -> tuple[float, float, float, float]:
        """The velocity and acceleration settings in SI: (v, w, a, alpha)."""
        return (*si_pair(velocity or self.velocity), *si_pair(acceleration or self.acceleration))

    def _splice_time(self, device: Device, motion: TrackedBaseMotion, attempt: int) -> float:
        """Motion time at which a plan made now takes over: a little ahead of the device, the
        further the more often it outran the planner."""
        ahead = LOOKAHEAD_STEPS * self._dt * LOOKAHEAD_GROWTH ** attempt
        return max(device.t + ahead, motion.t0)

    def _edit(self, look: Callable[[Device, int], Any], plan: Callable[[Any], Any]) -> Any:
        out = self.device.edit_planned(look, plan)
        if out is STALE:
            raise VehicleRefused(AlarmCode.WRONG_STATE,
                                 "the base changed faster than the new path could be planned: "
                                 "call again")
        return out

    @staticmethod
    def _running(device: Device) -> Any:
        """The motion a jog or a continuous move would re-plan: the running tracked motion,
        unless a stop decelerates it (then a new motion is submitted, and discarded)."""
        cur = device.current
        if cur is None or device.stopping or not isinstance(cur.motion, TrackedBaseMotion):
            return None
        return cur

    def _discard_not_started(self, device: Device) -> None:
        """Commit of a take-over when no tracked motion runs: the moves accepted but not
        started (or queued behind a brake) give way; the new one is then submitted."""
        if not device.stopping:
            device.discard_queue("replaced by a newer move before it started")
            self._op_generation = device.generation     # this operation's own discard

    def _take_over(self, device: Device, cur: Any, t: float, path: Path, label: str,
                   why: str = "") -> Any:
        """Commit: the running motion follows `path` from motion time t as a `label` motion;
        what was queued behind it was planned from its old end and is discarded (`why`, else
        "taken over by <label>"). A move taken over never reaches its goal: it retires as
        discarded and the motion runs on under a new id; a jog (or the joystick) updating itself
        keeps its id."""
        if device.t > t:
            return STALE
        self._admit(SERVO_ON, label, device)
        device.discard_queue(why or f"taken over by {label}")
        self._op_generation = device.generation         # this operation's own discard
        if not (label == cur.label and label in VELOCITY_DRIVEN):
            device.renumber(cur, f"taken over by {label}")
        cur.motion = cur.motion.handover(t, path, label)
        cur.label = label
        return cur.id

    def _submit(self, plan: Callable[[Pose2D], Path], label: str,
                allowed: tuple[VehicleState, ...]) -> dict:
        """Queue a tracked motion along plan(start of the motion)."""
        odometry = self.odometry
        return self._submit_motion(lambda start: TrackedBaseMotion(odometry, plan(start), label),
                                   label, allowed)

    def _submit_motion(self, make: Callable[[Pose2D], Any], label: str,
                       allowed: tuple[VehicleState, ...]) -> dict:
        """Plan from the end of the queue (under no lock) and queue it; planned again if a stop
        or another change came in meanwhile, checked against the state then."""
        def plan(start: Pose2D) -> Any:
            with self.lock:
                self._admit(allowed, label, self.device)
            return make(start)
        motion_id = self.device.submit(plan, label)
        if motion_id is None:
            raise VehicleRefused(AlarmCode.QUEUE_FULL,
                                 f"the motion queue is full ({self.device.capacity} motions)")
        self._accepted_motion()
        return {"motion_id": motion_id}

    def _drive(self, target: tuple[float, float], hold: float, accel: tuple[float, float],
               label: str, take_over: bool, brake: bool = False) -> dict:
        """Velocity drive: re-plan the running jog/joystick motion from its reference a little
        ahead of now (speed continuous), take over another running move (`take_over`, else
        refused), or start one on an idle base. The deadman ends it `hold` s of the job's clock
        from now unless called again. A `brake` of the running drive goes in whatever is queued
        behind it, and discards that (planned from the drive's old end; the base goes Ready)."""
        def look(device: Device, attempt: int):
            cur = self._running(device)
            if brake and (device.paused or cur is None or cur.label != label):
                return None     # over already, or held by a pause (its deadman ends it after)
            if device.paused:
                raise VehicleRefused(AlarmCode.WRONG_STATE, PAUSED_DRIVE.format(label))
            if not take_over and (device.queue and not brake
                                  or cur is not None and cur.label != label):
                raise self._busy(label)         # the joystick drives no further than its own
            return None if cur is None else (cur, self._splice_time(device, cur.motion, attempt))

        def plan(seen):
            if seen is None:
                return self._discard_not_started if take_over else (lambda device: None)
            cur, t = seen
            motion = cur.motion
            path = velocity_path(motion.at(t), *motion.reference_twist(t), target, hold, accel)

            def commit(device: Device) -> Any:
                out = self._take_over(device, cur, t, path, label,
                                      "the joystick was switched off" if brake else "")
                if out is not STALE:
                    self._arm_deadman(hold, target)
                return out
            return commit
        motion_id = self._edit(look, plan)
        if motion_id is None and target == (0.0, 0.0):
            return {"motion_id": 0}                  # standing still already: nothing to queue
        if motion_id is None:
            self._arm_deadman(hold, target)          # before the simulation can pick it up
            return self._submit(lambda start: velocity_path(start, 0.0, 0.0, target, hold, accel),
                                label, SERVO_ON)
        self._accepted_motion()
        return {"motion_id": motion_id}

    @staticmethod
    def _busy(label: str) -> VehicleRefused:
        return VehicleRefused(AlarmCode.WRONG_STATE,
                              f"the base is busy with other moves: {label} drives only an idle "
                              "base (wait, or call stop)")

    def _arm_deadman(self, hold: float, target: tuple[float, float]) -> None:
        """The drive ends `hold` s of the job's clock from now; a drive to rest ends by itself."""
        self._drive_deadline = self._world.time + hold if target != (0.0, 0.0) else math.inf
        self._deadman_fired = None

    def _retime(self, velocity: tuple[float, float], acceleration: tuple[float, float]) -> None:
        """Plan new settings for the running motion (a little ahead of now) and the queued
        ones, off the device's lock; commit them together. Velocity drives keep their speeds."""
        limits = self._limits(velocity, acceleration)

        def look(device: Device, attempt: int):
            cur, items = device.current, []
            if cur is not None and not device.stopping and hasattr(cur.motion, "replan") \
                    and cur.label not in VELOCITY_DRIVEN:
                items.append((cur.motion, self._splice_time(device, cur.motion, attempt)))
            running = len(items)
            items += [(q.motion, 0.0) for q in device.queue if hasattr(q.motion, "replan")]
            return items, running

        def plan(seen):
            items, running = seen
            changes = [m.replan(t, limits) for m, t in items]

            def commit(device: Device) -> None:
                if running and device.t > items[0][1]:
                    return STALE
                for change in changes:
                    if change is not None:
                        change()
            return commit
        self._edit(look, plan)
