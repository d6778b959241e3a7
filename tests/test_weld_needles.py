"""drop_double_sided hands over the length scales and needles of the mesh it returns (issue 33: found once)."""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import shapes
from meshcurv.defects import needle_vertices
from meshcurv.geometry import vertex_length_scales
from meshcurv.topology import MeshTopology
from meshcurv.weld import drop_double_sided


def _spiked_sphere():
    """An icosphere of radius 1 (92 vertices) with vertex 5 flung 40 radii out: a needle (its corner angles sum to
    0.06, below :data:`~meshcurv.defects.NEEDLE_ANGLE` = 0.5), while the rest of the sphere tells its outside."""
    sphere = shapes.icosphere(3)
    vertices = sphere.vertices.copy()
    vertices[5] *= 40.0
    return vertices, sphere.faces


@pytest.mark.parametrize("inward_first", [False, True], ids=["outward first", "inward first"])
def test_the_needles_handed_over_are_those_of_the_returned_faces(inward_first):
    vertices, faces = _spiked_sphere()
    first = faces[:, ::-1] if inward_first else faces
    both = MeshTopology.from_faces(np.vstack([first, first[:, ::-1]]), vertices.shape[0])
    one = drop_double_sided(vertices, both)
    assert one.n_dropped == faces.shape[0]
    # the side kept is the outward one, whatever came first (inward first: those copies reversed back)
    np.testing.assert_array_equal(one.topology.faces, faces)
    scales = vertex_length_scales(vertices, one.topology)
    np.testing.assert_array_equal(one.length_scales, scales)
    np.testing.assert_array_equal(one.needles, needle_vertices(vertices, one.topology, scales))
    assert np.flatnonzero(one.needles).tolist() == [5]  # the flung vertex, and only it
    assert not one.needles.flags.writeable


def test_nothing_dropped_hands_over_nothing():
    sphere = shapes.icosphere(3)
    one = drop_double_sided(sphere.vertices, MeshTopology.from_faces(sphere.faces))
    assert one.n_dropped == 0 and one.length_scales is None and one.needles is None
