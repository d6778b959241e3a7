"""The public rules of meshcurv.radius and meshcurv.defects refuse arrays that do not fit the topology.

Each took a topology and arrays of their own before; a vertex array of another length than the
topology's vertices reached a compiled kernel that read past its end (a silent answer, or a crash
of the process: "malloc(): smallbin double linked list corrupted"), or ended in numpy's IndexError.
Each now raises InvalidMeshError naming the argument and the expected shape.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import defects, radius, shapes
from meshcurv.errors import InvalidMeshError, InvalidOptionError
from meshcurv.geometry import vertex_length_scales
from meshcurv.topology import MeshTopology

SPHERE = shapes.icosphere(2)
VERTICES = np.ascontiguousarray(SPHERE.vertices, dtype=np.float64)
TOPOLOGY = MeshTopology.from_faces(SPHERE.faces, VERTICES.shape[0])
N = VERTICES.shape[0]
NORMALS = VERTICES / np.linalg.norm(VERTICES, axis=1)[:, None]
VALID = np.ones(N, dtype=bool)

# every public rule that takes (vertices, topology)
RULES = {
    "edge_radius": lambda v: radius.edge_radius(v, TOPOLOGY),
    "component_radii": lambda v: radius.component_radii(v, TOPOLOGY),
    "check_radius": lambda v: radius.check_radius(0.3, v, TOPOLOGY),
    "resolve_radius": lambda v: radius.resolve_radius(None, v, TOPOLOGY),
    "small_radius_note": lambda v: radius.small_radius_note(0.01, v, TOPOLOGY, 2.0),
    "scale_centres": lambda v: radius.scale_centres(v, TOPOLOGY, VALID, NORMALS),
    "noise_radii": lambda v: radius.noise_radii(v, TOPOLOGY, NORMALS, VALID),
    "voxel_surface_radius": lambda v: radius.voxel_surface_radius(v, TOPOLOGY, lambda r: (NORMALS, VALID, VALID)),
    "local_scale_ratios": lambda v: radius.local_scale_ratios(v, TOPOLOGY),
    "needle_vertices": lambda v: defects.needle_vertices(v, TOPOLOGY, vertex_length_scales(VERTICES, TOPOLOGY)),
}


@pytest.mark.parametrize("rows", [10, 2 * N], ids=["fewer", "more"])
@pytest.mark.parametrize("rule", sorted(RULES))
def test_vertices_of_another_length_than_the_topology_are_refused(rule, rows):
    vertices = np.resize(VERTICES, (rows, 3))
    with pytest.raises(InvalidMeshError, match=rf"`vertices` has {rows} rows but the topology has {N} vertices"):
        RULES[rule](vertices)


@pytest.mark.parametrize("rule", sorted(RULES))
def test_nan_vertices_are_refused(rule):
    vertices = VERTICES.copy()
    vertices[3, 1] = np.nan
    with pytest.raises(InvalidMeshError, match="NaN or infinite coordinates"):
        RULES[rule](vertices)


@pytest.mark.parametrize(
    "call",
    [
        lambda mask: defects.scale_vertices(TOPOLOGY, mask),
        lambda mask: defects.scale_edges(TOPOLOGY, mask),
        lambda mask: defects.needle_corners(TOPOLOGY, mask),
        lambda mask: defects.defect_codes(TOPOLOGY, np.zeros(TOPOLOGY.n_faces, dtype=bool), mask),
    ],
    ids=["scale_vertices", "scale_edges", "needle_corners", "defect_codes"],
)
@pytest.mark.parametrize("mask", [np.zeros(10, dtype=bool), np.zeros(N, dtype=np.int64)], ids=["short", "int"])
def test_needles_must_be_one_bool_per_vertex(call, mask):
    with pytest.raises(InvalidMeshError, match=rf"`needles` must be a bool array of shape \({N},\)"):
        call(mask)


def test_the_needles_must_follow_a_topology():
    with pytest.raises(InvalidMeshError, match="`topology` must be a MeshTopology; got ndarray"):
        defects.scale_vertices(SPHERE.faces, np.zeros(N, dtype=bool))


def test_degenerate_must_be_one_bool_per_face():
    with pytest.raises(InvalidMeshError, match=rf"`degenerate` must be a bool array of shape \({TOPOLOGY.n_faces},\)"):
        defects.defect_codes(TOPOLOGY, np.zeros(N, dtype=bool))


def test_scales_valid_normals_and_edges_of_another_length_are_refused():
    scales = vertex_length_scales(VERTICES, TOPOLOGY)
    with pytest.raises(InvalidMeshError, match=rf"`scales` must be a real array of shape \({N},\)"):
        defects.needle_vertices(VERTICES, TOPOLOGY, scales[:10])
    with pytest.raises(InvalidMeshError, match=rf"`valid` must be a bool array of shape \({N},\)"):
        radius.scale_centres(VERTICES, TOPOLOGY, VALID[:10], NORMALS)
    with pytest.raises(InvalidMeshError, match=rf"`normals` must be a real array of shape \({N}, 3\)"):
        radius.noise_radii(VERTICES, TOPOLOGY, NORMALS[:10], VALID)
    with pytest.raises(InvalidMeshError, match="`edges` has vertex index .* out of range for 10 vertices"):
        radius.noise_level(VERTICES[:10], NORMALS[:10], VALID[:10], TOPOLOGY.edges)


def test_the_checked_rules_answer_as_before_on_a_sound_mesh():
    """An invariance: the needles given by hand (none on a clean sphere) change nothing."""
    needles = defects.needle_vertices(VERTICES, TOPOLOGY, vertex_length_scales(VERTICES, TOPOLOGY))
    assert not needles.any()
    assert np.array_equal(defects.scale_vertices(TOPOLOGY, needles), TOPOLOGY.referenced_vertices)
    assert defects.scale_edges(TOPOLOGY, needles) is TOPOLOGY.edges
    assert np.array_equal(radius.scale_centres(VERTICES, TOPOLOGY, VALID, NORMALS), VALID)


@pytest.mark.parametrize("given", [None, "x", -1.0, np.nan])
def test_small_radius_note_checks_its_radius(given):
    # fuzz_api.py seed 135, case 1920: a TypeError from the comparison inside
    with pytest.raises(InvalidOptionError, match="`radius` must be"):
        radius.small_radius_note(given, VERTICES, TOPOLOGY, 2.0)
