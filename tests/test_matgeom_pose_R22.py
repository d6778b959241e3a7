"""matgeom's valid mask is the same in every pose (issue 29: invariance to rigid motion).

Flat faces in axis planes give dihedral angles of exactly 0 (normals along an axis, dot products exactly 1);
turned, ``arccos`` of dot products a few ulps below 1 gives angles up to 3e-8. Whether the normal's eigenvalue
ties with the next one must not follow that round-off.
"""

import importlib.util
import warnings
from pathlib import Path

import numpy as np
import pytest

import meshcurv
from meshcurv._backend import use_backend

DATA = Path(__file__).parent / "data" / "matgeom"
BACKENDS = ["numpy"] + (["numba"] if importlib.util.find_spec("numba") else [])


def rotation(seed):
    """A random rotation matrix (QR of a Gaussian matrix, determinant +1)."""
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def matgeom(vertices, faces, backend, monkeypatch=None):
    """matgeom's result; with ``monkeypatch``, without the staircase rule (a subdivided cube is read as a voxel
    surface, every vertex valid=False: the tie rule below is checked on the mask it leaves without that rule)."""
    if monkeypatch is not None:
        monkeypatch.setattr(meshcurv.estimators.matgeom, "on_staircase", lambda *args, **kwargs: False)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        with use_backend(backend):
            return meshcurv.principal_curvatures(vertices, faces, method="matgeom")


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", ["fandisk", "cube_sub4"])
@pytest.mark.parametrize("staircase", [True, False], ids=["staircase_rule", "tie_rule_only"])
def test_valid_mask_is_the_same_after_a_rigid_motion(name, backend, staircase, monkeypatch):
    with np.load(DATA / f"{name}.npz") as case:
        vertices, faces = np.asarray(case["vertices"], float), case["faces"]
    patch = None if staircase else monkeypatch
    result = matgeom(vertices, faces, backend, patch)
    size = float(np.ptp(vertices))
    for seed in range(3):
        shift = np.random.default_rng(seed).uniform(-10.0, 10.0, size=3) * size
        moved = matgeom(vertices @ rotation(seed).T + shift, faces, backend, patch)
        assert np.array_equal(moved.valid, result.valid), f"seed {seed}: {int((moved.valid != result.valid).sum())}"
        both = result.valid
        if not both.any():  # the cube under the staircase rule: nothing valid in any pose
            continue
        scale = max(np.abs(result.k_max[both]).max(), np.abs(result.k_min[both]).max())
        # matGeom's numbers are dimensionless and rotation invariant: where valid, the same to round-off
        np.testing.assert_allclose(moved.k_min[both], result.k_min[both], rtol=0, atol=1e-6 * scale)
        np.testing.assert_allclose(moved.k_max[both], result.k_max[both], rtol=0, atol=1e-6 * scale)
