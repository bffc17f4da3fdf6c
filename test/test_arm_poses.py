"""HgMatrix parsing (`hg_to_pose`): what it accepts and, for what it refuses, the comment, on a
table of matrices (the checks' cost was cut: the answers must not change)."""
import numpy as np
import pinocchio as pin
import pytest

from acti_motion.arm.poses import hg_to_pose, pose_to_hg
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
