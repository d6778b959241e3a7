"""Every compiled kernel against its NumPy twin, directly (issue 18).

Each row of :data:`TWINS` pairs one kernel of :mod:`meshcurv._kernels` with the
NumPy code it mirrors and the inputs it is checked on: the NumPy side runs under
``use_backend("numpy")`` (the public function that dispatches, or the private
NumPy implementation), the kernel is called directly from its module with the
arguments its NumPy wrapper passes. Equal to the bit (``assert_array_equal``)
where both sides do the same operations in the same order; otherwise within a
tolerance derived, beside each check, from what differs (the order of a sum, an
iterative against a direct eigen-solver). :func:`test_every_kernel_has_a_twin`
fails when a public kernel is in neither :data:`TWINS` nor :data:`EXCEPTIONS`.

Where rounding may tip a discrete choice, the check compares what both sides
define instead: a direction up to its sign where ``atan2`` sits on its branch
cut (:func:`atan2_branch`), a jet's frame-free quantities where two components
of the normal tie and the two frames differ by 90 degrees, any least-variance
direction where a neighbourhood has no unique one. Known disagreements are
listed in :data:`DISAGREEMENTS` (strict xfail).

Inputs: analytic meshes of :mod:`meshcurv.shapes` (icosphere, torus,
ellipsoid, a noisy sphere, an open saddle), a mesh with every defect (zero-area
and repeated-vertex faces, a non-manifold fin, flipped faces, a hole, a bow-tie
vertex, unreferenced vertices, a second component a thousand times smaller),
NaN normals where a kernel takes normals, and random point clouds.
"""

from __future__ import annotations

import functools
import importlib
import inspect
import pkgutil
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import pytest

pytest.importorskip("numba")

from meshcurv import shapes  # noqa: E402
from meshcurv._backend import kernel_threads, use_backend  # noqa: E402
from meshcurv.neighborhoods import _face_sum_scratch  # noqa: E402
from meshcurv.topology import MeshTopology  # noqa: E402

EPS = np.finfo(float).eps


def kernels(module: str):
    """The module ``meshcurv._kernels.<module>`` itself (not the backend's serialised proxy)."""
    return importlib.import_module(f"meshcurv._kernels.{module}")


# -- inputs -------------------------------------------------------------------------------------


def _defects():
    """An icosphere with every defect, and a second sphere touching it at one vertex (a bow-tie)."""
    sphere = shapes.icosphere(8)
    vertices, faces = sphere.vertices.copy(), sphere.faces.copy()
    vertices[faces[0, 2]] = vertices[faces[0, 0]]  # two zero-area faces and a zero-length edge
    faces[100] = faces[100, ::-1]  # a flipped face: three inconsistently oriented edges
    faces = np.delete(faces, range(200, 206), axis=0)  # a hole: a boundary loop
    extra = [
        [faces[50, 0], faces[50, 1], 0],  # a fin: a non-manifold edge
        [faces[7, 1], faces[7, 1], faces[9, 2]],
    ]  # a face repeating a vertex
    top, bottom = np.argmax(vertices[:, 2]), np.argmin(vertices[:, 2])
    n = vertices.shape[0]
    other = sphere.faces + n
    other[other == bottom + n] = top  # the second sphere's bottom is the first one's top
    other[500] = other[500, ::-1]  # flipped among the last faces: matGeom's face-id sums out of range
    moved = sphere.vertices + (sphere.vertices[top] - sphere.vertices[bottom])
    unreferenced = [[5.0, 5.0, 5.0], [-5.0, 0.0, 1.0]]
    # a lone triangle a thousand times smaller, far away: a second component of its own scale
    lone = 1e-3 * np.eye(3) + 10.0
    m = n + moved.shape[0] + 2
    return (np.vstack([vertices, moved, unreferenced, lone]), np.vstack([faces, extra, other, [[m, m + 1, m + 2]]]))


@functools.cache
def mesh(name: str) -> tuple[np.ndarray, np.ndarray]:
    """``(vertices, faces)``, float64 and int64, C-contiguous."""
    if name == "icosphere":
        made = shapes.icosphere(10)
    elif name == "torus":
        made = shapes.torus(n_major=40, n_minor=20)
    elif name == "ellipsoid":
        made = shapes.ellipsoid(subdivisions=8)
    elif name == "noisy":
        made = shapes.with_normal_noise(shapes.icosphere(12), 0.3, seed=3)
    elif name == "saddle":  # open: a boundary all around
        made = shapes.saddle(spacing=0.05)
    elif name == "flat":  # thinner than a few edges: a ball reaches the other side
        made = shapes.ellipsoid((3.0, 3.0, 0.15), subdivisions=16)
    elif name == "thin_torus":
        made = shapes.torus(major_radius=3.0, minor_radius=0.12, n_major=90, n_minor=12)
    elif name == "defects":
        vertices, faces = _defects()
        return np.ascontiguousarray(vertices, np.float64), np.ascontiguousarray(faces, np.int64)
    else:
        raise KeyError(name)
    return np.ascontiguousarray(made.vertices, np.float64), np.ascontiguousarray(made.faces, np.int64)


#: Every mesh; the clean ones (whose small balls are connected pieces of surface); the closed ones.
MESHES = ("icosphere", "torus", "ellipsoid", "noisy", "saddle", "defects")
CLEAN = ("icosphere", "torus", "ellipsoid", "noisy", "saddle")
#: Meshes thinner than their balls: the surface-connected balls leave the other side out (issue 29).
THIN = ("flat", "thin_torus")


@functools.cache
def topology(name: str) -> MeshTopology:
    """The mesh's topology, built and with every property read on the NumPy backend."""
    vertices, faces = mesh(name)
    with use_backend("numpy"):
        built = MeshTopology._build(faces, vertices.shape[0])
        for attribute in (
            "bowtie_vertices",
            "neighbour_lists",
            "vertex_components",
            "n_components",
            "referenced_vertices",
            "degenerate_faces",
            "interior_edges",
        ):
            getattr(built, attribute)
    return built


@functools.cache
def numpy_normals(name: str) -> np.ndarray:
    """Area-weighted vertex normals of the NumPy path (NaN at unreferenced and cancelled vertices)."""
    from meshcurv import geometry

    vertices, faces = mesh(name)
    with use_backend("numpy"):
        return geometry.vertex_normals(vertices, faces)


def mean_edge(name: str) -> float:
    from meshcurv import geometry

    vertices, _ = mesh(name)
    with use_backend("numpy"):
        return geometry.mean_edge_length(vertices, topology(name).edges)


@functools.cache
def cloud(name: str) -> tuple[np.ndarray, np.ndarray]:
    """A random point cloud and its unit normals: an ellipsoid's surface with noise, or a flat square."""
    rng = np.random.default_rng(7)
    if name == "ellipsoid_cloud":
        directions = rng.standard_normal((3000, 3))
        directions /= np.linalg.norm(directions, axis=1, keepdims=True)
        axes = np.array([3.0, 2.0, 1.0])
        points = directions * axes
        normals = points / axes**2
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        points = points + 0.01 * rng.standard_normal(points.shape)
    elif name == "plane_cloud":  # nearly flat neighbourhoods: the smallest eigenvalue near 0
        points = np.column_stack([rng.uniform(-1, 1, (2000, 2)), 1e-3 * rng.standard_normal(2000)])
        normals = np.tile([0.0, 0.0, 1.0], (2000, 1))
    elif name == "degenerate_cloud":  # neighbourhoods without a unique normal: three lines, 15 copies of a point
        steps = np.arange(40)[:, None] * 0.01
        lines = [
            steps * direction + 10.0 * k
            for k, direction in enumerate(([1.0, 2.0, 3.0], [0.0, 0.0, 1.0], [1.0, -1.0, 0.0]))
        ]
        points = np.vstack([*lines, np.tile([-20.0, 0.0, 0.0], (15, 1))])
        normals = np.tile([0.0, 0.0, 1.0], (points.shape[0], 1))
    else:
        raise KeyError(name)
    return np.ascontiguousarray(points), np.ascontiguousarray(normals)


CLOUDS = ("ellipsoid_cloud", "plane_cloud")


def knn_indices(points: np.ndarray, k: int = 10) -> np.ndarray:
    from scipy.spatial import cKDTree

    from meshcurv._pointcloud_normals import knn

    return knn(cKDTree(points), points, k)[1]


def searched_balls(points, centres, radius, k, usable=None, wide=0.0, k_wide=0):
    """The rows of the compiled search of the measures' balls alone: ``(index, counts, wide_index, wide_counts)`` of
    :func:`meshcurv._kernels.pointcloud.measured_balls` with no normals (every tie key and ``n_j . n_c`` 0: nothing
    faces away, tied points stay in index order), no tie tolerance and no least count (``least`` above any count:
    a full row keeps its first ``k``). Each row: the ``k`` nearest ``usable`` points strictly closer than the radius
    in the order of ``(squared distance, index)``, padded with N (what the k-d tree's
    :func:`meshcurv._pointcloud_estimators._ball_indices` gives); the smaller balls the prefixes of the wide ones'
    search (``k_wide`` > 0)."""
    from meshcurv._pointcloud_estimators import FACING_MARGIN

    n = points.shape[0]
    usable = np.ones(n, dtype=bool) if usable is None else usable
    grid = kernels("neighborhoods").pool_grid(points, np.flatnonzero(usable), float(wide if k_wide else radius))
    return kernels("pointcloud").measured_balls(
        np.ascontiguousarray(points),
        np.zeros((n, 3)),
        np.ascontiguousarray(centres, dtype=np.int64),
        float(radius),
        k,
        float(wide),
        k_wide,
        *grid,
        np.zeros(0, dtype=np.int64),
        0.0,
        n + 2,
        FACING_MARGIN,
        64 * kernel_threads(),
    )


# -- comparison helpers -------------------------------------------------------------------------


def assert_sums_close(actual, desired, magnitude, terms, err_msg="", *, relative=0.0):
    """The same terms summed in another order.

    Each order's rounding error is at most ``(terms - 1) u sum|term|``, ``u = eps / 2``
    (recursive, pairwise or parallel summation, Higham 2002, sec. 4.2), so the
    two differ by at most ``(terms - 1) eps sum|term|``; ``magnitude`` is
    ``sum|term|`` (an array like ``desired``, or a bound on it) and ``terms``
    the count (or a bound on it). ``relative``: a further error relative to
    the value itself (every term scaled by the same factor ``1 + delta``).
    """
    actual, desired = np.asarray(actual), np.asarray(desired)
    np.testing.assert_array_equal(np.isnan(actual), np.isnan(desired), err_msg=f"{err_msg}: NaN positions")
    bound = max(terms - 1, 1) * EPS * np.broadcast_to(magnitude, desired.shape) + relative * np.abs(desired)
    finite = ~np.isnan(desired)
    difference = np.abs(actual[finite] - desired[finite])
    excess = difference - bound[finite]
    assert (excess <= 0).all(), (
        f"{err_msg}: {int((excess > 0).sum())} entries beyond the bound; largest difference "
        f"{difference.max():.3g} (bound there {bound[finite][np.argmax(excess)]:.3g})"
    )


def assert_directions_close(actual, desired, atol, err_msg="", *, up_to_sign=False):
    """Rows of vectors within ``atol`` (per row), NaN at the same places; ``up_to_sign`` (True, or a
    (N,) mask of rows): either sign of each row."""
    actual, desired = np.asarray(actual), np.asarray(desired)
    np.testing.assert_array_equal(np.isnan(actual), np.isnan(desired), err_msg=f"{err_msg}: NaN positions")
    actual, desired = np.nan_to_num(actual, nan=0.0), np.nan_to_num(desired, nan=0.0)
    if np.any(up_to_sign):
        flip = np.broadcast_to(up_to_sign, actual.shape[:1]) & (np.einsum("ij,ij->i", actual, desired) < 0)
        actual = np.where(flip[:, None], -actual, actual)
    difference = np.abs(actual - desired).max(axis=1)
    atol = np.broadcast_to(atol, difference.shape)
    bad = ~(difference <= atol)
    assert not bad.any(), (
        f"{err_msg}: {int(bad.sum())} of {bad.size} rows differ; largest difference "
        f"{np.nanmax(difference):.3g}, tolerance there {atol[np.nanargmax(difference)]:.3g}"
    )


def atan2_branch(along, normals, atol):
    """Rows where ``theta = atan2(b, a - c) / 2`` of a 2x2 tangent restriction may take either branch.

    ``along`` is the direction of the larger eigenvalue before any rotation, ``cos(theta) t1 +
    sin(theta) t2`` (``_tensors.tangent_basis``). With ``a < c`` and ``b`` within rounding of 0,
    theta is near +pi/2 or -pi/2 as the rounding of ``b`` falls: the direction (t2 or -t2) is then
    defined up to its sign only (meshcurv's directions are, conventionally), which happens exactly
    where ``|cos(theta)| = |along . t1|`` is within the direction's tolerance ``atol`` of 0.
    """
    from meshcurv._tensors import tangent_basis

    t1, _ = tangent_basis(np.where(np.isfinite(normals), normals, 0.0))
    return np.abs(np.einsum("ij,ij->i", along, t1)) <= atol


# -- geometry -----------------------------------------------------------------------------------


def check_face_cross_products(name):
    from meshcurv import geometry

    vertices, faces = mesh(name)
    with use_backend("numpy"):
        expected = geometry.face_cross_products(vertices, faces)
    # the same three products and differences per component
    np.testing.assert_array_equal(kernels("geometry").face_cross_products(vertices, faces), expected)


def check_face_winding_numbers(name):
    from meshcurv.orient import WINDING_BETA, _winding_tree, face_winding_numbers

    vertices, faces = mesh(name)
    rng = np.random.default_rng(6)
    # half of the faces (the undecided pieces of a holey mesh), each seen from its centroid as in orient
    tree = _winding_tree(vertices[faces[rng.random(faces.shape[0]) < 0.5]])
    positions = tree.corners.mean(axis=1)
    own = np.arange(positions.shape[0], dtype=np.int64)
    arguments = (tree.corners, tree.centres, tree.dipoles, tree.moments, tree.radii, positions, own, tree.depth)
    with use_backend("numpy"):
        expected = face_winding_numbers(*arguments, WINDING_BETA)
    got = kernels("orient").face_winding_numbers(*arguments, WINDING_BETA)
    # the same nodes and faces counted (the far test on the same squared distances), the terms summed in another
    # order (a walk against levels) and each term's products grouped otherwise: a few hundred terms of at most
    # 2 pi each, a few eps of 4 pi apart per term
    np.testing.assert_allclose(got, expected, rtol=0, atol=1e-12)


