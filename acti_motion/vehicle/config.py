"""The base's start-up settings and limits: the node's parameters (one comment per field is the
parameter's description; `ranged` fields have documented bounds). The limits keep the base
stoppable: a stop decelerates at the acceleration limit, and from the velocity limit it must take
at most `MAX_STOP_S`."""
from __future__ import annotations

from dataclasses import dataclass

from acti_motion.config_fields import QUEUE_SIZE_RANGE, check_ranges, ranged


MAX_STOP_S = 10.0      # the longest stop from the velocity limit at the acceleration limit [s]


@dataclass
class VehicleConfig:
    """Start-up settings and limits of the base (spec units); the node's parameters."""
    queue_size: int = ranged(32, *QUEUE_SIZE_RANGE)  # motion queue capacity
    # velocity limit, translation [mm/s]
    velocity_limit_translation: float = ranged(1000.0, 1.0, 10000.0)
    # velocity limit, rotation [degree/s]
    velocity_limit_rotation: float = ranged(90.0, 0.1, 3600.0)
    # acceleration limit, translation [mm/s²]
    accel_limit_translation: float = ranged(1000.0, 1.0, 100000.0)
    # acceleration limit, rotation [degree/s²]
    accel_limit_rotation: float = ranged(180.0, 0.1, 36000.0)
    # mm/s: the slowest velocity setting (set_velocity)
    velocity_min_translation: float = ranged(1.0, 0.1, 10000.0)
    # degree/s: the slowest yaw-rate setting
    velocity_min_rotation: float = ranged(0.1, 0.01, 3600.0)
    # mm/s²: the lowest acceleration setting
    accel_min_translation: float = ranged(1.0, 0.1, 100000.0)
    # degree/s²: the lowest angular acceleration setting
    accel_min_rotation: float = ranged(1.0, 0.01, 36000.0)
    # velocity at start-up [mm/s]
    default_velocity_translation: float = ranged(300.0, 0.1, 10000.0)
    # turn rate at start-up [degree/s]
    default_velocity_rotation: float = ranged(45.0, 0.01, 3600.0)
    # acceleration at start-up [mm/s²]
    default_accel_translation: float = ranged(500.0, 0.1, 100000.0)
    # turn acceleration at start-up [degree/s²]
    default_accel_rotation: float = ranged(90.0, 0.01, 36000.0)
    # mm: targets and set_position within ±this in x and y
    work_area: float = ranged(100000.0, 1.0, 1000000.0)
    # degree: the largest rotation a move or set_position asks
    turn_limit: float = ranged(3600.0, 1.0, 36000.0)
    jog_timeout: int = ranged(500, 1, 32767)     # ms from the last jog command to the stop
    joy_axis_linear: int = ranged(1, 0, 63)      # sensor_msgs/Joy axis for forward speed …
    joy_axis_angular: int = ranged(0, 0, 63)     # … and for the yaw rate (left stick)
    joy_enable_button: int = ranged(-1, -1, 127)  # a button that must be held (-1: none)
    io_config: str = ""                          # I/O ids (YAML); "" = config/vehicle_io.yaml
    battery_capacity_wh: float = ranged(960.0, 1.0, 1.0e6)  # battery capacity [Wh]
    battery_charge: float = ranged(1.0, 0.0, 1.0)  # state of charge at start-up, 0 … 1
    battery_low_voltage: float = ranged(46.0, 0.0, 1000.0)     # V: warning 110 below
    battery_cutoff_voltage: float = ranged(44.0, 0.0, 1000.0)  # V: fault 201 below (servo off)
    # V: a battery alarm's cause is gone this far above its level
    battery_hysteresis: float = ranged(1.0, 0.0, 100.0)
    stuck_error: float = ranged(100.0, 1.0, 100000.0)  # mm of tracking error …
    stuck_angle: float = ranged(20.0, 0.1, 360.0)  # … or degrees of heading error …
    stuck_time: float = ranged(0.3, 0.0, 10.0)  # … held this long (s): the base is Stuck
    arrival_error: float = ranged(20.0, 0.1, 100000.0)  # mm: a move that ends farther from its target is Stuck …
    arrival_angle: float = ranged(3.0, 0.01, 180.0)  # … or more degrees off its heading


def check_config(c: VehicleConfig) -> None:
    """ValueError unless every ranged field is within its range (the start-up velocity and
    acceleration are checked against the minimums and limits as the setters would, by
    VehicleCore), the battery's cut-off is below its warning level, and a stop from the velocity limit at the acceleration limit takes at most
    MAX_STOP_S, in translation and in rotation."""
    check_ranges(c, "vehicle configuration")
    if not c.battery_cutoff_voltage < c.battery_low_voltage:
        raise ValueError(f"vehicle configuration: battery_cutoff_voltage ({c.battery_cutoff_voltage:g}"
                         f" V) must be below battery_low_voltage ({c.battery_low_voltage:g} V): the "
                         "warning comes before the cut-off")
    for axis, v, a, unit in (
            ("translation", c.velocity_limit_translation, c.accel_limit_translation, "mm/s"),
            ("rotation", c.velocity_limit_rotation, c.accel_limit_rotation, "degree/s")):
        if v / a > MAX_STOP_S:
            raise ValueError(
                f"vehicle configuration: a stop from the {axis} velocity limit ({v:g} {unit}) at "
                f"the acceleration limit ({a:g} {unit}²) would take {v / a:.3g} s: at most "
                f"{MAX_STOP_S:g} s keeps the base stoppable")
