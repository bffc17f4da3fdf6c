"""The manipulator core: the ACT common port and the middle-level motion port, without ROS.

Each public operation is one IDL operation, named as the ROS service (snake case), taking the IDL
parameters by their snake-case names and returning a `Reply` whose id is one the spec lists for
that operation (`@returns`). Units are the spec's: mm, degree, mm/s, degree/s, s, %.

Frames: the arm frame is `base_link`; the robot frame is the arm frame moved by the base offset
(setBaseOffset gives the robot frame seen from the arm frame); the control point is the flange
moved by the control-point offset. Every Cartesian value of the ports is the control point in
the robot frame. `elbow` is the arm angle in degrees (see `acti_motion.arm.kinematics`);
`struct_flag` reports the posture's branch (bits 0x1 θ2 < 0, 0x2 θ4 > 0, 0x4 θ6 < 0) and is
ignored on input: moves take the branch nearest to where they start.

`ArmCore` is in parts, by the thread that runs them: this module holds the operations (the
serving threads call them) and the state; `watch.SoftLimitWatch` is what the simulation thread
runs after each step; `planning.MovePlanning` plans and checks a move on the caller's thread
before it is queued; `settings` holds `ArmConfig`, the bounds of the settings and their checks.
"""
from __future__ import annotations

import math
import threading
from functools import lru_cache
from typing import Callable

import numpy as np

from acti_motion.arm.kinematics import ArmKinematics
from acti_motion.arm.limits import SoftLimits
from acti_motion.arm.planning import MovePlanning
from acti_motion.arm.poses import Frames, compose_relative, hg_as_set, pose_to_hg
from acti_motion.arm.settings import (BASE_OFFSET_MM, CONTROL_POINT_OFFSET_MM, MAX_ACCEL_TIME_S,
                                      MIN_SPEED_JOINT_DEG_S, RATED_ROUNDING_DEG_S,
                                      SOFT_LIMIT_CARTESIAN_MM, SPEED_ROTATION_DEG_S,
                                      SPEED_TRANSLATION_MM_S, ArmConfig, _accel_time, _car_point,
                                      _check_config, _in_range, _limit_value, _min_accel_time,
                                      _offset)
from acti_motion.arm.trajectories import ArcPath, ArmSetpoint, CartesianPlanner, LinePath
from acti_motion.arm.watch import Alarm, AlarmType, SoftLimitWatch
from acti_motion.executor import STOPPED, MotionExecutor
from acti_motion.replies import (Refused, Reply, ReturnCode, finite_floats, finite_vector, plans,
                                 ratio_percent, returns, value_error)
from acti_sim.world import GRIPPER_JOINTS

__all__ = ["ArmConfig", "ArmCore", "ArmSetpoint", "Alarm", "AlarmType"]

STATE_SERVO_ON = 0x01
STATE_MOVING = 0x02
STATE_ALARM = 0x04
STATE_BUFFER_FULL = 0x08
STATE_PAUSED = 0x10

R = ReturnCode
# The ids the spec lists per kind of operation (OK and NG always; see `returns`).
GETTER: tuple[ReturnCode, ...] = ()
CONTROL: tuple[ReturnCode, ...] = ()
SETTER = (R.VALUE_ERR,)
MOVE = (R.STATUS_ERR, R.VALUE_ERR, R.FULL_MOTION_QUEUE_ERR, R.NOT_SV_ON_ERR)

REST_DRIFT_RAD = 1e-9                     # sensed joints this close give the same feedback pose
SERVO_OFF_REASON = "servo off"   # what a wait on a motion servo_off discarded is told


@lru_cache(maxsize=1)
def shared_kinematics() -> ArmKinematics:
    return ArmKinematics()


