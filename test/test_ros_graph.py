"""The robot in the ROS graph, over DDS against the main job: robot_description (late joiners
get it), /tf + /tf_static of the standard type (Jazzy's type hash) holding every link, agreeing
with the arm's and the base's own feedback; /odom continuous across set_position; the camera."""
import math
import os

import numpy as np
import pinocchio as pin
import pytest
from acti_msgs import srv
from acti_msgs.msg import VehiclePosition
from nav_msgs.msg import Odometry
from rclpy.qos import DurabilityPolicy, QoSProfile
from sensor_msgs.msg import CameraInfo, Image
from std_msgs.msg import String
from tf2_msgs.msg import TFMessage

from acti_motion.link_poses import urdf_joints
from acti_sim.world import URDF_PATH
from ros_harness import node_fixture, wait_until

# Jazzy's tf2_msgs/msg/TFMessage, as generated code built against a ROS 2 Jazzy install states it
TF_MESSAGE_HASH = "RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087"
ARM, BASE = "/acti_middle_node/", "/vehicle_node/"
CAMERA = (160, 120)
LATCHED = QoSProfile(depth=1, durability=DurabilityPolicy.TRANSIENT_LOCAL)
STATIC = QoSProfile(depth=100, durability=DurabilityPolicy.TRANSIENT_LOCAL)   # tf2's

robot = node_fixture("acti_bringup", "camera_rate_hz:=4.0", f"camera_width:={CAMERA[0]}",
                     f"camera_height:={CAMERA[1]}")


@pytest.fixture(scope="module")
def tf(ros, robot):
    """Every transform heard on /tf and /tf_static: child frame → (parent, 4×4), the latest."""
    tree: dict[str, tuple[str, np.ndarray]] = {}

    def hear(msg: TFMessage) -> None:
        for t in msg.transforms:
            r, p = t.transform.rotation, t.transform.translation
            T = np.eye(4)
            T[:3, :3] = pin.Quaternion(r.w, r.x, r.y, r.z).toRotationMatrix()
            T[:3, 3] = p.x, p.y, p.z
            tree[t.child_frame_id] = (t.header.frame_id, T)
    subs = [ros.node.create_subscription(TFMessage, "/tf", hear, 100),
            ros.node.create_subscription(TFMessage, "/tf_static", hear, STATIC)]
    yield tree
    for s in subs:
        ros.node.destroy_subscription(s)


def lookup(tree: dict, parent: str, child: str) -> np.ndarray:
    """child's pose in parent, walking up the tree from child."""
    T = np.eye(4)
    frame = child
    while frame != parent:
        up, rel = tree[frame]
        T, frame = rel @ T, up
    return T


def hg(values) -> np.ndarray:
    T = np.eye(4)
    T[:3, :] = np.reshape(values, (3, 4))
    T[:3, 3] /= 1000.0
    return T


def test_robot_description_reaches_a_late_subscriber(ros, robot):
    ros.call(srv.GetState, ARM + "get_state")          # the node has long published it
    got = []
    sub = ros.node.create_subscription(String, "/robot_description", got.append, LATCHED)
    try:
        assert ros.spin_until(lambda: got, 10.0)
        with open(URDF_PATH) as f:
            assert got[0].data == f.read()
    finally:
        ros.node.destroy_subscription(sub)


def test_tf_is_the_standard_type_with_jazzys_hash(ros, robot, tf):
    assert wait_until(lambda: len(ros.node.get_publishers_info_by_topic("/tf")) >= 2, 10.0)
    for topic in ("/tf", "/tf_static"):
        infos = ros.node.get_publishers_info_by_topic(topic)
        assert infos and {i.topic_type for i in infos} == {"tf2_msgs/msg/TFMessage"}
        assert {str(i.topic_type_hash) for i in infos} == {TF_MESSAGE_HASH}


