"""Where the base is in `map` (the frame named by position_frame), for Nav2: `initialpose` in,
position_frame → odom out (published with odom → base_link by vehicle_node).

- `localization: odometry` (the default, as before): position_frame → odom is the frame that
  set_position (the spec's setPosition) redefined; the base's pose in it is its dead reckoning.
  A pose on `initialpose` is a set_position.
- `localization: ground_truth`: position_frame → odom is such that the base's pose in it is the
  simulator's true pose (ground-truth localisation: no AMCL needed, and odometry's drift never
  shows in `map`). The map is the world frame at start (identity: the robot starts at the world's
  origin); a pose on `initialpose` says where the base is in the map now, which moves the map
  against the world (as nav2_loopback_sim does). set_position still sets the spec's position
  (get_position), not this transform.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Callable

from geometry_msgs.msg import PoseWithCovarianceStamped
from rclpy.node import Node

from acti_motion.replies import Reply
from acti_motion.vehicle.paths import Pose2D
from acti_sim.world import World

MODES = ("odometry", "ground_truth")


@dataclass
class LocalizationConfig:
    localization: str = "odometry"    # position_frame → odom from set_position ("odometry") or from the simulator's true pose ("ground_truth": what Nav2's loopback simulator gives); initialpose sets it either way


def yaw_of(q: Any) -> float:
    """The yaw of a quaternion message (x, y, z, w)."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class Localization:
    """The map → odom transform of one base, and its `initialpose` subscription."""

    def __init__(self, node: Node, config: LocalizationConfig, map_frame: str,
                 set_position: Callable[[tuple[float, float, float]], Reply], plane: Any) -> None:
        if config.localization not in MODES:
            raise ValueError(f"localization is {config.localization!r}: use one of "
                             f"{', '.join(MODES)}")
        self.ground_truth = config.localization == "ground_truth"
        self.map_frame = map_frame
        self._map_in_world = Pose2D(0.0, 0.0, 0.0)       # the world's pose in the map
        self._truth = Pose2D(0.0, 0.0, 0.0)              # the base's latest true pose (world)
        self._set_position = set_position
        self._log = node.get_logger()
        plane.create_subscription(PoseWithCovarianceStamped, "initialpose", self._on_initial_pose, 10)

    def map_to_odom(self, world: World, odom_pose: Pose2D, odometry_frame: Pose2D) -> Pose2D:
        """The transform to publish: the odometry's frame, or the one that puts the base at its
        true pose in the map (simulation thread)."""
        if not self.ground_truth:
            return odometry_frame
        x, y, yaw = world.base_pose()
        self._truth = Pose2D(x, y, yaw)
        return self._map_in_world.compose(self._truth).compose(odom_pose.inverse())

    def _on_initial_pose(self, msg: PoseWithCovarianceStamped) -> None:
        frame = msg.header.frame_id.lstrip("/")
        if frame not in ("", self.map_frame):
            self._log.warn(f"initialpose ignored: it is in {frame!r}, and the map is "
                           f"{self.map_frame!r}")
            return
        p = msg.pose.pose
        pose = Pose2D(p.position.x, p.position.y, yaw_of(p.orientation))
        if self.ground_truth:
            self._map_in_world = pose.compose(self._truth.inverse())
            return
        reply = self._set_position((1000.0 * pose.x, 1000.0 * pose.y, math.degrees(pose.theta)))
        if not reply.ok:
            self._log.warn(f"initialpose refused (as set_position): {reply.comment}")