def check_patch_volumes(name):
    from meshcurv.orient import patch_volumes

    vertices, faces = mesh(name)
    n_labels, labels = topology(name).vertex_components
    rng = np.random.default_rng(5)
    # the mesh's components, and three interleaved patches over them (labels need not be contiguous)
    for patch, count in ((labels[faces[:, 0]], n_labels), (np.arange(faces.shape[0]) * 7 % 3, 3)):
        patch = np.ascontiguousarray(patch, dtype=np.int64)
        flip = rng.random(faces.shape[0]) < 0.3
        with use_backend("numpy"):
            expected = patch_volumes(vertices, faces, patch, flip, count)
        got = kernels("orient").patch_volumes(vertices, faces, patch, flip, count)
        # each face's triple product a . (b x c) grouped otherwise (np.cross and einsum against one
        # expression): a few eps |a||b||c| apart, then the same terms summed in another order
        centre = (
            np.stack([np.bincount(patch, weights=vertices[faces[:, 0], k], minlength=count) for k in range(3)], axis=1)
            / np.maximum(np.bincount(patch, minlength=count), 1)[:, None]
        )
        sizes = np.prod([np.linalg.norm(vertices[faces[:, k]] - centre[patch], axis=1) for k in range(3)], axis=0)
        magnitude = 8 * np.bincount(patch, weights=sizes, minlength=count)
        for kind, a, b in (("signed", got[0], expected[0]), ("absolute", got[1], expected[1])):
            assert_sums_close(a, b, magnitude, faces.shape[0], f"{name}: {kind} volumes, {count} patches")
        assert (np.sign(got[0]) == np.sign(expected[0]))[np.abs(expected[0]) > 1e-6 * expected[1]].all()


def check_vertex_normal_sums(name):
    from meshcurv import _geometry

    vertices, faces = mesh(name)
    with use_backend("numpy"):
        cross = _geometry.face_cross_products(vertices, faces)
        expected = _geometry.vertex_normal_sums(cross, faces, vertices.shape[0])  # the sums of vertex_normals
    # np.bincount adds the faces' rows in face order, as the kernel does: the same sums
    np.testing.assert_array_equal(kernels("geometry").vertex_normal_sums(cross, faces, vertices.shape[0]), expected)


def check_vertex_normal_and_area_sums(name):
    from meshcurv import _geometry

    vertices, faces = mesh(name)
    cross = _geometry.face_cross_products(vertices, faces)
    dropped = np.random.default_rng(4).random(faces.shape[0]) < 0.1
    with use_backend("numpy"):
        expected = _geometry.vertex_normal_and_area_sums(cross, faces, dropped, vertices.shape[0])
    got = kernels("geometry").vertex_normal_and_area_sums(cross, faces, dropped, vertices.shape[0])
    # the faces' rows in face order (np.bincount's), a dropped face adding nothing (NumPy: zeros); each area the
    # same square root of the same three squares added left to right (np.linalg.norm over three columns)
    np.testing.assert_array_equal(got[0], expected[0])
    np.testing.assert_array_equal(got[1], expected[1])


def check_normalize_normal_sums(name):
    from meshcurv import geometry

    if name == "random":
        rng = np.random.default_rng(0)
        summed = rng.standard_normal((3000, 3)) * 10.0 ** rng.integers(-150, 150, (3000, 1))
        summed[:5] = 0.0  # cancelled: NaN
        summed[5:10] = [1e-100, 0.0, 0.0]  # tiny but not cancelled: a unit vector
        summed[10] = [1.0, 1e-13, 0.0]
        summed[11] = [1e-300, 1e-310, 0.0]  # subnormal components
        summed[12] = [np.nan, 0.0, 1.0]
        summed[13] = [np.inf, 0.0, 1.0]
    else:
        vertices, faces = mesh(name)
        with use_backend("numpy"):
            summed = np.zeros_like(vertices)
            np.add.at(summed, faces.ravel(), np.repeat(geometry.face_cross_products(vertices, faces), 3, axis=0))
    with use_backend("numpy"):
        expected = geometry.normalize_normal_sums(summed)
    # one norm, one comparison, three divisions per row on both sides
    np.testing.assert_array_equal(kernels("geometry").normalize_normal_sums(summed), expected)


def check_edge_lengths(name):
    from meshcurv import geometry

    vertices, _ = mesh(name)
    edges = topology(name).edges
    with use_backend("numpy"):
        expected = geometry.edge_lengths(vertices, edges)
    # einsum adds the three squares as (x^2 + z^2) + y^2 (its SIMD pairing), the kernel left to right:
    # sums of the same three positive terms within 2 eps of each other, halved by the square root,
    # plus its own rounding (half an ulp each side)
    np.testing.assert_allclose(kernels("geometry").edge_lengths(vertices, edges), expected, rtol=2 * EPS, atol=0)


def check_vertex_edge_lengths(name):
    from meshcurv import geometry

    vertices, _ = mesh(name)
    edges = topology(name).edges
    with use_backend("numpy"):
        expected = geometry.vertex_edge_lengths(vertices, edges)
    # np.bincount over edges.ravel() adds each edge to both ends in edge order, as the kernel does, but
    # the lengths themselves differ by up to 2 eps (see check_edge_lengths): the means of at most
    # `degree` of them, rounded alike, within (degree + 2) eps
    degree = int(topology(name).vertex_degrees.max())
    np.testing.assert_allclose(
        kernels("geometry").vertex_edge_lengths(vertices, edges, vertices.shape[0]),
        expected,
        rtol=(degree + 2) * EPS,
        atol=0,
    )


def check_mean_edge_length(name):
    from meshcurv import geometry

    vertices, _ = mesh(name)
    edges = topology(name).edges
    with use_backend("numpy"):
        expected = geometry.mean_edge_length(vertices, edges)
        lengths = geometry.edge_lengths(vertices, edges)
    got = kernels("geometry").mean_edge_length(vertices, edges)
    # NumPy's pairwise sum against the kernel's parallel reduction of the same positive lengths
    assert_sums_close(got * edges.shape[0], expected * edges.shape[0], lengths.sum(), edges.shape[0])


# -- topology -----------------------------------------------------------------------------------


def check_build_edges(name):
    from meshcurv.topology import _build_edges

    vertices, faces = mesh(name)
    expected = _build_edges(faces, vertices.shape[0])
    for width in (np.int32, np.int64):  # the buckets in either integer type give the same edges
        got = kernels("topology").build_edges(faces, vertices.shape[0], np.zeros(0, width))
        for label, a, b in zip(("edges", "face_edges", "edge_faces", "counts", "forward"), got, expected):
            np.testing.assert_array_equal(a, b, err_msg=f"{label}, {width.__name__} buckets")


def check_bowtie_vertices(name):
    from meshcurv.topology import _bowtie_vertices

    top = topology(name)
    expected = _bowtie_vertices(top)
    # the inputs hold what they are meant to: the two spheres' contact, the fin's ends, the hole's pinches
    assert (expected.sum() > 1) if name == "defects" else not expected.any()
    linked = (top.edge_face_counts == 2) & (top.edge_faces[:, 0] != top.edge_faces[:, 1])  # as the wrapper
    got = kernels("topology").bowtie_vertices(
        top.faces, top.face_edges, top.edge_faces, linked, ~top.degenerate_faces, top.n_vertices
    )
    np.testing.assert_array_equal(got, expected)


def check_double_sided_suspects(name):
    from meshcurv.weld import double_sided_suspects

    _, faces = mesh(name)
    # the mesh, and the mesh stored double-sided (every face again, reversed: each edge non-manifold)
    for shown in (faces, np.vstack([faces, faces[:, ::-1]])):
        top = MeshTopology.from_faces(shown, topology(name).n_vertices)
        arrays = (top.faces, top.edge_faces, top.edge_face_counts, top._edge_forward_counts)
        with use_backend("numpy"):
            expected = double_sided_suspects(*arrays)
        np.testing.assert_array_equal(kernels("topology").double_sided_suspects(*arrays), expected)
        assert expected.all() if shown is not faces else not expected.any() or name == "defects"


def check_component_labels(name):
    top = topology(name)
    with use_backend("numpy"):
        count, labels = MeshTopology._build(top.faces, top.n_vertices).vertex_components
    got_labels, got_count = kernels("topology").component_labels(top.edges, top.referenced_vertices, top.n_vertices)
    assert got_count == count
    np.testing.assert_array_equal(got_labels, labels)


def check_neighbour_lists(name):
    top = topology(name)
    with use_backend("numpy"):
        expected = MeshTopology._build(top.faces, top.n_vertices).neighbour_lists
    got = kernels("topology").neighbour_lists(top.edges, top.n_vertices)
    # both list each vertex's neighbours in increasing order (scipy's CSR is canonical; the
    # kernel scans the sorted edges, where (p, v) with p < v comes before (v, q))
    np.testing.assert_array_equal(got[0], expected[0], err_msg="indptr")
    np.testing.assert_array_equal(got[1], expected[1], err_msg="indices")


# -- geometry: degenerate faces, and diagnosis --------------------------------------------------


def check_cross_and_degenerate(name):
    from meshcurv import geometry
    from meshcurv._geometry import DEGENERATE_AREA_RATIO, cross_and_degenerate, vertex_length_scales

    vertices, _ = mesh(name)
    top = topology(name)
    compiled = kernels("geometry").cross_and_degenerate
    with use_backend("numpy"):
        scales = vertex_length_scales(vertices, top)
        cross, degenerate = cross_and_degenerate(vertices, top.faces, scales, DEGENERATE_AREA_RATIO)
        one_scale = geometry.degenerate_faces(vertices, top, mean_edge_length=0.5)
        np.testing.assert_array_equal(geometry.degenerate_faces(vertices, top), degenerate)
    assert degenerate.sum() == (3 if name == "defects" else 0)
    got = compiled(vertices, top.faces, scales, DEGENERATE_AREA_RATIO)
    # the cross products as check_face_cross_products (the same products and differences); the area's three
    # squares are added in another association (einsum's), which could only matter for an area within an ulp of
    # the threshold: none here (the zero-area faces are exactly 0, the others far above 1e-12 of the squared scale)
    np.testing.assert_array_equal(got[0], cross)
    np.testing.assert_array_equal(got[1], degenerate)
    np.testing.assert_array_equal(
        compiled(vertices, top.faces, np.full(top.n_vertices, 0.5), DEGENERATE_AREA_RATIO)[1], one_scale
    )


def check_long_edges(name):
    from meshcurv.defects import NEEDLE_REACH
    from meshcurv.geometry import vertex_length_scales

    vertices, _ = mesh(name)
    vertices = vertices.copy()
    vertices[0] *= 1e3  # a vertex flung away: its edges are long
    top = topology(name)
    with use_backend("numpy"):
        reach = NEEDLE_REACH * vertex_length_scales(vertices, top)
    first, second = top.edges[:, 0], top.edges[:, 1]
    sides = vertices[second] - vertices[first]  # the NumPy path of defects.needle_vertices
    expected = np.einsum("ij,ij->i", sides, sides) > np.square(np.minimum(reach[first], reach[second]))
    np.testing.assert_array_equal(kernels("diagnosis").long_edges(vertices, top.edges, reach), expected)


def check_mesh_facts(name):
    from meshcurv import diagnosis
    from meshcurv.geometry import DEGENERATE_AREA_RATIO, face_cross_products, vertex_length_scales

    vertices, faces = mesh(name)
    top = topology(name)
    with use_backend("numpy"):
        scales = vertex_length_scales(vertices, top)
        facts = diagnosis.diagnose(vertices, top)
        cross = face_cross_products(vertices, faces)
    lower, upper, area, six_volume, mean, n_degenerate, n_zero_length = kernels("diagnosis").mesh_facts(
        vertices, faces, top.edges, top.referenced_vertices, scales, DEGENERATE_AREA_RATIO, diagnosis.ZERO_LENGTH_RATIO
    )
    # minima, maxima and counts are exact; the three sums are parallel reductions in another order
    np.testing.assert_array_equal(lower, facts.bounding_box[0])
    np.testing.assert_array_equal(upper, facts.bounding_box[1])
    assert n_degenerate == facts.n_degenerate_faces
    assert n_zero_length == facts.n_zero_length_edges
    double_areas = np.sqrt(np.einsum("ij,ij->i", cross, cross))
    assert_sums_close(area, facts.area, 0.5 * double_areas.sum(), faces.shape[0], "area")
    n_edges = top.edges.shape[0]
    assert_sums_close(
        mean * n_edges, facts.mean_edge_length * n_edges, facts.mean_edge_length * n_edges, n_edges, "mean edge length"
    )
    if facts.volume is not None:
        # each term (a - centre) . cross: the centre itself is a sum of V coordinates in another
        # order (a relative error of V eps in it), hence V + F terms
        reach = np.abs(vertices[top.referenced_vertices]).max() * 2
        magnitude = reach * double_areas.sum()
        assert_sums_close(six_volume, 6 * facts.volume, magnitude, faces.shape[0] + vertices.shape[0], "volume")


# -- normal cycle -------------------------------------------------------------------------------


def numpy_normal_cycle(name, monkeypatch, steps):
    """The NumPy path of ``normal_cycle.estimate``: its result and the (V, 7) measures and areas it smooths."""
    from meshcurv.estimators import normal_cycle
    from meshcurv._prepared import PreparedMesh
    from meshcurv.estimators._support import Stages

    vertices, _ = mesh(name)
    seen = []
    original = normal_cycle._smooth_vertex_field

    def record(values, top, n_steps):
        seen.append(np.array(values))
        return original(values, top, n_steps)

    with use_backend("numpy"), monkeypatch.context() as patch:
        patch.setattr(normal_cycle, "_smooth_vertex_field", record)
        result, _ = normal_cycle.estimate(
            PreparedMesh.as_given(vertices, topology(name)), smoothing_steps=steps, stages=Stages(normal_cycle.STAGES)
        )
    assert len(seen) == 1, "normal_cycle.estimate no longer smooths its sums in one call: update this test"
    return result, seen[0]


def compiled_normal_cycle_sums(name):
    from meshcurv.geometry import DEGENERATE_AREA_RATIO, vertex_length_scales

    vertices, _ = mesh(name)
    top = topology(name)
    with use_backend("numpy"):
        scales = vertex_length_scales(vertices, top)
    return kernels("normal_cycle").normal_cycle_sums(
        vertices,
        top.faces,
        top.edges,
        top.edge_faces,
        top.edge_face_counts,
        top._edge_forward_counts,
        scales,
        DEGENERATE_AREA_RATIO,
        kernel_threads(),
    )


def check_normal_cycle_sums(name, monkeypatch):
    from meshcurv import geometry
    from meshcurv.defects import VertexDefects, defect_codes

    vertices, _ = mesh(name)
    top = topology(name)
    result, measures = numpy_normal_cycle(name, monkeypatch, 0)
    with use_backend("numpy"):
        degenerate = geometry.degenerate_faces(vertices, top)
        invalid = VertexDefects(*defect_codes(top, degenerate)).invalid_vertices
    sums, got_degenerate = compiled_normal_cycle_sums(name)
    np.testing.assert_array_equal(got_degenerate, degenerate)
    # the NumPy path smooths the measures and areas of the valid vertices (the others zeroed)
    got = sums[:, :7] * (~invalid)[:, None]
    # the measures: the same edge terms (|beta| |e| / 2 <= pi |e| / 2 each, times unit products),
    # added to each vertex in another order (np.bincount: the edges where it is the first end, then the
    # others; the kernel: the edges in order), at most the vertex's degree of them
    degree = int(top.vertex_degrees.max())
    edge_lengths = np.linalg.norm(vertices[top.edges[:, 1]] - vertices[top.edges[:, 0]], axis=1)
    bound = np.bincount(top.edges.ravel(), np.repeat(np.pi / 2 * edge_lengths, 2), minlength=top.n_vertices)
    assert_sums_close(got[:, :6], measures[:, :6], bound[:, None], degree, "measures")
    # the areas: the same face thirds (the same norm) added in face order on both sides
    np.testing.assert_array_equal(got[:, 6], measures[:, 6], err_msg="areas")
    # the normals: the cross products of the non-degenerate faces, in face order on both sides
    with use_backend("numpy"):
        from meshcurv.geometry import normalize_normal_sums

        normals = normalize_normal_sums(sums[:, 7:])
    np.testing.assert_array_equal(normals, result.normals)


