"""``quadric`` on voxel soups of anisotropic voxels (issue 29, Q32).

A voxel soup's faces have corners of their own, moved by a few hundredths of an edge (the fuzzer's detached faces).
On a torus voxelised at 1 x 0.5 x 0.5 (its axis along the long voxels) with every face detached, the caps of the tube
are terraces one voxel high: there a fit over the soup's default ball turned its normal by a right angle from its
vertex's, and the ball grown in that frame (``quadric._scatter_check``) read the steps edge-on, its normal facing
into the solid and its curvatures' signs reversed (``voxel_torus(12, 4)``: 201-334 valid vertices off the exact H by
more than half of the largest ``|k|``, most of them H -0.12 for 0.14).

Expected values: the exact outward normals and mean curvatures of the torus (at each vertex's corner of the clean
surface, :class:`meshcurv.shapes.VoxelMesh`).
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes

from conftest import chosen_backend
from test_quadric_soups_V30 import _soup

pytest.importorskip("skimage")


def _torus_normals(torus, corners: np.ndarray) -> np.ndarray:
    """The exact outward normals of ``torus`` (axis along x, through its ``center``) at its closest points of
    ``corners`` (the clean surface's vertices)."""
    points = np.asarray(torus.closest_points)[corners] - np.asarray(torus.center)
    ring = points.copy()
    ring[:, 0] = 0.0
    ring *= 9.0 / np.linalg.norm(ring, axis=1, keepdims=True)
    normals = points - ring
    return normals / np.linalg.norm(normals, axis=1, keepdims=True)


@pytest.mark.parametrize("backend", ["numba", pytest.param("numpy", marks=pytest.mark.slow)])
def test_anisotropic_soup_fits_face_outward(backend):
    """``voxel_torus(9, 3)`` at 1 x 0.5 x 0.5 voxels, every face detached by 0.05 edges (this draw): no valid
    vertex's normal faces into the solid, none with the sign of its mean curvature reversed (before: 7 such valid
    vertices, off the exact H by more than half of the largest ``|k|``), and those left out are voxel staircase."""
    torus = shapes.voxel_torus(9.0, 3.0, (1.0, 0.5, 0.5))
    vertices, faces = _soup(torus.vertices, torus.faces, 1.0, 0.05, 3)
    n_clean = len(torus.vertices)
    corners = np.concatenate([np.arange(n_clean), np.asarray(torus.faces)[faces != torus.faces]])
    with chosen_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = meshcurv.principal_curvatures(vertices, faces, method="quadric")
    referenced = np.zeros(len(vertices), dtype=bool)
    referenced[faces] = True
    valid = result.valid & referenced
    assert valid.sum() > 0.4 * referenced.sum()  # (the soup is read: about 57% valid)
    exact_normals = _torus_normals(torus, corners)
    facing = np.einsum("ij,ij->i", np.asarray(result.normals)[valid], exact_normals[valid])
    assert (facing > 0).all(), f"{int((facing <= 0).sum())} valid normals face into the solid"
    exact_mean = np.asarray(torus.mean)[corners][valid]
    largest = float(np.max(np.maximum(np.abs(torus.k_min), np.abs(torus.k_max))))
    reversed_ = (result.mean[valid] * exact_mean < 0) & (np.abs(result.mean[valid] - exact_mean) > 0.5 * largest)
    assert not reversed_.any()
    left_out = referenced & ~result.valid
    codes = np.asarray(result.invalid_reason)[left_out]
    assert (codes == meshcurv.defects.STAIRCASE).sum() > 0.9 * left_out.sum()
