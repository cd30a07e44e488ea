"""The rotations' leaf module: its torch ops and numba twins agree with scipy's rotations, and it
imports nothing of physgs (the import circle gaussians <-> part_transform it ended stays gone)."""

import ast
from pathlib import Path

import numpy as np
import torch
from scipy.spatial.transform import Rotation

from physgs import rotations as R

ROOT = Path(__file__).resolve().parents[1]


def _wxyz_to_scipy(q):
    return Rotation.from_quat(np.asarray(q)[..., [1, 2, 3, 0]])


def test_products_and_matrices_match_scipy():
    rng = np.random.default_rng(0)
    a, b = rng.normal(size=(2, 16, 4))
    a /= np.linalg.norm(a, axis=-1, keepdims=True)
    b /= np.linalg.norm(b, axis=-1, keepdims=True)
    prod = R.quat_multiply(torch.from_numpy(a), torch.from_numpy(b)).numpy()
    want = (_wxyz_to_scipy(a) * _wxyz_to_scipy(b)).as_matrix()  # b first, then a
    got = R.quat_to_rotmat(torch.from_numpy(prod)).numpy()
    np.testing.assert_allclose(got, want, atol=1e-12)
    for i in range(len(a)):  # the numba twins
        np.testing.assert_allclose(R.hamilton(tuple(a[i]), tuple(b[i])), prod[i], atol=1e-14)
        Rq = np.zeros((3, 3))
        R.quat_rotmat(*a[i], Rq)
        np.testing.assert_allclose(Rq, _wxyz_to_scipy(a[i]).as_matrix(), atol=1e-12)
    axis = torch.tensor([[0.0, 0.6, 0.8]], dtype=torch.float64)
    angle = torch.tensor([0.7], dtype=torch.float64)
    rv = Rotation.from_rotvec(0.7 * np.array([0.0, 0.6, 0.8])).as_matrix()
    np.testing.assert_allclose(R.rodrigues(axis, angle)[0].numpy(), rv, atol=1e-12)
    q = R.axis_angle_quat(axis, angle)
    np.testing.assert_allclose(R.quat_to_rotmat(q)[0].numpy(), rv, atol=1e-12)
    assert torch.equal(
        R.quat_to_rotmat(torch.zeros(4, dtype=torch.float64)), torch.eye(3, dtype=torch.float64)
    )


def test_the_module_is_a_leaf():
    tree = ast.parse((ROOT / "src" / "physgs" / "rotations.py").read_text())
    mods = [n.module for n in ast.walk(tree) if isinstance(n, ast.ImportFrom)]
    mods += [a.name for n in ast.walk(tree) if isinstance(n, ast.Import) for a in n.names]
    assert not [m for m in mods if m and m.startswith("physgs")], mods
    pt = (ROOT / "src" / "physgs" / "models" / "part_transform.py").read_text()
    assert "physgs.models.gaussians" not in "".join(
        ln for ln in pt.splitlines() if ln.lstrip().startswith(("import", "from"))
    )