def check_normal_cycle_finish(name, monkeypatch):
    from meshcurv.defects import VertexDefects, defect_codes
    from meshcurv.smoothing import smooth_vertex_field

    top = topology(name)
    steps = 3
    result, measures = numpy_normal_cycle(name, monkeypatch, steps)
    sums, degenerate = compiled_normal_cycle_sums(name)
    invalid = VertexDefects(*defect_codes(top, degenerate)).invalid_vertices
    # the kernel from the NumPy path's measures and areas (and the normal sums, checked by normal_cycle_sums)
    given = np.ascontiguousarray(np.column_stack([measures, sums[:, 7:]]))
    indptr, indices = top.neighbour_lists
    k_min, k_max, dir_min, dir_max, normals, valid = kernels("normal_cycle").normal_cycle_finish(
        given, invalid, indptr, indices, steps
    )
    np.testing.assert_array_equal(valid, result.valid)
    np.testing.assert_array_equal(normals, result.normals)
    # Each smoothing pass adds a vertex's (degree + 1) values in another order (the sparse product:
    # the neighbours, then the vertex), within degree eps of their sum of |values|; averages pass
    # those errors on without growing them, so after the passes a measure is within
    # steps (degree + 1) eps of the same smoothing of |measures|, and so is the area (positive).
    # The tensor (measure / area) is then within that, relative to |measure| / area, and the tangent
    # restriction, the closed form (a few eps) and Weyl's bound (eigenvalues move by at most the
    # perturbation's norm, <= 3 x its largest entry) turn it into k's tolerance: 8 x that.
    degree = int(top.vertex_degrees.max())
    with use_backend("numpy"):
        absolute = smooth_vertex_field(np.abs(measures), top, steps)
    with np.errstate(invalid="ignore", divide="ignore"):
        size = absolute[:, :6].max(axis=1) / absolute[:, 6]
    atol = 8 * (steps * (degree + 1) + 8) * EPS * np.where(result.valid, size, 0.0)
    for label, got, expected in (("k_min", k_min, result.k_min), ("k_max", k_max, result.k_max)):
        np.testing.assert_array_equal(np.isnan(got), np.isnan(expected), err_msg=label)
        difference = np.abs(got - expected)[result.valid]
        assert (difference <= atol[result.valid]).all(), f"{label}: largest difference {difference.max():.3g}"
    # a direction moves by the tensor's error over the eigenvalue gap; at (nearly) umbilic vertices
    # (the icosphere's) it is undefined and not compared
    gap = result.k_max - result.k_min
    separated = result.valid & (gap > 1e3 * atol)
    assert separated.sum() > (0 if name in ("icosphere", "noisy") else result.valid.sum() // 2)
    direction_atol = 4 * atol[separated] / gap[separated]
    # rotate=True: dir_min is the larger eigenvalue's direction before the rotation
    branch = atan2_branch(result.dir_min[separated], result.normals[separated], direction_atol)
    for label, got, expected in (("dir_min", dir_min, result.dir_min), ("dir_max", dir_max, result.dir_max)):
        np.testing.assert_array_equal(np.isnan(got), np.isnan(expected), err_msg=label)
        assert_directions_close(got[separated], expected[separated], direction_atol, label, up_to_sign=branch)


# -- tensors ------------------------------------------------------------------------------------


def tensors_and_normals(name):
    """(N, 6) symmetric tensors and (N, 3) unit normals: random ones, or a mesh's normal-cycle tensors."""
    rng = np.random.default_rng(11)
    if name == "random":
        tensor = rng.standard_normal((4000, 6)) * 10.0 ** rng.integers(-3, 4, (4000, 1))
        normals = rng.standard_normal((4000, 3))
        normals[:6] = [[0, 0, 1], [0, 1, 0], [1, 0, 0], [1, 1, 0], [0, 1, 1], [-1, -1, -1]]  # ties of |n|
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        tensor[6] = [2.0, 2.0, 2.0, 0.0, 0.0, 0.0]  # umbilic: b = a - c = 0 exactly, theta = 0 on both sides
        normals[7] = np.nan  # a missing normal: NaN rows
        return tensor, normals
    vertices, _ = mesh(name)
    sums, _ = compiled_normal_cycle_sums(name)
    with np.errstate(invalid="ignore", divide="ignore"):
        tensor = sums[:, :6] / sums[:, 6:7]
    normals = numpy_normals(name)
    keep = np.isfinite(tensor).all(axis=1) & np.isfinite(normals).all(axis=1)
    return np.ascontiguousarray(tensor[keep]), np.ascontiguousarray(normals[keep])


def check_principal_from_shape_operator(name):
    from meshcurv import _tensors

    tensor, normals = tensors_and_normals(name)
    magnitude = np.abs(tensor).max(axis=1)
    for rotate in (False, True):
        for mean_from_trace in (False, True):
            with use_backend("numpy"):
                expected = _tensors.principal_from_shape_operator(
                    tensor, normals, rotate=rotate, mean_from_trace=mean_from_trace
                )
            got = kernels("tensors").principal_from_shape_operator(tensor, normals, rotate, mean_from_trace)
            label = f"rotate={rotate}, mean_from_trace={mean_from_trace}"
            # the frame and T t are the same operations; einsum's three-term dots (a, b, c) add in
            # another association (within 2 eps of |T| each); hypot, arctan2, cos and sin are NumPy's
            # against the C library's (each within 1 ulp): k is within a few eps of |T| and a
            # direction within a few eps of |T| / (k_max - k_min), its condition number
            for k, (got_k, expected_k) in enumerate(zip(got[:2], expected[:2])):
                np.testing.assert_array_equal(np.isnan(got_k), np.isnan(expected_k))
                finite = ~np.isnan(expected_k)
                assert (np.abs(got_k - expected_k)[finite] <= 8 * EPS * magnitude[finite]).all(), (
                    f"{label}, k {k}: largest difference {np.nanmax(np.abs(got_k - expected_k)):.3g}"
                )
            gap = expected[1] - expected[0]
            finite = np.isfinite(gap)
            umbilic = gap[finite] == 0  # theta = atan2(0, 0) = 0 on both sides: the same frame
            atol = 16 * EPS * magnitude[finite] / np.where(umbilic, 1.0, gap[finite])
            atol[umbilic] = 4 * EPS
            along = (expected[2] if rotate else expected[3])[finite]
            branch = atan2_branch(along, normals[finite], atol)
            for got_d, expected_d in zip(got[2:], expected[2:]):
                np.testing.assert_array_equal(np.isnan(got_d), np.isnan(expected_d))
                assert_directions_close(got_d[finite], expected_d[finite], atol, label, up_to_sign=branch)


# -- matGeom ------------------------------------------------------------------------------------


def matgeom_pairing_of(name):
    """matGeom's (ev1, ev2, ef1, ef2) and out-of-range mask, as ``matgeom_tensors`` chooses them."""
    from meshcurv.estimators.matgeom import matgeom_pairing

    top = topology(name)
    vertices, faces = mesh(name)
    if top.interior_edges.all() and not top.degenerate_faces.any():
        ev1, ev2 = top.edges[:, 0], top.edges[:, 1]
        ef1, ef2 = top.edge_faces[:, 0], top.edge_faces[:, 1]
    else:
        ev1, ev2, ef1, ef2 = matgeom_pairing(faces, vertices.shape[0])
    return ev1, ev2, ef1, ef2, (ef1 >= faces.shape[0]) | (ef2 >= faces.shape[0])


def check_matgeom_vertex_tensors(name):
    from meshcurv.estimators.matgeom import _vertex_tensors

    vertices, faces = mesh(name)
    ev1, ev2, ef1, ef2, out_of_range = matgeom_pairing_of(name)
    assert out_of_range.any() == (name == "defects")
    expected = _vertex_tensors(
        vertices, faces, ev1, ev2, np.where(out_of_range, 0, ef1), np.where(out_of_range, 0, ef2), out_of_range
    )
    got = kernels("matgeom").matgeom_vertex_tensors(vertices, faces, ev1, ev2, ef1, ef2, kernel_threads())
    # each edge's term is the same operations in the same order (Octave's), except that (1) the mean
    # edge length is NumPy's pairwise sum against the kernel's loop, within E eps of each other: the
    # same factor on every weight, so on every tensor (relative to its value), the quotient d / mean
    # rounded apart (eps per term); and (2) np.bincount adds a vertex's edges in another order than
    # the kernel: (count - 1) eps of the sum of |terms| (|beta| <= pi, |e e^T| <= 1)
    lengths = np.linalg.norm(vertices[ev2] - vertices[ev1], axis=1)
    weights = np.pi * lengths / lengths.mean()
    ends = np.concatenate([ev1, ev2])
    counts = np.maximum(np.bincount(ends, minlength=vertices.shape[0]), 1)
    magnitude = np.bincount(ends, np.tile(weights, 2), minlength=vertices.shape[0]) / counts
    assert_sums_close(got, expected, magnitude[:, None], int(counts.max()) + 2, "tensors", relative=ev1.size * EPS)


def check_matgeom_principal(name):
    from meshcurv.estimators import matgeom
    from meshcurv._prepared import PreparedMesh
    from meshcurv.estimators._support import Stages

    vertices, _ = mesh(name)
    top = topology(name)
    with use_backend("numpy"):
        tensors, *_ = matgeom.matgeom_tensors(vertices, top, 3)
        result, _ = matgeom.estimate(
            PreparedMesh.as_given(vertices, top), smoothing_steps=3, stages=Stages(matgeom.STAGES)
        )
    c1, c2, u1, u2, normal = kernels("matgeom").matgeom_principal(np.ascontiguousarray(tensors))
    # cyclic Jacobi against LAPACK's eigh: both backward stable, eigenvalues within p eps |T| (Frobenius)
    # with a small p (at most 6 on these meshes: 16 leaves a margin); eigenvectors within that over the
    # gap to the nearest eigenvalue, and each defined up to its sign only (neither solver fixes it);
    # where two eigenvalues have (nearly) equal magnitudes their order is undefined: not compared
    six = np.nan_to_num(tensors, nan=0.0)
    frobenius = np.sqrt((six[:, :3] ** 2).sum(axis=1) + 2 * (six[:, 3:] ** 2).sum(axis=1))
    for label, got, expected in (("c1", c1, result.k_min), ("c2", c2, result.k_max)):
        np.testing.assert_array_equal(np.isnan(got), np.isnan(expected), err_msg=label)
        finite = ~np.isnan(expected)
        difference = np.abs(got - expected)[finite]
        assert (difference <= 16 * EPS * frobenius[finite]).all(), f"{label}: largest difference {difference.max():.3g}"
    with use_backend("numpy"):
        from meshcurv.estimators._eigen import sorted_by_magnitude

        values, _ = sorted_by_magnitude(tensors)
    magnitudes = np.abs(values)
    gaps = np.minimum(magnitudes[:, 1] - magnitudes[:, 0], magnitudes[:, 2] - magnitudes[:, 1])
    with np.errstate(invalid="ignore", divide="ignore"):
        atol = 2 * 16 * EPS * frobenius / gaps  # each solver within 16 eps |T| / gap
    # all three eigenvalues apart (the vectors then defined up to sign) and not a zero tensor
    separated = np.isfinite(gaps) & (gaps > 1e6 * EPS * frobenius)
    assert separated.sum() > (0 if name in ("icosphere", "noisy") else tensors.shape[0] // 2)
    for label, got, expected in (
        ("u1", u1, result.dir_min),
        ("u2", u2, result.dir_max),
        ("normal", normal, result.normals),
    ):
        np.testing.assert_array_equal(np.isnan(got), np.isnan(expected), err_msg=label)
        assert_directions_close(got[separated], expected[separated], atol[separated], label, up_to_sign=True)


def check_matgeom_finish(name):
    """Its twins composed: smooth_over_neighbours, then matgeom_principal (each checked against NumPy above), to the bit."""
    vertices, faces = mesh(name)
    ev1, ev2, ef1, ef2, _ = matgeom_pairing_of(name)
    tensors = kernels("matgeom").matgeom_vertex_tensors(vertices, faces, ev1, ev2, ef1, ef2, kernel_threads())
    indptr, indices = topology(name).neighbour_lists
    for steps in (0, 1, 2, 3, 4):  # odd and even: the last pass reads either buffer
        smoothed = kernels("smoothing").smooth_over_neighbours(tensors, indptr, indices, steps)
        expected = kernels("matgeom").matgeom_principal(smoothed)
        got = kernels("matgeom").matgeom_finish(tensors.copy(), indptr, indices, steps)
        for label, a, b in zip(("c1", "c2", "u1", "u2", "normal"), got, expected, strict=True):
            np.testing.assert_array_equal(a, b, err_msg=f"{label}, {steps} steps")


# -- smoothing ----------------------------------------------------------------------------------


def check_smooth_over_neighbours(name):
    from meshcurv.smoothing import smooth_vertex_field

    vertices, _ = mesh(name)
    top = topology(name)
    rng = np.random.default_rng(5)
    field = np.column_stack([vertices, rng.standard_normal((vertices.shape[0], 2))])
    field[3, 1] = np.nan  # NaN spreads one ring per pass on both sides
    indptr, indices = top.neighbour_lists
    degree = int(top.vertex_degrees.max())
    magnitude = np.nanmax(np.abs(field), axis=0)
    for steps in (1, 4):
        with use_backend("numpy"):
            expected = smooth_vertex_field(field, top, steps)
            expected_flat = smooth_vertex_field(field[:, 0], top, steps)
        got = kernels("smoothing").smooth_over_neighbours(field, indptr, indices, steps)
        # each pass adds a vertex's degree + 1 values in another order (the sparse product: the
        # neighbours, then the vertex; the kernel: the vertex, then its neighbours) and scales them
        # alike: within 2 (degree + 1) eps of the largest |value| per pass
        assert_sums_close(got, expected, magnitude, steps * (degree + 1), f"{steps} passes")
        got_flat = kernels("smoothing").smooth_over_neighbours(
            np.ascontiguousarray(field[:, :1]), indptr, indices, steps
        )[:, 0]
        assert_sums_close(got_flat, expected_flat, magnitude[0], steps * (degree + 1), f"{steps} passes, (V,)")


# -- icc ----------------------------------------------------------------------------------------


def icc_normals(name):
    """Vertex normals with noise, and NaN rows at a few vertices (where a normal is undefined)."""
    normals = numpy_normals(name).copy()
    rng = np.random.default_rng(2)
    normals += 0.1 * rng.standard_normal(normals.shape)
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    normals[::97] = np.nan
    return np.ascontiguousarray(normals)


def check_face_measures(name):
    from meshcurv.estimators import icc

    vertices, faces = mesh(name)
    normals = icc_normals(name)
    with use_backend("numpy"):
        expected = icc.face_measures(vertices, faces, normals)
    got = kernels("icc").face_measures(vertices, faces, normals)
    # mu^{X,Y} (columns 3-8): the same products and differences as np.cross and the outer products
    np.testing.assert_array_equal(got[:, 3:], expected[:, 3:])
    # mu_0, mu_1, mu_2: three-term dots, which einsum adds as (x + z) + y and the kernel left to right,
    # within 2 eps of the sum of |terms| of each other; by Cauchy-Schwarz that sum is at most the
    # product of the two vectors' norms
    x0, x1, x2 = (vertices[faces[:, k]] for k in range(3))
    u0, u1, u2 = (np.linalg.norm(normals[faces[:, k]], axis=1) for k in range(3))
    mean = np.linalg.norm(normals[faces].mean(axis=1), axis=1)
    x01, x02 = np.linalg.norm(x1 - x0, axis=1), np.linalg.norm(x2 - x0, axis=1)
    corners = normals[faces]
    magnitude = 0.5 * np.column_stack(
        [
            mean * np.linalg.norm(np.cross(x1 - x0, x2 - x0), axis=1),
            mean
            * (
                np.linalg.norm(corners[:, 0] - corners[:, 2], axis=1) * x01
                + np.linalg.norm(corners[:, 1] - corners[:, 0], axis=1) * x02
            ),
            u0 * u1 * u2,
        ]
    )
    assert_sums_close(got[:, :3], expected[:, :3], magnitude, 3)


def check_curvatures_from_measures(name):
    from meshcurv._tensors import apply6
    from meshcurv.estimators import icc

    vertices, faces = mesh(name)
    normals = icc_normals(name)
    measures = icc.face_measures(vertices, faces, normals)
    # each vertex's measures summed over its faces (the 1-ring ball), and rows the step must leave NaN
    summed = np.zeros((vertices.shape[0], 9))
    for k in range(3):
        np.add.at(summed, faces[:, k], np.nan_to_num(measures))
    summed[1::50, 0] = 0.0  # no corrected area
    summed[2::50, 0] *= -1.0  # negative corrected area
    summed[3::50, 1] = np.inf  # an infinite mean curvature measure: k NaN, directions finite
    summed = np.ascontiguousarray(summed)
    with use_backend("numpy"):
        expected = icc.curvatures_from_measures(summed, normals)
    got = kernels("icc").curvatures_from_measures(summed, normals)
    # k: the same divisions, frexp/ldexp scaling and square root (exact operations in both)
    for label, got_k, expected_k in zip(("k_min", "k_max"), got[:2], expected[:2]):
        np.testing.assert_array_equal(got_k, expected_k, err_msg=label)
    assert np.isnan(got[0][1::50]).all() and np.isnan(got[0][2::50]).all() and np.isnan(got[0][::97]).all()
    # the directions: _tangent_eigen of the shape operator -sym(mu^{X,Y}) / mu_0, within the bounds of
    # check_principal_from_shape_operator (the same closed form against NumPy's einsum association)
    with np.errstate(invalid="ignore", divide="ignore"):
        tensor = -summed[:, 3:] / summed[:, :1]
    magnitude = np.abs(tensor).max(axis=1)
    finite = np.isfinite(expected[2]).all(axis=1)
    # the eigen-gap of the tangent restriction, d_max . T d_max - d_min . T d_min: a direction is within
    # a few eps of |T| / gap (its condition number); an umbilic (gap 0) is the same frame on both sides
    d_min, d_max = expected[2][finite], expected[3][finite]
    gap = np.einsum("ij,ij->i", d_max, apply6(tensor[finite], d_max)) - np.einsum(
        "ij,ij->i", d_min, apply6(tensor[finite], d_min)
    )
    atol = np.where(gap > 0, 16 * EPS * magnitude[finite] / np.where(gap > 0, gap, 1.0), 4 * EPS)
    branch = atan2_branch(expected[3][finite], normals[finite], atol)
    for got_d, expected_d in zip(got[2:], expected[2:]):
        np.testing.assert_array_equal(np.isnan(got_d), np.isnan(expected_d))
        assert_directions_close(got_d[finite], expected_d[finite], atol, name, up_to_sign=branch)


# -- neighbourhoods -----------------------------------------------------------------------------


def check_vertex_face_lists(name):
    # no NumPy twin in the library (only the compiled walk uses these lists): the oracle is a
    # stable sort of the corners by vertex, the faces of each vertex in index order
    vertices, faces = mesh(name)
    order = np.argsort(faces.ravel(), kind="stable")
    indptr = np.concatenate([[0], np.cumsum(np.bincount(faces.ravel(), minlength=vertices.shape[0]))])
    for threads in (1, 2, 3, 64):  # each thread places its range of faces: the same lists however many
        got_indptr, got_indices = kernels("neighborhoods").vertex_face_lists(faces, vertices.shape[0], threads)
        np.testing.assert_array_equal(got_indptr, indptr)
        np.testing.assert_array_equal(got_indices, order // 3)


def check_reordering(name):
    # the mesh shuffled (vertices and faces), so that the order to find is not the identity
    from meshcurv import _locality

    vertices, faces = mesh(name)
    rng = np.random.default_rng(8)
    order = rng.permutation(vertices.shape[0])
    index = np.empty_like(order)
    index[order] = np.arange(order.size)
    vertices, faces = vertices[order], index[faces][rng.permutation(faces.shape[0])]
    with use_backend("numpy"):
        expected = _locality.reordering(vertices, faces)
    got = _locality.reordering(vertices, faces)  # the compiled kernel
    for field in ("order", "index", "face_order", "vertices", "faces"):
        np.testing.assert_array_equal(getattr(got, field), getattr(expected, field), err_msg=field)


def cells_of(name, kind):
    vertices, faces = mesh(name)
    return faces if kind == "faces" else np.ascontiguousarray(topology(name).edges)


def check_cell_centres(name):
    from meshcurv import neighborhoods

    vertices, _ = mesh(name)
    for kind in ("faces", "edges"):
        cells = cells_of(name, kind)
        # the NumPy path of neighborhoods._ball_sums (corners' mean, largest corner distance)
        with use_backend("numpy"):
            centres, reach = neighborhoods.cell_centres(vertices, cells)
        corners = vertices[cells]  # and the textbook formulas, to the bit on these meshes
        np.testing.assert_array_equal(centres, corners.mean(axis=1), err_msg=kind)
        np.testing.assert_array_equal(
            reach, np.linalg.norm(corners - centres[:, None, :], axis=2).max(axis=1), err_msg=kind
        )
        got_centres, got_reach = kernels("neighborhoods").cell_centres(vertices, cells)
        # the corners added in order and divided by their count; three squares added in order
        np.testing.assert_array_equal(got_centres, centres, err_msg=kind)
        np.testing.assert_array_equal(got_reach, reach, err_msg=kind)


def ball_values(name, kind):
    rng = np.random.default_rng(9)
    return rng.uniform(-1.0, 1.0, (cells_of(name, kind).shape[0], 3))


def numpy_ball_sums(name, kind, values, radius, usable=None, *, connected=False):
    """The NumPy path of ``ball_face_sums`` / ``ball_edge_sums``, and the same sums of ``|values|``
    (``connected``: over the surface-connected piece of each ball, faces only)."""
    from meshcurv import neighborhoods

    vertices, _ = mesh(name)
    cells = cells_of(name, kind)
    with use_backend("numpy"):
        if kind == "faces":
            return (
                neighborhoods.ball_face_sums(vertices, cells, radius, values, usable=usable, connected=connected),
                neighborhoods.ball_face_sums(
                    vertices, cells, radius, np.abs(values), usable=usable, connected=connected
                ),
            )
        return (
            neighborhoods.ball_edge_sums(vertices, cells, radius, values, usable=usable),
            neighborhoods.ball_edge_sums(vertices, cells, radius, np.abs(values), usable=usable),
        )


def ball_terms(name, kind, radius):
    """A bound on the cells of a ball: those whose centroid is within radius + largest reach of a vertex."""
    from scipy.spatial import cKDTree

    vertices, _ = mesh(name)
    corners = vertices[cells_of(name, kind)]
    centres = corners.mean(axis=1)
    reach = np.linalg.norm(corners - centres[:, None, :], axis=2).max()
    return int(max(len(found) for found in cKDTree(centres).query_ball_point(vertices, radius + reach)))


def check_ball_cell_sums(name):
    vertices, _ = mesh(name)
    radius = 2.0 * mean_edge(name)
    compiled = kernels("neighborhoods")
    for kind in ("faces", "edges"):
        cells = cells_of(name, kind)
        values = ball_values(name, kind)
        expected, magnitude = numpy_ball_sums(name, kind, values, radius)
        centres, reach = compiled.cell_centres(vertices, cells)
        cutoff = radius + float(reach.max())  # one group of cells, searched with their largest reach
        got = compiled.ball_cell_sums(
            vertices, cells, centres, values, radius, cutoff, 64 * kernel_threads(), 0, vertices.shape[0]
        )
        # the same weights (face_in_ball_ratios / segment_in_ball_lengths: the same operations),
        # summed in grid order against the k-d tree's sparse product
        assert_sums_close(got, expected, magnitude, ball_terms(name, kind, radius), kind)
        assert np.count_nonzero(expected) > expected.size // 2


def check_connected_face_sums(name):
    # 0.95 edges: the ball leaves out most corners of the 1-ring, whose sides still cross it (the walk must go on
    # through the ends of a side that meets the ball with both ends outside); 2 edges: a ball of several rings
    for edges in (0.95, 2.0):
        check_connected_face_sums_at(name, edges * mean_edge(name))
    check_connected_face_sums_per_vertex(name)


@functools.cache
def face_sum_inputs(name):
    """``(vertices, faces, kernels, values, usable, centroids, reach, n, indptr, indices)`` of the walks' sums."""
    vertices, faces = mesh(name)
    compiled = kernels("neighborhoods")
    centres, reach = compiled.cell_centres(vertices, faces)
    n = vertices.shape[0]
    return (
        vertices,
        faces,
        compiled,
        ball_values(name, "faces"),
        np.random.default_rng(4).random(faces.shape[0]) > 0.1,
        centres,
        reach,
        n,
        *compiled.vertex_face_lists(faces, n, kernel_threads()),
    )


def walked_face_sums(name, values, radii, usable, *, scratch=None, into=None, start=0, stop=None):
    """The compiled walks' sums of the mesh ``name`` for the vertices ``[start, stop)`` (all by default).

    ``connected_face_sums`` for 1-D ``radii`` (one, or one per vertex), into ``into`` of shape (V, m);
    ``connected_face_sums_nested`` for 2-D ``radii`` (one row per level, of 1 or V radii) and ``values`` of one
    set or one per level, into (levels, V, m). ``into`` is new zeros when None; ``scratch`` by default one chunk a
    kernel thread (:func:`meshcurv.neighborhoods._face_sum_scratch`).
    """
    vertices, faces, compiled, _, _, centres, reach, n, indptr, indices = face_sum_inputs(name)
    nested = radii.ndim == 2
    if into is None:
        into = np.zeros(((radii.shape[0],) if nested else ()) + (n, values.shape[-1]))
    if scratch is None:
        scratch = _face_sum_scratch(kernel_threads(), n, faces.shape[0], nested and radii.shape[0] > 1)
    walk = compiled.connected_face_sums_nested if nested else compiled.connected_face_sums
    stop = n if stop is None else stop
    walk(
        vertices,
        faces,
        centres,
        reach,
        usable,
        values,
        np.ascontiguousarray(radii),
        indptr,
        indices,
        into,
        scratch,
        start,
        stop,
    )
    return into


def check_connected_face_sums_per_vertex(name):
    """A radius per vertex: the NumPy path's sums at those radii (the same faces and shares, in another order)."""
    _, _, _, values, usable, _, _, n, _, _ = face_sum_inputs(name)
    radii = np.random.default_rng(2).uniform(0.9, 2.5, n) * mean_edge(name)
    got = walked_face_sums(name, values, radii, usable)
    expected, magnitude = numpy_ball_sums(name, "faces", values, radii, usable, connected=True)
    assert_sums_close(got, expected, magnitude, ball_terms(name, "faces", float(radii.max())), "a radius per vertex")


def check_connected_face_sums_nested(name):
    """Nested radii (one for all, or per vertex; the same values or one set per radius) in one walk: each row
    against the NumPy path's sums at that row's radii (the same faces and shares, summed in another order)."""
    _, _, _, values, usable, _, _, n, _, _ = face_sum_inputs(name)
    h = mean_edge(name)
    per_vertex = np.random.default_rng(2).uniform(0.9, 2.5, n) * h
    sets = np.stack([values, -2.0 * values, values[::-1].copy()])  # one set of values per radius
    for radii, given in (
        (per_vertex[None, :], values[None]),
        (np.array([0.5, 1.0, 2.0])[:, None] * per_vertex, sets),
        (np.array([[0.95], [2.0], [4.0]]) * h, values[None]),
    ):
        got = walked_face_sums(name, given, radii, usable)
        for r, row in enumerate(radii):
            radius = row[0] if row.size == 1 else row
            expected, magnitude = numpy_ball_sums(
                name, "faces", given[r if given.shape[0] > 1 else 0], radius, usable, connected=True
            )
            assert_sums_close(
                got[r],
                expected,
                magnitude,
                ball_terms(name, "faces", float(np.max(radius))),
                f"{radii.shape[0]} radii, row {r}",
            )


def check_connected_face_sums_at(name, radius):
    _, faces, _, values, usable, _, _, n, _, _ = face_sum_inputs(name)
    for mask in (None, usable):
        # the same faces as the NumPy path's connected pieces (the walk's, found by connected
        # components of all balls at once), summed in another order
        expected, magnitude = numpy_ball_sums(name, "faces", values, radius, mask, connected=True)
        allowed = np.ones(faces.shape[0], dtype=bool) if mask is None else mask
        radii = np.array([radius])  # one radius for all vertices
        got = walked_face_sums(name, values, radii, allowed)
        assert_sums_close(
            got, expected, magnitude, ball_terms(name, "faces", radius), "all faces" if mask is None else "usable faces"
        )
        # ranges of centres, one scratch for all (as the calls of ball_face_sums): only their rows each time;
        # with the int64 scratch of meshes whose indices do not fit in int32 (this one's are int32)
        scratch = tuple(
            a.astype(np.int64) if a.dtype == np.int32 else a for a in _face_sum_scratch(3, n, faces.shape[0])
        )
        part = walked_face_sums(name, values, radii, allowed, scratch=scratch, start=n // 3, stop=n // 2)
        np.testing.assert_array_equal(part[n // 3 : n // 2], got[n // 3 : n // 2])
        assert not part[: n // 3].any() and not part[n // 2 :].any()
        for lo, hi in ((0, n // 3), (n // 2, n)):
            walked_face_sums(name, values, radii, allowed, scratch=scratch, into=part, start=lo, stop=hi)
        np.testing.assert_array_equal(part, got)


def test_face_sum_scratch_takes_int64_only_beyond_int32_indices():
    small = _face_sum_scratch(2, 10, 16)
    assert [a.dtype for a in small] == [np.int32, np.int32, np.int32, np.float64, np.int32, np.int32, np.int32]
    assert [a.shape for a in small] == [(2, 16), (2, 10), (2, 10), (2, 10), (2, 10), (2, 0), (2, 0)]
    assert all((a == -1).all() for a in small[:3])
    # nested: the level of each queued vertex (V); the clusters' spare stays empty
    assert [a.shape for a in _face_sum_scratch(2, 10, 16, nested=True)[5:]] == [(2, 10), (2, 0)]
    # no chunks: the dtype is chosen without allocating a mesh of 2^31 faces
    large = _face_sum_scratch(0, 10, 2**31)
    assert [a.dtype for a in large] == [np.int64, np.int64, np.int64, np.float64, np.int64, np.int64, np.int64]


# -- jets ---------------------------------------------------------------------------------------


def jet_inputs(name):
    """``(points, normals, radius, adjacency)``: a clean mesh (with its neighbour lists) or a cloud."""
    if name in CLOUDS:
        points, normals = cloud(name)
        return points, normals, (0.5 if name == "ellipsoid_cloud" else 0.15), None
    vertices, _ = mesh(name)
    return vertices, numpy_normals(name), 3.0 * mean_edge(name), topology(name).neighbour_lists


def jet_conditions(points, pool, centres, radius, frame, degree, counts, adjacency=None):
    """(N,) condition number of the scaled normal matrix each NumPy fit solved in ``frame`` (NaN: none).

    ``radius``: one for all, or one per centre.

    The matrices of :func:`meshcurv.jets._fit_chunk` over the same balls (the surface-connected
    pieces with ``adjacency``), the degree chosen as ``jets._solve`` chooses it (the highest whose
    points are spread, :data:`meshcurv.jets.MIN_SPREAD`).
    """
    from meshcurv import jets
    from meshcurv.neighborhoods import _ball_pairs, connected_ball_pairs

    conditions = np.full(points.shape[0], np.nan)
    if adjacency is None:
        balls = (
            (chunk, centre, pool[neighbour])
            for chunk, centre, neighbour in _ball_pairs(points[pool], points[centres], radius)
        )
    else:
        allowed = np.zeros(points.shape[0], dtype=bool)
        allowed[pool] = True
        balls = connected_ball_pairs(points, centres, radius, adjacency, allowed)
    for chunk, centre, neighbour in balls:
        index, rows = centres[chunk], centre - chunk.start
        offsets = (points[neighbour] - points[index[rows]]) / (radius[centre][:, None] if np.ndim(radius) else radius)
        weights = np.maximum(1.0 - np.einsum("ij,ij->i", offsets, offsets), 0.0) ** 2
        matrix, right = jets._fit_chunk(offsets, rows, index.size, [part[index] for part in frame], weights, degree)
        todo = np.ones(index.size, dtype=bool)
        for d in range(degree, 1, -1):
            m = jets._n_terms(d)
            candidates = np.flatnonzero(todo & (counts[index] >= m))
            if candidates.size == 0:
                continue
            _, ok, scaled = jets._solve_block(matrix[candidates, :m, :m], right[candidates, :m], d)
            conditions[index[candidates[ok]]] = np.linalg.cond(scaled[ok])
            todo[candidates[ok]] = False
    return conditions


def compare_jets(got, expected, label, fit, adjacency=None):
    """``(coefficients, frame, counts)`` of two fits of the same balls; ``fit``: ``(points, normals,
    radius, centres, pool, degree)`` of both; ``adjacency``: the balls are the surface-connected pieces."""
    from meshcurv import jets
    from meshcurv._tensors import tangent_basis

    coefficients, frame, counts = expected
    got_coefficients, got_frame, got_counts = got
    points, normals, radius, centres, pool, degree = fit
    np.testing.assert_array_equal(got_counts, counts, err_msg=f"{label}: counts")
    np.testing.assert_array_equal(np.isnan(got_coefficients), np.isnan(coefficients), err_msg=f"{label}: fitted")
    # The moments are sums over the ball in another order (grid or walk against k-d tree pairs),
    # perturbing each by at most n eps relative (n: the ball's points); to first order the solution
    # then moves by the scaled matrix's condition number times that, relative to its size (Higham
    # 2002, sec. 7.1), and the second fit inherits the first one's error through its frame: the
    # larger of the two fits' condition numbers. Coefficients are in units of the radius.
    conditions = np.fmax(
        jet_conditions(points, pool, centres, radius, [*tangent_basis(normals), normals], degree, counts, adjacency),
        jet_conditions(points, pool, centres, radius, frame, degree, counts, adjacency),
    )
    size = np.maximum(np.nan_to_num(np.abs(coefficients), nan=0.0).max(axis=1), 1.0)
    # where no fit was possible the frame is the first one: tangent_basis's operations, exact
    atol = np.where(np.isnan(conditions), 4 * EPS, conditions * np.maximum(counts, 1) * EPS * size)[centres]
    # Where two components of the normal tie in magnitude (the icosphere's symmetric vertices),
    # tangent_basis takes the first and the kernel's frame may take the other on a rounding of the
    # normal: a frame turned by 90 degrees, in which the same jet has other coefficients. There
    # the frame-free quantities are compared: the normal, the jet's normal and its shape operator.
    smallest = np.sort(np.abs(frame[2][centres]), axis=1)[:, :2]
    tie = np.abs(smallest[:, 1] - smallest[:, 0]) <= atol
    turned = tie & (np.abs(got_frame[0][centres] - frame[0][centres]).max(axis=1) > atol)
    assert turned.sum() <= max(2, centres.size // 100), f"{label}: {turned.sum()} frames turned"
    same = centres[~turned]
    assert_directions_close(got_coefficients[same], coefficients[same], atol[~turned], f"{label}: coefficients")
    for part, got_part, expected_part in zip(("t1", "t2", "n"), got_frame, frame):
        assert_directions_close(got_part[same], expected_part[same], atol[~turned], f"{label}: {part}")
    other = centres[turned]
    assert_directions_close(got_frame[2][other], frame[2][other], atol[turned], f"{label}: n (turned frames)")
    with use_backend("numpy"):
        six, fitted = jets.shape_operators(coefficients[other], [part[other] for part in frame], 1.0)
        got_six, got_fitted = jets.shape_operators(got_coefficients[other], [part[other] for part in got_frame], 1.0)
    assert_directions_close(got_fitted, fitted, atol[turned], f"{label}: jet normals (turned frames)")
    assert_directions_close(
        got_six, six, atol[turned] * size[centres][turned], f"{label}: shape operators (turned frames)"
    )


def check_fit_jet_pairs(name):
    from meshcurv import jets

    points, normals, radius, _ = jet_inputs(name)
    n = points.shape[0]
    rng = np.random.default_rng(10)
    pool_mask = rng.random(n) > 0.1  # some points stay out of every ball
    pool = np.flatnonzero(pool_mask)
    centres = np.flatnonzero(rng.random(n) > 0.5)
    facing = normals.copy()
    facing[rng.random(n) < 0.02] *= -1  # a few normals facing away: some balls refused
    larger = radius * 2.0**0.5
    for degree, check in ((3, True), (4, False)):
        arguments = (jets._exponents(degree), jets.MIN_SPREAD, centres, 64 * kernel_threads(), pool)
        options = (facing if check else points, check, jets.AWAY_FRACTION, 0.0, np.zeros(0))
        got = kernels("jets").fit_jet_pairs(
            points, normals, np.array([radius]), larger, degree, jets.ITERATIONS, *arguments, *options
        )
        label = f"degree {degree}, facing {check}"
        # the smaller balls: the points of the larger walk within the radius, in the order of fit_jets' own walk
        alone = kernels("jets").fit_jets(
            points, normals, np.array([radius]), degree, jets.ITERATIONS, *arguments, *options
        )
        for got_part, expected_part in zip(got[:6], alone):
            np.testing.assert_array_equal(got_part, expected_part, err_msg=f"{label}: smaller balls")
        # both radii against the NumPy fits (the larger balls' sums in another order: compare_jets' tolerance)
        for k, r in enumerate((radius, larger)):
            with use_backend("numpy"):
                expected = jets.fit_jets(
                    points,
                    normals,
                    r,
                    degree=degree,
                    centres=centres,
                    neighbours=pool_mask,
                    facing=facing if check else None,
                )
            coefficients, t1, t2, normal, counts, _ = got[6 * k : 6 * k + 6]
            compare_jets(
                (coefficients, (t1, t2, normal), counts),
                expected,
                f"{label}, radius {r:g}",
                (points, normals, r, centres, pool, degree),
            )


def check_jet_curvatures(name):
    from meshcurv import jets

    points, normals, radius, _ = jet_inputs(name)
    n = points.shape[0]
    rng = np.random.default_rng(9)
    coefficients, frame, _ = jets.fit_jets(points, normals, radius, degree=3)
    coefficients[rng.random(n) < 0.05] = np.nan  # failed fits: NaN, and the given normals
    radii = radius * rng.uniform(0.7, 1.4, n)
    with use_backend("numpy"):
        expected = jets.jet_curvatures(coefficients, frame, radii, normals)
    got = kernels("jets").jet_curvatures(coefficients, frame, radii, normals)
    # the normals: the same operations in the same order
    np.testing.assert_array_equal(got[4], expected[4])
    # the shape operator: NumPy's matmul adds its second product by a fused multiply-add here (its BLAS), as the
    # kernel does (equal to the bit on this project's machines); another BLAS may round each of its products'
    # entries otherwise, within 2 eps of |T|. The tangent eigen-problem: k within 8 eps of |T| and directions
    # within 16 eps of |T| / (k_max - k_min) (check_principal_from_shape_operator)
    six, _ = jets.shape_operators(coefficients, frame, 1.0)
    magnitude = np.abs(six / radii[:, None]).max(axis=1)
    for got_k, expected_k in zip(got[:2], expected[:2]):
        np.testing.assert_array_equal(np.isnan(got_k), np.isnan(expected_k))
        finite = ~np.isnan(expected_k)
        assert (np.abs(got_k - expected_k)[finite] <= 16 * EPS * magnitude[finite]).all()
    gap = expected[1] - expected[0]
    finite = np.isfinite(gap)
    atol = 32 * EPS * magnitude[finite] / np.where(gap[finite] == 0, 1.0, gap[finite])
    branch = atan2_branch(expected[3][finite], expected[4][finite], atol)
    for got_d, expected_d in zip(got[2:4], expected[2:4]):
        np.testing.assert_array_equal(np.isnan(got_d), np.isnan(expected_d))
        assert_directions_close(got_d[finite], expected_d[finite], atol, name, up_to_sign=branch)


def check_fit_jets(name):
    from meshcurv import jets

    points, normals, radius, _ = jet_inputs(name)
    n = points.shape[0]
    rng = np.random.default_rng(8)
    pool_mask = rng.random(n) > 0.1  # some points stay out of every ball
    centres = np.flatnonzero(rng.random(n) > 0.5)
    facing = normals.copy()
    facing[rng.random(n) < 0.02] *= -1  # a few normals facing away: some balls refused
    facing[rng.random(n) < 0.01] = np.nan  # and a few missing: not counted
    per_centre = radius * rng.uniform(1.0, 1.4, centres.size)  # a radius per centre (no smaller balls)
    areas = rng.uniform(0.5, 2.0, n)  # points weighted by their areas (a mesh whose sampling varies)
    for degree, mask, check, radii, weights in (
        (4, None, False, radius, None),
        (3, pool_mask, True, radius, None),
        (2, None, True, radius, None),
        (3, pool_mask, False, per_centre, None),
        (3, pool_mask, True, radius, areas),
    ):
        details = {}
        with use_backend("numpy"):
            expected = jets.fit_jets(
                points,
                normals,
                radii,
                degree=degree,
                centres=centres,
                neighbours=mask,
                facing=facing if check else None,
                details=details,
                areas=weights,
            )
        pool = np.arange(n) if mask is None else np.flatnonzero(mask)
        by_vertex = spread(radii, centres, n, 0.0) if np.ndim(radii) else np.array([radius])
        found = kernels("jets").fit_jets(
            points,
            normals,
            by_vertex,
            degree,
            jets.ITERATIONS,
            jets._exponents(degree),
            jets.MIN_SPREAD,
            centres,
            64 * kernel_threads(),
            pool,
            facing if check else points,
            check,
            jets.AWAY_FRACTION,
            0.0,
            np.zeros(0) if weights is None else weights,
        )
        coefficients, t1, t2, normal, counts, away = found
        label = (
            f"degree {degree}, pool {'all' if mask is None else 'some'}, facing {check}, radii {np.size(radii)}, "
            f"areas {weights is not None}"
        )
        compare_jets(
            (coefficients, (t1, t2, normal), counts), expected, label, (points, normals, radii, centres, pool, degree)
        )
        # the shares facing away: the same counts divided alike
        np.testing.assert_array_equal(away, details["away"], err_msg=f"{label}: away")
        if check:
            assert 0 < np.isnan(expected[0][centres]).any(axis=1).sum() < centres.size // 2, label


def spread(rows, centres, n, fill):
    """(n, ...) rows of all vertices from the rows of ``centres``, ``fill`` elsewhere."""
    out = np.full((n, *rows.shape[1:]), fill)
    out[centres] = rows
    return out


def check_fit_jets_connected(name):
    from meshcurv import jets

    points, normals, radius, (indptr, indices) = jet_inputs(name)
    n = points.shape[0]
    rng = np.random.default_rng(6)
    allowed = rng.random(n) > 0.1
    centres = np.flatnonzero(rng.random(n) > 0.5)
    facing = normals.copy()
    facing[rng.random(n) < 0.02] *= -1
    compiled = kernels("jets").fit_jets_connected
    per_centre = radius * rng.uniform(1.0, 1.4, centres.size)  # a radius per centre (no smaller balls)
    areas = rng.uniform(0.5, 2.0, n)
    for degree, mask, check, radii, weights in (
        (4, None, False, radius, None),
        (3, allowed, True, radius, None),
        (3, allowed, True, per_centre, None),
        (3, allowed, False, radius, areas),
    ):
        # the NumPy path's connected balls (the walk's, found by connected components of all balls at once)
        details = {}
        with use_backend("numpy"):
            expected = jets.fit_jets(
                points,
                normals,
                radii,
                degree=degree,
                centres=centres,
                neighbours=mask,
                facing=facing if check else None,
                details=details,
                adjacency=(indptr, indices),
                areas=weights,
            )
        arguments = (
            points,
            normals,
            radii if np.ndim(radii) else np.array([radius]),
            degree,
            jets.ITERATIONS,
            jets._exponents(degree),
            jets.MIN_SPREAD,
            centres,
            kernel_threads(),
            np.ones(n, dtype=bool) if mask is None else mask,
            indptr,
            indices,
            facing if check else points,
            check,
            jets.AWAY_FRACTION,
        )
        # one row per centre: spread to rows of all vertices (NaN, counts 0, elsewhere) as NumPy gives them
        extra = (0.0, np.zeros(0) if weights is None else weights)  # settled, areas
        rows = compiled(*arguments, False, *extra)
        assert all(row.shape[0] == centres.size for row in rows)
        coefficients, t1, t2, normal, counts, away = (
            spread(row, centres, n, 0.0 if k == 4 else np.nan) for k, row in enumerate(rows)
        )
        label = (
            f"degree {degree}, {'all' if mask is None else 'some'} allowed, facing {check}, radii {np.size(radii)}, "
            f"areas {weights is not None}"
        )
        pool = np.arange(n) if mask is None else np.flatnonzero(mask)
        compare_jets(
            (coefficients, (t1, t2, normal), counts),
            expected,
            label,
            (points, normals, radii, centres, pool, degree),
            (indptr, indices),
        )
        np.testing.assert_array_equal(away, details["away"], err_msg=f"{label}: away")
        # normals only: the unit normals of the same fits (jets.jet_normals), at the centres, NaN elsewhere;
        # frame-free, so compared everywhere, within the fits' tolerance (the coefficients' largest)
        fitted = spread(compiled(*arguments, True, *extra)[0], centres, n, np.nan)
        with use_backend("numpy"):
            expected_normals = jets.jet_normals(expected[0], expected[1])
        np.testing.assert_array_equal(np.isnan(fitted), np.isnan(expected_normals), err_msg=f"{label}: normals only")
        close = np.isfinite(expected_normals).all(axis=1)
        worst = np.abs(coefficients[close] - expected[0][close]).max(initial=0.0)
        assert_directions_close(fitted[close], expected_normals[close], 4 * worst + 4 * EPS, f"{label}: normals only")


# -- point clouds -------------------------------------------------------------------------------


def check_pca_normals(name):
    from meshcurv._pointcloud_normals import _pca_normals_numpy

    points, _ = cloud(name)
    indices = knn_indices(points)
    expected = _pca_normals_numpy(points, indices)
    got = kernels("pointcloud").pca_normals(points, np.ascontiguousarray(indices))
    # a closed form (Smith 1961) against LAPACK's eigh: the same vector up to its sign, each within
    # eps |A| / (lambda_1 - lambda_0) of the exact one (the eigenvalue's error moves the null space of
    # A - lambda I by that much), the closed form's trigonometric root adding a few eps |A| more
    group = np.concatenate([points[:, None, :], points[indices]], axis=1)
    group = group - group.mean(axis=1, keepdims=True)
    values, vectors = np.linalg.eigh(np.einsum("nki,nkj->nij", group, group))
    unique = values[:, 1] - values[:, 0] > 1e-8 * values[:, 2]  # a unique least-variance direction
    assert unique.all() != (name == "degenerate_cloud")
    atol = 64 * EPS * values[unique, 2] / (values[unique, 1] - values[unique, 0])
    assert_directions_close(got[unique], expected[unique], atol, name, up_to_sign=True)
    # elsewhere any direction of the smallest eigenvalues' space will do, and the two choose differently
    # (the kernel's closed form, LAPACK's basis): both are unit vectors, orthogonal to the line of a
    # collinear neighbourhood
    np.testing.assert_allclose(np.linalg.norm(got, axis=1), 1.0, rtol=0, atol=4 * EPS)
    line = ~unique & (values[:, 2] > 0) & (values[:, 1] <= 1e-8 * values[:, 2])
    assert line.sum() == (120 if name == "degenerate_cloud" else 0)
    for label, normal in (("numpy", expected), ("kernel", got)):
        along = np.abs(np.einsum("ij,ij->i", normal[line], vectors[line, :, 2]))
        assert (along <= 1e-6).all(), (
            f"{label}: {int((along > 1e-6).sum())} of {line.sum()} normals of collinear "
            f"neighbourhoods not orthogonal to their line (|n . d| up to {along.max():.3g})"
        )


def check_nearest_neighbours(name):
    from scipy.spatial import cKDTree

    from meshcurv._pointcloud_normals import knn

    points, _ = cloud(name)
    n, k = points.shape[0], 10
    tree = cKDTree(points)
    expected_distances, expected_indices = knn(tree, points, k)
    # a reach at the median distance of the 11th neighbour: about half the rows settled on the grid, the others
    # left over; then a reach that holds every row's neighbours
    for reach in (float(np.median(expected_distances[:, -1])), 0.5):
        grid = kernels("neighborhoods").pool_grid(points, np.arange(n), reach)
        distances, indices, exact = kernels("pointcloud").nearest_neighbours(
            points, k, reach, *grid, 64 * kernel_threads()
        )
        # settled rows: k + 1 neighbours within reach at distinct distances, the k-d tree's to the bit
        assert 0.2 < exact.mean() < 0.8 if reach < 0.5 else exact.all(), reach
        np.testing.assert_array_equal(distances[exact], expected_distances[exact])
        np.testing.assert_array_equal(indices[exact], expected_indices[exact])
    x, y = np.meshgrid(np.arange(40.0), np.arange(30.0))  # a square lattice: two neighbours at 1 at least
    lattice = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    grid = kernels("neighborhoods").pool_grid(lattice, np.arange(lattice.shape[0]), 5.0)
    exact = kernels("pointcloud").nearest_neighbours(lattice, k, 5.0, *grid, 64 * kernel_threads())[2]
    assert not exact.any()  # (a lattice's neighbours tie: their order is the k-d tree's, searched by the caller)


def check_neighbour_differences(name):
    from meshcurv._pointcloud_estimators import FLAT_TURN, _neighbour_differences

    points, normals = cloud(name)
    n = points.shape[0]
    indices = knn_indices(points)
    rng = np.random.default_rng(13)
    # curvatures varying over the cloud, some undefined (NaN, inf), some points not valid
    k_min = points[:, 0] + 0.01 * rng.standard_normal(n)
    k_max = k_min + np.abs(points[:, 1])
    k_min[rng.random(n) < 0.05] = np.nan
    k_max[rng.random(n) < 0.01] = np.inf
    k_min[indices[0]] = np.nan  # point 0: no neighbour with an estimate
    k_min[0], k_max[0] = 0.1, 0.2
    valid = (rng.random(n) < 0.9) & np.isfinite(k_min) & np.isfinite(k_max)
    valid[0] = True
    spacing = 0.01 + 0.001 * rng.random(n)
    expected = _neighbour_differences(k_min, k_max, indices, valid, spacing)
    got = kernels("pointcloud").neighbour_differences(
        k_min, k_max, indices, valid, spacing, float(FLAT_TURN), 64 * kernel_threads()
    )
    # the same operations per neighbour, the same sort and mean of the two middle values: to the bit
    np.testing.assert_array_equal(got[valid], expected[valid])
    assert np.isnan(got[~valid]).all() and np.isnan(got[valid]).any()  # (a point with no estimated neighbour)


def check_ball_triangle_sums(name):
    from meshcurv._pointcloud_estimators import (
        EDGE_ON,
        MIN_BALL_POINTS,
        TRIANGLES,
        _distinct_ranks,
        _rank_pattern,
        _triangle_sums,
    )
    from meshcurv.estimators.icc import face_measures

    points, normals = cloud(name)
    n = points.shape[0]
    radius = 0.4 if name == "ellipsoid_cloud" else 0.12
    index, counts, _, _ = searched_balls(points, np.arange(n), radius, 48)
    rows = counts >= MIN_BALL_POINTS
    index, counts = np.ascontiguousarray(index[rows]), counts[rows]
    pattern = _rank_pattern(TRIANGLES)
    expected = _triangle_sums(points, normals, index, counts, pattern)
    got = kernels("pointcloud").ball_triangle_sums(points, normals, index, counts.astype(np.int64), pattern, EDGE_ON)
    # the same triangles (ranks drawn alike), each turned alike and measured with icc's operations;
    # the T measures of a ball summed in another order: within 2 T eps of the sum of |measures|
    ranks = _distinct_ranks(pattern, counts)
    triangles = np.take_along_axis(index[:, None, :], ranks.reshape(index.shape[0], 1, -1), axis=2)
    measures = np.abs(face_measures(points, triangles.reshape(-1, 3), normals))
    magnitude = measures.reshape(index.shape[0], pattern.shape[0], 9).sum(axis=1)
    assert_sums_close(got, expected, magnitude, pattern.shape[0] + 1)


def orientation_inputs(name):
    """Unit normals of random signs, their k nearest neighbours and a usable mask."""
    points, normals = cloud(name)
    rng = np.random.default_rng(13)
    flipped = normals * np.where(rng.random(points.shape[0]) < 0.5, -1.0, 1.0)[:, None]
    usable = rng.random(points.shape[0]) > 0.05
    return points, np.ascontiguousarray(flipped), knn_indices(points), usable


def check_edge_cosines(name):
    from meshcurv._pointcloud_normals import GRAPH_NEIGHBOURS

    _, normals, indices, _ = orientation_inputs(name)
    indices = np.ascontiguousarray(indices[:, :GRAPH_NEIGHBOURS])
    n, k = indices.shape
    # the NumPy path of orientation_signs: the edges' cosines by einsum over the gathered normals
    expected = np.einsum("ij,ij->i", normals[np.repeat(np.arange(n), k)], normals[indices.ravel()]).reshape(n, k)
    # einsum adds the three products as (x + z) + y, the kernel left to right; the sum of |products|
    # of two unit vectors is at most 1
    assert_sums_close(kernels("pointcloud").edge_cosines(normals, indices), expected, 1.0, 3)


def check_graph_edges(name):
    from meshcurv._pointcloud_normals import GRAPH_NEIGHBOURS, _graph_geometry

    points, normals, indices, usable = orientation_inputs(name)
    indices = np.ascontiguousarray(indices[:, :GRAPH_NEIGHBOURS])
    indices[::97, 0] = np.arange(0, indices.shape[0], 97)  # some points their own neighbour: no edge
    got = kernels("pointcloud").graph_edges(points, normals, indices, usable)
    expected = _graph_geometry(points, normals, indices, usable)
    for label, a, b in zip(("rows", "cols", "kept"), got[:3], expected[:3]):
        np.testing.assert_array_equal(a, b, err_msg=label)
    # einsum adds the three products in another order: within 2 eps of the sum of |products| (at most |d|,
    # and 1 for the cosine); the slope over |d| then within a few eps
    length = np.linalg.norm(points[expected[1]] - points[expected[0]], axis=1)
    for label, a, b, magnitude in zip(
        ("ahead", "behind", "cosine"), got[3:6], expected[3:6], (length, length, np.ones_like(length))
    ):
        assert_sums_close(a, b, magnitude, 3, err_msg=label)
    assert_sums_close(got[6], expected[6], 1.0, 3, err_msg="slope", relative=4 * EPS)


def check_edge_weights(name):
    from meshcurv._pointcloud_normals import FACING_COSINE, GRAPH_NEIGHBOURS, STACKED_OFFSET, _edge_weights

    points, normals, indices, usable = orientation_inputs(name)
    rows, cols, _, ahead, behind, cosine, slope = kernels("pointcloud").graph_edges(
        points, normals, np.ascontiguousarray(indices[:, :GRAPH_NEIGHBOURS]), usable
    )
    rng = np.random.default_rng(17)
    spacing = rng.uniform(0.0, 0.2, points.shape[0])  # some ends far enough off the other's plane to be stacked
    flat = rng.random(rows.size) < 0.5
    slope[::53], ahead[::71] = np.nan, np.nan  # zero offsets: NaN products
    got = kernels("pointcloud").edge_weights(
        flat, ahead, behind, cosine, slope, spacing, rows, cols, STACKED_OFFSET, FACING_COSINE
    )
    expected = _edge_weights(flat, ahead, behind, cosine, slope, spacing, rows, cols)
    for label, a, b in zip(("stacked", "weights", "opposite"), got, expected):
        np.testing.assert_array_equal(a, b, err_msg=label)  # the same operations in the same order
    assert expected[0].any() and (~expected[0] & ~flat).any()


def check_kept_rows(name):
    from meshcurv.pointcloud import _kept_rows

    points, _ = cloud(name)
    indices = knn_indices(points)
    distances = np.linalg.norm(points[indices] - points[:, None, :], axis=2)
    n = points.shape[0]
    for keep in (np.ones(n, dtype=bool), np.random.default_rng(19).random(n) > 0.01, np.arange(n) >= 5):
        expected = _kept_rows(distances, indices, keep)
        got_distances, got_indices = distances.copy(), indices.copy()
        m, again = kernels("pointcloud").kept_rows(got_distances, got_indices, keep)  # (in place)
        assert m == keep.sum()
        np.testing.assert_array_equal(got_distances[:m], expected[0])
        np.testing.assert_array_equal(got_indices[:m], expected[1])
        np.testing.assert_array_equal(np.flatnonzero(again), expected[2])
        assert keep.all() or expected[2].size  # rows that held a point gone


def check_far_winding(name):
    """The winding numbers of an oriented cloud with the far sum compiled and in NumPy (the same terms)."""
    from scipy.spatial import cKDTree

    from meshcurv._pointcloud_normals import winding_numbers

    points, normals = cloud(name)
    rng = np.random.default_rng(3)
    areas = rng.uniform(0.5, 1.5, points.shape[0]) * 1e-3
    usable = rng.random(points.shape[0]) > 0.05
    queries = np.arange(0, points.shape[0], 7)
    sources = np.flatnonzero(usable)[::3]
    results = {}
    for backend in ("numpy", "numba"):
        with use_backend(backend):
            results[backend] = winding_numbers(points, normals, areas, usable, cKDTree(points), queries, sources)
    # the same terms, summed in another order: round-off of sums of about a thousand terms of size <= 1
    np.testing.assert_allclose(results["numba"], results["numpy"], rtol=0, atol=1e-9)


def check_spanning_signs(name):
    from meshcurv._pointcloud_normals import orientation_signs

    points, normals, indices, usable = orientation_inputs(name)
    # the kernel is reached through orientation_signs (its only caller builds the graph's edges and
    # their order): Kruskal with a union-find against scipy's minimum spanning tree and pointer
    # jumping. The weights are distinct, so the spanning forest is the same; the signs relative to
    # each component's root are then the same, the roots (and so each component's overall sign) may differ
    for given, with_points in ((False, False), (True, False), (True, True)):
        results = {}
        for backend in ("numpy", "numba"):
            with use_backend(backend):
                results[backend] = orientation_signs(
                    normals, indices, usable, given=given, points=points if with_points else None
                )
        (expected, labels), (got, got_labels) = results["numpy"], results["numba"]
        label = f"given={given}, points={with_points}"
        # the same partition into components, under other names
        pairs = np.unique(np.column_stack([labels, got_labels]), axis=0)
        assert pairs.shape[0] == np.unique(labels).size == np.unique(got_labels).size, label
        relative = got * expected
        first = np.zeros(labels.max() + 1)
        first[labels[::-1]] = relative[::-1]
        np.testing.assert_array_equal(relative, first[labels], err_msg=label)
        assert (expected < 0).any() and (expected > 0).any(), label  # the normals' random signs are turned


def check_first_point_parts(name):
    n = orientation_inputs(name)[0].shape[0]
    rng = np.random.default_rng(29)
    # a union-find's roots: components of random sizes (singletons among them), each rooted at any of its points
    labels = np.minimum(rng.integers(0, n // 7, n), rng.integers(0, n // 3, n))
    shuffled = rng.permutation(n)
    root_of = np.zeros(labels.max() + 1, dtype=np.int64)
    root_of[labels[shuffled]] = shuffled  # (some member of each component: whichever NumPy writes last)
    roots = root_of[labels]
    signs = np.where(rng.random(n) < 0.5, -1.0, 1.0)
    got_signs, got_labels = kernels("pointcloud_graph").first_point_parts(signs, roots.astype(np.int64))
    # the definition: each component's first point (np.minimum.at), its sign +1, the components numbered in
    # the order of their first points
    first = np.full(n, n, dtype=np.int64)
    np.minimum.at(first, roots, np.arange(n))
    first = first[roots]
    np.testing.assert_array_equal(got_signs, signs * signs[first])
    np.testing.assert_array_equal(got_labels, np.unique(first, return_inverse=True)[1].reshape(-1))
    assert np.unique(got_labels).size > 10 and (got_signs[first] == 1.0).all()


# -- the table ----------------------------------------------------------------------------------
# -- the table ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Twin:
    """A compiled kernel (``module.name`` of :mod:`meshcurv._kernels`), its NumPy twin and its inputs."""

    kernel: str
    twin: str
    check: Callable
    inputs: tuple


def check_line_spread(name):
    from meshcurv._pointcloud_normals import _line_spread_numpy

    points, _ = cloud(name)
    indices = knn_indices(points)
    line = np.stack([np.linspace(0, 1, 40), np.zeros(40), np.zeros(40)], axis=1)  # spread 0
    for p, i in ((points, indices), (line, knn_indices(line))):
        np.testing.assert_allclose(
            kernels("pointcloud").line_spread(p, np.ascontiguousarray(i)),
            _line_spread_numpy(p, i),
            rtol=1e-9,
            atol=1e-6,
        )


def check_flat_balls(name):
    from scipy.spatial import cKDTree

    from meshcurv._pointcloud_estimators import (
        BALL_OFFSET,
        BALL_SHARE,
        BALL_SUPPORT,
        SUPPORT_ITERATIONS,
        SUPPORT_POINTS,
        _ball_indices,
        _flat_balls,
        _usable_tree,
    )

    points, _ = cloud(name)
    n = points.shape[0]
    # the cloud and a line beside it with a few points: balls with and without a surface
    t = np.linspace(0.0, 1.0, 200)
    points = np.concatenate([points, np.stack([t, t, t + 5.0], axis=1), [[0.5, 0.6, 5.5], [0.2, 0.1, 5.1]]])
    centres = np.arange(points.shape[0])
    radius = 0.4 if name == "ellipsoid_cloud" else 0.12
    for k in (24, 96):
        index, counts = _ball_indices(
            _usable_tree(cKDTree(points), points, np.ones(points.shape[0], dtype=bool)), points, centres, radius, k
        )
        expected = _flat_balls(points, centres, index, counts)
        got = kernels("pointcloud").flat_balls(
            points,
            centres,
            index,
            counts.astype(np.int64),
            -(-k // SUPPORT_POINTS),
            SUPPORT_ITERATIONS,
            BALL_OFFSET,
            BALL_SHARE,
            BALL_SUPPORT,
        )
        np.testing.assert_array_equal(got, expected)
        assert expected[:n].mean() > 0.9 and not expected[n : n + 200].any()  # (the line's own balls)


def check_measured_balls(name):
    _check_the_search(name)
    _check_the_cuts(name)


def _check_the_search(name):
    """The search of :func:`check_measured_balls` alone (:func:`searched_balls`): the k-d tree's rows."""
    from scipy.spatial import cKDTree

    from meshcurv._pointcloud_estimators import LARGER, _ball_indices, _usable_tree

    points, _ = cloud(name)
    n = points.shape[0]
    rng = np.random.default_rng(12)
    radius = 0.4 if name == "ellipsoid_cloud" else 0.12
    centres = np.flatnonzero(rng.random(n) > 0.5)
    tree = cKDTree(points)
    for usable, k, k_wide in ((np.ones(n, dtype=bool), 24, 0), (rng.random(n) > 0.2, 96, 0), (None, 24, 48)):
        usable = rng.random(n) > 0.2 if usable is None else usable
        search = _usable_tree(tree, points, usable)
        index, counts, wide_index, wide_counts = searched_balls(
            points, centres, radius, k, usable, radius * LARGER, k_wide
        )
        # continuous random points: no two distances tie, so the nearest k are the same in the same order
        label = f"k={k}, k_wide={k_wide}, {'all' if usable.all() else 'some'} usable"
        expected_index, expected_counts = _ball_indices(search, points, centres, radius, k)
        np.testing.assert_array_equal(counts, expected_counts, err_msg=label)
        np.testing.assert_array_equal(index, expected_index, err_msg=label)
        assert (counts < k).any() and ((counts == k).any() or k > 24), label  # full balls (cut to k) and partial
        assert usable[index[index < n]].all(), label
        if k_wide:  # the smaller balls the prefixes of the larger ones' search: both the k-d tree's
            expected_index, expected_counts = _ball_indices(search, points, centres, radius * LARGER, k_wide)
            np.testing.assert_array_equal(wide_counts, expected_counts, err_msg=label)
            np.testing.assert_array_equal(wide_index, expected_index, err_msg=label)
    # ties (a lattice): the smaller balls of the wide search are those of the search over the smaller radius itself
    lattice = np.stack(np.meshgrid(*[np.arange(12.0)] * 2, [0.0]), axis=-1).reshape(-1, 3)
    everything = np.arange(lattice.shape[0])
    for k, k_wide in ((20, 48), (20, 96), (12, 96)):
        index, counts, _, _ = searched_balls(lattice, everything, 2.5, k, None, 2.5 * LARGER, k_wide)
        expected_index, expected_counts, _, _ = searched_balls(lattice, everything, 2.5, k)
        np.testing.assert_array_equal(counts, expected_counts)
        np.testing.assert_array_equal(index, expected_index)
        assert (counts == k).any() and (counts < k).any()  # (rows cut through a ring of ties, and partial rows)


def _check_the_cuts(name):
    """The balls of :func:`check_measured_balls` with their ties cut whole and ordered and their points facing away
    or on another sheet dropped: its NumPy twin's, to the bit (the same squared distances, tests and keys)."""
    from scipy.spatial import cKDTree

    from meshcurv._pointcloud_estimators import (
        FACING_MARGIN,
        LARGER,
        MIN_BALL_POINTS,
        SQUARED_TIE,
        _measured_balls,
        _usable_tree,
    )

    points, normals = cloud(name)
    # and a square lattice beside it (rings of points at one distance: cuts through them), some normals NaN
    x, y = (grid.ravel() for grid in np.meshgrid(np.arange(16.0), np.arange(16.0)))
    lattice = np.column_stack([x, y, np.zeros(x.size)]) * 0.04 + 5.0
    lattice_normals = np.column_stack([0.1 * np.sin(x), 0.05 * y, np.ones(x.size)])
    lattice_normals /= np.linalg.norm(lattice_normals, axis=1, keepdims=True)
    lattice_normals[::9] = np.nan
    rng = np.random.default_rng(26)
    points = np.concatenate([points, lattice])
    normals = np.concatenate([normals, lattice_normals])
    normals = np.ascontiguousarray(np.where((rng.random(points.shape[0]) < 0.1)[:, None], -normals, normals))
    n = points.shape[0]
    radius = 0.4 if name == "ellipsoid_cloud" else 0.12
    wide = radius * LARGER
    centres, usable = np.flatnonzero(rng.random(n) > 0.4), rng.random(n) > 0.15
    on_lattice = centres >= n - lattice.shape[0]
    search = _usable_tree(cKDTree(points), points, usable)
    for k, k_wide, sheets in ((11, 0, None), (24, 48, rng.integers(-1, 3, n)), (40, 96, None)):
        grid = kernels("neighborhoods").pool_grid(points, np.flatnonzero(usable), float(wide if k_wide else radius))
        got = kernels("pointcloud").measured_balls(
            points,
            normals,
            centres,
            float(radius),
            k,
            float(wide),
            k_wide,
            *grid,
            np.zeros(0, dtype=np.int64) if sheets is None else sheets.astype(np.int64),
            SQUARED_TIE,
            MIN_BALL_POINTS,
            FACING_MARGIN,
            64 * kernel_threads(),
        )
        expected = _measured_balls(search, points, normals, centres, radius, k, wide, k_wide, sheets)
        for label, a, b in zip(("index", "counts", "wide_index", "wide_counts"), got, expected):
            np.testing.assert_array_equal(a, b, err_msg=f"{label}, k={k}, k_wide={k_wide}")
        assert (got[1] < k).any() and (got[1] > 0).any(), k
        # the inputs meant something: against the search alone, rows less points (cut whole, facing away, on
        # another sheet) on the lattice and off it, and the lattice's runs of ties ordered by their keys, not by index
        counts = searched_balls(points, centres, radius, k, usable)[1]
        assert (got[1][on_lattice] < counts[on_lattice]).any() and (got[1][~on_lattice] < counts[~on_lattice]).any()
        reordered = 0
        for row in np.flatnonzero(on_lattice):
            members = got[0][row, : got[1][row]]
            squared = ((points[members] - points[centres[row]]) ** 2).sum(axis=1)
            reordered += (members[np.lexsort((members, squared))] != members).any()
        assert reordered > 0, k


def check_cut_neighbours(name):
    from scipy.spatial import cKDTree

    from meshcurv._pointcloud_normals import TIE_LEAST, TIE_TOLERANCE, _cut_neighbours

    points, _ = cloud(name)
    x, y = (grid.ravel() for grid in np.meshgrid(np.arange(12.0), np.arange(12.0)))
    points = np.concatenate([points, np.column_stack([x, y, np.zeros(x.size)]) * 0.05 + 5.0])  # rings of ties
    distances, indices = cKDTree(points).query(points, k=12)
    distances, indices = np.ascontiguousarray(distances[:, 1:]), np.ascontiguousarray(indices[:, 1:])
    centres = np.random.default_rng(4).permutation(points.shape[0])
    for given in (None, centres):
        expected = _cut_neighbours(distances, indices, 10, given)
        got = kernels("pointcloud").cut_neighbours(
            distances,
            indices,
            10,
            np.zeros(0, dtype=np.int64) if given is None else given.astype(np.int64),
            TIE_TOLERANCE,
            TIE_LEAST,
        )
        np.testing.assert_array_equal(got[0], expected[0])
        np.testing.assert_array_equal(got[1], expected[1])
        assert (expected[1] != indices[:, :10]).any()  # (groups dropped whole)


def check_stacked(name):
    from meshcurv._pointcloud_normals import _stacked

    points, normals = cloud(name)
    n = points.shape[0]
    rng = np.random.default_rng(9)
    # a second sheet over the cloud: the same points lifted along their normals, half of them turned
    lifted = points + 0.05 * normals
    turned = np.where((rng.random(n) < 0.5)[:, None], -normals, normals)
    both, both_normals = np.vstack([points, lifted]), np.vstack([normals, turned])
    near = knn_indices(both, k=17)
    queries = np.flatnonzero(rng.random(2 * n) > 0.5)
    usable = rng.random(2 * n) > 0.1
    step = float(np.median(np.linalg.norm(both[near[:, 1]] - both, axis=1)))
    for alike in (True, False):
        with use_backend("numpy"):
            expected = _stacked(both, both_normals, usable, step, queries, near[queries], alike=alike)
        with use_backend("numba"):
            got = _stacked(both, both_normals, usable, step, queries, near[queries], alike=alike)
        np.testing.assert_array_equal(got, expected, err_msg=f"alike={alike}")
    assert expected.any() or got.any()


def check_ball_turn_extremes(name):
    from meshcurv import radius

    vertices, _ = mesh(name)
    normals = numpy_normals(name)  # NaN rows (the defects' unreferenced and cancelled vertices) add nothing
    edges = topology(name).edges.astype(np.int64)
    n = vertices.shape[0]
    radii = 2.5 * mean_edge(name) * np.random.default_rng(5).uniform(0.5, 1.5, n)  # one radius per centre
    centres = np.arange(0, n, 3, dtype=np.int64)
    pool = np.flatnonzero(topology(name).referenced_vertices).astype(np.int64)
    creases = radius._edge_turns(normals, edges, n)
    expected = radius.ball_turn_extremes.numpy(vertices, normals, radii, centres, pool, creases)
    # the same pairs (squared distances summed x, y, z against r^2), each pair's products summed x, y, z, and
    # extremes that do not depend on the pairs' order: to the bit
    got = kernels("turns").ball_turn_extremes(vertices, normals, radii, centres, pool, creases)
    for a, b in zip(got, expected):
        np.testing.assert_array_equal(a, b)
    assert (expected[0] < 1).any() and (expected[1] > 0).any()


TWINS = [
    Twin("geometry.face_cross_products", "_geometry.face_cross_products", check_face_cross_products, MESHES),
    Twin(
        "geometry.vertex_normal_sums",
        "_geometry.vertex_normal_sums",
        check_vertex_normal_sums,
        MESHES,
    ),
    Twin(
        "geometry.vertex_normal_and_area_sums",
        "_geometry.vertex_normal_and_area_sums",
        check_vertex_normal_and_area_sums,
        MESHES,
    ),
    Twin(
        "geometry.normalize_normal_sums",
        "_geometry.normalize_normal_sums",
        check_normalize_normal_sums,
        ("random", "torus", "defects"),
    ),
    Twin("geometry.edge_lengths", "_geometry.edge_lengths", check_edge_lengths, MESHES),
    Twin("geometry.vertex_edge_lengths", "_geometry.vertex_edge_lengths", check_vertex_edge_lengths, MESHES),
    Twin("geometry.mean_edge_length", "_geometry.mean_edge_length", check_mean_edge_length, MESHES),
    Twin("geometry.cross_and_degenerate", "_geometry.cross_and_degenerate", check_cross_and_degenerate, MESHES),
    Twin("orient.patch_volumes", "orient.patch_volumes", check_patch_volumes, MESHES),
    Twin("orient.face_winding_numbers", "orient.face_winding_numbers", check_face_winding_numbers, MESHES),
    Twin("topology.build_edges", "topology._build_edges", check_build_edges, MESHES),
    Twin("topology.bowtie_vertices", "topology._bowtie_vertices", check_bowtie_vertices, MESHES),
    Twin("topology.component_labels", "topology.component_labels", check_component_labels, MESHES),
    Twin("topology.double_sided_suspects", "weld.double_sided_suspects", check_double_sided_suspects, MESHES),
    Twin("topology.neighbour_lists", "topology.neighbour_lists", check_neighbour_lists, MESHES),
    Twin("diagnosis.mesh_facts", "diagnosis.diagnose", check_mesh_facts, MESHES),
    Twin("diagnosis.long_edges", "defects.needle_vertices (its long edges)", check_long_edges, MESHES),
    Twin(
        "normal_cycle.normal_cycle_sums", "normal_cycle.estimate up to its smoothing", check_normal_cycle_sums, MESHES
    ),
    Twin(
        "normal_cycle.normal_cycle_finish",
        "normal_cycle.estimate from its smoothing on",
        check_normal_cycle_finish,
        MESHES,
    ),
    Twin(
        "tensors.principal_from_shape_operator",
        "_tensors.principal_from_shape_operator",
        check_principal_from_shape_operator,
        ("random", "torus", "ellipsoid", "defects"),
    ),
    Twin("matgeom.matgeom_vertex_tensors", "matgeom._vertex_tensors", check_matgeom_vertex_tensors, MESHES),
    Twin(
        "matgeom.matgeom_principal",
        "matgeom.estimate (_eigen.sorted_by_magnitude and the swap)",
        check_matgeom_principal,
        MESHES,
    ),
    Twin(
        "matgeom.matgeom_finish",
        "smoothing.smooth_over_neighbours, then matgeom.matgeom_principal",
        check_matgeom_finish,
        MESHES,
    ),
    Twin("smoothing.smooth_over_neighbours", "smoothing.smooth_over_neighbours", check_smooth_over_neighbours, MESHES),
    Twin("icc.face_measures", "_measures.face_measures", check_face_measures, MESHES),
    Twin(
        "icc.curvatures_from_measures",
        "_measures.curvatures_from_measures",
        check_curvatures_from_measures,
        MESHES,
    ),
    Twin("locality.morton_reordering", "_locality.morton_reordering", check_reordering, MESHES),
    Twin(
        "neighborhoods.vertex_face_lists",
        "a stable sort of the corners (no twin in the library)",
        check_vertex_face_lists,
        MESHES,
    ),
    Twin("neighborhoods.cell_centres", "the centres and reach of neighborhoods._ball_sums", check_cell_centres, MESHES),
    Twin("neighborhoods.ball_cell_sums", "neighborhoods.ball_face_sums / ball_edge_sums", check_ball_cell_sums, MESHES),
    Twin(
        "neighborhoods.connected_face_sums",
        "neighborhoods.ball_face_sums(connected=True)",
        check_connected_face_sums,
        MESHES + THIN,
    ),
    Twin(
        "neighborhoods.connected_face_sums_nested",
        "neighborhoods.ball_face_sums(connected=True) at each radius",
        check_connected_face_sums_nested,
        MESHES + THIN,
    ),
    Twin("jets.fit_jets", "jets.fit_jets", check_fit_jets, CLEAN + CLOUDS),
    Twin("jets.jet_curvatures", "jets.jet_curvatures", check_jet_curvatures, CLOUDS),
    Twin("jets.fit_jet_pairs", "jets.fit_jets at both radii", check_fit_jet_pairs, CLEAN + CLOUDS),
    Twin(
        "jets.fit_jets_connected",
        "jets.fit_jets(adjacency=) and jets.jet_normals",
        check_fit_jets_connected,
        MESHES + THIN,
    ),
    Twin(
        "pointcloud.pca_normals",
        "_pointcloud_normals._pca_normals_numpy",
        check_pca_normals,
        CLOUDS + ("degenerate_cloud",),
    ),
    Twin("pointcloud.nearest_neighbours", "_pointcloud_normals.knn", check_nearest_neighbours, CLOUDS),
    Twin(
        "pointcloud.neighbour_differences",
        "_pointcloud_estimators._neighbour_differences",
        check_neighbour_differences,
        CLOUDS,
    ),
    Twin("pointcloud.ball_triangle_sums", "_pointcloud_estimators._triangle_sums", check_ball_triangle_sums, CLOUDS),
    Twin("pointcloud.edge_cosines", "the cosines of _pointcloud_normals.orientation_signs", check_edge_cosines, CLOUDS),
    Twin("pointcloud.far_winding", "_pointcloud_normals.winding_numbers", check_far_winding, CLOUDS),
    Twin("pointcloud.spanning_signs", "_pointcloud_normals.orientation_signs", check_spanning_signs, CLOUDS),
    Twin(
        "pointcloud_graph.first_point_parts",
        "np.minimum.at and np.unique (the NumPy forest's numbering)",
        check_first_point_parts,
        CLOUDS,
    ),
    Twin("pointcloud.graph_edges", "_pointcloud_normals._graph_geometry", check_graph_edges, CLOUDS),
    Twin("pointcloud.edge_weights", "_pointcloud_normals._edge_weights", check_edge_weights, CLOUDS),
    Twin("pointcloud.kept_rows", "pointcloud._kept_rows", check_kept_rows, CLOUDS),
    Twin(
        "pointcloud.measured_balls",
        "_pointcloud_estimators._measured_balls",
        check_measured_balls,
        CLOUDS,
    ),
    Twin("pointcloud.cut_neighbours", "_pointcloud_normals._cut_neighbours", check_cut_neighbours, CLOUDS),
    Twin("pointcloud.line_spread", "_pointcloud_normals._line_spread_numpy", check_line_spread, CLOUDS),
    Twin("pointcloud.flat_balls", "_pointcloud_estimators._flat_balls", check_flat_balls, CLOUDS),
    Twin("pointcloud.stacked", "_pointcloud_normals._stacked", check_stacked, CLOUDS),
    Twin("turns.ball_turn_extremes", "radius.ball_turn_extremes", check_ball_turn_extremes, MESHES + THIN),
]

#: Public kernels checked here only through another path, each with the reason. Empty: every
#: public kernel has a row in TWINS.
EXCEPTIONS: dict[str, str] = {
    "quadric.residual_spreads": "tests/test_quadric_scatter_Q21.py::test_residual_spreads_backends_agree: against "
    "estimators.quadric.residual_spreads (its NumPy body) within 1e-9: the same sums in another order",
    "pilot.interpolated_normals": "tests/test_jets_sampled.py::test_the_compiled_interpolation_is_the_numpy_one: "
    "against jets.interpolated_normals (its NumPy twin) to round-off",
    "neighborhoods.clustered_face_sums": "tests/test_neighborhoods_clusters.py::test_cluster_sums_equal_the_walk_face_"
    "by_face: the same sums as neighborhoods.connected_face_sums (its row above, twin of ball_face_sums(connected=True)) "
    "to round-off",
    "neighborhoods.coarse_face_sums": "tests/test_neighborhoods_clusters.py::test_coarse_sums_do_not_depend_on_the_"
    "backend: against neighborhoods._coarse_face_sums_numpy",
    "neighborhoods.pool_grid": "a search structure, not a result: the twins of pointcloud.measured_balls and "
    "jets.fit_jets, which search it, find the same balls with k-d trees",
    "icc.nested_jet_normals": "tests/test_multiscale.py: against jets.fit_jet_normals at each radius, on both backends",
    "topology.build_topology": "the body of topology.build_edges (its row above), which calls it",
    "topology.build_edges_into": "the body of topology.build_topology, called by topology.build_edges (its row above)",
    "topology.bowtie_from_twins": "tests/test_topology.py::test_bowtie_vertices_from_the_twin_sides_are_those_of_the_"
    "definition: against the NumPy definition on random defective spheres",
    "topology.bowtie_walks": "the body of topology.bowtie_from_twins (its row above), which calls it; from the "
    "build's corner counts: tests/test_topology.py::test_bowtie_vertices_from_the_twin_sides_are_those_of_the_definition",
    "matgeom.matgeom_vertex_sums": "the body of matgeom.matgeom_vertex_tensors (its row above), which calls it; its "
    "zero-area faces: tests/test_topology.py::test_the_zero_area_faces_a_kernel_found_are_kept",
    "pointcloud_graph.morton_codes": "tests/test_pointcloud_graph_kernels.py::test_morton_codes_and_their_order_are_"
    "numpys: against pointcloud._morton_codes, to the bit",
    "pointcloud_graph.stable_order": "tests/test_pointcloud_graph_kernels.py::test_stable_order_of_any_codes: "
    'against np.argsort(kind="stable"), to the bit',
    "pointcloud_graph.spanning_sheets": "tests/test_pointcloud_graph_kernels.py::test_spanning_sheets_is_spanning_"
    "signs_and_the_sheets: against pointcloud.spanning_signs (its row above) and _pointcloud_normals._sheets",
    "pointcloud_graph.torn_ends": "tests/test_pointcloud_graph_kernels.py::test_torn_ends_are_numpys: against the "
    "NumPy lines of _pointcloud_normals.oriented_signs",
    "pointcloud_graph.gathered_results": "tests/test_pointcloud_graph_kernels.py::test_gathered_results_are_numpys: "
    "against pointcloud._gathered_results, to the bit",
}

#: Cases where a kernel and its twin disagree: ``(kernel, input) -> reason`` (strict xfail). Empty: the one
#: found, pca_normals on collinear neighbourhoods (its normal up to 3.7 degrees out of the plane orthogonal
#: to the line), was fixed (a rank-1 ``A - lambda I`` takes a direction orthogonal to its longest row).
DISAGREEMENTS: dict[tuple[str, str], str] = {}


def _cases():
    for twin in TWINS:
        for name in twin.inputs:
            reason = DISAGREEMENTS.get((twin.kernel, name))
            marks = [pytest.mark.xfail(strict=True, reason=reason)] if reason else []
            yield pytest.param(twin, name, id=f"{twin.kernel}-{name}", marks=marks)


@pytest.mark.slow
@pytest.mark.parametrize(("twin", "name"), list(_cases()))
def test_kernel_agrees_with_its_twin(twin, name, monkeypatch):
    parameters = inspect.signature(twin.check).parameters
    if "monkeypatch" in parameters:
        twin.check(name, monkeypatch)
    else:
        twin.check(name)


def public_kernels() -> set[str]:
    """``module.name`` of every public function defined in a public module of :mod:`meshcurv._kernels`."""
    import meshcurv._kernels as package

    found = set()
    for info in pkgutil.iter_modules(package.__path__):
        if info.name.startswith("_"):
            continue
        module = importlib.import_module(f"{package.__name__}.{info.name}")
        for attribute, value in vars(module).items():
            function = getattr(value, "py_func", value)  # a numba dispatcher or a plain function
            if (
                not attribute.startswith("_")
                and inspect.isfunction(function)
                and function.__module__ == module.__name__
            ):
                found.add(f"{info.name}.{attribute}")
    return found


def test_every_kernel_has_a_twin():
    kernels_found = public_kernels()
    assert len(kernels_found) >= 31  # the discovery itself works (31 kernels when this file was written)
    in_table = [twin.kernel for twin in TWINS]
    assert len(in_table) == len(set(in_table)), "a kernel has two rows"
    assert not set(in_table) & set(EXCEPTIONS), "a kernel is both in TWINS and in EXCEPTIONS"
    untested = kernels_found - set(in_table) - set(EXCEPTIONS)
    assert not untested, f"compiled kernels without a twin test (add a row to TWINS): {sorted(untested)}"
    gone = (set(in_table) | set(EXCEPTIONS)) - kernels_found
    assert not gone, f"rows for kernels that no longer exist: {sorted(gone)}"
    for twin in TWINS:
        module, _, name = twin.kernel.partition(".")
        assert callable(getattr(kernels(module), name)), twin.kernel
    from meshcurv._backend import TWINS as REGISTERED  # the twins that carry @twin: the row names that function

    for kernel, function in REGISTERED.items():
        named = f"{function.__module__.removeprefix('meshcurv.')}.{function.__qualname__}"
        assert [twin.twin for twin in TWINS if twin.kernel == kernel] == [named], kernel


# -- the chunks of the jet fits on threads (issue 31: no numba parallel pipeline to compile) ------------


def test_run_chunks_covers_every_item_once_in_the_ranges_of_prange():
    from meshcurv._kernels._common import run_chunks

    seen = []
    run_chunks(lambda lo, hi, out: out.append((lo, hi)), 10, 4, seen)
    assert sorted(seen) == [(0, 2), (2, 5), (5, 7), (7, 10)]  # c * n // k, as numba.prange's chunks
    seen.clear()
    run_chunks(lambda lo, hi, out: out.append((lo, hi)), 3, 64, seen)  # never more chunks than items
    assert sorted(seen) == [(0, 1), (1, 2), (2, 3)]
    seen.clear()
    run_chunks(lambda lo, hi, out: out.append((lo, hi)), 0, 8, seen)  # nothing to do: one empty range
    assert seen == [(0, 0)]


def test_run_chunks_passes_on_an_error_of_a_chunk():
    import numba

    from meshcurv._kernels._common import run_chunks

    def failing(lo, hi):
        if lo > 0:
            raise ValueError(f"chunk {lo}-{hi} failed")

    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(min(2, numba.config.NUMBA_NUM_THREADS))
        with pytest.raises(ValueError, match="chunk 5-10 failed"):
            run_chunks(failing, 10, 2)
    finally:
        numba.set_num_threads(threads)


@pytest.mark.parametrize("connected", [False, True])
def test_jet_fits_on_two_threads_are_those_of_one(connected):
    """The chunks of the fits write their own rows: the outputs are equal to the bit whatever the threads."""
    import numba

    from meshcurv import jets

    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba has one thread here (NUMBA_NUM_THREADS)")
    points, normals, radius, (indptr, indices) = jet_inputs("ellipsoid")
    n = points.shape[0]
    compiled = kernels("jets")

    def fits():
        if connected:
            return compiled.fit_jets_connected(
                points,
                normals,
                np.array([radius]),
                3,
                jets.ITERATIONS,
                jets._exponents(3),
                jets.MIN_SPREAD,
                np.arange(n),
                7,
                np.ones(n, dtype=bool),
                indptr,
                indices,
                points,
                False,
                jets.AWAY_FRACTION,
                False,
                0.0,
                np.zeros(0),
            )
        return compiled.fit_jets(
            points,
            normals,
            np.array([radius]),
            3,
            jets.ITERATIONS,
            jets._exponents(3),
            jets.MIN_SPREAD,
            np.arange(n),
            7,
            np.arange(n),
            points,
            False,
            jets.AWAY_FRACTION,
            0.0,
            np.zeros(0),
        )

    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = fits()
        numba.set_num_threads(2)
        two = fits()
    finally:
        numba.set_num_threads(threads)
    assert np.isfinite(one[0]).all(axis=1).sum() > n // 2  # fits were made
    for a, b in zip(one, two):
        np.testing.assert_array_equal(a, b)


def test_the_jet_moments_are_compiled_only():
    from meshcurv._kernels.jets import _jet_moments

    with pytest.raises(NotImplementedError, match="compiled only"):
        _jet_moments(None, *([None] * 15))


def test_corrected_measures_on_two_threads_are_those_of_one():
    import numba

    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba has one thread here (NUMBA_NUM_THREADS)")
    vertices, faces = mesh("ellipsoid")
    normals = numpy_normals("ellipsoid")
    compiled = kernels("icc")

    def both():
        measures = compiled.face_measures(vertices, faces, normals)
        summed = np.zeros((vertices.shape[0], 9))
        np.add.at(summed, faces[:, 0], measures)  # any per-vertex sums will do
        return (measures, *compiled.curvatures_from_measures(summed, normals))

    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        one = both()
        numba.set_num_threads(2)
        two = both()
    finally:
        numba.set_num_threads(threads)
    assert np.isfinite(one[1]).sum() > vertices.shape[0] // 4
    for a, b in zip(one, two):
        np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("name", ["noisy", "defects"])
def test_connected_face_sums_are_the_nested_walk_of_one_ball_on_one_or_two_threads(name):
    """``connected_face_sums`` writes out the walk of ``_face_walk`` (issue 31: no reference counts per face);
    with one radius, ``connected_face_sums_nested`` walks with the shared helpers (its largest ball: the same
    faces, the same additions in the same order), so the two agree to the bit, per vertex radii too, and the
    chunks on threads give the sums of one thread."""
    import numba

    _, faces, _, values, usable, _, _, n, _, _ = face_sum_inputs(name)
    h = mean_edge(name)
    threads = numba.get_num_threads()
    for radii in (np.array([1.7 * h]), np.random.default_rng(2).uniform(0.9, 2.5, n) * h):
        nested = walked_face_sums(
            name, values[None], radii[None, :], usable, scratch=_face_sum_scratch(2, n, faces.shape[0])
        )
        assert np.count_nonzero(nested[0].any(axis=1)) > n // 2  # sums were made
        for count in (1, min(2, numba.config.NUMBA_NUM_THREADS)):
            try:
                numba.set_num_threads(count)
                got = walked_face_sums(name, values, radii, usable, scratch=_face_sum_scratch(2, n, faces.shape[0]))
            finally:
                numba.set_num_threads(threads)
            np.testing.assert_array_equal(got, nested[0])


def test_the_smaller_solve_is_compiled_only():
    from meshcurv._kernels.jets import _smaller_solve

    with pytest.raises(NotImplementedError, match="compiled only"):
        _smaller_solve(None, *([None] * 7))
