"""The coarse level of ``icc``'s normal fits under a change of spacing (issue 29; fuzz_labels round 26).

A dense surface's normals are fitted over clusters of vertices (``icc._coarse_level``): cubes of a tenth of the
normal radius, split by the axis and sign of each vertex normal's largest component. Both decisions sat on the
voxel lattice, where the last bits of a scaled mesh chose:

- the axis: at a voxel surface's edges and corners two components of a vertex normal are equal
  (``(-3, 3, 1) / sqrt(19)`` at a corner of a slab one voxel thick), and ``argmax`` took the one round-off made
  larger. A label of 10 voxels in one slice (fuzz_labels seed 460 case 313) had an area of 18.5976 voxels^2 at
  unit spacing and 18.5892 at 0.7 (its mean curvature 0.6751 and 0.6743).
- the cubes: their boundaries started at the surface's lowest corner, itself on the lattice, so a radius of a
  round number of voxels put them through lattice points (a given radius of 10 voxels: cubes of 3 voxels, 378
  vertices of a ball of radius 8.3 voxels on their boundaries; 1,532 clusters at unit spacing, 1,533 at 0.7).

The expected values are those of the unit spacing scaled (an invariance): areas by ``s^2``, curvatures by
``1 / s``.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from meshcurv import principal_curvatures
from meshcurv._backend import use_backend
from meshcurv.volume import label_curvatures

pytest.importorskip("skimage")

BACKENDS = ["numpy", "numba"]
SCALES = [0.7, 1e-3, 3.0]


def _backend(name: str):
    if name == "numba":
        pytest.importorskip("numba")
    return use_backend(name)


def _slab() -> np.ndarray:
    """Fuzz_labels seed 460 case 313's label: 10 voxels in one z-slice (4 x 3 voxels less two), where it was in
    the image (the coordinates' round-off, hence which component of a tied normal is larger, depends on it)."""
    image = np.zeros((11, 14, 4), dtype=np.uint8)
    image[6, 10, 2] = 1
    image[7:10, 10:13, 2] = 1
    return image


def _ball() -> np.ndarray:
    """A voxel ball of radius 8.3 voxels, its centre off the voxel centres."""
    offsets = np.indices((21, 21, 21)) - 10.2
    return (np.einsum("i...,i...->...", offsets, offsets) <= 8.3**2).astype(np.uint8)


def _row(image, scale: float, backend: str, radius=None):
    with _backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        options = {} if radius is None else {"radius": radius * scale}
        return label_curvatures(image, spacing=[scale] * 3, **options).iloc[0]


def _assert_scaled(row, scaled, scale):
    assert scaled["radius"] == pytest.approx(row["radius"] * scale, rel=1e-9)
    assert scaled["area"] == pytest.approx(row["area"] * scale**2, rel=1e-9)
    assert scaled["n_used"] == row["n_used"]
    for column, power in (("mean_weighted", 1), ("mean_median", 1), ("k_min_p5", 1), ("gaussian_weighted", 2)):
        assert scaled[column] * scale**power == pytest.approx(row[column], rel=1e-9), column


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("scale", SCALES)
def test_a_slabs_tied_normals_pick_one_side_at_every_spacing(scale, backend):
    _assert_scaled(_row(_slab(), 1.0, backend), _row(_slab(), scale, backend), scale)


@pytest.mark.parametrize("backend", BACKENDS)
def test_the_slabs_normal_fits_scale_on_the_bare_mesh(backend):
    from meshcurv.volume import _surface

    index, faces, _, _ = _surface(np.pad(_slab(), 1), np.zeros(3), np.ones(3))  # (as label_curvatures' crop)
    with _backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        unit = principal_curvatures(index, faces, orient="consistent")
        scaled = principal_curvatures(index * 0.7, faces, orient="consistent")
    np.testing.assert_allclose(np.asarray(scaled.normals), np.asarray(unit.normals), atol=1e-9)
    np.testing.assert_allclose(np.asarray(scaled.mean) * 0.7, np.asarray(unit.mean), rtol=1e-9)


@pytest.mark.slow
@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_a_radius_of_whole_voxels_puts_no_cube_boundary_on_the_lattice(backend):
    # cubes of 3 voxels (a tenth of the normal radius, three radii): without the shift 378 vertices on boundaries
    row, scaled = _row(_ball(), 1.0, backend, radius=10.0), _row(_ball(), 0.7, backend, radius=10.0)
    _assert_scaled(row, scaled, 0.7)
