"""The base's obstacle behaviour (VehicleService table 7 and setVelocity's note), on the
simulation thread each step while the base translates. A part of VehicleCore, kept apart for its
one job; the world's geometry comes from ray casts (`ObstacleWatch`), not from the scan topic.

- Caution zone: `caution_distance` ahead of the footprint in the direction of travel. setVelocity:
  「障害物警戒時の速度は，本メソッドで設定した値とメソッド setCautionVelocity()で設定した値の
  最小値に制限されます」: while an obstacle is in it the speed is at most min(the velocity setting,
  `caution_velocity`); setCautionVelocity is not in the IDL, so the caution velocity is a
  parameter, bounded as setVelocity bounds a velocity. The limit slows the motion's clock, so the
  base keeps its path.
- Stop zone: `stop_distance` beyond the braking distance at the present speed. Table 7, 0x014
  Stuck 「障害物検知・停止状態」: an obstacle there stops the base at the acceleration limit (as
  stop does: the queue is discarded) and the base is Stuck, with alarm 121 giving the obstacle's
  range and bearing from base_link.
- How Stuck ends: table 7 marks Alarm and Locked 「解除指令受信まで動作指令拒否」 and Stuck not, so
  Stuck refuses no motion by itself: clear_alarm (1.4.1 「発生した全てのアラームを解除」) ends it,
  and so does stop or a motion the state accepts (a jog or cmd_vel backwards, a move away). A
  motion that heads into the stop zone again is stopped again at once: Stuck again.
- Avoid (table 7, 0x016 「障害物回避動作中」), with `avoid_obstacles`: a move to a target (not a jog,
  cmd_vel or the joystick) that meets an obstacle in its stop zone stops as above, and the base
  then detours on the known map (the world file's grid, `detour`) to the move's target: state
  Avoid from the stop to the detour's end. The moves queued behind are discarded with the
  blocked one, as a stop does. No detour on the map, or a detour blocked in turn: Stuck.
- Turning in place sweeps no zone ahead and is not watched; an arc is watched along its
  heading (the zone is straight ahead, not along the curve).
"""
from __future__ import annotations

import math
import threading
import time
from dataclasses import dataclass
from typing import Any

import numpy as np

from acti_motion.config_fields import check_ranges, ranged
from acti_motion.executor import Device
from acti_motion.vehicle.alarms import AlarmCode, Kind
from acti_motion.vehicle.detour import plan_detour
from acti_motion.vehicle.paths import BrakeMotion, Chain, Pose2D, straight_to, wrap_angle
from acti_motion.vehicle.states import SERVO_ON
from acti_sim.surroundings.occupancy import Grid
from acti_sim.world import World

AVOID = "avoid"          # the detour's motion label
REST_WAIT_S = 30.0       # the longest wait for the stop before a detour (wall time)
DETOUR_MARGIN = 0.05     # kept beyond the footprint's circumscribed circle on the map [m]
RAYS = 9                 # parallel rays across the footprint's width
RAY_HEIGHT = 0.1         # above base_link (the wheel axle): the middle of the base's body [m]
RAY_BACKSET = 0.05       # rays start this far inside the footprint: one touching still sees [m]
LOOK_AHEAD_S = 0.2       # a motion starting from rest: its direction this far ahead
MOVING = 1e-4            # [m/s] slower is no translation


@dataclass
class ObstacleConfig:
    """The obstacle zones (spec units: mm, mm/s); parameters of vehicle_node."""
    # mm ahead of the footprint (in the direction of travel) where the speed is limited to the caution velocity; 0: no caution zone
    caution_distance: float = ranged(800.0, 0.0, 10000.0)
    # mm the base keeps from an obstacle: it stops when one is within this plus its braking distance (Stuck); 0 with caution_distance 0: no obstacle watch
    stop_distance: float = ranged(100.0, 0.0, 5000.0)
    # mm/s: the speed limit in the caution zone, with the velocity setting's (the lower wins); bounded as set_velocity's translation
    caution_velocity: float = ranged(200.0, 0.1, 10000.0)
    avoid_obstacles: bool = False   # a move to a target whose way is blocked detours around the obstacle on the world's map (state Avoid); no detour: Stuck


@dataclass(frozen=True)
class Sighting:
    """The nearest obstacle ahead: its gap to the footprint and, from base_link, its range and
    bearing (m, rad)."""
    gap: float
    range: float
    bearing: float


