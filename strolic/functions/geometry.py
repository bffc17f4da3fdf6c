"""EF36–EF49: vectors, homogeneous transforms and poses.

Vec and Trn elements are single precision (§13, §14): the arithmetic is done in double and the
result rounded to R4. Pose data (§15, implementation-defined) is documented in ``pose_layout``.
"""
from __future__ import annotations

import math
from typing import TYPE_CHECKING

import numpy as np

from ..codes import (I2, R4, R8, Num, Pose, Trn, Vec, converted, make_int, make_real,
                     to_float32)
from ..errors import ExceptionKind as K, fail
from ..process import Process
from .args import expect, pop_count, pop_many, pop_num, pop_of

if TYPE_CHECKING:
    from ..vm import VM

# ---- conversions --------------------------------------------------------------------------------
def vec_of(values) -> Vec:
    return Vec(tuple(to_float32(float(v)) for v in values))


def matrix_of(trn: Trn) -> np.ndarray:
    """4×4 matrix [[N O A P], [0 0 0 1]] from the storage order P N O A."""
    v = trn.values
    matrix = np.eye(4)
    matrix[:3, 3] = v[0:3]
    matrix[:3, 0] = v[3:6]
    matrix[:3, 1] = v[6:9]
    matrix[:3, 2] = v[9:12]
    return matrix


def storage_order(matrix: np.ndarray) -> tuple[float, ...]:
    return tuple(float(x) for x in np.concatenate(
        [matrix[:3, 3], matrix[:3, 0], matrix[:3, 1], matrix[:3, 2]]))


def trn_of(matrix: np.ndarray) -> Trn:
    return Trn(tuple(to_float32(v) for v in storage_order(matrix)))


def pop_vec(proc: Process) -> Vec:
    return pop_of(proc, Vec, "a vector")


def pop_trn(proc: Process) -> Trn:
    return pop_of(proc, Trn, "a homogeneous transform")


# ---- vectors ------------------------------------------------------------------------------------
def vlen(vm: VM, proc: Process) -> None:
    proc.push(make_real(R4, math.hypot(*pop_vec(proc).xyz)))


def vector_binary(op):
    def handler(vm: VM, proc: Process) -> None:
        b = np.array(pop_vec(proc).xyz)
        a = np.array(pop_vec(proc).xyz)
        proc.push(vec_of(op(a, b)))
    return handler


vadd = vector_binary(np.add)
vsub = vector_binary(np.subtract)
vprodo = vector_binary(np.cross)


def vtimes(vm: VM, proc: Process) -> None:
    """VTIMES: a b → b·a (vector first, scalar on top); the scalar is converted to the stronger
    of its representation and the elements' R4 first (Annex 1 §5: an I4 is rounded to R4)."""
    scale = pop_num(proc)
    scale = converted(scale, max(scale.tag, R4))
    proc.push(vec_of(np.array(pop_vec(proc).xyz) * scale))


def vprodi(vm: VM, proc: Process) -> None:
    b = np.array(pop_vec(proc).xyz)
    a = np.array(pop_vec(proc).xyz)
    proc.push(make_real(R4, float(np.dot(a, b))))


def consv(vm: VM, proc: Process) -> None:
    z, y, x = pop_num(proc), pop_num(proc), pop_num(proc)
    proc.push(vec_of((x.value, y.value, z.value)))


def destv(vm: VM, proc: Process) -> None:
    for component in pop_vec(proc).xyz:
        proc.push(Num(R4, component))


# ---- transforms ---------------------------------------------------------------------------------
def tprod(vm: VM, proc: Process) -> None:
    """TPROD: C = A·B (A pushed first)."""
    b = matrix_of(pop_trn(proc))
    a = matrix_of(pop_trn(proc))
    proc.push(trn_of(a @ b))


def invert(matrix: np.ndarray) -> np.ndarray:
    """Inverse of a homogeneous transform; a singular rotation part stops the program."""
    rotation = matrix[:3, :3]
    if abs(np.linalg.det(rotation)) < 1e-9:
        raise fail(K.SINGULAR_TRANSFORM, "the rotation part is singular")
    inverse = np.eye(4)
    inverse[:3, :3] = np.linalg.inv(rotation)
    inverse[:3, 3] = -inverse[:3, :3] @ matrix[:3, 3]
    return inverse


def tinv(vm: VM, proc: Process) -> None:
    proc.push(trn_of(invert(matrix_of(pop_trn(proc)))))


