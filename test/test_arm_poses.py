"""HgMatrix parsing (`hg_to_pose`): what it accepts and, for what it refuses, the comment, on a
table of matrices (the checks' cost was cut: the answers must not change)."""
import numpy as np
import pinocchio as pin
import pytest

from acti_motion.arm.poses import EXACT_ROTATION, ROTATION_TOLERANCE, hg_to_pose, pose_to_hg
from acti_motion.replies import Refused, ReturnCode as R

TURNED = pin.exp3(np.array([0.3, -0.5, 0.9]))
CASES = {
    "identity": np.eye(3),
    "a rotation": TURNED,
    "a rotation rounded to 4 digits": np.round(TURNED, 4),
    "a mirror (det -1)": TURNED @ np.diag([1.0, 1.0, -1.0]),
    "scaled by 1.01": 1.01 * TURNED,
    "scaled by 0.5": 0.5 * TURNED,
    "an entry of 1.5": np.array([[1.5, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]),
    "singular": np.zeros((3, 3)),
}


def hg_of(R3: np.ndarray) -> list[float]:
    T = np.eye(4)
    T[:3, :3] = R3
    T[:3, 3] = [0.1, -0.2, 0.3]
    return pose_to_hg(T)


def expected_refusal(R3: np.ndarray) -> str | None:
    """The comment the checks gave before they were made cheaper (numpy's det and max)."""
    if np.max(np.abs(R3)) > 1.001:
        return (f"p: the 3×3 part is not a rotation: an entry is "
                f"{float(np.max(np.abs(R3))):.6g}, a rotation's are within ±1")
    err = float(np.max(np.abs(R3.T @ R3 - np.eye(3))))
    if err > 1e-3 or np.linalg.det(R3) <= 0:
        return (f"p: the 3×3 part is not a rotation (orthonormal, det +1): "
                f"|RᵀR − I| = {err:.3g}, det = {np.linalg.det(R3):.3g}")
    return None


@pytest.mark.parametrize("name", CASES)
def test_a_pose_is_accepted_or_refused_with_the_same_comment(name):
    R3 = CASES[name]
    want = expected_refusal(R3)
    if want is None:
        T = hg_to_pose(hg_of(R3), "p")
        assert np.allclose(T[:3, :3], R3, atol=2e-4) and np.allclose(T[:3, 3], [0.1, -0.2, 0.3])
        assert np.allclose(T[:3, :3].T @ T[:3, :3], np.eye(3), atol=1e-12)
    else:
        with pytest.raises(Refused) as e:
            hg_to_pose(hg_of(R3), "p")
        assert e.value.code == R.VALUE_ERR and e.value.comment == want


def test_a_value_that_is_no_number_is_refused_by_its_place():
    values = hg_of(np.eye(3))
    values[5] = float("nan")
    with pytest.raises(Refused) as e:
        hg_to_pose(values, "p")
    assert e.value.comment == "p[5] is nan: every value must be a finite number"


def hg_to_pose_in_numpy(values, name):
    """hg_to_pose as it was, all in numpy: the reference for the plain-float one."""
    m = np.array(values, dtype=float).reshape(3, 4)
    R = m[:, :3]
    largest = float(np.abs(R).max())
    if largest > 1.0 + ROTATION_TOLERANCE:
        return (f"{name}: the 3×3 part is not a rotation: an entry is {largest:.6g}, a "
                f"rotation's are within ±1")
    gram = R.T @ R
    gram.flat[::4] -= 1.0
    err = float(np.abs(gram).max())
    det = float(np.linalg.det(R))
    if err > ROTATION_TOLERANCE or det <= 0:
        return err, det
    T = np.eye(4)
    if err > EXACT_ROTATION:
        u, _, vt = np.linalg.svd(R)
        R = u @ vt
    T[:3, :3] = R
    T[:3, 3] = m[:, 3] / 1000.0
    return T


def test_the_pose_read_in_plain_floats_is_numpy_s():
    """The same pose to the last bit, the same refusals (their |RᵀR − I| to the last bit too),
    on rotations, near-rotations (made orthonormal), scaled and mirrored ones."""
    rng = np.random.default_rng(21)
    for k in range(400):
        R = pin.exp3(rng.normal(0, 2, 3)) * (1 + rng.choice([0.0, 1e-12, 1e-6, 1e-4, 0.01]))
        if k % 5 == 0:
            R = R @ np.diag([1.0, 1.0, -1.0])
        values = np.hstack([R, rng.normal(0, 1000, (3, 1))]).reshape(-1).tolist()
        want = hg_to_pose_in_numpy(values, "p")
        if isinstance(want, np.ndarray):
            assert np.array_equal(hg_to_pose(values, "p"), want)
            continue
        with pytest.raises(Refused) as e:
            hg_to_pose(values, "p")
        if isinstance(want, str):
            assert e.value.comment == want
        else:
            err, det = want
            assert f"|RᵀR − I| = {err:.3g}, det = " in e.value.comment
