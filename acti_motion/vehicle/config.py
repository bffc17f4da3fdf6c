"""The base's start-up settings and limits: the node's parameters (one comment per field is the
parameter's description)."""
from __future__ import annotations

from dataclasses import dataclass


@dataclass
class VehicleConfig:
    """Start-up settings and limits of the base (spec units); the node's parameters."""
    queue_size: int = 32                         # motion queue capacity
    velocity_limit_translation: float = 1000.0   # velocity limit, translation [mm/s]
    velocity_limit_rotation: float = 90.0        # velocity limit, rotation [degree/s]
    accel_limit_translation: float = 1000.0      # acceleration limit, translation [mm/s²]
    accel_limit_rotation: float = 180.0          # acceleration limit, rotation [degree/s²]
    velocity_min_translation: float = 1.0        # mm/s: the slowest velocity setting (set_velocity)
    velocity_min_rotation: float = 0.1           # degree/s: the slowest yaw-rate setting
    accel_min_translation: float = 1.0           # mm/s²: the lowest acceleration setting
    accel_min_rotation: float = 1.0              # degree/s²: the lowest angular acceleration setting
    default_velocity_translation: float = 300.0  # velocity at start-up [mm/s]
    default_velocity_rotation: float = 45.0      # turn rate at start-up [degree/s]
    default_accel_translation: float = 500.0     # acceleration at start-up [mm/s²]
    default_accel_rotation: float = 90.0         # turn acceleration at start-up [degree/s²]
    work_area: float = 100000.0                  # mm: targets and set_position within ±this in x and y
    turn_limit: float = 3600.0                   # degree: the largest rotation a move or set_position asks
    jog_timeout: int = 500                       # ms from the last jog command to the stop
    joy_axis_linear: int = 1                     # sensor_msgs/Joy axis for forward speed …
    joy_axis_angular: int = 0                    # … and for the yaw rate (left stick)
    joy_enable_button: int = -1                  # a button that must be held (-1: none)
    io_config: str = ""                          # I/O ids (YAML); "" = config/vehicle_io.yaml
    battery_capacity_wh: float = 960.0           # battery capacity [Wh]
    battery_charge: float = 1.0                  # state of charge at start-up, 0 … 1
    battery_low_voltage: float = 46.0            # V: warning 110 below
    battery_cutoff_voltage: float = 44.0         # V: fault 201 below (servo off)
    battery_hysteresis: float = 1.0              # V: a battery alarm's cause is gone this far above its level
    stuck_error: float = 100.0                   # mm of tracking error …
    stuck_angle: float = 20.0                    # … or degrees of heading error …
    stuck_time: float = 0.3                      # … held this long (s): the base is Stuck
    arrival_error: float = 20.0                  # mm: a move that ends farther from its target is Stuck …
    arrival_angle: float = 3.0                   # … or more degrees off its heading
