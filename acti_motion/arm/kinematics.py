"""Kinematics of the 7-axis SRS arm with Pinocchio: forward kinematics, the arm angle, and an
exact inverse kinematics that honours the arm angle.

Pinocchio loads `urdf/mobile_manipulator.urdf` and reduces it to the seven arm joints; the
model's root (the universe frame) is `base_link`, the arm frame of the ACT ports. Internally
everything is SI (m, rad) and poses are 4×4 homogeneous matrices (numpy).

The arm is an SRS arm: joints 1-3 (Z, Y, Z) meet at the shoulder S, joint 4 (Y) is the elbow E,
joints 5-7 (Z, Y, Z) meet at the wrist W. The arm angle ψ is the rotation of the elbow about the
shoulder-wrist line u = S→W (right hand), measured from the reference direction ŷ × u: ψ = 0
puts the elbow on that side (in the start posture, wrist above the shoulder: the elbow points
forward; reaching forward: the elbow below the line), ψ = ±180° on the other. The reference is
undefined only where the wrist is straight to the left or right of the shoulder (within
`LATERAL_CONE`; there ẑ × u takes its place), a place this arm rarely reaches through; the
start posture and the forward and upward workspace are far from it. Near that direction
relative moves do not use the reference: they carry the elbow along without twist
(`transport`) and turn it by the requested amount.
"""
from __future__ import annotations

import math
import threading
from dataclasses import dataclass
from itertools import product

import numpy as np
import pinocchio as pin

from acti_motion.arm import compiled
from acti_motion.arm.compiled import CLEAR
from acti_sim.world import ARM_JOINTS, URDF_PATH

TWO_PI = 2.0 * math.pi
LATERAL_CONE = 1e-3           # rad: where S→W is this close to ±y, ψ is measured from ẑ × u
_EPS = 1e-9
FEW_POSTURES = 24             # up to this many postures, checks run in plain floats
# Flags of CarPosWithElbow.struct_flag (reported; moves take the branch nearest the start).
FLAG_SHOULDER = 0x1   # θ2 < 0
FLAG_ELBOW = 0x2      # θ4 > 0
FLAG_WRIST = 0x4      # θ6 < 0
# The eight IK branches as signs of θ2, θ4, θ6, in the order they are tried (each sign then
# flipped where the reference's is negative, so that the reference's branch comes first).
BRANCH_SIGNS = np.array(list(product((1.0, -1.0), repeat=3)))


class Unreachable(ValueError):
    """No joint solution: the comment says why (too far, too close, joint limits)."""


