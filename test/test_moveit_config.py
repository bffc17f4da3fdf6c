"""config/moveit/: the files parse, the SRDF names only joints and links the URDF has, `home` is
go_home's posture, the limits and controllers are the node's, and every file is what
tools/moveit_config.py writes now (so none lags the URDF or the defaults)."""
from __future__ import annotations

import importlib.util
import math
import os
import xml.etree.ElementTree as ET

import pytest
import yaml

from acti_middle_node.gripper_controller import GripperConfig
from acti_middle_node.trajectory_controller import ControllerConfig
from acti_motion.arm.settings import ArmConfig
from acti_sim.world import ARM_JOINTS, URDF_PATH

ROOT = os.path.join(os.path.dirname(__file__), "..")
FOLDER = os.path.join(ROOT, "config", "moveit")
spec = importlib.util.spec_from_file_location("moveit_config",
                                              os.path.join(ROOT, "tools", "moveit_config.py"))
tool = importlib.util.module_from_spec(spec)
spec.loader.exec_module(tool)

URDF = ET.parse(URDF_PATH).getroot()
URDF_JOINTS = {j.get("name"): j for j in URDF.findall("joint")}
URDF_LINKS = {link.get("name") for link in URDF.findall("link")}


def read(name):
    with open(os.path.join(FOLDER, name)) as f:
        return f.read()


SRDF = ET.fromstring(read("acti_ros2.srdf"))


def test_the_files_are_what_the_tool_writes_now():
    for name, text in tool.files().items():
        assert read(name) == text, f"config/moveit/{name} is stale: run tools/moveit_config.py"


def test_the_srdf_names_only_urdf_joints_and_links():
    joints = {e.get("name") for e in SRDF.iter("joint")}
    links = ({e.get("name") for e in SRDF.iter("link")}
             | {e.get(k) for e in SRDF.iter("disable_collisions") for k in ("link1", "link2")}
             | {e.get(k) for e in SRDF.iter("chain") for k in ("base_link", "tip_link")}
             | {e.get("parent_link") for e in SRDF.iter("end_effector")})
    assert joints <= set(URDF_JOINTS) and links <= URDF_LINKS
    assert {g.get("name") for g in SRDF.iter("group")} == {"arm", "gripper"}
    reasons = {e.get("reason") for e in SRDF.iter("disable_collisions")}
    assert {"Adjacent", "Never"} <= reasons


def test_home_is_go_homes_posture():
    home = next(s for s in SRDF.iter("group_state") if s.get("name") == "home")
    values = {j.get("name"): float(j.get("value")) for j in home.iter("joint")}
    assert list(values) == list(ARM_JOINTS)
    assert list(values.values()) == pytest.approx(
        [math.radians(q) for q in ArmConfig().home_joints_deg], abs=1e-6)


def test_limits_are_the_urdfs_speeds_and_the_arms_accelerations():
    limits = yaml.safe_load(read("joint_limits.yaml"))["joint_limits"]
    for name in ARM_JOINTS:
        speed = float(URDF_JOINTS[name].find("limit").get("velocity"))
        assert limits[name]["max_velocity"] == speed
        assert limits[name]["max_acceleration"] == pytest.approx(
            speed / ArmConfig().min_accel_time_joint, rel=1e-6)


def test_the_controllers_are_the_nodes():
    manager = yaml.safe_load(read("moveit_controllers.yaml"))["moveit_simple_controller_manager"]
    arm, gripper = ControllerConfig().controller_name, GripperConfig().gripper_controller_name
    assert manager["controller_names"] == [arm, gripper]
    assert manager[arm]["joints"] == list(ARM_JOINTS)
    assert manager[arm]["action_ns"] == "follow_joint_trajectory"
    assert manager[gripper]["type"] == "GripperCommand"
    assert yaml.safe_load(read("kinematics.yaml"))["arm"]["kinematics_solver"]
