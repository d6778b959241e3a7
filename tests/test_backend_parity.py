"""One estimator on both backends (issue 29, class 10): the NumPy path computes what the compiled one does.

The compiled kernels walk each ball's surface-connected piece (``icc``'s normal
fits and sums) or search Euclidean balls on a grid (``quadric``,
``normal_cycle_ball``); the NumPy path must find the same balls and fit them
alike, so that a user's numbers do not depend on whether numba is installed.
The meshes are those where the two kinds of ball differ: thin parts (a flat
ellipsoid, a thin torus: a ball of the default radius reaches the other side),
open ones (a hemisphere, a sphere with a hole), noisy ones (closed, thin and open) and voxel surfaces
(marching cubes, closed, and open as where an object is cut by the image's
border), each small enough for the NumPy path to stay fast; and the label table
of objects cut by the image's border (the voxel pilot, the refit at the rim).

Tolerance: both sides fit the same points with the same operations; only the
order of the sums differs (grid or breadth-first order against k-d tree
pairs), some ``1e-16`` relative per operation, so 1e-6 of the largest
curvature leaves many orders of magnitude for conditioning. The parameters
(the radius, which the default derives from fits: ``icc``'s noise level and a
voxel surface's pilot pass) agree to 1e-9.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv._backend import use_backend
from meshcurv.errors import MeshQualityWarning
from meshcurv.geometry import mean_edge_length
from meshcurv.topology import MeshTopology

pytest.importorskip("numba")

# the two backends compared case by case (a minute or more per file): in make test (CI), not in make quick
pytestmark = pytest.mark.slow

#: Relative agreement of the two backends' curvatures and normals (of the largest |k|).
RTOL = 1e-6


def _with_hole(mesh):
    """``mesh`` with the faces around its top vertex removed: an open mesh with one boundary loop."""
    top = np.argmax(mesh.vertices[:, 2])
    centroids = mesh.vertices[mesh.faces].mean(axis=1)
    keep = np.linalg.norm(centroids - mesh.vertices[top], axis=1) > 0.35
    return mesh.vertices, mesh.faces[keep]


def _cut_open(mesh, fraction: float):
    """``mesh`` without the faces whose centroids lie beyond the plane ``axis 0 = centre + fraction * half its
    extent``: an open mesh, its boundary along the mesh's own edges (a voxel surface's staircase)."""
    vertices = mesh.vertices
    low, high = vertices[:, 0].min(), vertices[:, 0].max()
    plane = (low + high) / 2 + fraction * (high - low) / 2
    keep = vertices[mesh.faces][:, :, 0].mean(axis=1) < plane
    return vertices, mesh.faces[keep]


def meshes() -> dict:
    """name -> ``(vertices, faces)``: thin, open, noisy and voxel meshes of a few thousand vertices at most."""
    flat = shapes.ellipsoid((3.0, 3.0, 0.15), subdivisions=16)
    thin_torus = shapes.torus(major_radius=3.0, minor_radius=0.12, n_major=90, n_minor=12)
    hemisphere = shapes.hemisphere(12)
    noisy = shapes.with_normal_noise(shapes.icosphere(10), 0.3, seed=4)
    noisy_flat = shapes.with_normal_noise(shapes.ellipsoid((3.0, 3.0, 0.3), subdivisions=14), 0.2, seed=5)
    noisy_hemisphere = shapes.with_normal_noise(shapes.hemisphere(12, irregular=True, seed=6), 0.3, seed=7)
    voxel = shapes.voxel_sphere(6.0, seed=1)
    voxel_flat = shapes.voxel_ellipsoid((8.0, 8.0, 2.0), seed=2)
    voxel_open = shapes.voxel_ellipsoid((8.0, 6.0, 5.0), spacing=(0.7, 1.0, 1.3), seed=3)
    return {
        "flat_ellipsoid": (flat.vertices, flat.faces),
        "thin_torus": (thin_torus.vertices, thin_torus.faces),
        "hemisphere": (hemisphere.vertices, hemisphere.faces),
        "sphere_with_hole": _with_hole(shapes.icosphere(12)),
        "noisy_sphere": (noisy.vertices, noisy.faces),
        # noise on a thin part and on an open one: the noise level behind icc's default radius, measured
        # beside the far side and beside the rim
        "noisy_flat_ellipsoid": (noisy_flat.vertices, noisy_flat.faces),
        "noisy_hemisphere": (noisy_hemisphere.vertices, noisy_hemisphere.faces),
        "voxel_sphere": (voxel.vertices, voxel.faces),
        "voxel_flat_ellipsoid": (voxel_flat.vertices, voxel_flat.faces),
        "voxel_open_ellipsoid": _cut_open(voxel_open, 0.4),
    }


MESHES = meshes()


def mean_edge(name: str) -> float:
    vertices, faces = MESHES[name]
    return mean_edge_length(vertices, MeshTopology.from_faces(faces, vertices.shape[0]).edges)


def compute(name: str, method: str, backend: str, radius):
    vertices, faces = MESHES[name]
    with use_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        return meshcurv.principal_curvatures(vertices, faces, method=method, radius=radius)


def assert_same(a, b, label: str) -> None:
    """Two results of one mesh or point cloud (``a`` compiled, ``b`` the NumPy path's): the same valid vertices,
    reasons and parameters (numbers to 1e-9 relative), curvatures and normals within :data:`RTOL`."""
    np.testing.assert_array_equal(a.valid, b.valid, err_msg=f"{label}: valid")
    np.testing.assert_array_equal(a.invalid_reason, b.invalid_reason, err_msg=f"{label}: invalid_reason")
    assert set(a.parameters) == set(b.parameters), label
    for key, value in a.parameters.items():
        numbers = isinstance(value, (float, int)) and not isinstance(value, bool)
        if numbers or isinstance(value, (list, tuple, np.ndarray)) and np.asarray(value).dtype.kind == "f":
            np.testing.assert_allclose(b.parameters[key], value, rtol=1e-9, atol=0, err_msg=f"{label}: {key}")
        else:
            assert b.parameters[key] == value, f"{label}: {key}"
    # the largest |k| of the valid vertices (quadric refuses the balls that reach the other side of a thin part:
    # few valid vertices there); 1 where none is valid or all are flat. Not ``initial=1.0``: that made the unit
    # at least 1, a tolerance 6 times looser than 1e-6 of |k|max on the voxel sphere of radius 6
    curvatures = np.abs(np.concatenate([a.k_min[a.valid], a.k_max[a.valid]]))
    scale = float(curvatures.max(initial=0.0)) or 1.0
    for field in ("k_min", "k_max", "mean", "gaussian"):
        got, expected = getattr(b, field), getattr(a, field)
        unit = scale * scale if field == "gaussian" else scale
        np.testing.assert_array_equal(np.isnan(got), np.isnan(expected), err_msg=f"{label}: {field} NaN")
        np.testing.assert_allclose(got, expected, rtol=0, atol=RTOL * unit, err_msg=f"{label}: {field}")
    normals = b.normals
    if a.method == "matgeom":  # matGeom's N is an eigenvector, unoriented (documented): the same up to sign
        normals = normals * np.where(np.einsum("ij,ij->i", normals, a.normals) < 0, -1.0, 1.0)[:, None]
    np.testing.assert_allclose(normals, a.normals, rtol=0, atol=RTOL, err_msg=f"{label}: normals")


#: Every method (all run compiled kernels: geometry, orientation, tensors, their own), the ball methods at
#: their default radius and at a given one (in mean edge lengths), icc's adaptive scale too.
CASES = [
    ("icc", None),
    ("icc", 2.0),
    ("icc", "adaptive"),
    ("quadric", None),
    ("quadric", 3.0),
    ("normal_cycle_ball", None),
    ("normal_cycle_ball", 3.0),
    ("normal_cycle", None),
    ("matgeom", None),
    ("meyer", None),
    ("rusinkiewicz", None),
]


@pytest.mark.parametrize(
    ("method", "edges"),
    [
        pytest.param(m, e, id=f"{m}-{e or 'default'}", marks=[pytest.mark.slow] if e == "adaptive" else [])
        for m, e in CASES
    ],
)
@pytest.mark.parametrize("name", sorted(MESHES))
def test_backends_compute_one_estimator(name, method, edges):
    # the default radius (icc: from the noise level of fits over connected balls; a voxel surface:
    # from a pilot pass) and a given one, in mean edge lengths
    radius = edges * mean_edge(name) if isinstance(edges, float) else edges
    compiled = compute(name, method, "numba", radius)
    reference = compute(name, method, "numpy", radius)
    assert_same(compiled, reference, f"{name}, {method}, radius {radius}")


def test_methods_without_a_radius_are_all_covered():
    assert {method for method, _ in CASES} == set(meshcurv.METHODS)


@pytest.mark.slow  # 1-10 s each: the NumPy path of three radii
@pytest.mark.parametrize("method", ["icc", "quadric", "normal_cycle_ball"])
@pytest.mark.parametrize("name", ["flat_ellipsoid", "sphere_with_hole", "voxel_flat_ellipsoid"])
def test_backends_compute_one_multiscale_estimate(name, method):
    # icc sums every radius in one walk (another kernel than one radius at a time)
    vertices, faces = MESHES[name]
    radii = [r * mean_edge(name) for r in (1.0, 2.0, 4.0)]
    results = {}
    for backend in ("numba", "numpy"):
        with use_backend(backend), warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshQualityWarning)
            results[backend] = meshcurv.multiscale_curvatures(vertices, faces, radii, method=method)
    for radius, compiled, reference in zip(radii, results["numba"], results["numpy"]):
        assert_same(compiled, reference, f"{name}, {method}, multiscale radius {radius}")


def test_flat_ellipsoid_default_radius_does_not_depend_on_the_backend():
    # the case: on a 3 x 3 x 0.15 ellipsoid the NumPy path's Euclidean balls reached the
    # other side (radius 0.538 against 0.118, median H error 99% against 37%); the connected
    # balls measure the surface's noise, not its thickness, so the default is about one edge
    flat = shapes.ellipsoid((3.0, 3.0, 0.15), subdivisions=24)
    h = mean_edge_length(flat.vertices, MeshTopology.from_faces(flat.faces, flat.vertices.shape[0]).edges)
    radii = {}
    for backend in ("numba", "numpy"):
        # its rim (from 0.9 of the radius) is thinner than the balls there: those vertices are undefined, with a
        # warning (before, every vertex valid and 1,420 with H of the wrong sign; issue 29, T68/T69)
        with use_backend(backend), pytest.warns(MeshQualityWarning, match="ball reaches round the surface"):
            result = meshcurv.principal_curvatures(flat.vertices, flat.faces, method="icc")
        radii[backend] = result.parameters["radius"]
        error = np.abs(result.mean - flat.mean) / np.abs(flat.mean)
        assert np.median(error[result.valid]) < 0.5, backend
    assert radii["numpy"] == pytest.approx(radii["numba"], rel=1e-9)
    assert radii["numpy"] < 1.5 * h  # a clean mesh: one edge length, not the thickness


def two_sheets():
    """Two parallel unit squares 0.1 apart (21 x 21 vertices each), and the first one alone."""
    side = np.linspace(0.0, 1.0, 21)
    x, y = np.meshgrid(side, side, indexing="ij")
    sheet = np.column_stack([x.ravel(), y.ravel(), np.zeros(x.size)])
    corner = (np.arange(20)[:, None] * 21 + np.arange(20)[None, :]).ravel()
    faces = np.vstack(
        [np.column_stack([corner, corner + 21, corner + 22]), np.column_stack([corner, corner + 22, corner + 1])]
    )
    return (np.vstack([sheet, sheet + [0.0, 0.0, 0.1]]), np.vstack([faces, faces + sheet.shape[0]])), (sheet, faces)


#: The middle vertex of the first sheet.
MIDDLE = 10 * 21 + 10


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_connected_balls_leave_out_the_other_sheet(backend):
    # radius 0.3: the Euclidean ball of a vertex of one sheet holds faces of both, its
    # surface-connected piece those of its own sheet only (on either backend)
    from meshcurv.neighborhoods import ball_face_sums

    (vertices, faces), (sheet, sheet_faces) = two_sheets()
    ones = np.ones((faces.shape[0], 1))
    with use_backend(backend):
        connected = ball_face_sums(vertices, faces, 0.3, ones, connected=True)[MIDDLE, 0]
        both = ball_face_sums(vertices, faces, 0.3, ones)[MIDDLE, 0]
        alone = ball_face_sums(sheet, sheet_faces, 0.3, ones[: sheet_faces.shape[0]])[MIDDLE, 0]
    assert connected == pytest.approx(alone, rel=1e-12)
    assert both > 1.5 * alone  # the other sheet's disc, of radius sqrt(0.3^2 - 0.1^2)


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_connected_jet_balls_leave_out_the_other_sheet(backend):
    # the jets' walk over the edges: a fit's count is its own sheet's points within the radius
    from meshcurv.jets import fit_jets

    (vertices, faces), (sheet, _) = two_sheets()
    adjacency = MeshTopology.from_faces(faces, vertices.shape[0]).neighbour_lists
    normals = np.tile([0.0, 0.0, 1.0], (vertices.shape[0], 1))
    with use_backend(backend):
        _, _, connected = fit_jets(vertices, normals, 0.3, degree=2, centres=[MIDDLE], adjacency=adjacency)
        _, _, euclidean = fit_jets(vertices, normals, 0.3, degree=2, centres=[MIDDLE])
    distances = np.linalg.norm(vertices - vertices[MIDDLE], axis=1)
    own = distances[: sheet.shape[0]]
    assert connected[MIDDLE] == (own < 0.3).sum()  # strictly inside: a non-zero weight
    assert euclidean[MIDDLE] == (distances < 0.3).sum() > 1.5 * (own < 0.3).sum()


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_edge_lists_that_are_not_the_meshs_are_refused(backend):
    # both backends check `adjacency` alike before walking it
    from meshcurv.errors import InvalidMeshError
    from meshcurv.jets import fit_jets

    (vertices, faces), _ = two_sheets()
    indptr, indices = MeshTopology.from_faces(faces, vertices.shape[0]).neighbour_lists
    normals = np.tile([0.0, 0.0, 1.0], (vertices.shape[0], 1))
    with use_backend(backend):
        with pytest.raises(
            InvalidMeshError, match=r"`adjacency` must be CSR lists of 882 vertices; got indptr \(10,\)"
        ):
            fit_jets(vertices, normals, 0.3, adjacency=(indptr[:10], indices))
        wrong = np.array(indices, copy=True)
        wrong[5] = vertices.shape[0]
        with pytest.raises(InvalidMeshError, match=r"`adjacency` must hold vertex indices in 0\.\.881"):
            fit_jets(vertices, normals, 0.3, adjacency=(indptr, wrong))


def _relative_mismatch(got: np.ndarray, expected: np.ndarray) -> float:
    """The largest ``|got - expected| / |expected|`` over the finite values (0 where both are 0)."""
    finite = np.isfinite(expected)
    difference = np.abs(got[finite] - expected[finite])
    return float(np.max(difference / np.maximum(np.abs(expected[finite]), 1e-300), initial=0.0, where=difference > 0))


def test_backends_give_one_label_table_for_objects_cut_by_the_border():
    # label_curvatures on both backends (issue 29, class 10, for the voxel path users run most): a ball cut by
    # the image's first face, an ellipsoid cut by its last column face, a ball inside, in anisotropic voxels; the
    # table's every column equal, its numbers to 1e-6 relative (measured at 778af2a: 1e-12)
    pytest.importorskip("pandas")
    from meshcurv.volume import label_curvatures

    z, y, x = np.mgrid[:26, :30, :26]
    image = np.zeros(z.shape, dtype=np.uint8)
    image[(z - 2.3) ** 2 + (y - 14.6) ** 2 + (x - 9.2) ** 2 < 9.5**2] = 1
    image[((z - 17.4) / 6.0) ** 2 + ((y - 8.3) / 5.0) ** 2 + ((x - 23.8) / 4.0) ** 2 < 1.0] = 2
    image[(z - 18.2) ** 2 + (y - 21.7) ** 2 + (x - 10.1) ** 2 < 4.6**2] = 3
    tables = {}
    for backend in ("numba", "numpy"):
        with use_backend(backend), warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshQualityWarning)
            tables[backend] = label_curvatures(image, spacing=(0.7, 1.0, 1.3))
    compiled, reference = tables["numba"], tables["numpy"]
    assert list(compiled["label"]) == [1, 2, 3] and list(compiled["status"]) == ["ok"] * 3
    assert list(compiled.columns) == list(reference.columns)
    for column in compiled.columns:
        got, expected = reference[column].to_numpy(), compiled[column].to_numpy()
        if expected.dtype.kind == "f":
            np.testing.assert_array_equal(np.isnan(got), np.isnan(expected), err_msg=f"{column}: NaN")
            assert _relative_mismatch(got, expected) <= RTOL, column
        else:
            np.testing.assert_array_equal(got, expected, err_msg=column)
