"""TF for the nodes: tf2's topics and QoS, and TransformStamped from core values (REP 103: m, rad)."""
from __future__ import annotations

import math
from typing import Any

from geometry_msgs.msg import TransformStamped
from rclpy.node import Node
from rclpy.qos import DurabilityPolicy, QoSProfile
from tf2_msgs.msg import TFMessage

from acti_motion.link_poses import LinkTransform
from acti_motion.vehicle.paths import Pose2D

TF_QOS = QoSProfile(depth=100)                         # tf2_ros.TransformBroadcaster's
LATCHED_QOS = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)


def tf_publisher(node: Node) -> Any:
    return node.create_publisher(TFMessage, "tf", TF_QOS)


def static_tf_publisher(node: Node) -> Any:
    """tf_static: latched, so listeners that start later still get every static transform."""
    return node.create_publisher(TFMessage, "tf_static", LATCHED_QOS)


def link_transform(stamp: Any, t: LinkTransform) -> TransformStamped:
    msg = TransformStamped()
    msg.header.stamp = stamp
    msg.header.frame_id, msg.child_frame_id = t.parent, t.child
    tr, r = msg.transform.translation, msg.transform.rotation
    tr.x, tr.y, tr.z = t.translation
    r.x, r.y, r.z, r.w = t.rotation
    return msg


def planar_transform(stamp: Any, parent: str, child: str, pose: Pose2D,
                     height: float = 0.0) -> TransformStamped:
    """`child` at a floor pose (x, y, yaw) in `parent`, `height` above it."""
    return link_transform(stamp, LinkTransform(
        parent, child, (pose.x, pose.y, height),
        (0.0, 0.0, math.sin(pose.theta / 2), math.cos(pose.theta / 2))))
