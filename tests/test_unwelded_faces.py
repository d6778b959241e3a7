"""Faces detached from their neighbours by more than the weld tolerance (issue 29, "never lie").

A mesh whose faces do not share their corners (a triangle soup, split seams, an exported mesh whose
faces were moved one by one) is welded when the copies of a corner lie within
``weld.WELD_TOLERANCE_RATIO`` (1e-5) of the median edge length. Copies 1e-3 edge lengths apart were not
welded: each detached face was a flat island, bounded by boundary edges that lie on top of its
neighbours'. The methods over balls read the cracks as flat (H = 0.6 or 0 at valid vertices of a unit
sphere with a fifth of its faces detached, where the truth is 1). Such boundary edges on top of each
other are now welded across the crack, up to ``weld.CRACK_TOLERANCE_RATIO`` of their length; a real
boundary (no second edge on it) and a wider gap are left alone.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from scipy.spatial import cKDTree

import meshcurv
from meshcurv import MeshTopology, shapes
from meshcurv.errors import InvalidOptionError
from meshcurv.weld import CRACK_TOLERANCE_RATIO, weld_vertices

#: A valid vertex is a lie when its H is off by more than this share of the exact 1 / r (the fuzzer's bar).
TOLERANCE = 0.5

METHODS = ["quadric", "normal_cycle", "meyer", "icc", "normal_cycle_ball", "rusinkiewicz"]
BALL_METHODS = ["icc", "normal_cycle_ball", "rusinkiewicz"]


def _mean_edge(vertices: np.ndarray, faces: np.ndarray) -> float:
    return float(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1).mean())


def _detach(vertices, faces, picked, gap: float, rng):
    """The faces ``picked`` given corners of their own, each moved by ``gap`` mean edge lengths in a random direction.

    Returns the vertices (the intact ones first, then the copies), the faces and the copies' distance bound: two
    copies of a corner are at most ``2 * gap`` edge lengths apart, a copy and the intact corner ``gap``.
    """
    edge = _mean_edge(vertices, faces)
    corners = vertices[faces[picked]].reshape(-1, 3)
    directions = rng.normal(size=corners.shape)
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    corners = corners + directions * gap * edge
    faces = faces.copy()
    faces[picked] = len(vertices) + np.arange(corners.shape[0]).reshape(-1, 3)
    return np.concatenate([vertices, corners]), faces


def _sphere(radius: float = 1.0, subdivisions: int = 12):
    mesh = shapes.icosphere(subdivisions=subdivisions, radius=radius)
    return np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces)


def _detached(share: float, gap: float = 1e-3, seed: int = 3):
    """A unit icosphere with ``share`` of its faces given corners of their own, moved by ``gap`` edge lengths."""
    vertices, faces = _sphere()
    rng = np.random.default_rng(seed)
    return _detach(vertices, faces, rng.random(len(faces)) < share, gap, rng)


def _compute(vertices, faces, method):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the welding's note: tested on its own below
        return meshcurv.principal_curvatures(vertices, faces, method=method)


def _lies(vertices, faces, method, exact_mean) -> tuple[int, int]:
    result = _compute(vertices, faces, method)
    used = np.zeros(len(vertices), dtype=bool)
    used[faces.ravel()] = True
    valid = result.valid & used
    error = np.abs(result.mean[valid] - exact_mean[valid]) / np.abs(exact_mean[valid])
    return int((error > TOLERANCE).sum()), int(valid.sum())


def _same_faces(welded_vertices, welded_faces, vertices, faces) -> bool:
    """The welded faces are the intact ones up to re-indexing (each welded vertex taken to its nearest intact one)."""
    _, nearest = cKDTree(vertices).query(welded_vertices)
    mapped = np.sort(nearest[welded_faces], axis=1)
    return np.unique(nearest).size == nearest.size and bool(
        np.array_equal(np.unique(mapped, axis=0), np.unique(np.sort(faces, axis=1), axis=0))
    )


@pytest.mark.parametrize("method", METHODS)
def test_detached_faces_give_no_wrong_curvature(method):
    vertices, faces = _detached(0.2)
    wrong, valid = _lies(vertices, faces, method, np.ones(len(vertices)))
    assert valid > 0 and wrong == 0, f"{wrong} of {valid} valid vertices off"


@pytest.mark.parametrize("method", BALL_METHODS)
def test_a_whole_detached_soup_is_welded_back(method):
    """Every face with its own corners, moved by 1e-3 edge lengths: the sphere, every copy welded, H = 1."""
    vertices, faces = _sphere()
    n_intact = len(vertices)
    soup, soup_faces = _detach(vertices, faces, np.ones(len(faces), dtype=bool), 1e-3, np.random.default_rng(5))
    soup, soup_faces = soup[n_intact:], soup_faces - n_intact  # the intact vertices are no longer used
    result = _compute(soup, soup_faces, method)
    assert result.parameters["n_welded_vertices"] == soup_faces.size - n_intact  # all corner copies but one each
    error = np.abs(result.mean - 1.0)
    assert result.valid.all() and (error <= TOLERANCE).all(), f"{int((error > TOLERANCE).sum())} off"


@pytest.mark.parametrize("share", [0.2, 1.0])
def test_the_welded_topology_is_the_intact_one(share):
    """Invariance: welding the detached mesh gives the intact faces up to re-indexing, the vertices moved no more
    than the copies were (``gap`` edge lengths), and the copies not within the weld tolerance counted as welded
    across a crack."""
    gap = 1e-3
    vertices, faces = _sphere()
    rng = np.random.default_rng(11)
    picked = rng.random(len(faces)) < share
    moved, moved_faces = _detach(vertices, faces, picked, gap, rng)
    used = np.unique(moved_faces)
    index = np.full(len(moved), -1)
    index[used] = np.arange(used.size)
    moved, moved_faces = moved[used], index[moved_faces]  # only the vertices in use (the soup drops the intact)
    topology = MeshTopology.from_faces(moved_faces)
    welding = weld_vertices(moved, topology)
    assert welding.n_welded == len(moved) - len(np.unique(faces))
    # the copies that fell within the weld tolerance by chance are welded without the crack rule
    assert welding.n_welded - welding.n_cracked == weld_vertices(moved, topology, crack_ratio=0.0).n_welded
    assert _same_faces(welding.vertices, welding.topology.faces, vertices, faces)
    distance, _ = cKDTree(vertices).query(welding.vertices)
    assert distance.max() <= gap * _mean_edge(vertices, faces) * (1 + 1e-9)
    assert not welding.topology.boundary_edges.any()


def test_the_warning_says_what_was_welded_across_cracks():
    vertices, faces = _detached(0.2)
    with pytest.warns(UserWarning, match=r"of which \d+ across cracks up to 0\.05 edge lengths wide"):
        meshcurv.principal_curvatures(vertices, faces, method="quadric")


def test_a_gap_wider_than_the_tolerance_is_not_welded():
    """Faces sharing no vertex with each other, each moved 0.2 edge lengths off its neighbours (4x the tolerance)."""
    assert CRACK_TOLERANCE_RATIO < 0.2 / 2  # the gap exceeds the tolerance even for the two ends moved apart
    vertices, faces = _sphere()
    rng = np.random.default_rng(2)
    picked = np.zeros(len(faces), dtype=bool)
    taken = np.zeros(len(vertices), dtype=bool)
    for face in rng.permutation(len(faces))[:200]:  # an independent set of faces: no two detached faces touch
        if not taken[faces[face]].any():
            picked[face] = True
            taken[faces[face]] = True
    edge = _mean_edge(vertices, faces)
    normals = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]])
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    corners = (vertices[faces[picked]] + 0.2 * edge * normals[picked, None, :]).reshape(-1, 3)
    moved_faces = faces.copy()
    moved_faces[picked] = len(vertices) + np.arange(corners.shape[0]).reshape(-1, 3)
    welding = weld_vertices(np.concatenate([vertices, corners]), MeshTopology.from_faces(moved_faces))
    assert picked.sum() > 50 and welding.n_welded == 0


@pytest.mark.parametrize(
    "mesh",
    [
        shapes.hemisphere(12),
        shapes.hemisphere(12, irregular=True),
        shapes.saddle(spacing=0.1),
        shapes.saddle(spacing=0.1, jitter=0.3),
        shapes.cylinder(),
    ],
    ids=["hemisphere", "irregular hemisphere", "plate", "jittered plate", "open cylinder"],
)
def test_a_real_boundary_is_left_alone(mesh):
    vertices, faces = np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces)
    topology = MeshTopology.from_faces(faces)
    assert topology.boundary_edges.any()
    welding = weld_vertices(vertices, topology)
    assert welding.n_welded == 0 and welding.vertices is vertices and welding.topology is topology


def test_the_voxel_meshes_are_left_alone():
    pytest.importorskip("skimage")  # (marching cubes: the volume extra)
    mesh = shapes.voxel_sphere(radius=6.0)
    vertices, faces = np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces)
    keep = vertices[faces].mean(axis=1)[:, 2] > mesh.vertices[:, 2].mean()  # an open cap: a stepped boundary
    topology = MeshTopology.from_faces(faces[keep])
    assert topology.boundary_edges.any()
    assert weld_vertices(vertices, topology).n_welded == 0


@pytest.mark.parametrize("method", BALL_METHODS)
def test_a_resolution_change_of_ten_to_one(method):
    """Two spheres, radius 1 and 0.1, with the same faces (edges 10:1), a fifth of the faces of each detached by
    1e-2 of their own edge length (copies up to 2e-2 apart: more than the tolerance times the small edges for
    the large faces): both welded back, H = 1 and 10."""
    big, big_faces = _sphere(1.0)
    small, small_faces = _sphere(0.1)
    small = small + [3.0, 0.0, 0.0]
    rng = np.random.default_rng(7)
    vertices, faces = [], []
    offset = 0
    for part, part_faces in ((big, big_faces), (small, small_faces)):
        moved, moved_faces = _detach(part, part_faces, rng.random(len(part_faces)) < 0.2, 1e-2, rng)
        vertices.append(moved)
        faces.append(moved_faces + offset)
        offset += len(moved)
    vertices, faces = np.concatenate(vertices), np.concatenate(faces)
    welding = weld_vertices(vertices, MeshTopology.from_faces(faces))
    assert _same_faces(
        welding.vertices,
        welding.topology.faces,
        np.concatenate([big, small]),
        np.concatenate([big_faces, small_faces + len(big)]),
    )
    exact = np.where(vertices[:, 0] > 2.0, 10.0, 1.0)
    wrong, valid = _lies(vertices, faces, method, exact)
    assert valid > 0 and wrong == 0, f"{wrong} of {valid} valid vertices off"


@pytest.mark.parametrize("ratio", [-0.1, 0.5, 2.0])
def test_a_crack_ratio_out_of_range_is_refused(ratio):
    vertices, faces = _sphere(subdivisions=2)
    with pytest.raises(InvalidOptionError, match=r"`crack_ratio` must be in \[0, 0\.5\)"):
        weld_vertices(vertices, MeshTopology.from_faces(faces), crack_ratio=ratio)


def test_a_crack_ratio_of_zero_welds_no_crack():
    vertices, faces = _detached(0.2)
    assert weld_vertices(vertices, MeshTopology.from_faces(faces), crack_ratio=0.0).n_welded == 0