def cross_many(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Cross products of 3-vectors, row-wise for (N, 3) arrays (np.cross costs more on small
    arrays)."""
    return np.stack([a[..., 1] * b[..., 2] - a[..., 2] * b[..., 1],
                     a[..., 2] * b[..., 0] - a[..., 0] * b[..., 2],
                     a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]], axis=-1)


def rotate_about(axis: np.ndarray, angle: float) -> np.ndarray:
    """Rotation matrix of `angle` (rad) about the unit vector `axis`."""
    return pin.exp3(np.asarray(axis, float) * angle)


def wrap(a: float) -> float:
    """An angle in (-π, π]."""
    return math.pi - (math.pi - a) % TWO_PI


@dataclass(frozen=True)
class ArmPoints:
    shoulder: np.ndarray
    elbow: np.ndarray
    wrist: np.ndarray


class ArmKinematics:
    """The reduced Pinocchio model of the arm, with thread-local data (one per calling thread)."""

    def __init__(self, urdf_path: str = URDF_PATH, flange: str = "flange") -> None:
        full = pin.buildModelFromUrdf(urdf_path)
        lock = [i for i in range(1, full.njoints) if full.names[i] not in ARM_JOINTS]
        self.model = pin.buildReducedModel(full, lock, pin.neutral(full))
        if tuple(self.model.names[1:]) != ARM_JOINTS:
            raise ValueError(f"expected the arm joints {ARM_JOINTS}, got {list(self.model.names)}")
        self.flange_id = self.model.getFrameId(flange)
        self.lower = self.model.lowerPositionLimit.copy()
        self.upper = self.model.upperPositionLimit.copy()
        self.velocity = self.model.velocityLimit.copy()
        self._local = threading.local()
        self._check_srs_layout()

    # --- model data ---------------------------------------------------------------------------
    @property
    def data(self) -> pin.Data:
        d = getattr(self._local, "data", None)
        if d is None:
            d = self._local.data = self.model.createData()
        return d

    def _check_srs_layout(self) -> None:
        """Read the SRS geometry off the model at q = 0 and make sure it is one."""
        kinds = [self.model.joints[i].shortname() for i in range(1, 8)]
        if kinds != ["JointModelRZ", "JointModelRY"] * 3 + ["JointModelRZ"]:
            raise ValueError(f"not a Z-Y-Z-Y-Z-Y-Z arm: {kinds}")
        d = self.data
        pin.forwardKinematics(self.model, d, np.zeros(7))
        pin.updateFramePlacements(self.model, d)
        origins = [d.oMi[i].translation.copy() for i in range(1, 8)]
        flange = d.oMf[self.flange_id]
        axis_point = origins[0]
        for i in range(1, 8):
            if not np.allclose(d.oMi[i].rotation, np.eye(3), atol=1e-9):
                raise ValueError(f"joint{i} frame is rotated at q = 0; the IK assumes it is not")
            if not np.allclose(origins[i - 1][:2], axis_point[:2], atol=1e-9):
                raise ValueError(f"joint{i} is off the arm's vertical line at q = 0")
        if not (np.allclose(flange.rotation, np.eye(3)) and np.allclose(flange.translation[:2],
                                                                         axis_point[:2])):
            raise ValueError("the flange is not on the arm's line at q = 0")
        self.shoulder = origins[1]                      # joint2: J1, J2, J3 axes meet here
        self.upper_arm = float(origins[3][2] - origins[1][2])   # S → E (joint4)
        self.forearm = float(origins[5][2] - origins[3][2])     # E → W (joint6)
        self.hand = float(flange.translation[2] - origins[5][2])  # W → flange, along its z
        self.reach = self.upper_arm + self.forearm
        c_min = math.cos(max(abs(self.lower[3]), abs(self.upper[3])))
        self.min_reach = math.sqrt(self.upper_arm ** 2 + self.forearm ** 2
                                   + 2 * self.upper_arm * self.forearm * c_min)

    # --- forward kinematics --------------------------------------------------------------------
    def flange(self, q: np.ndarray) -> np.ndarray:
        """Flange pose in the arm frame (4×4, m)."""
        d = self.data
        pin.forwardKinematics(self.model, d, np.asarray(q, float))
        return pin.updateFramePlacement(self.model, d, self.flange_id).homogeneous

    def flange_many(self, qs: np.ndarray) -> np.ndarray:
        """Flange poses (N×4×4, m) of many postures at once, from the SRS geometry read off the
        model (the same poses as `flange`, in one compiled call)."""
        return compiled.flange_poses(np.asarray(qs, float).reshape(-1, 7), self.shoulder,
                                     self.upper_arm, self.forearm, self.hand)

    def points(self, q: np.ndarray) -> ArmPoints:
        d = self.data
        pin.forwardKinematics(self.model, d, np.asarray(q, float))
        return ArmPoints(d.oMi[2].translation.copy(), d.oMi[4].translation.copy(),
                         d.oMi[6].translation.copy())

    # --- the arm angle ---------------------------------------------------------------------------
    def reference(self, u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(e1, e2): the arm angle's zero direction and its +90° direction, normal to u = S→W.
        e1 = ŷ × u where u is clear of ±ŷ, else ẑ × u; in plain floats (one 3-vector: numpy's
        calls cost more than the arithmetic, twice in every CP plan)."""
        e1, e2 = self._reference_floats(*map(float, u))
        return np.array(e1), np.array(e2)

    @staticmethod
    def _reference_floats(x: float, y: float, z: float) -> tuple[tuple[float, ...], ...]:
        """`reference` of u = (x, y, z), as plain floats."""
        e = (z, 0.0, -x)                        # ŷ × u
        n = math.hypot(z, x)
        if n <= LATERAL_CONE:
            e, n = (-y, x, 0.0), math.hypot(y, x)   # ẑ × u
            if n <= 0.0:
                raise AssertionError("unreachable: y and z cannot both be parallel to u")
        a, b, c = e[0] / n, e[1] / n, e[2] / n
        return (a, b, c), (y * c - z * b, z * a - x * c, x * b - y * a)      # e1, u × e1

    @staticmethod
    def reference_strength(u: np.ndarray | tuple[float, float, float]) -> float:
        """|ŷ × u|: 1 far from the arm angle's undefined direction (u = ±ŷ), 0 on it."""
        return float(math.hypot(u[0], u[2]))

    def elbow_direction(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(u, n): the unit S→W and the unit direction from the elbow circle's centre to E
        (read-only). The thread's last answer is kept: a CP plan asks for its start's twice."""
        q = np.asarray(q, float)
        key = q.tobytes()
        last = getattr(self._local, "elbow", None)
        if last is not None and last[0] == key:
            return last[1]
        d = self.data                         # in plain floats: a few 3-vectors
        pin.forwardKinematics(self.model, d, q)
        oMi = d.oMi
        sx, sy, sz = oMi[2].translation.tolist()
        ex, ey, ez = oMi[4].translation.tolist()
        wx, wy, wz = oMi[6].translation.tolist()
        ux, uy, uz = wx - sx, wy - sy, wz - sz
        r = math.sqrt(ux * ux + uy * uy + uz * uz)
        ux, uy, uz = ux / r, uy / r, uz / r
        vx, vy, vz = ex - sx, ey - sy, ez - sz
        along = vx * ux + vy * uy + vz * uz
        nx, ny, nz = vx - along * ux, vy - along * uy, vz - along * uz
        norm = math.sqrt(nx * nx + ny * ny + nz * nz)
        u = np.array([ux, uy, uz])
        n = (np.array(self._reference_floats(ux, uy, uz)[0]) if norm < 1e-9   # stretched: any
             else np.array([nx / norm, ny / norm, nz / norm]))                # angle; report 0
        u.flags.writeable = n.flags.writeable = False
        self._local.elbow = (key, (u, n))
        return u, n

    def angle_of(self, u: np.ndarray, n: np.ndarray) -> float:
        e1, e2 = self._reference_floats(*u.tolist())
        n0, n1, n2 = n.tolist()
        return math.atan2(n0 * e2[0] + n1 * e2[1] + n2 * e2[2],
                          n0 * e1[0] + n1 * e1[1] + n2 * e1[2])

    def arm_angle(self, q: np.ndarray) -> float:
        """The arm angle ψ (rad) of the posture q."""
        return self.angle_of(*self.elbow_direction(q))

    @staticmethod
    def transport(n: np.ndarray, u0: np.ndarray, u1: np.ndarray) -> np.ndarray:
        """The elbow direction n (normal to u0) carried to u1 by the smallest rotation."""
        axis = cross_many(u0, u1)
        sin, cos = float(np.linalg.norm(axis)), float(np.dot(u0, u1))
        if sin > 1e-12:
            n = rotate_about(axis / sin, math.atan2(sin, cos)) @ n
        n = n - np.dot(n, u1) * u1
        return n / np.linalg.norm(n)

    def direction_at(self, u: np.ndarray, psi: float) -> np.ndarray:
        e1, e2 = self.reference(u)
        return math.cos(psi) * e1 + math.sin(psi) * e2

    @staticmethod
    def flags(q: np.ndarray) -> int:
        """The branch of q as CarPosWithElbow.struct_flag bits."""
        return ((FLAG_SHOULDER if q[1] < 0 else 0) | (FLAG_ELBOW if q[3] > 0 else 0)
                | (FLAG_WRIST if q[5] < 0 else 0))

    def wrist_direction(self, flange: np.ndarray) -> tuple[float, float, float]:
        """The unit direction S→W of a flange pose (4×4), in plain floats."""
        (_, _, ax, px), (_, _, ay, py), (_, _, az, pz) = flange[:3].tolist()
        sx, sy, sz = self.shoulder.tolist()
        x, y, z = px - self.hand * ax - sx, py - self.hand * ay - sy, pz - self.hand * az - sz
        r = max(math.sqrt(x * x + y * y + z * z), 1e-12)
        return x / r, y / r, z / r

    def wrist_of(self, flange: np.ndarray) -> np.ndarray:
        """The wrist point of a flange pose (4×4), or of each of many (N×4×4)."""
        return flange[..., :3, 3] - self.hand * flange[..., :3, 2]

    # --- inverse kinematics ------------------------------------------------------------------------
    def solve(self, flange: np.ndarray, reference_q: np.ndarray, *, psi: float | None = None,
              elbow_dir: np.ndarray | None = None, lower: np.ndarray | None = None,
              upper: np.ndarray | None = None) -> np.ndarray:
        """Joints (rad) that put the flange at `flange` (4×4, m) with the elbow at arm angle `psi`
        (rad) or towards `elbow_dir` (a unit vector normal to S→W), nearest to `reference_q`
        among the solutions within [lower, upper] (default: the model's limits).
        Raises Unreachable with the reason when there is none."""
        lower = self.lower if lower is None else lower
        upper = self.upper if upper is None else upper
        ref = np.asarray(reference_q, float)
        w = self.wrist_of(flange)
        v = w - self.shoulder
        dist = float(np.linalg.norm(v))
        a, b = self.upper_arm, self.forearm
        if dist > self.reach + 1e-9:
            raise Unreachable(f"out of reach: the wrist would be {dist * 1e3:.1f} mm from the "
                              f"shoulder, the arm reaches {self.reach * 1e3:.1f} mm")
        if dist < self.min_reach - 1e-9:
            raise Unreachable(f"too close: the wrist would be {dist * 1e3:.1f} mm from the "
                              f"shoulder, the elbow folds to {self.min_reach * 1e3:.1f} mm")
        u = v / dist
        h = (a * a - b * b + dist * dist) / (2 * dist)
        rho = math.sqrt(max(a * a - h * h, 0.0))
        if elbow_dir is None:
            elbow_dir = self.direction_at(u, 0.0 if psi is None else psi)
        n = elbow_dir - np.dot(elbow_dir, u) * u
        n = n / np.linalg.norm(n)
        elbow = self.shoulder + h * u + rho * n
        # All eight branches at once, the reference's signs of θ2, θ4, θ6 first. When none of
        # the reference's nor the first in-limit branch's is near zero and that branch has the
        # reference's signs, it is the nearest and it is taken; else the nearest of those within
        # the limits (a target near θ6 = 0 on the other side has a same-sign twin with θ5 and
        # θ7 half a turn away: taking it swung the wrist 180°).
        signs = BRANCH_SIGNS * np.where(ref[1::2] < 0, -1.0, 1.0)
        q, inside = self._nearest_turns(
            compiled.branches(elbow[None], w[None], flange[None], signs, ref[None],
                              self.shoulder, a, b), ref, lower, upper)
        valid = np.flatnonzero(inside)
        if not len(valid):
            raise Unreachable("no joint solution within the joint limits for this pose and elbow")
        first = valid[0]
        if (min(abs(ref[1]), abs(ref[3]), abs(ref[5])) > CLEAR
                and min(abs(q[first, 1]), abs(q[first, 3]), abs(q[first, 5])) > CLEAR
                and np.all(np.sign(q[first, 1::2]) == np.sign(ref[1::2]))):
            best = q[first]
        else:
            cost = np.where(inside, np.sum((q - ref) ** 2, axis=1), np.inf)
            best = q[int(np.argmin(cost))]
        self._verify(best, flange)
        return best

    def solve_many(self, flanges: np.ndarray, elbow_dirs: np.ndarray, reference: np.ndarray, *,
                   chained: bool) -> tuple[np.ndarray, np.ndarray]:
        """`solve` for many flange poses at once (N×4×4, elbows towards elbow_dirs, N×3), and which
        of them it solved exactly as `solve` would: those whose reference and solution are clear
        of a branch boundary (|θ2|, |θ4|, |θ6| > CLEAR, so the branch is the reference's) and
        within the model's limits. `chained`: pose i is solved nearest to solution i − 1, the
        first nearest to `reference` (7), and only a leading run counts as solved; else each
        pose nearest to reference[i] (N×7). `solve` decides the others one by one (and says why
        where there is no solution)."""
        return compiled.solve_poses(
            flanges, elbow_dirs, reference.reshape(-1, 7), chained, self.shoulder,
            self.upper_arm, self.forearm, self.hand, self.reach, self.min_reach, self.lower,
            self.upper)

    @staticmethod
    def _nearest_turns(q: np.ndarray, ref: np.ndarray, lower: np.ndarray,
                       upper: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Each angle of the rows of q moved by whole turns to the value nearest the reference
        within its limits, and which rows have such a value for every angle."""
        k0 = np.round((ref - q) / TWO_PI)
        options = q[..., None] + TWO_PI * (k0[..., None] + np.array([-1.0, 0.0, 1.0]))
        inside = (options >= lower[:, None] - 1e-9) & (options <= upper[:, None] + 1e-9)
        pick = np.argmin(np.where(inside, np.abs(options - ref[:, None]), np.inf), axis=-1)
        nearest = np.take_along_axis(options, pick[..., None], axis=-1)[..., 0]
        return nearest, np.all(np.any(inside, axis=-1), axis=-1)

    def _verify(self, q: np.ndarray, flange: np.ndarray) -> None:
        got = self.flange(q)
        if not compiled.reproduces(got[None], flange[None])[0]:
            raise AssertionError(f"IK solution does not reproduce the pose:\n{got}\n{flange}")
