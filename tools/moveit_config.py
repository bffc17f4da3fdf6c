"""Write config/moveit/ (the MoveIt 2 configuration of the arm) from the URDF and the nodes'
defaults: `python tools/moveit_config.py [folder]`. test_moveit_config.py checks that the files
in the repository are what this writes, so they follow the URDF and the defaults.

- acti_ros2.srdf: groups `arm` (arm_base_link … tool_center_point) and `gripper`, the end
  effector, the states `home` (go_home's posture, home_joints_deg), `open` and `closed`, and the
  collision pairs MoveIt may skip, found as MoveIt Setup Assistant finds them: links joined by a
  joint (Adjacent), in contact in the start posture (Default), in contact in nearly every or no
  sampled posture (Always, Never). Contacts come from PyBullet over SAMPLES random postures.
- kinematics.yaml: KDL for `arm`.
- joint_limits.yaml: the URDF's speeds, and accelerations as the arm allows them (rated speed /
  min_accel_time_joint).
- moveit_controllers.yaml: the simple controller manager on arm_controller and gripper_controller.
"""
from __future__ import annotations

import math
import os
import sys
import xml.etree.ElementTree as ET
from itertools import combinations

import numpy as np
import pybullet
import yaml

from acti_middle_node.gripper_controller import GripperConfig
from acti_middle_node.trajectory_controller import ControllerConfig
from acti_motion.arm.settings import ArmConfig
from acti_sim.world import ARM_JOINTS, GRIPPER_JOINTS, URDF_PATH

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
FOLDER = os.path.join(ROOT, "config", "moveit")
ROBOT = "acti_ros2"
ARM_CHAIN = ("arm_base_link", "tool_center_point")
SAMPLES = 3000
ALWAYS = 0.95          # in contact in this share of the samples: Always
SEED = 30


def urdf() -> ET.Element:
    return ET.parse(URDF_PATH).getroot()


def joints_of(robot: ET.Element) -> dict[str, ET.Element]:
    return {j.get("name"): j for j in robot.findall("joint")}


def colliding_links(robot: ET.Element) -> list[str]:
    return [link.get("name") for link in robot.findall("link") if link.find("collision") is not None]


def adjacent_pairs(robot: ET.Element) -> set[tuple[str, str]]:
    """Links with geometry joined by a joint, through links without geometry (the flange)."""
    geometry = set(colliding_links(robot))
    parent = {j.find("child").get("link"): j.find("parent").get("link")
              for j in robot.findall("joint")}

    def solid_parent(link: str) -> str | None:
        up = parent.get(link)
        while up is not None and up not in geometry:
            up = parent.get(up)
        return up
    return {tuple(sorted((link, solid_parent(link)))) for link in geometry
            if solid_parent(link) is not None}


def contact_counts(robot: ET.Element) -> tuple[dict[tuple[str, str], int], set[tuple[str, str]]]:
    """{pair: postures in contact} over SAMPLES random postures, and the pairs in contact in the
    start posture (initial_joints_deg, gripper closed), by PyBullet's collision detection."""
    client = pybullet.connect(pybullet.DIRECT)
    try:
        body = pybullet.loadURDF(URDF_PATH, useFixedBase=True, physicsClientId=client,
                                 flags=pybullet.URDF_USE_SELF_COLLISION
                                 | pybullet.URDF_USE_SELF_COLLISION_INCLUDE_PARENT)
        index = {pybullet.getJointInfo(body, i, physicsClientId=client)[12].decode(): i
                 for i in range(pybullet.getNumJoints(body, physicsClientId=client))}
        index[pybullet.getBodyInfo(body, physicsClientId=client)[0].decode()] = -1
        names = {i: n for n, i in index.items()}
        movable = [(i, info) for i in range(pybullet.getNumJoints(body, physicsClientId=client))
                   if (info := pybullet.getJointInfo(body, i, physicsClientId=client))[2]
                   != pybullet.JOINT_FIXED]

        def touching(posture: dict[int, float]) -> set[tuple[str, str]]:
            for i, q in posture.items():
                pybullet.resetJointState(body, i, q, physicsClientId=client)
            pybullet.performCollisionDetection(physicsClientId=client)
            return {tuple(sorted((names[c[3]], names[c[4]])))
                    for c in pybullet.getContactPoints(body, body, physicsClientId=client)
                    if c[3] != c[4]}
        rng = np.random.default_rng(SEED)
        counts: dict[tuple[str, str], int] = {}
        for _ in range(SAMPLES):
            posture = {}
            for i, info in movable:
                lo, hi = (info[8], info[9]) if info[8] < info[9] else (-math.pi, math.pi)
                posture[i] = float(rng.uniform(lo, hi))
            for pair in touching(posture):
                counts[pair] = counts.get(pair, 0) + 1
        start = dict.fromkeys((i for i, _ in movable), 0.0)
        joint_index = {info[1].decode(): i for i, info in movable}
        for name, q in zip(ARM_JOINTS, ArmConfig().initial_joints_deg):
            start[joint_index[name]] = math.radians(q)
        return counts, touching(start)
    finally:
        pybullet.disconnect(client)


