"""The side of ``icc``'s coarse clusters under a change of spacing (issue 29; fuzz_labels round 26, seed 460 case 313).

A dense surface's normals are fitted over clusters of vertices (``icc._coarse_level``): cubes of a tenth of the
normal radius, split by the axis and sign of each vertex normal's largest component. At a voxel surface's edges and
corners two components of a vertex normal are equal (``(-3, 3, 1) / sqrt(19)`` at a corner of a slab one voxel
thick), and ``argmax`` took the one round-off made larger: a label of 10 voxels in one slice (case 313) had an area
of 18.5976 voxels^2 at unit spacing and 18.5892 at 0.7. The tied components are now one side of their own
(``icc.AXIS_TIE``). Expected values: those of the unit spacing scaled (an invariance): areas by ``s^2``, curvatures
by ``1 / s``.
"""

from __future__ import annotations


import numpy as np
import pytest

from conftest import assert_label_row_scaled, label_row


pytest.importorskip("skimage")

SCALES = [0.7, 1e-3, 3.0]


def _slab() -> np.ndarray:
    """Fuzz_labels seed 460 case 313's label: 10 voxels in one z-slice (4 x 3 voxels less two), where it was in
    the image (the coordinates' round-off, hence which component of a tied normal is larger, depends on it)."""
    image = np.zeros((11, 14, 4), dtype=np.uint8)
    image[6, 10, 2] = 1
    image[7:10, 10:13, 2] = 1
    return image


@pytest.mark.parametrize("backend", ["numpy", "numba"])
@pytest.mark.parametrize("scale", SCALES)
def test_a_slabs_tied_normals_pick_one_side_at_every_spacing(scale, backend):
    assert_label_row_scaled(label_row(_slab(), 1.0, backend), label_row(_slab(), scale, backend), scale)
