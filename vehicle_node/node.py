"""VehicleNode: the thin ROS adapter of `acti_motion.vehicle.core.VehicleCore`.

Services: one per IDL operation (operations.py). Action: ~/wait_motion (actions.py).
Topics (REP 103: m, rad):
  odom (nav_msgs/Odometry)            wheel odometry, odom → base_link, 50 Hz, with covariances
  /tf (tf2_msgs/TFMessage)            odom → base_link and position_frame → odom, 50 Hz
  ~/ground_truth (nav_msgs/Odometry)  the simulator's true pose of base_link in the world, 50 Hz
  ~/state (acti_msgs/VehicleStatus)   state code and string of table 7 and what makes it, 10 Hz
  /diagnostics (DiagnosticArray)      battery and alarms, 1 Hz
  cmd_vel (geometry_msgs/Twist, in)   a move_jog per message (stops after the jog timeout),
                                      clamped to the unit's limits (said once in the log);
                                      TwistStamped with cmd_vel_stamped
  scan (sensor_msgs/LaserScan)        the laser scanner, frame base_scan (acti_bringup.surroundings)
  map (nav_msgs/OccupancyGrid)        the world file's obstacles, latched
  initialpose (in)                    where the base is in the map (acti_bringup.surroundings.localization)
  joy (sensor_msgs/Joy, in)           drives the base while set_joystick(true)
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from acti_msgs.msg import VehicleStatus
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry
from rclpy.node import Node
from sensor_msgs.msg import Joy
from tf2_msgs.msg import TFMessage

from acti_bringup.serving.adapter import Plane, serve_operations
from acti_bringup.serving.parameters import declare_config
from acti_bringup.serving.spinning import warn_of_namesakes
from acti_bringup.simulation import Simulation
from acti_bringup.surroundings.localization import Localization, LocalizationConfig
from acti_bringup.surroundings.scan import ScanPublisher
from acti_bringup.surroundings.world_map import MapPublisher
from acti_bringup.visual.transforms import planar_transform, tf_publisher
from acti_motion.vehicle.paths import Odometry as WheelOdometry, Pose2D
from acti_motion.replies import Reply
from acti_motion.vehicle import planner
from acti_motion.vehicle.core import VehicleConfig, VehicleCore
from acti_motion.vehicle.alarms import AlarmType
from acti_motion.vehicle.obstacles import ObstacleConfig
from acti_sim.world import World
from vehicle_node.actions import WaitConfig, WaitMotionServer
from vehicle_node.operations import OPERATIONS

ODOM_RATE_HZ = 50.0
STATE_RATE_HZ = 10.0
DIAGNOSTICS_RATE_HZ = 1.0
# The floor is flat: z, roll and pitch are known to 1 mm / 1 mrad, their rates to 1 mm/s, 1 mrad/s;
# a wheel's sideways slip to 1 mm/s. x, y, yaw and the forward and yaw rates come from the wheels.
PLANAR_VARIANCE = 1e-6


@dataclass
class FrameConfig:
    position_frame: str = "map"    # frame of the spec's position (get/set_position); position_frame → odom on /tf is what set_position redefined (rename it if a localizer publishes map → odom)
    odom_tf: bool = True           # publish odom → base_link and position_frame → odom on /tf (false when another node, e.g. a filter, publishes them)
    cmd_vel_stamped: bool = False  # cmd_vel is geometry_msgs/TwistStamped (Nav2's enable_stamped_cmd_vel) instead of Twist (Jazzy's default)


def write_success(response: Any, reply: Reply) -> None:
    response.success = reply.ok
    response.message = reply.comment


def odometry_message(stamp: Any, frame: str, position: tuple[float, float, float],
                     orientation: tuple[float, float, float, float], v: float,
                     w: float) -> Odometry:
    """An Odometry of base_link (position m, quaternion x y z w), without covariances."""
    msg = Odometry()
    msg.header.stamp = stamp
    msg.header.frame_id = frame
    msg.child_frame_id = "base_link"
    p, q = msg.pose.pose.position, msg.pose.pose.orientation
    p.x, p.y, p.z = position
    q.x, q.y, q.z, q.w = orientation
    msg.twist.twist.linear.x = v
    msg.twist.twist.angular.z = w
    return msg


def wheel_odometry_message(stamp: Any, pose: Pose2D, odo: WheelOdometry,
                           height: float) -> Odometry:
    """The continuous dead reckoning in `odom` (base_link `height` above the floor: on the wheel
    axle), with its covariances (row-major 6×6 of x, y, z, roll, pitch, yaw; for the twist: of
    vx, vy, vz and the three rates)."""
    msg = odometry_message(stamp, "odom", (pose.x, pose.y, height),
                           (0.0, 0.0, math.sin(pose.theta / 2), math.cos(pose.theta / 2)),
                           odo.v, odo.w)
    pose_cov = [0.0] * 36
    for (i, j), value in zip(((0, 0), (0, 1), (0, 5), (1, 1), (1, 5), (5, 5)),
                             odo.covariance[[0, 0, 0, 1, 1, 2], [0, 1, 2, 1, 2, 2]]):
        pose_cov[6 * i + j] = pose_cov[6 * j + i] = float(value)
    for k in (2, 3, 4):
        pose_cov[7 * k] = PLANAR_VARIANCE
    var_v, var_w = odo.twist_variance
    twist_cov = [0.0] * 36
    twist_cov[0], twist_cov[35] = var_v + PLANAR_VARIANCE, var_w + PLANAR_VARIANCE
    for k in (1, 2, 3, 4):
        twist_cov[7 * k] = PLANAR_VARIANCE
    msg.pose.covariance, msg.twist.covariance = pose_cov, twist_cov
    return msg


class VehicleNode(Node):
    """`vehicle_node`: hosts its own simulation unless given a shared one."""

    def __init__(self, simulation: Simulation | None = None) -> None:
        super().__init__("vehicle_node")
        self.simulation = simulation or Simulation(self)
        planner.start()        # TOPP-RA plans in a process of their own: the step never waits
        self.core = VehicleCore(self.simulation.executor, declare_config(self, VehicleConfig),
                                declare_config(self, ObstacleConfig))
        self.core.retimer.start()   # set_velocity answers before its re-plan (1.4.32)
        self.motion, self.goals = Plane(self, "motion"), Plane(self, "goals")
        serve_operations(self, self.motion, self.core, OPERATIONS, write_success)
        self.wait_motion = WaitMotionServer(self.goals, self.core, declare_config(self, WaitConfig))
        self.frames = declare_config(self, FrameConfig)
        if self.frames.position_frame in ("", "odom", "base_link"):
            raise ValueError("position_frame must name a frame of its own, not odom or base_link")
        self._odom = self.create_publisher(Odometry, "odom", 10)
        self._tf = tf_publisher(self) if self.frames.odom_tf else None
        self._truth = self.create_publisher(Odometry, "~/ground_truth", 10)
        self._state = self.create_publisher(VehicleStatus, "~/state", 10)
        warn_of_namesakes(self, self._state)
        self._diagnostics = self.create_publisher(DiagnosticArray, "/diagnostics", 10)
        self._cmd_vel_clamped = False
        self._joy_axes_missing = False
        # commands that move the base arrive on the motion plane, like the move services
        if self.frames.cmd_vel_stamped:
            self.motion.create_subscription(TwistStamped, "cmd_vel",
                                            lambda msg: self._on_cmd_vel(msg.twist), 10)
        else:
            self.motion.create_subscription(Twist, "cmd_vel", self._on_cmd_vel, 10)
        self.scan = ScanPublisher(self, self.simulation)
        self.world_map = MapPublisher(self, self.simulation, self.frames.position_frame)
        self.core.know_map(self.world_map.grid)
        self.localization = Localization(self, declare_config(self, LocalizationConfig),
                                         self.frames.position_frame, self.core.set_position,
                                         self.motion)
        self.motion.create_subscription(Joy, "joy", self._on_joy, 10)
        sim = self.simulation
        odometry_out = [p for p in (self._odom, self._truth, self._tf) if p is not None]
        sim.publish_at(ODOM_RATE_HZ, self._publish_odometry, *odometry_out)
        sim.publish_at(STATE_RATE_HZ, self._publish_state, self._state)
        sim.publish_at(DIAGNOSTICS_RATE_HZ, self._publish_diagnostics, self._diagnostics)

    # --- topics in ---------------------------------------------------------------------------
    def _on_cmd_vel(self, msg: Twist) -> None:
        """Clamp to the unit's limits, as ROS base drivers do (a differential drive ignores
        linear.y); say so once. A NaN or infinite linear.x or angular.z is no command: ignored,
        so a running jog ends at its jog timeout, as when commands stop."""
        if not (math.isfinite(msg.linear.x) and math.isfinite(msg.angular.z)):
            self.get_logger().warn(
                f"cmd_vel ignored: linear.x = {msg.linear.x} m/s, angular.z = {msg.angular.z} "
                "rad/s must be finite (a running jog stops at its jog timeout)",
                throttle_duration_sec=2.0)
            return
        x, th, clamped = self.core.clamp_velocity(1000.0 * msg.linear.x, math.degrees(msg.angular.z))
        if (clamped or msg.linear.y != 0.0) and not self._cmd_vel_clamped:
            self._cmd_vel_clamped = True
            limits = self.core.config
            self.get_logger().info(
                f"cmd_vel is clamped to the unit's limits (±{limits.velocity_limit_translation:g} "
                f"mm/s, ±{limits.velocity_limit_rotation:g} degree/s) and linear.y is ignored "
                "(differential drive); this is logged once")
        reply = self.core.move_jog(x_vel=x, y_vel=0.0, theta_vel=th)
        if not reply.ok:
            self.get_logger().warn(f"cmd_vel refused: {reply.comment}", throttle_duration_sec=2.0)

    def _on_joy(self, msg: Joy) -> None:
        c = self.core.config
        if max(c.joy_axis_linear, c.joy_axis_angular) >= len(msg.axes) and not self._joy_axes_missing:
            self._joy_axes_missing = True
            self.get_logger().warn(
                f"joy has {len(msg.axes)} axes, and joy_axis_linear {c.joy_axis_linear} or "
                f"joy_axis_angular {c.joy_axis_angular} is not one of them: that axis reads as "
                "centred (0); set the parameter to this joystick's axis (this is logged once)")
        self.core.joy_input(list(msg.axes), list(msg.buttons))

    # --- topics out (simulation thread) -------------------------------------------------------
    def _publish_odometry(self, world: World) -> None:
        odo, stamp = self.core.odometry, self.simulation.now()
        pose, frame = odo.continuous()
        self._odom.publish(wheel_odometry_message(stamp, pose, odo, world.wheel_radius))
        if self._tf is not None:
            self._tf.publish(TFMessage(transforms=[
                planar_transform(stamp, "odom", "base_link", pose, world.wheel_radius),
                planar_transform(stamp, self.frames.position_frame, "odom",
                                 self.localization.map_to_odom(world, pose, frame))]))
        v, w = world.base_twist()
        self._truth.publish(odometry_message(stamp, "world", *world.base_link_pose(), v, w))

    def _publish_state(self, world: World) -> None:
        core = self.core
        s = core.state()
        motion_id = core.device.status()[0]
        self._state.publish(VehicleStatus(
            stamp=self.simulation.now(), state=int(s), msg=core.state_string(s), power=core.power,
            servo=core.servo, joystick=core.joystick, digital_sensor_lock=core.digital_sensor_lock,
            queue_length=core.device.queue_length, motion_id=motion_id,
            battery_voltage=core.battery.voltage, num_of_active_alarm=len(core.alarms.active())))

    def _publish_diagnostics(self, world: World) -> None:
        """Entries named like diagnostic_updater's ("vehicle_node: battery"), with the robot's
        namespace in front ("robot1/vehicle_node: …", hardware "robot1/base"): /diagnostics is
        the fleet's one topic, and an aggregator keys on the names."""
        core, c = self.core, self.core.config
        robot = self.get_namespace().strip("/")
        name, hardware = (f"{robot}/{self.get_name()}", f"{robot}/base") if robot else \
            (self.get_name(), "base")
        volts = core.battery.voltage
        battery = DiagnosticStatus(
            name=f"{name}: battery", hardware_id=hardware,
            level=(DiagnosticStatus.ERROR if volts < c.battery_cutoff_voltage else
                   DiagnosticStatus.WARN if volts < c.battery_low_voltage else DiagnosticStatus.OK),
            message=f"{volts:.1f} V", values=[
                KeyValue(key="voltage [V]", value=f"{volts:.2f}"),
                KeyValue(key="charge [%]", value=f"{100.0 * core.battery.charge:.1f}"),
                KeyValue(key="power [W]", value=f"{core.battery.power:.0f}")])
        active = core.alarms.active()
        faults = [a for a in active if a.type == AlarmType.FAULT]
        alarms = DiagnosticStatus(
            name=f"{name}: alarms", hardware_id=hardware,
            level=(DiagnosticStatus.ERROR if faults else
                   DiagnosticStatus.WARN if active else DiagnosticStatus.OK),
            message=core.state_string(core.state()),
            values=[KeyValue(key=str(a.code), value=f"{a.type.name}: {a.source}") for a in active])
        msg = DiagnosticArray(status=[battery, alarms])
        msg.header.stamp = self.simulation.now()
        self._diagnostics.publish(msg)