def disabled_pairs(robot: ET.Element) -> list[tuple[str, str, str]]:
    """(link, link, reason) of every pair MoveIt may skip, sorted."""
    adjacent = adjacent_pairs(robot)
    counts, at_start = contact_counts(robot)
    out = []
    for pair in combinations(sorted(colliding_links(robot)), 2):
        n = counts.get(pair, 0)
        reason = ("Adjacent" if pair in adjacent else "Default" if pair in at_start else
                  "Always" if n >= ALWAYS * SAMPLES else "Never" if n == 0 else None)
        if reason:
            out.append((*pair, reason))
    return out


def srdf(robot: ET.Element) -> str:
    home = [math.radians(q) for q in ArmConfig().home_joints_deg]
    top = float(joints_of(robot)[GRIPPER_JOINTS[0]].find("limit").get("upper"))
    lines = [
        '<?xml version="1.0"?>',
        "<!-- Written by tools/moveit_config.py from the URDF and the nodes' defaults: edit those,",
        "     then run it again (test_moveit_config.py checks that this is what it writes). -->",
        f'<robot name="{ROBOT}">',
        '  <group name="arm">',
        f'    <chain base_link="{ARM_CHAIN[0]}" tip_link="{ARM_CHAIN[1]}"/>',
        "  </group>",
        '  <group name="gripper">',
        '    <link name="gripper_base"/>',
        *(f'    <link name="{j.replace("_joint", "")}"/>' for j in GRIPPER_JOINTS),
        *(f'    <joint name="{j}"/>' for j in GRIPPER_JOINTS),
        "  </group>",
        '  <group_state name="home" group="arm">',
        *(f'    <joint name="{j}" value="{q:.6f}"/>' for j, q in zip(ARM_JOINTS, home)),
        "  </group_state>",
        '  <group_state name="open" group="gripper">',
        f'    <joint name="{GRIPPER_JOINTS[0]}" value="{top:g}"/>',
        "  </group_state>",
        '  <group_state name="closed" group="gripper">',
        f'    <joint name="{GRIPPER_JOINTS[0]}" value="0"/>',
        "  </group_state>",
        '  <end_effector name="hand" parent_link="flange" group="gripper" parent_group="arm"/>',
        *(f'  <disable_collisions link1="{a}" link2="{b}" reason="{why}"/>'
          for a, b, why in disabled_pairs(robot)),
        "</robot>"]
    return "\n".join(lines) + "\n"


def joint_limits(robot: ET.Element) -> dict:
    joints = joints_of(robot)
    min_accel_time = ArmConfig().min_accel_time_joint
    limits = {}
    for name in (*ARM_JOINTS, GRIPPER_JOINTS[0]):
        velocity = float(joints[name].find("limit").get("velocity"))
        limits[name] = {
            "has_velocity_limits": True, "max_velocity": velocity,
            "has_acceleration_limits": name in ARM_JOINTS,
            "max_acceleration": round(velocity / min_accel_time, 6) if name in ARM_JOINTS else 0.0}
    return {"default_velocity_scaling_factor": 0.5, "default_acceleration_scaling_factor": 0.5,
            "joint_limits": limits}


def controllers() -> dict:
    arm, gripper = ControllerConfig().controller_name, GripperConfig().gripper_controller_name
    return {
        "moveit_controller_manager":
            "moveit_simple_controller_manager/MoveItSimpleControllerManager",
        "moveit_simple_controller_manager": {
            "controller_names": [arm, gripper],
            arm: {"type": "FollowJointTrajectory", "action_ns": "follow_joint_trajectory",
                  "default": True, "joints": list(ARM_JOINTS)},
            gripper: {"type": "GripperCommand", "action_ns": "gripper_cmd", "default": True,
                      "joints": [GRIPPER_JOINTS[0]], "command_joint": GRIPPER_JOINTS[0],
                      "parallel": False}}}


KINEMATICS = {"arm": {"kinematics_solver": "kdl_kinematics_plugin/KDLKinematicsPlugin",
                      "kinematics_solver_search_resolution": 0.005,
                      "kinematics_solver_timeout": 0.05}}
HEADER = ("# Written by tools/moveit_config.py from the URDF and the nodes' defaults: edit those, "
          "then\n# run it again (test_moveit_config.py checks that this is what it writes).\n")


def files() -> dict[str, str]:
    """{file name: contents} of the configuration."""
    robot = urdf()

    def dump(data: dict) -> str:
        return HEADER + yaml.safe_dump(data, sort_keys=False)
    return {f"{ROBOT}.srdf": srdf(robot), "kinematics.yaml": dump(KINEMATICS),
            "joint_limits.yaml": dump(joint_limits(robot)),
            "moveit_controllers.yaml": dump(controllers())}


def main(folder: str = FOLDER) -> None:
    os.makedirs(folder, exist_ok=True)
    for name, text in files().items():
        with open(os.path.join(folder, name), "w") as f:
            f.write(text)


if __name__ == "__main__":
    main(*sys.argv[1:])
