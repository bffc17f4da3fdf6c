"""Poses of the ACT ports: HgMatrix (float64[12], 3×4 row by row, translation in mm) ↔ 4×4 (m).

Internally a pose is a 4×4 homogeneous numpy matrix in metres. A rotation part read from a
request must be a rotation within a small tolerance (rounded values such as 0.7071 pass); it is
then made exactly orthonormal.
"""
from __future__ import annotations

import math
from typing import Iterable

import numpy as np
import pinocchio as pin

from acti_motion.arm import compiled
from acti_motion.replies import Refused, ReturnCode, finite_floats

ROTATION_TOLERANCE = 1e-3
EXACT_ROTATION = 1e-15      # |RᵀR − I| of a rotation kept as given (one a getter answered)
_ORIGIN = np.zeros(3)
_IDENTITY = np.eye(4)


def quaternion_xyzw(rotation: np.ndarray) -> np.ndarray:
    """The unit quaternion (x, y, z, w) of a rotation matrix. Not pin.Quaternion(rotation): in
    this Pinocchio it leaks about 80 bytes a call, which the arm node's ~/state (20 Hz) turned
    into 90 kB a minute; pin.SE3ToXYZQUAT gives the same quaternion and leaks nothing."""
    return pin.SE3ToXYZQUAT(pin.SE3(rotation, _ORIGIN))[3:]


def hg_to_pose(values: Iterable[float], name: str,
               code: ReturnCode = ReturnCode.VALUE_ERR) -> np.ndarray:
    """A 4×4 pose (m) from an HgMatrix, else Refused(code) that says what is wrong."""
    try:
        v = finite_floats(values, 12, name)
    except Refused as r:
        raise Refused(code, r.comment) from None
    rows = [v[0:3], v[4:7], v[8:11]]          # plain floats where they serve: fewer numpy calls
    largest = max(map(abs, rows[0] + rows[1] + rows[2]))
    if largest > 1.0 + ROTATION_TOLERANCE:      # no rotation has such entries
        raise Refused(code, f"{name}: the 3×3 part is not a rotation: an entry is "
                            f"{largest:.6g}, a rotation's are within ±1")
    R = np.array(rows)
    gram = R.T @ R
    gram.flat[::4] -= 1.0
    err = float(np.maximum.reduce(np.abs(gram), axis=None))   # (`.max()` is a Python call)
    det = _det3(rows)
    if err > ROTATION_TOLERANCE or det <= 0:
        raise Refused(code, f"{name}: the 3×3 part is not a rotation (orthonormal, det +1): "
                            f"|RᵀR − I| = {err:.3g}, det = {det:.3g}")
    if err > EXACT_ROTATION:             # made orthonormal; an exact one keeps its last digits
        u, _, vt = np.linalg.svd(R)
        rows = (u @ vt).tolist()
    return np.array([[*rows[0], v[3] / 1000.0], [*rows[1], v[7] / 1000.0],
                     [*rows[2], v[11] / 1000.0], [0.0, 0.0, 0.0, 1.0]])


def _det3(r: list[list[float]]) -> float:
    """The determinant of a 3×3 matrix given as rows (plain floats: a tenth of numpy's cost)."""
    (a, b, c), (d, e, f), (g, h, i) = r
    return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)


def pose_to_hg(T: np.ndarray) -> list[float]:
    m = np.array(T[:3, :4], dtype=float)
    m[:, 3] *= 1000.0
    return [float(x) for x in m.reshape(-1)]


def hg_as_set(T: np.ndarray, values: Iterable[float]) -> list[float]:
    """The HgMatrix of pose T (from `values` by hg_to_pose) with the translation exactly as
    given in `values`: mm → m → mm is not exact (-1023.3 came back as -1023.2999999999998)."""
    hg = pose_to_hg(T)
    hg[3::4] = [float(x) for x in list(values)[3::4]]
    return hg


def inverse(T: np.ndarray) -> np.ndarray:
    out = np.eye(4)
    R = T[:3, :3]
    out[:3, :3] = R.T
    out[:3, 3] = -R.T @ T[:3, 3]
    return out


def rotation_angle(R0: np.ndarray, R1: np.ndarray) -> float:
    """Angle (rad) of the rotation that takes R0 to R1."""
    return float(np.linalg.norm(pin.log3(R1 @ R0.T)))


def compose_relative(start: np.ndarray, delta: np.ndarray) -> np.ndarray:
    """The Cartesian Rel rule, in the robot frame: p' = p + Δp, R' = ΔR·R."""
    return compiled.relative_pose(start, delta)


def position_error_mm(A: np.ndarray, B: np.ndarray) -> float:
    return float(np.linalg.norm(A[:3, 3] - B[:3, 3]) * 1000.0)


def orientation_error_deg(A: np.ndarray, B: np.ndarray) -> float:
    return math.degrees(rotation_angle(A[:3, :3], B[:3, :3]))


class Frames:
    """The two offsets of the middle-level port: `base` = the robot frame seen from the arm frame
    (setBaseOffset), `tool` = the control point seen from the flange (setControlPointOffset)."""

    def __init__(self, base: np.ndarray | None = None, tool: np.ndarray | None = None,
                 base_hg: list[float] | None = None) -> None:
        self.base = np.eye(4) if base is None else base
        self.tool = np.eye(4) if tool is None else tool
        self.base_hg = pose_to_hg(self.base) if base_hg is None else base_hg   # as set
        self.base_inverse, self._tool_inv = inverse(self.base), inverse(self.tool)
        self.tool_reach = float(np.linalg.norm(self.tool[:3, 3]))   # m: control point ↔ flange
        self._plain = bool(np.array_equal(self.base, _IDENTITY)
                           and np.array_equal(self.tool, _IDENTITY))

    def with_base(self, base: np.ndarray, base_hg: list[float]) -> "Frames":
        """These frames with another base offset, `base_hg` being it as set (getBaseOffset)."""
        return Frames(base, self.tool, base_hg)

    def with_tool(self, tool: np.ndarray) -> "Frames":
        """These frames with another control-point offset (the base offset kept as set)."""
        return Frames(self.base, tool, self.base_hg)

    def flange_of(self, P: np.ndarray) -> np.ndarray:
        """Flange pose (arm frame) that puts the control point at P (robot frame). Without
        offsets P itself (a product with identities is exact: a CP plan is spared it)."""
        return P if self._plain else self.base @ P @ self._tool_inv

    def tool_of(self, F: np.ndarray) -> np.ndarray:
        """Control-point pose (robot frame) of the flange pose F (arm frame); F without offsets."""
        return F if self._plain else self.base_inverse @ F @ self.tool
