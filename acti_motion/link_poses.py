"""Every URDF joint's transform (parent link → child link) from measured joint positions, by
Pinocchio forward kinematics over the whole URDF model: what robot_state_publisher computes,
without its node. Fixed joints never change; movable ones follow the joints."""
from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Sequence

import numpy as np
import pinocchio as pin

from acti_sim.world import URDF_PATH


@dataclass(frozen=True)
class LinkTransform:
    """The child link's pose in the parent link's frame: translation (m), quaternion x, y, z, w."""
    parent: str
    child: str
    translation: tuple[float, float, float]
    rotation: tuple[float, float, float, float]


@dataclass(frozen=True)
class UrdfJoint:
    name: str
    parent: str
    child: str
    fixed: bool


def urdf_joints(urdf_text: str) -> list[UrdfJoint]:
    """The joints of a URDF in document order."""
    root = ET.fromstring(urdf_text)
    return [UrdfJoint(j.get("name"), j.find("parent").get("link"), j.find("child").get("link"),
                      j.get("type") == "fixed")
            for j in root.iter("joint")]


class LinkPoses:
    """Forward kinematics of the whole robot from joint states (names and positions, rad or m)."""

    def __init__(self, urdf_path: str = URDF_PATH) -> None:
        with open(urdf_path) as f:
            joints = urdf_joints(f.read())
        self.model = pin.buildModelFromUrdf(urdf_path)
        self.data = self.model.createData()
        self.fixed = [j for j in joints if j.fixed]
        self.movable = [j for j in joints if not j.fixed]
        self._frame = {link: self.model.getFrameId(link, pin.BODY)
                       for j in joints for link in (j.parent, j.child)}
        # where each movable joint's value goes in q; continuous joints take (cos, sin)
        self._slot = {}
        for j in self.movable:
            jid = self.model.getJointId(j.name)
            self._slot[j.name] = (self.model.joints[jid].idx_q, self.model.joints[jid].nq)
        self._q = pin.neutral(self.model)

    def fixed_transforms(self) -> list[LinkTransform]:
        poses = self._poses(self.fixed, self._q)
        return [LinkTransform(j.parent, j.child, tuple(p[:3]), tuple(p[3:]))
                for j, p in zip(self.fixed, poses.tolist())]

    def movable_poses(self, names: Sequence[str], positions: Sequence[float]) -> np.ndarray:
        """Row k: the child link of `movable[k]` in its parent link, as translation x, y, z (m)
        and quaternion x, y, z, w. Joints not named keep their last value."""
        q = self._q
        for name, value in zip(names, positions):
            slot = self._slot.get(name)
            if slot is None:
                continue
            i, nq = slot
            if nq == 2:
                q[i], q[i + 1] = math.cos(value), math.sin(value)
            else:
                q[i] = value
        return self._poses(self.movable, q)

    def _poses(self, joints: list[UrdfJoint], q: np.ndarray) -> np.ndarray:
        pin.framesForwardKinematics(self.model, self.data, q)
        oMf, frame = self.data.oMf, self._frame
        return np.array([pin.SE3ToXYZQUAT(oMf[frame[j.parent]].actInv(oMf[frame[j.child]]))
                         for j in joints])
