"""Every URDF joint's transform (parent link → child link) from measured joint positions, by
Pinocchio forward kinematics over the whole URDF model: what robot_state_publisher computes,
without its node. Fixed joints never change; movable ones follow the joints."""
from __future__ import annotations

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
        return self._transforms(self.fixed, self._q)

    def movable_transforms(self, names: Sequence[str], positions: Sequence[float]
                           ) -> list[LinkTransform]:
        """The movable joints' transforms; joints not named keep their last value."""
        q = self._q
        for name, value in zip(names, positions):
            slot = self._slot.get(name)
            if slot is None:
                continue
            i, nq = slot
            if nq == 2:
                q[i], q[i + 1] = np.cos(value), np.sin(value)
            else:
                q[i] = value
        return self._transforms(self.movable, q)

    def _transforms(self, joints: list[UrdfJoint], q: np.ndarray) -> list[LinkTransform]:
        pin.framesForwardKinematics(self.model, self.data, q)
        out = []
        for j in joints:
            rel = self.data.oMf[self._frame[j.parent]].actInv(self.data.oMf[self._frame[j.child]])
            t, quat = rel.translation, pin.Quaternion(rel.rotation).coeffs()
            out.append(LinkTransform(j.parent, j.child, (float(t[0]), float(t[1]), float(t[2])),
                                     (float(quat[0]), float(quat[1]), float(quat[2]),
                                      float(quat[3]))))
        return out
