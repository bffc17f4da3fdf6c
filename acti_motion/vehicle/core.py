"""The mobile-base core: the VehicleService operations, without ROS.

Each public method is one IDL operation, named as the ROS service, taking the IDL parameters by
their snake-case names (nested structs as tuples in field order) and returning a `Reply`: a
refusal is `success = false` with the reason as the message, and raises a warning (state
Warning-###) until clearAlarm or the next accepted command. Units are the spec's: mm, degree,
mm/s, degree/s, mm/s², degree/s², ms; the motion layer below works in m, rad, s.

The operations live in three parts, one per thread and lock: control.py (the control path,
under the short state lock), planning.py (the planning path, under the planning lock) and
sensing.py (the simulation thread's step). This module holds the state they share and what
both paths call (`_accepted_motion`).
"""
from __future__ import annotations

import math
import threading

from acti_motion.executor import Device, MotionExecutor
from acti_motion.replies import Refused
from acti_motion.vehicle.alarms import Alarms, Kind
from acti_motion.vehicle.config import VehicleConfig, check_config
from acti_motion.vehicle.control import FIRMWARE_VERSION, IF_VERSION, WHEEL_AXES, Control
from acti_motion.vehicle.cruise import warm_up
from acti_motion.vehicle.obstacles import ObstacleConfig, Obstacles
from acti_motion.vehicle.paths import Odometry
from acti_motion.vehicle.planning import (LOOKAHEAD_GROWTH, LOOKAHEAD_STEPS, PAUSED, PAUSED_DRIVE,
                                          Planning)
from acti_motion.vehicle.refusals import bounded_pair
from acti_motion.vehicle.retiming import Retimer
from acti_motion.vehicle.sensing import Sensing
from acti_motion.vehicle.states import VehicleState
from acti_sim.battery import Battery, BatteryModel, VoltageLevel
from acti_sim.io_module import IoModule

__all__ = ["FIRMWARE_VERSION", "IF_VERSION", "LOOKAHEAD_GROWTH", "LOOKAHEAD_STEPS", "PAUSED",
           "PAUSED_DRIVE", "WHEEL_AXES", "VehicleConfig", "VehicleCore", "VehicleState"]


class VehicleCore(Control, Planning, Sensing, Obstacles):
    """Power, servo, state, alarms, I/O, battery, odometry and the motion queue of the base.

    Two locks: `lock` guards the state for a moment (control operations, checks, commits);
    `planning` lets one planning operation at a time plan, under no lock that the control
    operations or the simulation take. A plan is committed only if the device did not change
    meanwhile (the device's generation and revision), else it is planned again. The control
    path is `Control`, the planning path `Planning`, the simulation thread's step `Sensing`.
    """

    def __init__(self, executor: MotionExecutor, config: VehicleConfig | None = None,
                 obstacles: ObstacleConfig | None = None) -> None:
        self.config = c = config or VehicleConfig()
        check_config(c)
        world = executor.world
        self.lock = threading.RLock()
        self.planning = threading.RLock()
        self.odometry = Odometry(world.wheel_radius, world.wheel_separation, world.wheel_positions())
        self.device: Device = executor.add_device("base", c.queue_size, self.odometry.pose)
        self.alarms = Alarms()
        self.battery = Battery(BatteryModel(capacity_wh=c.battery_capacity_wh), c.battery_charge)
        self._battery_low = VoltageLevel(c.battery_low_voltage, c.battery_hysteresis)
        self._battery_empty = VoltageLevel(c.battery_cutoff_voltage, c.battery_hysteresis)
        self._contact = False
        self.io = IoModule.load(c.io_config, {"bumper": lambda: int(self._contact)})
        self.power = False
        self.servo = False
        self.locked = False
        self.stuck = False
        self.digital_sensor_lock = False
        self._contact_armed = True
        self._stuck_since: float | None = None
        self._drive_deadline = math.inf      # world time at which a jog/joystick drive ends
        self._deadman_fired: int | None = None
        self._op_generation = 0              # the device's generation when the planning operation began
        self._op_arrival = 0                 # the device's `arrival()` when it was called
        self.velocity_bounds = ((c.velocity_min_translation, c.velocity_min_rotation),
                                (c.velocity_limit_translation, c.velocity_limit_rotation))
        self.accel_bounds = ((c.accel_min_translation, c.accel_min_rotation),
                             (c.accel_limit_translation, c.accel_limit_rotation))
        try:                          # the start-up settings obey the rules of the setters
            self.velocity = bounded_pair(
                (c.default_velocity_translation, c.default_velocity_rotation), *self.velocity_bounds,
                "default velocity", ("mm/s", "degree/s"))
            self.acceleration = bounded_pair(
                (c.default_accel_translation, c.default_accel_rotation), *self.accel_bounds,
                "default acceleration", ("mm/s²", "degree/s²"))
        except Refused as r:
            raise ValueError(f"vehicle configuration: {r.comment}") from None
        self.jog_timeout = c.jog_timeout
        self.joystick = False
        self._stick = (0.0, 0.0)             # the last Joy sample's deflections that drove the base
        self._dt = executor.dt
        self._world = world                  # its clock: the job's (the deadman counts it)
        self._init_obstacles(obstacles or ObstacleConfig(), world)
        self.retimer = Retimer(self._retime_to_settings)     # its thread: retimer.start()
        warm_up(self._limits())           # the first request does not pay for first-use costs
        executor.before_step(self._sense)

    def _accepted_motion(self) -> None:
        """Both paths: an accepted motion, and stop, end Stuck (and a pending or running
        detour's Avoid: the detour itself sets it again once queued)."""
        self.stuck = False
        self.avoiding = False
        self.alarms.clear(Kind.STUCK)
