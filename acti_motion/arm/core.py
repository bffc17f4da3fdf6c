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
"""
from __future__ import annotations

import math
import threading
from contextlib import contextmanager
from dataclasses import dataclass
from enum import IntEnum
from functools import lru_cache
from typing import Any, Callable, Iterator

import numpy as np

from acti_motion.config_fields import QUEUE_SIZE_RANGE, check_ranges, ranged
from acti_motion.executor import STOPPED, MotionExecutor
from acti_motion.arm.kinematics import ArmKinematics, Unreachable, rotate_about
from acti_motion.arm.poses import Frames, compose_relative, hg_to_pose, inverse, pose_to_hg
from acti_motion.profiles import Trapezoid
from acti_motion.replies import (Refused, Reply, ReturnCode, finite_number, finite_vector, plans,
                                 ratio_percent, returns, value_error)
from acti_motion.arm.trajectories import (ArcPath, ArmMotion, ArmSetpoint, CartesianLimits,
                                      CartesianPlanner, LinearJointPath, LinePath,
                                      positions_along)
from acti_sim.world import GRIPPER_JOINTS

__all__ = ["ArmConfig", "ArmCore", "ArmSetpoint", "Alarm", "AlarmType"]

STATE_SERVO_ON = 0x01
STATE_MOVING = 0x02
STATE_ALARM = 0x04
STATE_BUFFER_FULL = 0x08
STATE_PAUSED = 0x10

ALARM_JOINT_SOFT_LIMIT = 0x4
ALARM_CARTESIAN_SOFT_LIMIT = 0x5

R = ReturnCode
# The ids the spec lists per kind of operation (OK and NG always; see `returns`).
GETTER: tuple[ReturnCode, ...] = ()
CONTROL: tuple[ReturnCode, ...] = ()
SETTER = (R.VALUE_ERR,)
MOVE = (R.STATUS_ERR, R.VALUE_ERR, R.FULL_MOTION_QUEUE_ERR, R.NOT_SV_ON_ERR)

CARTESIAN_WATCH_TOLERANCE_MM = 0.1
REL_ELBOW_CLEARANCE = math.sin(math.radians(10.0))
JOINT_WATCH_TOLERANCE_DEG = 1e-6
REST_DRIFT_RAD = 1e-9                     # sensed joints this close give the same feedback pose

# Bounds of the settings that keep the arm stoppable and every plan quick (README: arm settings).
# A stop decelerates over the running move's accel time, so an accel time of minutes is a
# misconfiguration, not a setting; speeds below the minimums would time a move over days.
MAX_ACCEL_TIME_S = 10.0
# the shortest accel time at the fastest control rate (2 kHz): two cycles; a node refuses less than
# two of its own cycles
MIN_ACCEL_TIME_S = 0.001
MIN_SPEED_JOINT_DEG_S = 0.1
RATED_ROUNDING_DEG_S = 5e-4   # a rated speed given as shown to 0.001°/s (get_max_speed_joint)
SPEED_TRANSLATION_MM_S = (1.0, 10000.0)
SPEED_ROTATION_DEG_S = (0.1, 3600.0)
SOFT_LIMIT_CARTESIAN_MM = 100000.0       # |limit|: a box of 200 m holds every reachable point
BASE_OFFSET_MM = 100000.0                # |translation| of set_base_offset
CONTROL_POINT_OFFSET_MM = 2000.0         # |translation| of set_control_point_offset
TARGET_MM = 1000000.0                    # |x|, |y|, |z| of a Cartesian target or Rel step
ELBOW_DEG = 360.0                        # |elbow| of a Cartesian target (Abs) or turn (Rel)
REACH_SAMPLES = 64                       # points of a CP path checked against the reach first
MAX_CHECK_SAMPLES = 20000                # points of a CP path checked against the soft limits
SERVO_OFF_REASON = "servo off"   # what a wait on a motion servo_off discarded is told
NEAR_LIMIT_MM = 1.0      # samples this close to a Cartesian soft limit: checked between, finer
NEAR_LIMIT_DEG = 0.01    # the same for a joint soft limit along a CP path's joint spline


class AlarmType(IntEnum):
    FAULT = 0
    WARNING = 1
    UNKNOWN = 2


@dataclass(frozen=True)
class Alarm:
    code: int
    type: AlarmType
    description: str

    def as_tuple(self) -> tuple[int, int, str]:
        return (self.code, int(self.type), self.description)


@dataclass
class ArmConfig:
    """Start-up settings of the arm (the node's parameters); units as on the services. The
    comment of each field is its parameter's description."""
    # motion queue capacity (FULL_MOTION_QUEUE_ERR beyond)
    queue_size: int = ranged(32, *QUEUE_SIZE_RANGE)
    # joint and Cartesian speed ratio at start-up [%] (the spec says 0)
    initial_speed_ratio: int = ranged(0, 0, 100)
    # PTP accel/decel time [s] (set_accel_time_joint)
    accel_time_joint: float = ranged(0.3, MIN_ACCEL_TIME_S, MAX_ACCEL_TIME_S)
    # minimum joint accel time [s]: joint accel limit = max speed / it (set_min_accel_time_joint)
    min_accel_time_joint: float = ranged(0.1, MIN_ACCEL_TIME_S, MAX_ACCEL_TIME_S)
    # CP accel/decel time [s] (set_accel_time_cartesian)
    accel_time_cartesian: float = ranged(0.3, MIN_ACCEL_TIME_S, MAX_ACCEL_TIME_S)
    # minimum CP accel time [s] (set_min_accel_time_cartesian)
    min_accel_time_cartesian: float = ranged(0.1, MIN_ACCEL_TIME_S, MAX_ACCEL_TIME_S)
    # maximum CP speed [mm/s] (set_max_speed_cartesian)
    max_speed_translation: float = ranged(500.0, *SPEED_TRANSLATION_MM_S)
    # maximum CP rotation and elbow speed [degree/s] (set_max_speed_cartesian)
    max_speed_rotation: float = ranged(90.0, *SPEED_ROTATION_DEG_S)
    # gripper opening speed, both fingers [mm/s]
    gripper_speed: float = 100.0
    # Cartesian soft limits of the control point, robot frame [mm]: x lower, x upper, y lower,
    # y upper, z lower, z upper (set_soft_limit_cartesian)
    soft_limit_cartesian: tuple[float, ...] = (-1000.0, 1200.0, -1000.0, 1000.0, -100.0, 1600.0)
    # J1 … J7 at start-up [degree]
    initial_joints_deg: tuple[float, ...] = (0.0, 30.0, 0.0, -60.0, 0.0, 60.0, 0.0)
    # go_home target J1 … J7 [degree] (set_home)
    home_joints_deg: tuple[float, ...] = (0.0, 30.0, 0.0, -60.0, 0.0, 60.0, 0.0)


@lru_cache(maxsize=1)
def shared_kinematics() -> ArmKinematics:
    return ArmKinematics()


def _offset(offset: list[float], bound_mm: float, code: ReturnCode) -> np.ndarray:
    """The pose of an offset HgMatrix whose translation is within `bound_mm`, else `code`."""
    pose = hg_to_pose(offset, "offset", code=code)
    shift = float(np.max(np.abs(pose[:3, 3]))) * 1000.0
    if shift > bound_mm:
        raise Refused(code, f"offset: a translation of {shift:.6g} mm: each axis must be within "
                            f"±{bound_mm:g} mm")
    return pose


def _within(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    """Every element of a within tol of b's (plain floats: numpy is slower for 7 values)."""
    return all(abs(x - y) <= tol for x, y in zip(a.tolist(), b.tolist()))


def _ignored(why: str) -> Reply:
    return Reply(ReturnCode.OK, f"ignored: {why}")


def _near_limits_refined(ss: np.ndarray, values: np.ndarray, evaluate: Callable[[np.ndarray], np.ndarray],
                         lower: np.ndarray, upper: np.ndarray, margin: float,
                         count: int = 16) -> np.ndarray:
    """`values` (rows at the path parameters ss) with `count` more rows, in order, inside every
    interval that has an end within `margin` of a limit: what the path does between two samples
    near a limit is checked too, as the run's watch, which samples every control period, would
    see it (accepted moves tripped it by 1e-6° or 0.12 mm)."""
    near = np.any((values <= lower + margin) | (values >= upper - margin), axis=1)
    todo = np.flatnonzero(near[:-1] | near[1:])
    if not len(todo):
        return values
    t = np.linspace(0.0, 1.0, count + 2)[1:-1]
    extra = (ss[todo, None] + (ss[todo + 1] - ss[todo])[:, None] * t).ravel()
    order = np.argsort(np.concatenate([ss, extra]), kind="stable")
    return np.vstack([values, evaluate(extra)])[order]


def _first_exit(values: np.ndarray, lower: np.ndarray, upper: np.ndarray,
                tol: float) -> tuple[int, int] | None:
    """(sample, axis) where rows of `values` first go from inside [lower, upper] to outside,
    or where the last row is outside; None when the path stays (or ends) inside."""
    inside = (values >= lower - tol) & (values <= upper + tol)
    if inside.all():                     # the usual case, at the least cost
        return None
    exits = np.argwhere(inside[:-1] & ~inside[1:])
    if len(exits):
        k, axis = exits[0]
        return int(k) + 1, int(axis)
    outside = np.flatnonzero(~inside[-1])
    if len(outside):
        return len(values) - 1, int(outside[0])
    return None


def _check_config(c: ArmConfig) -> None:
    """The start-up settings that have no setter, else ValueError (the node does not start);
    the others are applied through their setters (`ArmCore._apply_settings`)."""
    check_ranges(c, "arm configuration")
    if not (math.isfinite(c.gripper_speed) and c.gripper_speed > 0):
        raise ValueError(f"gripper_speed must be finite and > 0, got {c.gripper_speed}")


def _in_range(x: float, lo: float, hi: float, name: str, unit: str) -> float:
    """x if finite and within [lo, hi], else VALUE_ERR that gives the bounds."""
    x = finite_number(x, name)
    if not lo <= x <= hi:
        raise value_error(f"{name} is {x:g} {unit}: it must be within {lo:g} … {hi:g} {unit}")
    return x


class ArmCore:
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
        self.soft_limit_joint = self.hard_limit_joint.copy()          # rows: [lower, upper]
        self.speed_joint = ratio_percent(c.initial_speed_ratio, "initial_speed_ratio")
        self.speed_cartesian = self.speed_joint
        self.min_accel_time_joint = self.accel_time_joint = MAX_ACCEL_TIME_S
        self.min_accel_time_cartesian = self.accel_time_cartesian = MAX_ACCEL_TIME_S
        self.frames = Frames()
        self._feedback = world.arm_positions()
        self._finger = world.gripper_position()
        self.device = executor.add_device("arm", c.queue_size,
                                          ArmSetpoint(q0.copy(), self._finger))
        self._apply_settings(c)
        self.servo = False
        self._alarms: list[Alarm] = []
        self._alarm_lock = threading.Lock()
        self._inside: np.ndarray | None = None
        self._batch = threading.local()               # the moves an `all_or_nothing` collects
        self._cartesian_memo: tuple | None = None     # (joints sample, frames, its pose)
        executor.after_step(self._sample)

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

    # === the simulation thread: snapshot and soft-limit watch ===================================
    def _sample(self, world) -> None:
        self._feedback = world.arm_positions()
        self._finger = world.gripper_position()
        self._watch()

    def _watch(self) -> None:
        """Stop and raise an alarm when the commanded set-point exceeds a soft limit while
        moving (5.4.8: 範囲を超える場合は、動作を停止してアラーム). Against the limits its plan was
        checked with, a motion can only leave them by a crossing, and one that starts outside
        them (a move back inside) may move; against a limit that changed since, it is stopped
        wherever it is outside it, also from its first step (it ran on outside a limit set while
        it waited in the queue).

        At rest nothing is computed (the FK is most of a step's Python work): the first moving
        step compares against the rest point, under the limits in force then."""
        d = self.device
        cur = d.current
        if cur is None:
            self._inside = None
            return
        if self._inside is None:
            self._inside = self._within_watch_limits(d.hold.joints)[1]
        values, inside = self._within_watch_limits(cur.motion.at(d.t).joints)
        was, self._inside = self._inside, inside
        if self._alarms:
            return
        checked = getattr(cur.motion, "limits_checked", None)
        changed = (np.ones(len(inside), bool) if checked is None
                   else np.any(checked != self._limit_rows(), axis=1))
        left = np.flatnonzero(~inside & (was | changed))
        if not len(left):
            return
        i = int(left[0])
        lj, lc = self.soft_limit_joint, self.soft_limit_cartesian
        when = "with a move paused there" if d.paused else "while moving"
        if i < self.axis_count:
            alarm = Alarm(ALARM_JOINT_SOFT_LIMIT, AlarmType.WARNING,
                          f"joint soft limit exceeded {when}: J{i + 1} = {values[i]:.3f}° "
                          f"left [{lj[i, 0]:g}, {lj[i, 1]:g}]°")
        else:
            axis = "xyz"[i - self.axis_count]
            lim = lc[i - self.axis_count]
            alarm = Alarm(ALARM_CARTESIAN_SOFT_LIMIT, AlarmType.WARNING,
                          f"Cartesian soft limit exceeded {when}: {axis} = {values[i]:.2f} mm "
                          f"left [{lim[0]:g}, {lim[1]:g}] mm")
        with self._alarm_lock:
            self._alarms.append(alarm)
        self.stop_motion(fastest=True, reason=f"alarm 0x{alarm.code:X} ({alarm.description})")

    def _limit_rows(self) -> np.ndarray:
        """The soft limits as rows (lower, upper): J1 … J7 (degree), then x, y, z (mm)."""
        return np.concatenate([self.soft_limit_joint, self.soft_limit_cartesian])

    def _within_watch_limits(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Joint values (degree) and control-point position (mm) of set-point q, and which of
        them lie within the soft limits widened by the watch tolerances."""
        p = self.frames.tool_of(self.kin.flange(q))[:3, 3] * 1000.0
        values = np.concatenate([np.degrees(q), p])
        lj, lc = self.soft_limit_joint, self.soft_limit_cartesian
        lower = np.concatenate([lj[:, 0] - JOINT_WATCH_TOLERANCE_DEG,
                                lc[:, 0] - CARTESIAN_WATCH_TOLERANCE_MM])
        upper = np.concatenate([lj[:, 1] + JOINT_WATCH_TOLERANCE_DEG,
                                lc[:, 1] + CARTESIAN_WATCH_TOLERANCE_MM])
        return values, (values >= lower) & (values <= upper)

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
        return {"pos": [*np.degrees(self._feedback), opening_mm]}

    @returns(*GETTER)
    def get_manip_info(self) -> Reply:
        period_ms = self.executor.dt * 1000.0
        cycle_ms = round(period_ms)
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
        return {"soft_limit": [(float(hi), float(lo)) for lo, hi in self.soft_limit_joint]}

    @returns(R.STATUS_ERR, R.VALUE_ERR)
    def set_soft_limit_joint(self, soft_limit: list) -> None:
        self._check_idle("set_soft_limit_joint")
        if len(soft_limit) != self.axis_count:
            raise value_error(f"soft_limit needs {self.axis_count} limits (J1 … J{self.axis_count}),"
                              f" got {len(soft_limit)}")
        limits = np.empty((self.axis_count, 2))
        for i, lim in enumerate(soft_limit):
            upper, lower = self._limit_value(lim, f"soft_limit[{i}] (J{i + 1})")
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
        return {"offset": pose_to_hg(self.frames.base)}

    @returns(*GETTER)
    def get_max_speed_cartesian(self) -> dict:
        return {"speed": self.max_speed_cartesian}

    @returns(*GETTER)
    def get_max_speed_joint(self) -> dict:
        return {"speed": [float(v) for v in self.max_speed_joint]}

    @returns(*GETTER)
    def get_min_accel_time_cartesian(self) -> dict:
        return {"acl_time": self.min_accel_time_cartesian}

    @returns(*GETTER)
    def get_min_accel_time_joint(self) -> dict:
        return {"acl_time": self.min_accel_time_joint}

    @returns(*GETTER)
    def get_soft_limit_cartesian(self) -> dict:
        return {f"{a}_limit": (float(hi), float(lo))
                for a, (lo, hi) in zip("xyz", self.soft_limit_cartesian)}

    @returns(*GETTER)
    def get_home(self) -> dict:
        return {"joint_point": [float(v) for v in self.home]}

    # === middle-level port: settings ==============================================================
    @returns(*SETTER)
    def set_speed_joint(self, spd_ratio: int) -> None:
        self.speed_joint = ratio_percent(spd_ratio, "spd_ratio")

    @returns(*SETTER)
    def set_speed_cartesian(self, spd_ratio: int) -> None:
        self.speed_cartesian = ratio_percent(spd_ratio, "spd_ratio")

    @returns(*SETTER)
    def set_accel_time_joint(self, acl_time: float) -> None:
        self.accel_time_joint = self._accel_time(acl_time, self.min_accel_time_joint,
                                                 "set_min_accel_time_joint")

    @returns(*SETTER)
    def set_accel_time_cartesian(self, acl_time: float) -> None:
        self.accel_time_cartesian = self._accel_time(acl_time, self.min_accel_time_cartesian,
                                                     "set_min_accel_time_cartesian")

    @returns(*SETTER)
    def set_min_accel_time_joint(self, acl_time: float) -> Reply:
        self.min_accel_time_joint = self._min_accel_time(acl_time)
        if self.accel_time_joint < self.min_accel_time_joint:
            self.accel_time_joint = self.min_accel_time_joint
            return Reply(comment=f"the joint accel time was below it and is now {acl_time:g} s")
        return Reply()

    @returns(*SETTER)
    def set_min_accel_time_cartesian(self, acl_time: float) -> Reply:
        self.min_accel_time_cartesian = self._min_accel_time(acl_time)
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
            upper, lower = self._limit_value(lim, f"{axis}_limit")
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
                             lambda: setattr(self, "frames", Frames(base, self.frames.tool)))

    @returns(R.STATUS_ERR)
    def set_control_point_offset(self, offset: list[float]) -> None:
        """Refused while anything runs, is paused mid-move or is queued: those targets were
        planned with the present control point (5.4.23: not while moving)."""
        self._check_idle("set_control_point_offset")
        tool = _offset(offset, CONTROL_POINT_OFFSET_MM, ReturnCode.NG)
        self._set_while_idle("set_control_point_offset", R.STATUS_ERR,
                             "it was planned for the present control point",
                             lambda: setattr(self, "frames", Frames(self.frames.base, tool)))

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
        q = finite_vector(joint_point, self.axis_count, "joint_point")
        self._check_joint_target(q, "joint_point")
        self.home = q

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
        goal = np.radians(finite_vector(joint_points, self.axis_count, "joint_points"))
        self._check_joint_target(np.degrees(goal), "move_ptp_joint_abs")   # before the queue
        return self.queue_joint_move(lambda start: goal, "move_ptp_joint_abs")

    @returns(*MOVE)
    @plans
    def move_ptp_joint_rel(self, joint_points: list[float]) -> dict:
        self._check_can_move(self.speed_joint, "set_speed_joint")
        step = finite_vector(joint_points, self.axis_count, "joint_points")
        self._check_joint_step(step, "joint_points")
        delta = np.radians(step)
        return self.queue_joint_move(lambda start: start.joints + delta, "move_ptp_joint_rel")

    @returns(*MOVE)
    @plans
    def go_home(self) -> dict:
        self._check_can_move(self.speed_joint, "set_speed_joint")
        goal = np.radians(self.home)
        return self.queue_joint_move(lambda start: goal, "go_home")

    @returns(*MOVE)
    @plans
    def move_ptp_cartesian_abs(self, car_point: tuple) -> dict:
        self._check_can_move(self.speed_joint, "set_speed_joint")
        target, psi = self._car_point(car_point, "car_point")
        self._check_target(target, "move_ptp_cartesian_abs")
        return self._queue_ptp_cartesian(lambda P0: target, "move_ptp_cartesian_abs", psi=psi)

    @returns(*MOVE)
    @plans
    def move_ptp_cartesian_rel(self, car_point: tuple) -> dict:
        self._check_can_move(self.speed_joint, "set_speed_joint")
        delta, turn = self._car_point(car_point, "car_point")
        return self._queue_ptp_cartesian(lambda P0: compose_relative(P0, delta),
                                         "move_ptp_cartesian_rel", turn=turn)

    @returns(*MOVE)
    @plans
    def move_linear_cartesian_abs(self, car_point: tuple) -> dict:
        self._check_can_move(self.speed_cartesian, "set_speed_cartesian")
        target, psi = self._car_point(car_point, "car_point")
        self._check_target(target, "move_linear_cartesian_abs")
        return self.queue_cartesian(lambda P0: LinePath(P0, target), "move_linear_cartesian_abs",
                                     psi=psi)

    @returns(*MOVE)
    @plans
    def move_linear_cartesian_rel(self, car_point: tuple) -> dict:
        self._check_can_move(self.speed_cartesian, "set_speed_cartesian")
        delta, turn = self._car_point(car_point, "car_point")
        return self.queue_cartesian(lambda P0: LinePath(P0, compose_relative(P0, delta)),
                                     "move_linear_cartesian_rel", turn=turn)

    @returns(*MOVE)
    @plans
    def move_circular_cartesian_abs(self, car_point_r: tuple, car_point_t: tuple) -> dict:
        """2014 revision: arc from where the previous motion ends, through R's position, to T
        (R's orientation and elbow are not used)."""
        self._check_can_move(self.speed_cartesian, "set_speed_cartesian")
        via, _ = self._car_point(car_point_r, "car_point_r")
        target, psi = self._car_point(car_point_t, "car_point_t")
        self._check_target(via, "move_circular_cartesian_abs: car_point_r")
        self._check_target(target, "move_circular_cartesian_abs")
        return self.queue_cartesian(lambda P0: ArcPath(P0, via[:3, 3], target),
                                     "move_circular_cartesian_abs", psi=psi)

    @returns(*MOVE)
    @plans
    def move_circular_cartesian_rel(self, car_point_r: tuple, car_point_t: tuple) -> dict:
        self._check_can_move(self.speed_cartesian, "set_speed_cartesian")
        via, _ = self._car_point(car_point_r, "car_point_r")
        delta, turn = self._car_point(car_point_t, "car_point_t")
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
        """The spec lists no FULL_MOTION_QUEUE_ERR here: a full queue is STATUS_ERR."""
        ratio = ratio_percent(angle_ratio, "angle_ratio")
        try:
            return self.queue_gripper(ratio, "move_gripper")
        except Refused as r:
            if r.code == R.FULL_MOTION_QUEUE_ERR:
                raise Refused(R.STATUS_ERR, r.comment) from None
            raise

    # === state, feedback and progress (also for the node's topics and actions) =====================
    def state_word(self) -> int:
        d = self.device
        # after servo_off the axes stay powered until the decelerating stop is at rest
        word = STATE_SERVO_ON if self.servo or d.current is not None else 0
        if d.current is not None and not (d.paused and d.rate <= 0.0) \
                or d.current is None and d.queue and not d.paused:
            word |= STATE_MOVING
        if self._alarms:
            word |= STATE_ALARM
        if d.full:
            word |= STATE_BUFFER_FULL
        if d.paused:
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
        """The spec refuses these while moving (state bit 0x02) or alarmed; paused is not moving."""
        if self.state_word() & STATE_MOVING:
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

    @staticmethod
    def _limit_value(lim: Any, name: str) -> tuple[float, float]:
        """(upper, lower) of a LimitValue, finite and upper >= lower, else VALUE_ERR."""
        if isinstance(lim, dict):
            lim = (lim.get("upper"), lim.get("lower"))
        if len(lim) != 2:
            raise value_error(f"{name} needs upper and lower")
        upper = finite_number(lim[0], f"{name}.upper")
        lower = finite_number(lim[1], f"{name}.lower")
        if upper <= lower:
            raise value_error(f"{name}: upper {upper:g} must be above lower {lower:g}")
        return upper, lower

    def _accel_time(self, acl_time: float, minimum: float, setter: str) -> float:
        t = finite_number(acl_time, "acl_time")
        if t < minimum:
            raise value_error(f"acl_time {t:g} s is below the minimum accel time {minimum:g} s "
                              f"({setter} sets it)")
        return _in_range(t, minimum, MAX_ACCEL_TIME_S, "acl_time", "s")

    def _min_accel_time(self, acl_time: float) -> float:
        t = finite_number(acl_time, "acl_time")
        floor = 2 * self.executor.dt
        if t < floor:
            raise value_error(f"acl_time {t:g} s is below two control cycles ({floor:.4f} s)")
        return _in_range(t, floor, MAX_ACCEL_TIME_S, "acl_time", "s")

    def _check_joint_target(self, goal_deg: np.ndarray, name: str) -> None:
        lo, hi = self.soft_limit_joint[:, 0].tolist(), self.soft_limit_joint[:, 1].tolist()
        for i, (q, a, b) in enumerate(zip(np.asarray(goal_deg, float).tolist(), lo, hi)):
            if not a - 1e-9 <= q <= b + 1e-9:
                raise value_error(f"{name}: J{i + 1} = {q:.10g}° is outside the soft limit "
                                  f"[{a:g}, {b:g}]°")

    def _check_joint_step(self, step_deg: np.ndarray, name: str) -> None:
        """A relative move wider than a joint's soft-limit range leaves it from any start:
        VALUE_ERR before the queue is looked at (a full queue would have hidden it)."""
        span = (self.soft_limit_joint[:, 1] - self.soft_limit_joint[:, 0]).tolist()
        for i, (d, w) in enumerate(zip(np.asarray(step_deg, float).tolist(), span)):
            if abs(d) > w + 1e-9:
                raise value_error(f"{name}: J{i + 1} by {d:g}° leaves the soft limit from any "
                                  f"start (its range is {w:g}°)")

    def _car_point(self, car_point: Any, name: str) -> tuple[np.ndarray, float]:
        """(pose 4×4 m, elbow rad) of a CarPosWithElbow, else VALUE_ERR."""
        if isinstance(car_point, dict):
            car_point = (car_point.get("car_pos"), car_point.get("elbow"),
                         car_point.get("struct_flag", 0))
        pose = hg_to_pose(car_point[0], f"{name}.car_pos")
        far = float(np.max(np.abs(pose[:3, 3]))) * 1000.0
        if far > TARGET_MM:
            raise value_error(f"{name}.car_pos: a translation of {far:.6g} mm is out of any reach "
                              f"(at most ±{TARGET_MM:g} mm per axis)")
        elbow = _in_range(car_point[1], -ELBOW_DEG, ELBOW_DEG, f"{name}.elbow", "°")
        return pose, math.radians(elbow)

    def _check_target(self, target: np.ndarray, label: str, frames: Frames | None = None) -> None:
        """A target (4×4, m) within the Cartesian soft limit and the arm's reach, else VALUE_ERR.
        Absolute targets are checked before the queue is looked at (a full queue would have
        hidden it), and again when planned, with the frames in force then."""
        self._check_cartesian_positions(target[None, :3, 3] * 1000.0, label)
        self._check_reach(target[None, :3, 3], self.frames if frames is None else frames, label)

    def _check_reach(self, positions: np.ndarray, frames: Frames, label: str) -> None:
        """Control-point positions (robot frame, m) no farther from the shoulder than the arm,
        hand and control-point offset reach, else VALUE_ERR: checked before any IK or planning,
        so a target kilometres away is refused at once."""
        kin = self.kin
        to_robot = inverse(frames.base)
        shoulder = to_robot[:3, :3] @ kin.shoulder + to_robot[:3, 3]
        radius = kin.reach + kin.hand + float(np.linalg.norm(frames.tool[:3, 3]))
        dist = np.linalg.norm(positions - shoulder, axis=1)
        far = np.flatnonzero(~(dist <= radius + 1e-9))
        if len(far):
            k = int(far[0])
            where = ("the target" if k == len(positions) - 1 else
                     f"the path at {100.0 * k / max(1, len(positions) - 1):.0f} %")
            raise value_error(f"{label}: {where} is out of reach: {dist[k] * 1e3:.6g} mm from the "
                              f"shoulder, the arm reaches {radius * 1e3:.1f} mm")

    def _check_cartesian_positions(self, positions_mm: np.ndarray, label: str) -> None:
        lim = self.soft_limit_cartesian
        hit = _first_exit(positions_mm, lim[:, 0], lim[:, 1], 1e-9)
        if hit is not None:
            k, axis = hit
            where = "the target" if k == len(positions_mm) - 1 else "the path"
            raise value_error(f"{label}: {where} leaves the Cartesian soft limit: "
                              f"{'xyz'[axis]} = {positions_mm[k, axis]:.10g} mm, limit "
                              f"[{lim[axis, 0]:g}, {lim[axis, 1]:g}] mm")

    def _check_joint_path(self, qs_deg: np.ndarray, label: str) -> None:
        lim = self.soft_limit_joint
        hit = _first_exit(qs_deg, lim[:, 0], lim[:, 1], 1e-9)
        if hit is not None:
            k, j = hit
            raise value_error(f"{label}: the path leaves the joint soft limit: J{j + 1} = "
                              f"{qs_deg[k, j]:.10g}°, limit [{lim[j, 0]:g}, {lim[j, 1]:g}]°")

    # === queueing ======================================================================================
    def queue_joint_move(self, goal_of: Callable[[ArmSetpoint], np.ndarray], label: str,
                          speed_ratio: float | None = None, ramp: float | None = None) -> dict:
        """A PTP move to goal_of(start) (rad): synchronized trapezoid at the joint speed ratio
        and accel time (or the given ones: STROLIC programs keep their own)."""
        ratio = self.speed_joint if speed_ratio is None else speed_ratio
        speed = np.radians(self.max_speed_joint) * ratio / 100.0
        ramp = self.accel_time_joint if ramp is None else ramp

        def plan(start: ArmSetpoint) -> ArmMotion:
            frames = self.frames          # read while planning: the offsets wait for it
            goal = goal_of(start)
            self._check_joint_target(np.degrees(goal), label)
            path = LinearJointPath(start.joints, goal)
            steps = 1 + max(1, math.ceil(max(map(abs, np.degrees(path.delta).tolist()))))
            ss = np.linspace(0.0, 1.0, steps)

            def positions_mm(ss: np.ndarray) -> np.ndarray:
                qs = path.q0 + ss[:, None] * path.delta
                return frames.tool_of(self.kin.flange_many(qs))[:, :3, 3] * 1000.0
            lim = self.soft_limit_cartesian
            self._check_cartesian_positions(_near_limits_refined(
                ss, positions_mm(ss), positions_mm, lim[:, 0], lim[:, 1], NEAR_LIMIT_MM), label)
            timing = Trapezoid.for_axes(path.delta, speed, ramp)
            return ArmMotion(path, timing, start.finger, start.finger, ramp, "joint")
        return self._submit(plan, label)

    def _elbow_goal(self, start_q: np.ndarray, flange: np.ndarray, psi: float | None,
                    turn: float) -> tuple[float | None, float]:
        """(psi, turn) for the planners. Abs: psi as given. Rel: psi = the start's arm angle +
        turn, except where the start or the target is near the arm angle's undefined direction
        (wrist left or right of the shoulder): there the elbow is carried along without twist
        and turned by `turn` (psi None)."""
        if psi is not None:
            return psi, 0.0
        kin = self.kin
        u0 = kin.elbow_direction(start_q)[0]
        w = kin.wrist_of(flange) - kin.shoulder
        u1 = w / max(float(np.linalg.norm(w)), 1e-12)
        if min(kin.reference_strength(u0), kin.reference_strength(u1)) > REL_ELBOW_CLEARANCE:
            return kin.angle_of(*kin.elbow_direction(start_q)) + turn, 0.0
        return None, turn

    def _queue_ptp_cartesian(self, target_of: Callable[[np.ndarray], np.ndarray], label: str, *,
                             psi: float | None = None, turn: float = 0.0) -> dict:
        """A PTP move to the control-point pose target_of(start pose), with the elbow at arm
        angle `psi`, or (Rel) turned by `turn` (rad) from where it starts."""
        kin = self.kin
        lo, hi = np.radians(self.soft_limit_joint[:, 0]), np.radians(self.soft_limit_joint[:, 1])

        def goal_of(start: ArmSetpoint) -> np.ndarray:
            frames = self.frames          # read while planning: the offsets wait for it
            target = target_of(frames.tool_of(kin.flange(start.joints)))
            self._check_target(target, label, frames)
            flange = frames.flange_of(target)
            goal_psi, goal_turn = self._elbow_goal(start.joints, flange, psi, turn)
            try:
                if goal_psi is not None:
                    return kin.solve(flange, start.joints, psi=goal_psi, lower=lo, upper=hi)
                u0, n0 = kin.elbow_direction(start.joints)
                w = kin.wrist_of(flange) - kin.shoulder
                u1 = w / max(float(np.linalg.norm(w)), 1e-12)
                elbow = rotate_about(u1, goal_turn) @ kin.transport(n0, u0, u1)
                return kin.solve(flange, start.joints, elbow_dir=elbow, lower=lo, upper=hi)
            except Unreachable as e:
                raise value_error(f"{label}: {e}") from None
        return self.queue_joint_move(goal_of, label)

    def queue_cartesian(self, path_of: Callable[[np.ndarray], LinePath], label: str, *,
                         psi: float | None = None, turn: float = 0.0,
                         speed_ratio: float | None = None, ramp: float | None = None) -> dict:
        """A CP move along path_of(start pose); the elbow ends at arm angle `psi`, or (Rel) is
        turned by `turn` (rad) from where it starts. Speed ratio and accel time: the port's
        settings unless given."""
        v, w = self.max_speed_cartesian
        ratio = (self.speed_cartesian if speed_ratio is None else speed_ratio) / 100.0
        ramp = self.accel_time_cartesian if ramp is None else ramp
        limits = CartesianLimits(
            speed=v * ratio / 1000.0, angular_speed=math.radians(w * ratio), ramp=ramp,
            joint_velocity=np.radians(self.max_speed_joint),
            joint_accel=np.radians(self.max_speed_joint) / self.min_accel_time_joint)

        def plan(start: ArmSetpoint) -> ArmMotion:
            frames = self.frames          # read while planning: the offsets wait for it
            try:
                path = path_of(frames.tool_of(self.kin.flange(start.joints)))
                self.planner.check_length(path, frames)
            except ValueError as e:
                raise value_error(f"{label}: {e}") from None
            coarse = positions_along(path, np.linspace(0.0, 1.0, REACH_SAMPLES + 1))
            self._check_cartesian_positions(coarse * 1000.0, label)
            self._check_reach(coarse, frames, label)
            ss = np.linspace(0.0, 1.0, min(MAX_CHECK_SAMPLES,
                                           1 + max(2, math.ceil(path.length / 0.002))))
            self._check_cartesian_positions(positions_along(path, ss) * 1000.0, label)
            goal_psi, goal_turn = self._elbow_goal(start.joints, frames.flange_of(path.pose(1.0)),
                                                   psi, turn)
            try:
                result = self.planner.plan(path, frames, start.joints, limits, psi=goal_psi,
                                           turn=goal_turn)
            except Unreachable as e:
                raise value_error(f"{label}: {e}") from None
            dense = np.linspace(0.0, 1.0, 4 * len(result.path.ss))
            lim = self.soft_limit_joint

            def joints_deg(ss: np.ndarray) -> np.ndarray:
                return np.degrees(result.path.spline(ss))
            self._check_joint_path(_near_limits_refined(
                dense, joints_deg(dense), joints_deg, lim[:, 0], lim[:, 1], NEAR_LIMIT_DEG), label)
            return ArmMotion(result.path, result.timing, start.finger, start.finger, ramp,
                             "cartesian")
        return self._submit(plan, label)

    def queue_gripper(self, ratio: int, label: str) -> dict:
        self._check_can_move()
        finger = self.finger_max * ratio / 100.0
        speed = self.config.gripper_speed / 2000.0      # one finger, m/s
        ramp = self.min_accel_time_joint

        def plan(start: ArmSetpoint) -> ArmMotion:
            timing = Trapezoid.for_axes(np.array([finger - start.finger]), np.array([speed]), ramp)
            return ArmMotion(LinearJointPath(start.joints, start.joints), timing, start.finger,
                             finger, ramp, "gripper")
        return self._submit(plan, label)

    def _submit(self, plan: Callable[[ArmSetpoint], ArmMotion], label: str) -> dict | Reply:
        """Queue one planned move; inside `all_or_nothing` (on this thread), collect it."""
        guarded = self._guarded(plan, label)
        collected = getattr(self._batch, "plans", None)
        if collected is not None:
            collected.append((guarded, label))
            return {"motion_id": 0}
        motion_id = self.device.submit(guarded, label)
        if motion_id is None:
            raise self._full()
        why = self.device.doomed(motion_id)
        if why is not None:         # OK as 5.4.19 has it, and said: its wait will say the same
            return Reply(R.OK, f"discarded: {why} (a stop discards every command given until "
                               "the arm is at rest)", {"motion_id": motion_id})
        return {"motion_id": motion_id}

    @contextmanager
    def all_or_nothing(self) -> Iterator[list[int]]:
        """The moves queued inside the block (on this thread) go in together when it ends, each
        planned from the end of the one before, or none of them: a refusal of any, or a queue
        without room for all (FULL_MOTION_QUEUE_ERR), queues nothing. The list yielded gets
        their ids, in order (a program's pose sequence is one command)."""
        plans: list = []
        self._batch.plans = plans
        ids: list[int] = []
        try:
            yield ids
        finally:
            self._batch.plans = None
        if plans:
            got = self.device.submit_all(plans)
            if got is None:
                raise self._full()
            ids.extend(got)

    def _full(self) -> Refused:
        return Refused(R.FULL_MOTION_QUEUE_ERR,
                       f"the motion queue is full ({self.device.capacity} motions): wait or stop")

    def _guarded(self, plan: Callable[[ArmSetpoint], ArmMotion],
                 label: str) -> Callable[[ArmSetpoint], ArmMotion]:
        def guarded(start: ArmSetpoint) -> ArmMotion:
            """A refusal passes; any other failure of planning is this request's NG, said. The
            servo and alarms are checked again here, after the device took its generation: a
            servo_off (or an alarm) that came while this request waited for another's plan
            stopped an idle arm, and the move would have been queued behind it."""
            self._check_can_move()
            limits = self._limit_rows()
            try:
                motion = plan(start)
            except Refused:
                raise
            except Unreachable as e:
                raise value_error(f"{label}: {e}") from None
            except Exception as e:
                raise Refused(R.NG, f"{label} could not be planned: {type(e).__name__}: {e}") \
                    from None
            if not math.isfinite(motion.duration):
                raise value_error(f"{label}: the move would take forever at these settings")
            motion.limits_checked = limits
            return motion
        return guarded

    def current_ramp(self) -> float:
        cur = self.device.current
        return cur.motion.ramp if cur is not None else self.accel_time_joint

    def stop_motion(self, fastest: bool = False, reason: str = STOPPED) -> None:
        """Stop at the motion's accel time (or the fastest the settings allow); `reason` is
        what a wait on a discarded motion is told."""
        cur = self.device.current
        if fastest:
            ramp = (self.min_accel_time_cartesian
                    if cur is not None and cur.motion.kind == "cartesian"
                    else self.min_accel_time_joint)
        else:
            ramp = self.current_ramp()
        self.device.stop(ramp, reason)