def test_tf_holds_every_link_and_agrees_with_the_feedback(ros, robot, tf):
    call = ros.call
    assert call(srv.ServoON, ARM + "servo_on").return_id.id == 0
    assert call(srv.SetSpeedJoint, ARM + "set_speed_joint", spd_ratio=100).return_id.id == 0
    # both port offsets: the feedback is the control point (tool) in the robot frame (base)
    base = [1, 0, 0, 20.0, 0, 1, 0, -10.0, 0, 0, 1, 30.0]
    c, s = math.cos(0.3), math.sin(0.3)
    tool = [c, -s, 0, 5.0, s, c, 0, 0.0, 0, 0, 1, 120.0]
    assert call(srv.SetBaseOffset, ARM + "set_base_offset", offset=base).return_id.id == 0
    assert call(srv.SetControlPointOffset, ARM + "set_control_point_offset",
                offset=tool).return_id.id == 0
    move = call(srv.MovePTPJointAbs, ARM + "move_ptp_joint_abs",
                joint_points=[20.0, 30.0, -10.0, -70.0, 15.0, 50.0, 40.0])
    assert move.return_id.id == 0
    assert call(srv.VehicleSetPower, BASE + "set_power", on_off=True).success
    assert call(srv.VehicleSetServo, BASE + "set_servo", on_off=True).success
    assert call(srv.VehicleMoveLinearAbs, BASE + "move_linear_abs",
                pos=VehiclePosition(x=300.0, y=200.0, theta=30.0)).success
    assert wait_until(lambda: call(srv.GetState, ARM + "get_state").state & 0x02 == 0
                      and call(srv.VehicleGetState, BASE + "get_state").state == 0x010
                      and at(call(srv.VehicleGetPosition, BASE + "get_position").pos,
                             (300.0, 200.0, 30.0), 5.0), 60.0)
    assert ros.spin_until(lambda: {"flange", "base_link"} <= tf.keys(), 10.0)

    links = {j.child for j in urdf_joints(open(URDF_PATH).read())}
    assert links <= tf.keys(), f"missing links: {links - tf.keys()}"
    assert tf["base_link"][0] == "odom" and tf["odom"][0] == "map"

    def control_point_error() -> tuple[float, float]:
        flange = lookup(tf, "base_link", "flange")
        want = np.linalg.inv(hg(base)) @ flange @ hg(tool)
        got = hg(call(srv.GetFeedbackPosCartesian, ARM + "get_feedback_pos_cartesian").pos.car_pos)
        return np.abs(got[:3, 3] - want[:3, 3]).max(), np.abs(got[:3, :3] - want[:3, :3]).max()
    assert agrees(ros, control_point_error, (1e-4, 1e-6)), control_point_error()   # 0.1 mm
    assert agrees(ros, lambda: position_error(ros, tf), POSITION_BOUND), position_error(ros, tf)


def test_odom_does_not_jump_on_set_position(ros, robot, tf):
    odom = []
    sub = ros.node.create_subscription(Odometry, "/odom", odom.append, 10)
    try:
        assert ros.spin_until(lambda: len(odom) >= 3, 10.0)
        before = odom[-1].pose.pose.position
        assert ros.call(srv.VehicleSetPosition, BASE + "set_position",
                        pos=VehiclePosition(x=5000.0, y=-2000.0, theta=-90.0)).success
        seen = len(odom)
        assert ros.spin_until(lambda: len(odom) >= seen + 10, 10.0)
        after = odom[-1].pose.pose.position
        assert math.hypot(after.x - before.x, after.y - before.y) < 1e-3        # at rest: no jump
        cov = np.reshape(odom[-1].pose.covariance, (6, 6))
        assert np.all(np.diag(cov) > 0) and np.allclose(cov, cov.T)
        assert np.all(np.linalg.eigvalsh(cov) > 0)
    finally:
        ros.node.destroy_subscription(sub)
    # the redefinition is map → odom: map → base_link is the new position
    assert agrees(ros, lambda: position_error(ros, tf), POSITION_BOUND), position_error(ros, tf)
    assert at(ros.call(srv.VehicleGetPosition, BASE + "get_position").pos,
              (5000.0, -2000.0, -90.0), 1.0)


