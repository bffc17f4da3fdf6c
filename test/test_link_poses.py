"""ROS-free pieces of the ROS graph: the links' forward kinematics over the whole URDF, and the
wheel odometry's continuous frame and covariance."""
import math

import numpy as np
import pinocchio as pin
import pytest

from acti_motion.arm.core import shared_kinematics
from acti_motion.link_poses import LinkPoses
from acti_motion.vehicle.paths import Odometry, Pose2D
from acti_sim.world import ARM_JOINTS


def test_links_chain_to_the_flange_as_the_arm_kinematics_says():
    links, kin = LinkPoses(), shared_kinematics()
    rng = np.random.default_rng(3)
    fixed = {t.child: (t.parent, t.translation + t.rotation) for t in links.fixed_transforms()}
    for _ in range(20):
        q = rng.uniform(kin.lower, kin.upper)
        names = [*ARM_JOINTS, "gripper_finger_left_joint", "left_wheel_joint"]
        poses = links.movable_poses(names, [*q, 0.02, 7.0])
        tree = dict(fixed)
        tree.update({j.child: (j.parent, p) for j, p in zip(links.movable, poses.tolist())})
        T, frame = pin.SE3.Identity(), "flange"
        while frame != "base_link":
            parent, xyzquat = tree[frame]
            T, frame = pin.XYZQUATToSE3(np.array(xyzquat)) * T, parent
        assert np.allclose(T.homogeneous, kin.flange(q), atol=1e-12)
        wheel = tree["left_wheel"][1]                      # continuous: q holds (cos, sin)
        assert 2 * math.atan2(wheel[4], wheel[6]) == pytest.approx(7.0 - 2 * math.pi)


def test_odometry_stays_continuous_through_a_reset_and_its_covariance_grows():
    odo = Odometry(0.1, 0.5, np.zeros(2))
    wheels = np.zeros(2)
    for _ in range(240):                                   # 1 m straight, with a slight turn
        wheels += [0.0415, 0.0418]
        odo.update(wheels, 1 / 240)
    before, _ = odo.continuous()
    cov = odo.covariance.copy()
    frame = odo.reset(Pose2D(5.0, -2.0, -math.pi / 2))
    after, odom_in_position = odo.continuous()
    assert (after.x, after.y, after.theta) == pytest.approx((before.x, before.y, before.theta))
    assert odom_in_position == frame
    pose = odom_in_position.compose(after)
    assert (pose.x, pose.y, pose.theta) == pytest.approx((5.0, -2.0, -math.pi / 2))
    assert np.all(np.linalg.eigvalsh(cov) > 0) and cov[0, 0] == pytest.approx(1e-7 / 2, rel=0.05)
    for _ in range(240):
        wheels += [0.0415, 0.0418]
        odo.update(wheels, 1 / 240)
    assert np.all(np.diag(odo.covariance) > np.diag(cov))
    assert odo.twist_variance[0] > 0 and odo.v == pytest.approx(1.0, rel=0.01)


def test_the_covariance_propagates_as_the_first_order_matrix_form_says():
    """F P Fᵀ + G Q Gᵀ written out in floats: the same as with the matrices, step by step."""
    from acti_motion.vehicle.paths import WHEEL_VARIANCE_PER_M
    rng = np.random.default_rng(5)
    odo, wheels, P, b = Odometry(0.1, 0.5, np.zeros(2)), np.zeros(2), np.zeros((3, 3)), 0.5
    for _ in range(300):
        theta = odo.pose.theta - odo.frame.theta
        step = rng.normal(0.0, 0.02, 2) + [0.03, 0.01]
        wheels = wheels + step
        odo.update(wheels, 1 / 250)
        dl, dr = step * 0.1
        ds, dth = (dl + dr) / 2, (dr - dl) / b
        c, s, k = math.cos(theta + dth / 2), math.sin(theta + dth / 2), ds / (2 * b)
        F = np.array([[1.0, 0.0, -ds * s], [0.0, 1.0, ds * c], [0.0, 0.0, 1.0]])
        G = np.array([[c / 2 - k * s, c / 2 + k * s], [s / 2 + k * c, s / 2 - k * c],
                      [1 / b, -1 / b]])
        Q = np.diag([WHEEL_VARIANCE_PER_M * abs(dr), WHEEL_VARIANCE_PER_M * abs(dl)])
        P = F @ P @ F.T + G @ Q @ G.T
        assert np.allclose(odo.covariance, P, rtol=1e-9, atol=1e-18)


def test_a_quaternion_from_a_rotation_is_pinocchios_and_leaks_nothing():
    """pin.Quaternion(R) leaked about 80 bytes a call: the arm node's ~/state grew the main job
    by 90 kB a minute, idle."""
    import os
    from acti_motion.arm.poses import quaternion_xyzw

    def rss_kb() -> int:
        with open(f"/proc/{os.getpid()}/status") as f:
            return int(f.read().split("VmRSS:")[1].split()[0])
    rotation = pin.exp3(np.array([0.3, -0.2, 1.1]))
    q = quaternion_xyzw(rotation)
    assert np.allclose(pin.Quaternion(q[3], *q[:3]).matrix(), rotation)
    for _ in range(2000):
        quaternion_xyzw(rotation)
    before = rss_kb()
    for _ in range(50000):
        quaternion_xyzw(rotation)
    assert rss_kb() - before < 1000                     # pin.Quaternion(R): ~3900 kB