class ObstacleWatch:
    """Parallel rays from the footprint's front (or back) edge along the direction of travel."""

    def __init__(self, footprint: tuple[float, float, float, float]) -> None:
        self.footprint = footprint
        self._across = np.linspace(footprint[2], footprint[3], RAYS)

    def look(self, world: World, forward: bool, reach: float) -> Sighting | None:
        """The nearest obstacle within `reach` metres of the footprint's edge, or None."""
        (px, py, pz), _ = world.base_link_pose()
        yaw = world.base_pose()[2]
        sign = 1.0 if forward else -1.0
        edge = (self.footprint[1] if forward else -self.footprint[0]) - RAY_BACKSET
        c, s = math.cos(yaw), math.sin(yaw)
        ahead = np.array([sign * c, sign * s, 0.0])
        left = np.array([-s, c, 0.0])
        origins = (np.array([px, py, pz + RAY_HEIGHT]) + sign * edge * np.array([c, s, 0.0])
                   + self._across[:, None] * left)
        length = reach + RAY_BACKSET
        fractions = world.cast_rays(origins.tolist(), (origins + length * ahead).tolist())
        i = int(np.argmin(fractions))
        if fractions[i] >= 1.0:
            return None
        along = fractions[i] * length
        x, y = sign * (edge + along), self._across[i]          # the hit, in base_link
        return Sighting(max(0.0, along - RAY_BACKSET), math.hypot(x, y), math.atan2(y, x))