def tprodv(vm: VM, proc: Process) -> None:
    """TPRODV: the vector is a point, c = R·b + p."""
    b = np.array(pop_vec(proc).xyz)
    a = matrix_of(pop_trn(proc))
    proc.push(vec_of(a[:3, :3] @ b + a[:3, 3]))


# ---- poses --------------------------------------------------------------------------------------
POSE_ELEMENTS = 14   # 12 × R8 transform (storage order), I2 configuration, R8 elbow angle (degree)


def pose_of(matrix: np.ndarray, configuration: int, elbow: float) -> Pose:
    values = storage_order(matrix)
    return Pose(tuple(make_real(R8, v) for v in values)
                + (make_int(I2, configuration), make_real(R8, elbow)))


def pose_parts(pose: Pose) -> tuple[np.ndarray, int, float]:
    """Matrix, configuration bits and elbow angle of a pose of this implementation's layout."""
    elements = pose.elements
    if len(elements) != POSE_ELEMENTS or not elements[12].is_integer:
        raise fail(K.TYPE_MISMATCH, "pose data is not 12 reals, a configuration and an elbow angle")
    values = tuple(float(e.value) for e in elements[:12])
    matrix = matrix_of(Trn(values))
    return matrix, elements[12].value, float(elements[13].value)


def pop_pose(proc: Process) -> tuple[np.ndarray, int, float]:
    return pose_parts(pop_of(proc, Pose, "a pose"))


def trn(vm: VM, proc: Process) -> None:
    matrix, _, _ = pop_pose(proc)
    proc.push(trn_of(matrix))


def pnt(vm: VM, proc: Process) -> None:
    """PNT: the configuration and elbow angle come from the VM's current configuration."""
    matrix = matrix_of(pop_trn(proc))
    proc.push(pose_of(matrix, vm.configuration, vm.elbow))


def loc(vm: VM, proc: Process) -> None:
    matrix, _, _ = pop_pose(proc)
    proc.push(vec_of(matrix[:3, 3]))


def deviation(in_tool_frame: bool):
    """DEV: p' = p + b (robot frame); DEVH: p' = p + R·b (tool frame)."""
    def handler(vm: VM, proc: Process) -> None:
        shift = np.array(pop_vec(proc).xyz)
        matrix, configuration, elbow = pop_pose(proc)
        matrix = matrix.copy()
        matrix[:3, 3] += matrix[:3, :3] @ shift if in_tool_frame else shift
        proc.push(pose_of(matrix, configuration, elbow))
    return handler


dev = deviation(False)
devh = deviation(True)


def padd(vm: VM, proc: Process) -> None:
    """PADD a b: the pose reached by the relative move a from b (as the arm's Rel moves: p' = p + Δp,
    R' = ΔR·R in the robot frame); configuration from a, elbow angles add."""
    base, _, base_elbow = pop_pose(proc)
    delta, configuration, elbow = pop_pose(proc)
    result = np.eye(4)
    result[:3, :3] = delta[:3, :3] @ base[:3, :3]
    result[:3, 3] = delta[:3, 3] + base[:3, 3]
    proc.push(pose_of(result, configuration, elbow + base_elbow))


def psub(vm: VM, proc: Process) -> None:
    """PSUB a b: the relative pose d with d b PADD = a (Δp = p_a − p_b, ΔR = R_a·R_bᵀ)."""
    base, _, base_elbow = pop_pose(proc)
    target, configuration, elbow = pop_pose(proc)
    result = np.eye(4)
    result[:3, :3] = target[:3, :3] @ base[:3, :3].T
    result[:3, 3] = target[:3, 3] - base[:3, 3]
    proc.push(pose_of(result, configuration, elbow - base_elbow))


def consp(vm: VM, proc: Process) -> None:
    """CONSP a1 … a14 14: numbers in the pose layout (see POSE_ELEMENTS)."""
    count = pop_count(proc)
    if count != POSE_ELEMENTS:
        raise fail(K.TYPE_MISMATCH, f"a pose has {POSE_ELEMENTS} elements, not {count}")
    elements = [expect(e, Num, "a number") for e in pop_many(proc, count)]
    matrix, configuration, elbow = pose_parts(Pose(tuple(elements)))
    proc.push(pose_of(matrix, configuration, elbow))


def destp(vm: VM, proc: Process) -> None:
    pose = pop_of(proc, Pose, "a pose")
    pose_parts(pose)
    proc.stack.extend(pose.elements)
    proc.push(Num(I2, len(pose.elements)))