def _within(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    """Every element of a within tol of b's (plain floats: numpy is slower for 7 values)."""
    return all(abs(x - y) <= tol for x, y in zip(a.tolist(), b.tolist()))


def _ignored(why: str) -> Reply:
    return Reply(ReturnCode.OK, f"ignored: {why}")


class ArmCore(SoftLimitWatch, MovePlanning):
    """State, settings and motion queue of the 7-axis arm with its 1-axis gripper."""

    def __init__(self, executor: MotionExecutor, config: ArmConfig | None = None) -> None:
        self.config = c = config or ArmConfig()
        _check_config(c)
        self.executor = executor
        self.kin = shared_kinematics()
        self.planner = CartesianPlanner(self.kin)
        world = executor.world
        self.axis_count = 7
        self.hard_limit_joint = np.degrees(np.stack([self.kin.lower, self.kin.upper], axis=1))
        self.hard_max_speed_joint = np.degrees(self.kin.velocity)
        q0 = self._start_joints(c.initial_joints_deg, "initial_joints_deg")
        self._start_joints(c.home_joints_deg, "home_joints_deg")
        self.home = np.array(c.home_joints_deg, float)
        world.reset_arm(q0)
        self.finger_max = world.limits[GRIPPER_JOINTS[0]].upper
        # settings (units of the ports)
        self.max_speed_joint = self.hard_max_speed_joint.copy()
        # rows (lower, upper): the joints' hardware range, the widest box (the config's is set
        # by `_apply_settings`, through its setter's checks)
        widest = [[-SOFT_LIMIT_CARTESIAN_MM, SOFT_LIMIT_CARTESIAN_MM]] * 3
        self.limits = SoftLimits(self.hard_limit_joint.copy(), np.array(widest),
                                 self.hard_limit_joint)
        self.speed_joint = ratio_percent(c.initial_speed_ratio, "initial_speed_ratio")
        self.speed_cartesian = self.speed_joint
        self.min_accel_time_joint = self.accel_time_joint = MAX_ACCEL_TIME_S
        self.min_accel_time_cartesian = self.accel_time_cartesian = MAX_ACCEL_TIME_S
        self.frames = Frames()
        self._feedback = world.arm_positions()
        self._measured = (world.time, self._feedback)
        self._finger = world.gripper_position()
        self._settling = False
        self.device = executor.add_device("arm", c.queue_size,
                                          ArmSetpoint(q0.copy(), self._finger))
        self._apply_settings(c)
        self.servo = False
        self._alarms: list[Alarm] = []
        self._alarm_lock = threading.Lock()
        self._inside: np.ndarray | None = None
        self._batch = threading.local()               # the moves an `all_or_nothing` collects
        self._batching: set[int] = set()              # the threads with such a block open
        self._cartesian_memo: tuple | None = None     # (joints sample, frames, its pose)
        self._posture_memo = None                     # a PTP plan's last posture: `_position_at`
        self._depth_memo = None                       # its depth inside the box
        self._joints_memo = None                      # a set-point's joints as floats
        self._speeds_memo = None                      # the joints' speeds at a ratio
        self._reach_memo = None                       # the reach's ball in the robot frame
        self._limits_memo = None                      # a CP move's limits at its settings
        executor.after_step(self._sample)

    @property
    def soft_limit_joint(self) -> np.ndarray:
        """The joint soft limits (degree), rows (lower, upper); setting them makes `limits` anew."""
        return self.limits.joint

    @soft_limit_joint.setter
    def soft_limit_joint(self, rows: np.ndarray) -> None:
        self.limits = self.limits.with_joint(rows)

    @property
    def soft_limit_cartesian(self) -> np.ndarray:
        """The Cartesian soft limits (mm), rows (lower, upper): x, y, z (as `soft_limit_joint`)."""
        return self.limits.cartesian

    @soft_limit_cartesian.setter
    def soft_limit_cartesian(self, rows: np.ndarray) -> None:
        self.limits = self.limits.with_cartesian(rows)

    def _apply_settings(self, c: ArmConfig) -> None:
        """The start-up settings that a service also sets, through that service's validation
        (the node's parameters of the same names use it too); ValueError names the one refused."""
        for name, reply in (
                ("min_accel_time_joint", self.set_min_accel_time_joint(c.min_accel_time_joint)),
                ("accel_time_joint", self.set_accel_time_joint(c.accel_time_joint)),
                ("min_accel_time_cartesian",
                 self.set_min_accel_time_cartesian(c.min_accel_time_cartesian)),
                ("accel_time_cartesian", self.set_accel_time_cartesian(c.accel_time_cartesian)),
                ("max_speed_translation/max_speed_rotation", self.set_max_speed_cartesian(
                    (c.max_speed_translation, c.max_speed_rotation))),
                ("soft_limit_cartesian", self.set_soft_limit_box(c.soft_limit_cartesian))):
            if not reply.ok:
                raise ValueError(f"{name}: {reply.comment}")

    def _start_joints(self, values: tuple[float, ...], name: str) -> np.ndarray:
        q = np.asarray(values, float)
        lo, hi = self.hard_limit_joint[:, 0], self.hard_limit_joint[:, 1]
        if q.shape != (self.axis_count,) or not np.all(np.isfinite(q)) \
                or np.any(q < lo) or np.any(q > hi):
            raise ValueError(f"{name} must be {self.axis_count} finite joint values within "
                             f"the joint limits, got {values}")
        return np.radians(q)

    # === common port ============================================================================
    @returns(R.STATUS_ERR)
    def servo_on(self) -> None:
        self.servo = True

    @returns()
    def servo_off(self) -> None:
        """All axes off; a moving arm stops first (the brakes then hold it where it stopped).
        New motions are refused at once; the state word keeps bit 0x01 until the arm is at rest."""
        self.servo = False
        self.stop_motion(reason=SERVO_OFF_REASON)

    @returns(*GETTER)
    def get_state(self) -> dict:
        return {"state": self.state_word()}

    @returns(*GETTER)
    def get_feedback_pos_joint(self) -> dict:
        """Measured J1 … J7 (degree), then the gripper axis as its opening (mm)."""
        opening_mm = 2000.0 * self._finger
        return {"pos": [*np.degrees(self._feedback).tolist(), opening_mm]}

    @returns(*GETTER)
    def get_manip_info(self) -> Reply:
        """cmd_cycle is the control period in whole ms (ULONG), at least 1: a period under
        1 ms (rate_hz up to 2000) is not a command cycle of none."""
        period_ms = self.executor.dt * 1000.0
        cycle_ms = max(1, round(period_ms))
        info = ("acti_ros2", "7-axis SRS arm with 1-axis gripper (PyBullet)", self.axis_count,
                cycle_ms, True)
        comment = ("" if abs(period_ms - cycle_ms) < 1e-9 else
                   f"cmd_cycle is rounded: the control period is {period_ms:.4f} ms "
                   "(choose rate_hz so that it is a whole number of ms)")
        return Reply(comment=comment, values={"manip_info": info})

    @returns(*GETTER)
    def get_active_alarm(self) -> dict:
        with self._alarm_lock:
            return {"alarms": [a.as_tuple() for a in self._alarms]}

    @returns(*CONTROL)
    def clear_alarms(self) -> Reply:
        with self._alarm_lock:
            n = len(self._alarms)
            self._alarms.clear()
        return Reply(comment=f"cleared {n} alarm(s)" if n else "no alarm was active")

    @returns(*GETTER)
    def get_soft_limit_joint(self) -> dict:
        return {"soft_limit": [(hi, lo) for lo, hi in self.soft_limit_joint.tolist()]}

    @returns(R.STATUS_ERR, R.VALUE_ERR)
    def set_soft_limit_joint(self, soft_limit: list) -> None:
        self._check_idle("set_soft_limit_joint")
        if len(soft_limit) != self.axis_count:
            raise value_error(f"soft_limit needs {self.axis_count} limits (J1 … J{self.axis_count}),"
                              f" got {len(soft_limit)}")
        limits = np.empty((self.axis_count, 2))
        for i, lim in enumerate(soft_limit):
            upper, lower = _limit_value(lim, f"soft_limit[{i}] (J{i + 1})", pinned=True)
            hlo, hhi = self.hard_limit_joint[i]
            if lower < hlo - 1e-9 or upper > hhi + 1e-9:
                raise value_error(f"soft_limit[{i}]: [{lower:g}, {upper:g}]° is outside J{i + 1}'s "
                                  f"hardware range [{hlo:.3f}, {hhi:.3f}]°")
            limits[i] = lower, upper
        self.soft_limit_joint = limits

    # === middle-level port: getters ==============================================================
    @returns(*GETTER)
    def get_feedback_pos_cartesian(self) -> dict:
        return {"pos": self._feedback_cartesian()}

    def _feedback_cartesian(self) -> tuple[list[float], float, int]:
        """The measured control-point pose, computed once per sample of the joints and setting
        of the frames: the simulation thread samples every control period, and callers within
        one period (a client polling at kHz) get the same pose without the kinematics again.
        An arm at rest keeps its pose too: its sensed joints drift by ~1e-10 rad a step, and a
        sample within REST_DRIFT_RAD of the one computed moves the control point by < 1 nm."""
        q, frames, memo = self._feedback, self.frames, self._cartesian_memo
        if memo is None or memo[1] is not frames or (
                memo[0] is not q and not _within(memo[0], q, REST_DRIFT_RAD)):
            memo = self._cartesian_memo = (q, frames, self.car_pos_with_elbow(q))
        return memo[2]

    @returns(*GETTER)
    def get_base_offset(self) -> dict:
        return {"offset": list(self.frames.base_hg)}

    @returns(*GETTER)
    def get_max_speed_cartesian(self) -> dict:
        return {"speed": self.max_speed_cartesian}

    @returns(*GETTER)
    def get_max_speed_joint(self) -> dict:
        return {"speed": self.max_speed_joint.tolist()}

    @returns(*GETTER)
    def get_min_accel_time_cartesian(self) -> dict:
        return {"acl_time": self.min_accel_time_cartesian}

    @returns(*GETTER)
    def get_min_accel_time_joint(self) -> dict:
        return {"acl_time": self.min_accel_time_joint}

    @returns(*GETTER)
    def get_soft_limit_cartesian(self) -> dict:
        return {f"{a}_limit": (hi, lo)
                for a, (lo, hi) in zip("xyz", self.soft_limit_cartesian.tolist())}

    @returns(*GETTER)
    def get_home(self) -> dict:
        return {"joint_point": self.home.tolist()}

    # === middle-level port: settings ==============================================================
    @returns(*SETTER)
    def set_speed_joint(self, spd_ratio: int) -> None:
        self.speed_joint = ratio_percent(spd_ratio, "spd_ratio")

    @returns(*SETTER)
    def set_speed_cartesian(self, spd_ratio: int) -> None:
        self.speed_cartesian = ratio_percent(spd_ratio, "spd_ratio")

    @returns(*SETTER)
    def set_accel_time_joint(self, acl_time: float) -> None:
        self.accel_time_joint = _accel_time(acl_time, self.min_accel_time_joint,
                                                 "set_min_accel_time_joint")

    @returns(*SETTER)
    def set_accel_time_cartesian(self, acl_time: float) -> None:
        self.accel_time_cartesian = _accel_time(acl_time, self.min_accel_time_cartesian,
                                                     "set_min_accel_time_cartesian")

    @returns(*SETTER)
    def set_min_accel_time_joint(self, acl_time: float) -> Reply:
        self.min_accel_time_joint = _min_accel_time(acl_time, self.executor.dt)
        if self.accel_time_joint < self.min_accel_time_joint:
            self.accel_time_joint = self.min_accel_time_joint
            return Reply(comment=f"the joint accel time was below it and is now {acl_time:g} s")
        return Reply()

    @returns(*SETTER)
    def set_min_accel_time_cartesian(self, acl_time: float) -> Reply:
        self.min_accel_time_cartesian = _min_accel_time(acl_time, self.executor.dt)
        if self.accel_time_cartesian < self.min_accel_time_cartesian:
            self.accel_time_cartesian = self.min_accel_time_cartesian
            return Reply(comment=f"the Cartesian accel time was below it and is now {acl_time:g} s")
        return Reply()

    @returns(*SETTER)
    def set_max_speed_joint(self, speed: list[float]) -> None:
        """Each within 0.1°/s … the joint's rated speed, as rounded to 0.001°/s (the URDF's
        2.35619 rad/s is 134.9997°/s: 135, the rating it stands for, was refused); a value
        within that rounding is the rated speed."""
        v = finite_vector(speed, self.axis_count, "speed")
        for i, (x, hw) in enumerate(zip(v, self.hard_max_speed_joint)):
            if not MIN_SPEED_JOINT_DEG_S <= x <= hw + RATED_ROUNDING_DEG_S:
                raise value_error(f"speed[{i}] (J{i + 1}) is {x:g}°/s: it must be at least "
                                  f"{MIN_SPEED_JOINT_DEG_S:g}°/s and at most the joint's rated "
                                  f"{hw:.3f}°/s")
        self.max_speed_joint = np.minimum(v, self.hard_max_speed_joint)

    @returns(*SETTER)
    def set_max_speed_cartesian(self, speed: tuple) -> None:
        if isinstance(speed, dict):
            speed = (speed.get("translation"), speed.get("rotation"))
        if len(speed) != 2:
            raise value_error("speed needs translation and rotation")
        translation = _in_range(speed[0], *SPEED_TRANSLATION_MM_S, "speed.translation", "mm/s")
        rotation = _in_range(speed[1], *SPEED_ROTATION_DEG_S, "speed.rotation", "°/s")
        self.max_speed_cartesian = (translation, rotation)

    @returns(*SETTER)
    def set_soft_limit_cartesian(self, x_limit: tuple, y_limit: tuple, z_limit: tuple) -> None:
        limits = np.empty((3, 2))
        for i, (axis, lim) in enumerate(zip("xyz", (x_limit, y_limit, z_limit))):
            upper, lower = _limit_value(lim, f"{axis}_limit")
            if max(abs(upper), abs(lower)) > SOFT_LIMIT_CARTESIAN_MM:
                raise value_error(f"{axis}_limit [{lower:g}, {upper:g}] mm: each limit must be "
                                  f"within ±{SOFT_LIMIT_CARTESIAN_MM:g} mm")
            limits[i] = lower, upper
        self.soft_limit_cartesian = limits

    @returns(*SETTER)
    def set_soft_limit_box(self, box: tuple[float, ...]) -> Reply:
        """set_soft_limit_cartesian with the limits in the config's order: x lower, x upper,
        y lower, y upper, z lower, z upper (the parameter soft_limit_cartesian)."""
        if len(box) != 6:
            raise value_error("soft_limit_cartesian needs x lower, x upper, y lower, y upper, "
                              f"z lower, z upper: 6 values, got {len(box)}")
        return self.set_soft_limit_cartesian(*((box[i + 1], box[i]) for i in (0, 2, 4)))

    def soft_limit_box(self) -> tuple[float, ...]:
        """The Cartesian soft limits in the config's order (see set_soft_limit_box)."""
        return tuple(float(x) for x in self.soft_limit_cartesian.reshape(-1))

    @returns(*SETTER)
    def set_base_offset(self, offset: list[float]) -> None:
        """NG (the spec lists no STATUS_ERR for it) while anything runs, is paused mid-move or
        is queued: their targets were given in the present robot frame, and a queued move ended
        100 mm from where the new frame said it should."""
        base = _offset(offset, BASE_OFFSET_MM, ReturnCode.VALUE_ERR)
        self._set_while_idle("set_base_offset", R.NG, "its target is in the present robot frame",
                             lambda: setattr(self, "frames",
                                             self.frames.with_base(base, hg_as_set(base, offset))))

    @returns(R.STATUS_ERR)
    def set_control_point_offset(self, offset: list[float]) -> None:
        """Refused while anything runs, is paused mid-move or is queued: those targets were
        planned with the present control point (5.4.23: not while moving)."""
        self._check_idle("set_control_point_offset")
        tool = _offset(offset, CONTROL_POINT_OFFSET_MM, ReturnCode.NG)
        self._set_while_idle("set_control_point_offset", R.STATUS_ERR,
                             "it was planned for the present control point",
                             lambda: setattr(self, "frames", self.frames.with_tool(tool)))

    def _set_while_idle(self, name: str, code: ReturnCode, why: str,
                        apply: Callable[[], None]) -> None:
        """apply() unless a motion is planned, runs, is paused or is queued (then `code`, saying
        `why`): what was accepted was planned and checked with the settings in force, and would
        run on under new ones. Decided under the device's accept lock, which it never waits for."""
        with self.device.idle_for_settings() as idle:
            if not idle:
                raise Refused(code, f"{name} is refused while a motion is planned, running, "
                                    f"paused or queued: {why} (wait or stop first)")
            apply()

    @returns(*SETTER)
    def set_home(self, joint_point: list[float]) -> None:
        q = finite_floats(joint_point, self.axis_count, "joint_point")
        self.limits.check_target(q, "joint_point")
        self.home = np.array(q)

    # === middle-level port: motion control ======================================================
    @returns(*CONTROL)
    def pause(self) -> Reply | None:
        """Holds the running move and whatever is queued behind it, also a move accepted and not
        yet started (5.4.17 ignores pause only when servo off, alarmed, paused or stopped)."""
        why = self._control_ignored()
        if why is None and self.device.paused:
            why = "already paused"
        if why is None and (not self.device.busy or self.device.stopping):
            why = "the arm is not moving" if not self.device.busy else "it is stopping"
        if why is not None:
            return _ignored(why)
        if not self.device.pause(self.current_ramp(), idle=False):
            return _ignored("a stop came first: nothing is left to pause")
        return None

    @returns(*CONTROL)
    def resume(self) -> Reply | None:
        if not self.device.paused:
            return _ignored("the arm is not paused")
        if not self.device.resume(self.current_ramp()):
            return _ignored("a stop is in progress")
        return None

    @returns(*CONTROL)
    def stop(self) -> Reply | None:
        why = self._control_ignored()
        if why is not None:
            return _ignored(why)
        self.stop_motion()
        return None

    # === middle-level port: moves =================================================================
    @returns(*MOVE)
    @plans
    def move_ptp_joint_abs(self, joint_points: list[float]) -> dict:
        self._check_can_move(self.speed_joint, "set_speed_joint")
        goal = finite_vector(joint_points, self.axis_count, "joint_points")
        return self._queue_joint_target(goal, "move_ptp_joint_abs")

    @returns(*MOVE)
    @plans
    def move_ptp_joint_rel(self, joint_points: list[float]) -> dict:
        self._check_can_move(self.speed_joint, "set_speed_joint")
        step = finite_floats(joint_points, self.axis_count, "joint_points")
        self.limits.check_step(step, "joint_points")
        return self.queue_joint_move(None, "move_ptp_joint_rel",
                                     step=list(map(math.radians, step)))

    @returns(*MOVE)
    @plans
    def go_home(self) -> dict:
        self._check_can_move(self.speed_joint, "set_speed_joint")
        return self._queue_joint_target(self.home, "go_home")

    def _queue_joint_target(self, goal_deg: np.ndarray, label: str) -> dict:
        """A PTP move to an absolute target (degree), checked against the soft limits before
        the queue is looked at: a full queue would have hidden that it is wrong from any start."""
        self.limits.check_target(goal_deg.tolist(), label)
        goal = np.radians(goal_deg)
        return self.queue_joint_move(lambda start: goal, label)

    @returns(*MOVE)
    @plans
    def move_ptp_cartesian_abs(self, car_point: tuple) -> dict:
        self._check_can_move(self.speed_joint, "set_speed_joint")
        target, psi = _car_point(car_point, "car_point")
        self._check_target(target, "move_ptp_cartesian_abs", psi=psi)
        return self._queue_ptp_cartesian(lambda P0: target, "move_ptp_cartesian_abs", psi=psi)

    @returns(*MOVE)
    @plans
    def move_ptp_cartesian_rel(self, car_point: tuple) -> dict:
        self._check_can_move(self.speed_joint, "set_speed_joint")
        delta, turn = _car_point(car_point, "car_point")
        self._check_step(delta, "move_ptp_cartesian_rel")
        return self._queue_ptp_cartesian(lambda P0: compose_relative(P0, delta),
                                         "move_ptp_cartesian_rel", turn=turn)

    @returns(*MOVE)
    @plans
    def move_linear_cartesian_abs(self, car_point: tuple) -> dict:
        self._check_can_move(self.speed_cartesian, "set_speed_cartesian")
        target, psi = _car_point(car_point, "car_point")
        self._check_target(target, "move_linear_cartesian_abs", psi=psi)
        return self.queue_cartesian(lambda P0: LinePath(P0, target), "move_linear_cartesian_abs",
                                     psi=psi)

    @returns(*MOVE)
    @plans
    def move_linear_cartesian_rel(self, car_point: tuple) -> dict:
        self._check_can_move(self.speed_cartesian, "set_speed_cartesian")
        delta, turn = _car_point(car_point, "car_point")
        self._check_step(delta, "move_linear_cartesian_rel")
        return self.queue_cartesian(lambda P0: LinePath(P0, compose_relative(P0, delta)),
                                     "move_linear_cartesian_rel", turn=turn)

    @returns(*MOVE)
    @plans
    def move_circular_cartesian_abs(self, car_point_r: tuple, car_point_t: tuple) -> dict:
        """2014 revision: arc from where the previous motion ends, through R's position, to T
        (R's orientation and elbow are not used)."""
        self._check_can_move(self.speed_cartesian, "set_speed_cartesian")
        via, _ = _car_point(car_point_r, "car_point_r")
        target, psi = _car_point(car_point_t, "car_point_t")
        self._check_target(via, "move_circular_cartesian_abs: car_point_r")
        self._check_target(target, "move_circular_cartesian_abs", psi=psi)
        return self.queue_cartesian(lambda P0: ArcPath(P0, via[:3, 3], target),
                                     "move_circular_cartesian_abs", psi=psi)

    @returns(*MOVE)
    @plans
    def move_circular_cartesian_rel(self, car_point_r: tuple, car_point_t: tuple) -> dict:
        self._check_can_move(self.speed_cartesian, "set_speed_cartesian")
        via, _ = _car_point(car_point_r, "car_point_r")
        delta, turn = _car_point(car_point_t, "car_point_t")
        self._check_step(via, "move_circular_cartesian_rel: car_point_r")
        self._check_step(delta, "move_circular_cartesian_rel")
        return self.queue_cartesian(
            lambda P0: ArcPath(P0, P0[:3, 3] + via[:3, 3], compose_relative(P0, delta)),
            "move_circular_cartesian_rel", turn=turn)

    # --- gripper -----------------------------------------------------------------------------------
    @returns(R.STATUS_ERR, R.VALUE_ERR, R.FULL_MOTION_QUEUE_ERR, R.NOT_SV_ON_ERR)
    @plans
    def open_gripper(self) -> dict:
        return self.queue_gripper(100, "open_gripper")

    @returns(R.STATUS_ERR, R.FULL_MOTION_QUEUE_ERR, R.NOT_SV_ON_ERR)
    @plans
    def close_gripper(self) -> dict:
        return self.queue_gripper(0, "close_gripper")

    @returns(R.STATUS_ERR, R.VALUE_ERR, R.NOT_SV_ON_ERR)
    @plans
    def move_gripper(self, angle_ratio: int) -> dict:
        """The spec lists no FULL_MOTION_QUEUE_ERR here: a full queue is STATUS_ERR. The state
        is answered before the argument, as by every motion command."""
        self._check_can_move()
        ratio = ratio_percent(angle_ratio, "angle_ratio")
        try:
            return self.queue_gripper(ratio, "move_gripper")
        except Refused as r:
            if r.code == R.FULL_MOTION_QUEUE_ERR:
                raise Refused(R.STATUS_ERR, r.comment) from None
            raise

    # === state, feedback and progress (also for the node's topics and actions) =====================
    def state_word(self) -> int:
        """The state word of one moment: the device's motion state read together
        (`Device.motion_state`) and the joints as the last control period measured them. Moving
        (0x02) while a motion runs or waits unpaused, or while the measured joints still settle
        onto a set-point at rest (a stop's tail: they move for tens of ms after it); after
        servo_off the axes stay powered (0x01) until then."""
        moving, paused, full = self.device.motion_state()
        moving = moving or self.settling
        word = STATE_SERVO_ON if self.servo or moving else 0
        if moving:
            word |= STATE_MOVING
        if self._alarms:
            word |= STATE_ALARM
        if full:
            word |= STATE_BUFFER_FULL
        if paused:
            word |= STATE_PAUSED
        return word

    @property
    def alarms(self) -> list[Alarm]:
        with self._alarm_lock:
            return list(self._alarms)

    def tool_pose(self, q: np.ndarray) -> np.ndarray:
        """Control point in the robot frame (4×4, m) at joints q (rad)."""
        return self.frames.tool_of(self.kin.flange(q))

    def car_pos_with_elbow(self, q: np.ndarray) -> tuple[list[float], float, int]:
        return (pose_to_hg(self.tool_pose(q)), math.degrees(self.kin.arm_angle(q)),
                self.kin.flags(q))

    @property
    def feedback_joints(self) -> np.ndarray:
        return self._feedback

    def measured(self) -> tuple[float, np.ndarray]:
        """(simulated time, joints) of the last measurement, taken together: a stamp read
        apart from the joints could be a step later (1.2 mm at 300 mm/s)."""
        return self._measured

    def motion_status(self) -> tuple[int, str, float, int]:
        """(current motion id or 0, its label, its completed fraction, queued motions)."""
        return self.device.status()

    # === checks ======================================================================================
    def _check_can_move(self, ratio: int | None = None, setter: str = "") -> None:
        if not self.servo:
            raise Refused(R.NOT_SV_ON_ERR, "servo is off: call servo_on first")
        if self._alarms:
            raise Refused(R.STATUS_ERR, "an alarm is active: see get_active_alarm, then call "
                                        "clear_alarms")
        if ratio is not None and ratio <= 0:
            raise Refused(R.STATUS_ERR, f"the speed ratio is 0 %: set it with {setter} first")

    def _check_idle(self, name: str) -> None:
        """The spec refuses these while moving or alarmed; paused is not moving. Moving is the
        motion's (`Device.motion_state`): the joints settling onto a set-point at rest, which
        the state word shows too, run no plan that a setting could change."""
        if self.device.motion_state()[0]:
            raise Refused(R.STATUS_ERR, f"{name} is refused while the arm moves "
                                        "(wait, pause or stop first)")
        if self._alarms:
            raise Refused(R.STATUS_ERR, f"{name} is refused while an alarm is active")

    def _control_ignored(self) -> str | None:
        if not self.servo:
            return "servo is off"
        if self._alarms:
            return "an alarm is active"
        return None

    # === stopping (the control operations and the watch) ===========================================
    def current_ramp(self) -> float:
        cur = self.device.current
        return cur.motion.ramp if cur is not None else self.accel_time_joint

    def stop_motion(self, fastest: bool = False, reason: str = STOPPED) -> None:
        """Stop at the motion's accel time (or the fastest the settings allow); `reason` is
        what a wait on a discarded motion is told."""
        ramp = self._fastest_ramp(self.device.current) if fastest else self.current_ramp()
        self.device.stop(ramp, reason)