class Obstacles:
    """The obstacle part of VehicleCore (mixed in; uses its attributes)."""

    config: Any
    obstacle_config: ObstacleConfig
    device: Device

    def _init_obstacles(self, config: ObstacleConfig, world: World) -> None:
        """Check the zones (the caution velocity as set_velocity would) and build the watch."""
        check_ranges(config, "vehicle configuration")
        lo, hi = self.velocity_bounds[0][0], self.velocity_bounds[1][0]
        if not lo <= config.caution_velocity <= hi:
            raise ValueError(f"vehicle configuration: caution_velocity is "
                             f"{config.caution_velocity:g} mm/s: as set_velocity, it must be within "
                             f"{lo:g} … {hi:g} mm/s")
        self.obstacle_config = config
        self.sighting: Sighting | None = None     # the latest one in a zone (for the view)
        self._capped = False
        on = config.caution_distance > 0 or config.stop_distance > 0
        self._obstacle_watch = ObstacleWatch(world.footprint) if on else None
        x0, x1, y0, y1 = world.footprint
        self._radius = max(math.hypot(x, y) for x in (x0, x1) for y in (y0, y1))
        self.avoiding = False                     # state Avoid: stopping for a detour, or on it
        self._detour_id: int | None = None
        self._known_map: Grid | None = None
        self._rest_truth = Pose2D(0.0, 0.0, 0.0)  # the true pose while a detour waits (world)

    @property
    def obstacle_watched(self) -> bool:
        """Whether any zone is on."""
        return self._obstacle_watch is not None

    def know_map(self, grid: Grid) -> None:
        """The map detours are planned on (the world file's obstacles, in the world frame)."""
        self._known_map = grid

    def zones(self, speed: float) -> tuple[float, float]:
        """(caution, stop) zone lengths ahead of the footprint at `speed` (m/s) [m]."""
        c = self.obstacle_config
        a = self.config.accel_limit_translation / 1000.0
        stop = c.stop_distance / 1000.0 + speed * speed / (2 * a) + 2 * speed * self._dt
        return c.caution_distance / 1000.0, stop

    def _watch_obstacles(self, world: World) -> None:
        """Each step: limit the speed in the caution zone, stop and go Stuck in the stop zone."""
        watch, device = self._obstacle_watch, self.device
        cur = device.current
        if watch is None or not world.obstacles:
            return
        if self.avoiding and self._detour_id is not None and device.retired_id >= self._detour_id:
            self.avoiding, self._detour_id = False, None          # the detour is over
        if self.avoiding and self._detour_id is None:
            self._rest_truth = Pose2D(*world.base_pose())        # for the detour's planning
        if (cur is None or device.stopping or isinstance(cur.motion, BrakeMotion)
                or not hasattr(cur.motion, "reference_twist")):
            self._lift_cap()
            return
        v_now = cur.motion.reference_twist(device.t)[0]
        v_next = cur.motion.reference_twist(device.t + LOOK_AHEAD_S)[0]
        v_ref = v_now if abs(v_now) > MOVING else v_next
        if abs(v_ref) <= MOVING:
            self._lift_cap()
            return
        speed = abs(self.odometry.v)
        caution, stop = self.zones(speed)
        sight = watch.look(world, v_ref > 0, max(caution, stop))
        self.sighting = sight
        if sight is not None and sight.gap <= stop:
            self._stop_for(sight, reversing=v_ref < 0)
        elif sight is not None and sight.gap <= caution:
            c = self.obstacle_config
            limit = min(c.caution_velocity, self.velocity[0]) / 1000.0
            reference = max(abs(v_now), abs(v_next))
            a = self.config.accel_limit_translation / 1000.0
            device.cap_rate(min(1.0, limit / reference), reference / a)
            self._capped = True
        else:
            self._lift_cap()

    def _lift_cap(self) -> None:
        if self._capped:
            self._capped = False
            a = self.acceleration[0] / 1000.0
            cur = self.device.current
            v = abs(cur.motion.reference_twist(self.device.t)[0]) if cur is not None and hasattr(
                cur.motion, "reference_twist") else 0.0
            self.device.cap_rate(1.0, max(v, MOVING) / a)

    def _stop_for(self, sight: Sighting, reversing: bool) -> None:
        """Stop at the acceleration limit; then a detour (Avoid) where one is allowed, else
        Stuck with alarm 121 giving the obstacle's range and bearing."""
        cur = self.device.current
        where = (f"obstacle {1000 * sight.gap:.0f} mm from the base (range "
                 f"{1000 * sight.range:.0f} mm, bearing {math.degrees(sight.bearing):.1f}° from "
                 "base_link)")
        with self.lock:
            self._lift_cap()
            if (self.obstacle_config.avoid_obstacles and self._known_map is not None
                    and cur is not None and cur.label not in (AVOID, "move_jog", "joystick")):
                goal = cur.motion.at(cur.motion.duration)
                self.avoiding, self._detour_id = True, None
                self._stop("an obstacle in the stop zone: a detour follows (Avoid)")
                threading.Thread(target=self._detour, args=(goal, where, reversing), daemon=True,
                                 name="acti-detour").start()
                return
            self._go_stuck(f"{where}: stopped")

    def _go_stuck(self, what: str) -> None:
        """Stuck with alarm 121 (the lock held); clear_alarm or a motion away ends it."""
        self.avoiding, self._detour_id = False, None
        self.stuck = True
        self.alarms.raise_(AlarmCode.OBSTACLE,
                           f"{what}; clear_alarm, or a motion away from it, ends Stuck", Kind.STUCK)
        self._stop("an obstacle in the stop zone (the base is Stuck)")

    def _detour(self, goal: Pose2D, where: str, reversing: bool) -> None:
        """Off the simulation thread: once the base is at rest, plan the detour to `goal`
        (odometry frame) and queue it; none: Stuck."""
        device, deadline = self.device, time.monotonic() + REST_WAIT_S
        while device.busy and self.avoiding and time.monotonic() < deadline:
            time.sleep(0.01)
        at_rest = self._world.time
        while self._world.time <= at_rest + self._dt and self.avoiding \
                and time.monotonic() < deadline:
            time.sleep(0.005)             # a step at rest records the true pose (`_rest_truth`)
        with self.planning_operation():
            if not self.avoiding or device.busy:
                return                      # a stop or another command came meanwhile
            rest = device.hold
            odom_in_world = self._rest_truth.compose(rest.inverse())
            start = odom_in_world.compose(rest)
            target = odom_in_world.compose(goal)
            points = plan_detour(self._known_map, start, target, self._radius + DETOUR_MARGIN,
                                 reversing)
            if points is None:
                with self.lock:
                    self._go_stuck(f"{where}: stopped, and the map has no way around it from "
                                   f"({start.x:.2f}, {start.y:.2f}) to ({target.x:.2f}, "
                                   f"{target.y:.2f}) m")
                return
            world_to_odom = odom_in_world.inverse()
            legs = [world_to_odom.compose(Pose2D(x, y, 0.0)) for x, y in points]
            limits = self._limits()

            def plan(start: Pose2D) -> Chain:
                paths, here = [], start
                for leg in legs[:-1]:
                    heading = math.atan2(leg.y - here.y, leg.x - here.x)
                    if abs(wrap_angle(heading - here.theta)) > math.pi / 2:
                        heading += math.pi                          # reached backwards
                    stop = Pose2D(leg.x, leg.y, here.theta + wrap_angle(heading - here.theta))
                    paths.append(straight_to(here, stop, limits, False))
                    here = stop
                paths.append(straight_to(here, goal, limits, True))
                return Chain(paths, start)
            try:
                motion_id = self._submit(plan, AVOID, SERVO_ON).get("motion_id")
            except Exception as e:        # refused (the state changed): Stuck says why
                with self.lock:
                    self._go_stuck(f"{where}: stopped, and the detour was refused: {e}")
                return
            with self.lock:
                self.avoiding, self._detour_id = True, motion_id
