"""The robot in the ROS graph, published by the process that hosts the simulation:
`robot_description` (the URDF the simulation loaded, latched) and, unless `link_tf` is off, the
transform of every link from the measured joints (Pinocchio over the whole URDF): fixed joints
once on /tf_static, movable ones on /tf at the joint_states rate. With `odom → base_link` from
`vehicle_node` that is the whole robot for RViz, with no robot_state_publisher."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

from rclpy.node import Node
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from acti_bringup.serving.parameters import declare_config
from acti_bringup.visual.transforms import LATCHED_QOS, link_transform, static_tf_publisher, tf_publisher
from acti_motion.link_poses import LinkPoses, LinkTransform
from acti_sim.world import World


@dataclass
class RobotGraphConfig:
    link_tf: bool = True    # publish every link's transform (/tf, /tf_static); false when robot_state_publisher does it from robot_description and joint_states


class RobotGraph:
    """robot_description and the links' TF of one hosted simulation."""

    def __init__(self, node: Node, urdf_path: str, rate_hz: float, now: Callable[[], Any],
                 publish_at: Callable[..., None]) -> None:
        """Links on the TF at `rate_hz` by `publish_at` (`Simulation.publish_at`: on the
        simulation thread, while anybody listens)."""
        self.config = declare_config(node, RobotGraphConfig)
        self._now = now
        with open(urdf_path) as f:
            urdf = f.read()
        self._description = node.create_publisher(String, "robot_description", LATCHED_QOS)
        self._description.publish(String(data=urdf))
        if not self.config.link_tf:
            return
        self.links = LinkPoses(urdf_path)
        self._static = static_tf_publisher(node)
        stamp = now()
        self._static.publish(TFMessage(transforms=[
            link_transform(stamp, t) for t in self.links.fixed_transforms()]))
        self._tf = tf_publisher(node)
        # one message, filled in place each time: building it anew cost ten times as much
        self._message = TFMessage(transforms=[
            link_transform(stamp, LinkTransform(j.parent, j.child, (0.0, 0.0, 0.0),
                                                (0.0, 0.0, 0.0, 1.0)))
            for j in self.links.movable])
        publish_at(rate_hz, self._publish_links, self._tf)

    def _publish_links(self, world: World) -> None:
        names, positions, _ = world.joint_states()
        poses = self.links.movable_poses(names, positions).tolist()
        stamp = self._now()
        for msg, (x, y, z, qx, qy, qz, qw) in zip(self._message.transforms, poses):
            msg.header.stamp = stamp
            t, r = msg.transform.translation, msg.transform.rotation
            t.x, t.y, t.z, r.x, r.y, r.z, r.w = x, y, z, qx, qy, qz, qw
        self._tf.publish(self._message)