# map → base_link against get_position: 0.1 mm, and 0.01° (the base at rest still creeps a
# little on its casters, and /tf is a sample of up to 20 ms ago)
POSITION_BOUND = (1e-4, 0.01)


def position_error(ros, tree: dict) -> tuple[float, float]:
    """(m, degree) between map → base_link on /tf and get_position."""
    pose = lookup(tree, "map", "base_link")
    p = ros.call(srv.VehicleGetPosition, BASE + "get_position").pos
    turn = math.degrees(math.atan2(pose[1, 0], pose[0, 0])) - p.theta
    return (math.hypot(pose[0, 3] - p.x / 1000.0, pose[1, 3] - p.y / 1000.0),
            abs((turn + 180.0) % 360.0 - 180.0))


def agrees(ros, error, bound: tuple[float, ...], timeout: float = 10.0) -> bool:
    """error() within bound once the /tf messages in flight are in (a loaded client lags)."""
    return ros.spin_until(lambda: all(e < b for e, b in zip(error(), bound)), timeout)


def at(pos, want: tuple[float, float, float], mm: float) -> bool:
    return math.hypot(pos.x - want[0], pos.y - want[1]) < mm and abs(pos.theta - want[2]) < 0.5


def test_camera_publishes_rgb_images_of_the_work_cell(ros, robot, tf):
    images, infos = [], []
    subs = [ros.node.create_subscription(Image, ARM + "camera/image_raw", images.append, 2),
            ros.node.create_subscription(CameraInfo, ARM + "camera/camera_info", infos.append, 2)]
    try:
        assert ros.spin_until(lambda: images and infos, 15.0)
    finally:
        for s in subs:
            ros.node.destroy_subscription(s)
    image, info = images[-1], infos[-1]
    width, height = CAMERA
    assert (image.encoding, image.width, image.height, image.step) == ("rgb8", width, height,
                                                                       3 * width)
    assert len(image.data) == 3 * width * height
    pixels = np.frombuffer(bytes(image.data), np.uint8).reshape(height, width, 3)
    assert pixels.std() > 10                                    # a scene, not a blank frame
    assert (info.width, info.height) == CAMERA and info.header.frame_id == image.header.frame_id
    assert info.k[2] == pytest.approx(width / 2 - 0.5) and info.k[0] == info.k[4] > 0
    assert ros.spin_until(lambda: image.header.frame_id in tf, 5.0)


@pytest.mark.skipif(os.geteuid() != 0, reason="the job's niceness -10 needs root")
def test_the_renderer_runs_below_the_control_loop(robot):
    """The render process (a child of the job) at niceness 0: its frames may wait, the robot not."""
    def children(pid: int) -> list[int]:
        tasks = f"/proc/{pid}/task"
        return [int(c) for t in os.listdir(tasks)
                for c in open(f"{tasks}/{t}/children").read().split()]

    def nice(pid: int) -> int:
        with open(f"/proc/{pid}/stat") as f:
            return int(f.read().rsplit(")", 1)[1].split()[16])
    def spawned() -> list[int]:           # python -c "from multiprocessing.spawn import …"
        return [c for c in children(robot.proc.pid)
                if b"spawn_main" in open(f"/proc/{c}/cmdline", "rb").read()]
    # spawned at -10 like every thread of the job, it lowers itself once it runs (the base's
    # planner, spawned too, goes lower still: acti_motion/vehicle/planner.py)
    assert wait_until(lambda: 0 in [nice(c) for c in spawned()]
                      and min(nice(c) for c in spawned()) >= 0, 30.0)
    assert nice(robot.proc.pid) == -10
