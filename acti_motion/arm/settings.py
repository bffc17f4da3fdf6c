"""The arm's settings: its start-up configuration (the node's parameters), the bounds of every
setting and of the values a service takes, and the pure helpers that check them.

No state and no thread of its own: these run on the caller's thread (a service, the node's
parameters, the core's start-up) and only compute, so they can be called from anywhere; what a
value is checked against at run time (the soft limits, the frames) lives in `ArmCore`.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from acti_motion.arm.poses import hg_to_pose
from acti_motion.config_fields import QUEUE_SIZE_RANGE, check_ranges, ranged
from acti_motion.replies import Refused, ReturnCode, finite_number, value_error

# Bounds of the settings that keep the arm stoppable and every plan quick (docs/interfaces.md: acti_middle_node services).
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
    gripper_speed: float = ranged(100.0, 1.0, 1000.0)
    # Cartesian soft limits of the control point, robot frame [mm]: x lower, x upper, y lower,
    # y upper, z lower, z upper (set_soft_limit_cartesian)
    soft_limit_cartesian: tuple[float, ...] = (-1000.0, 1200.0, -1000.0, 1000.0, -100.0, 1600.0)
    # J1 … J7 at start-up [degree]
    initial_joints_deg: tuple[float, ...] = (0.0, 30.0, 0.0, -60.0, 0.0, 60.0, 0.0)
    # go_home target J1 … J7 [degree] (set_home)
    home_joints_deg: tuple[float, ...] = (0.0, 30.0, 0.0, -60.0, 0.0, 60.0, 0.0)


def _check_config(c: ArmConfig) -> None:
    """The start-up settings that have no setter, else ValueError (the node does not start);
    the others are applied through their setters (`ArmCore._apply_settings`)."""
    check_ranges(c, "arm configuration")


def _in_range(x: float, lo: float, hi: float, name: str, unit: str) -> float:
    """x if finite and within [lo, hi], else VALUE_ERR that gives the bounds."""
    x = finite_number(x, name)
    if not lo <= x <= hi:
        raise value_error(f"{name} is {x:g} {unit}: it must be within {lo:g} … {hi:g} {unit}")
    return x


def _farthest_mm(pose: np.ndarray) -> float:
    """The largest of a pose's translation components, in mm (plain floats: numpy's max is
    four Python calls, a CP accept's cold core pays for each)."""
    return max(map(abs, pose[:3, 3].tolist())) * 1000.0


def _offset(offset: list[float], bound_mm: float, code: ReturnCode) -> np.ndarray:
    """The pose of an offset HgMatrix whose translation is within `bound_mm`, else `code`."""
    pose = hg_to_pose(offset, "offset", code=code)
    shift = _farthest_mm(pose)
    if shift > bound_mm:
        raise Refused(code, f"offset: a translation of {shift:.6g} mm: each axis must be within "
                            f"±{bound_mm:g} mm")
    return pose


def _limit_value(lim: Any, name: str, pinned: bool = False) -> tuple[float, float]:
    """(upper, lower) of a LimitValue, finite and upper > lower (or, with `pinned`, upper =
    lower too: the common port refuses only upper < lower for a joint, which may be held at one
    value), else VALUE_ERR."""
    if isinstance(lim, dict):
        lim = (lim.get("upper"), lim.get("lower"))
    if len(lim) != 2:
        raise value_error(f"{name} needs upper and lower")
    upper = finite_number(lim[0], f"{name}.upper")
    lower = finite_number(lim[1], f"{name}.lower")
    if upper < lower or upper == lower and not pinned:
        below = "at or above" if pinned else "above"
        raise value_error(f"{name}: upper {upper:g} must be {below} lower {lower:g}")
    return upper, lower


def _accel_time(acl_time: float, minimum: float, setter: str) -> float:
    t = finite_number(acl_time, "acl_time")
    if t < minimum:
        raise value_error(f"acl_time {t:g} s is below the minimum accel time {minimum:g} s "
                          f"({setter} sets it)")
    return _in_range(t, minimum, MAX_ACCEL_TIME_S, "acl_time", "s")


def _min_accel_time(acl_time: float, cycle_s: float) -> float:
    """An accel time of at least two control cycles (`cycle_s` each), else VALUE_ERR."""
    t = finite_number(acl_time, "acl_time")
    floor = 2 * cycle_s
    if t < floor:
        raise value_error(f"acl_time {t:g} s is below two control cycles ({floor:.4f} s)")
    return _in_range(t, floor, MAX_ACCEL_TIME_S, "acl_time", "s")


def _car_point(car_point: Any, name: str) -> tuple[np.ndarray, float]:
    """(pose 4×4 m, elbow rad) of a CarPosWithElbow, else VALUE_ERR."""
    if isinstance(car_point, dict):
        car_point = (car_point.get("car_pos"), car_point.get("elbow"),
                     car_point.get("struct_flag", 0))
    pose = hg_to_pose(car_point[0], f"{name}.car_pos")
    far = _farthest_mm(pose)
    if far > TARGET_MM:
        raise value_error(f"{name}.car_pos: a translation of {far:.6g} mm is out of any reach "
                          f"(at most ±{TARGET_MM:g} mm per axis)")
    elbow = _in_range(car_point[1], -ELBOW_DEG, ELBOW_DEG, f"{name}.elbow", "°")
    return pose, math.radians(elbow)
