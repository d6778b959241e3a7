"""The meshes users bring, right with the default call: marching cubes, soups, seams, any winding.

Oracles: the exact curvatures of the voxelised analytic solids (at each
vertex's closest point on the surface, :mod:`meshcurv.shapes`), and invariance
under welding (a soup or a seam-split mesh gives the welded mesh's values) and
winding (any winding of a closed mesh gives the outward mesh's values).
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.defects import FRAGMENT
from meshcurv.errors import InvalidOptionError, MeshQualityWarning
from meshcurv.estimators import ESTIMATORS
from meshcurv.lattice import voxel_grid
from meshcurv.result import INVALID_REASONS

METHODS = [name for name in ESTIMATORS if name != "matgeom"]


def quiet(vertices, faces, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        return meshcurv.principal_curvatures(vertices, faces, **options)


def median_error(estimate, exact):
    return float(np.nanmedian(np.abs(estimate - exact) / np.abs(exact)))


@pytest.fixture(scope="module")
def voxel_meshes():
    pytest.importorskip("skimage")
    return {
        "sphere": shapes.voxel_sphere(10.0, (1.0, 1.0, 1.0), seed=1),
        "sphere_2to1": shapes.voxel_sphere(10.0, (2.0, 1.0, 1.0), seed=2),
        "ellipsoid_fine": shapes.voxel_ellipsoid((2.0, 1.4, 1.0), (0.05, 0.05, 0.05), seed=3),
    }


# Targets of the issue on marching-cubes meshes (default call): isotropic H <= 3%, K <= 6%;
# anisotropic up to 4:1 H <= 6%, K <= 12%. Measured with this code: 0.8%/1.6%, 1.2%/2.4%, 1.2%/2.5%.
TARGETS = {"sphere": (0.03, 0.06), "sphere_2to1": (0.06, 0.12), "ellipsoid_fine": (0.03, 0.06)}


@pytest.mark.parametrize("name", sorted(TARGETS))
def test_marching_cubes_meshes_are_right_with_the_default_call(name, voxel_meshes):
    mesh = voxel_meshes[name]
    with pytest.warns(MeshQualityWarning, match="the mesh was wound inward"):
        r = meshcurv.principal_curvatures(mesh.vertices, mesh.faces)
    assert r.valid.all()
    assert (np.sign(r.mean) == np.sign(mesh.mean)).all()  # convex: positive, as given by marching cubes
    h_target, k_target = TARGETS[name]
    assert median_error(r.mean, mesh.mean) <= h_target
    assert median_error(r.gaussian, mesh.gaussian) <= k_target
    assert r.parameters["surface"] == "voxel"
    assert r.parameters["orient"] == "outward"
    np.testing.assert_allclose(sorted(r.parameters["voxel_spacing"]), sorted(mesh.spacing), rtol=1e-9)


def test_the_voxel_radius_is_not_what_the_smooth_rule_gives(voxel_meshes):
    # with the smooth-mesh rule (about one edge length) the staircase dominates: errors of 100% and more
    mesh = voxel_meshes["sphere"]
    r = quiet(mesh.vertices, mesh.faces, radius=float(np.max(mesh.spacing)))
    assert median_error(r.mean, mesh.mean) > 0.3


def _smoothed_sphere(radius, sigma):
    """Marching cubes at 0.5 of a ball's mask blurred by a Gaussian of ``sigma`` voxels (the biology pipeline).

    skimage returns float32 coordinates: interpolated values repeat a few times each across the symmetric
    solid, among the grid planes (the grid was not recognised there before: a radius of one edge, 34%
    median H error at radius 20).
    """
    skimage_measure = pytest.importorskip("skimage.measure")
    from scipy.ndimage import gaussian_filter

    axis = np.arange(-radius - 6, radius + 7, dtype=float) + 0.37  # an origin off the grid's symmetry
    x, y, z = np.meshgrid(axis, axis - 0.21, axis + 0.13, indexing="ij", sparse=True)
    mask = (x * x + y * y + z * z <= radius * radius).astype(float)
    vertices, faces, _, _ = skimage_measure.marching_cubes(gaussian_filter(mask, sigma), 0.5)
    return vertices.astype(float), np.ascontiguousarray(faces[:, ::-1])


@pytest.mark.slow
@pytest.mark.parametrize("sigma", [0.5, 1.0])
def test_a_smoothed_masks_isosurface_is_measured_as_a_voxel_surface(sigma):
    # the blurred level set stays within a fraction of a voxel of the sphere at sigma <= 1 (radius 20): the
    # curvature is 1/R to the estimator's error on voxel surfaces (1% target of the isotropic rows)
    vertices, faces = _smoothed_sphere(20.0, sigma)
    grid = voxel_grid(vertices)
    assert grid is not None
    np.testing.assert_allclose(grid.spacing, 1.0, rtol=1e-9)
    r = quiet(vertices, faces)
    assert r.parameters["surface"] == "voxel"
    centre = vertices.mean(axis=0)
    exact = 1.0 / np.linalg.norm(vertices - centre, axis=1)  # the closest sphere point's curvature
    assert median_error(r.mean, exact) < 0.01


def test_voxel_grid_is_found_on_marching_cubes_meshes_only(voxel_meshes):
    for mesh in voxel_meshes.values():
        moved = mesh.vertices + np.array([3.7, -1.1, 0.25])  # any origin
        grid = voxel_grid(moved)
        assert grid is not None and grid.fraction >= 0.95
        np.testing.assert_allclose(grid.spacing, mesh.spacing, rtol=1e-9)
    for smooth in (
        shapes.torus(),
        shapes.saddle(),
        shapes.icosphere(8),
        shapes.cylinder(),
        shapes.uv_sphere(),
        shapes.random_sphere(),
        shapes.ellipsoid(),
    ):
        assert voxel_grid(smooth.vertices) is None
        r = quiet(smooth.vertices, smooth.faces)
        assert r.parameters["surface"] == "smooth"


def soup(mesh):
    """Every face with its own three corners, as in an STL file."""
    return mesh.vertices[mesh.faces.ravel()], np.arange(3 * mesh.faces.shape[0]).reshape(-1, 3), mesh.faces.ravel()


def seam_split(mesh):
    """The faces with a corner at y > 0 take copies of their corners at x > 0: a cut along half a meridian.

    Originals left in no face are unreferenced vertices of the split mesh.
    """
    vertices, faces = mesh.vertices, mesh.faces.copy()
    upper = (vertices[faces, 1] > 0).any(axis=1)
    moved = np.unique(faces[upper][vertices[faces[upper], 0] > 0])
    copy = np.full(vertices.shape[0], -1)
    copy[moved] = vertices.shape[0] + np.arange(moved.size)
    corners = faces[upper]
    faces[upper] = np.where(copy[corners] >= 0, copy[corners], corners)
    origin = np.concatenate([np.arange(vertices.shape[0]), moved])
    return vertices[origin], faces, origin


@pytest.mark.parametrize("split", [soup, seam_split])
@pytest.mark.parametrize("method", METHODS)
def test_soups_and_seams_give_the_welded_mesh_values(method, split):
    mesh = shapes.torus(3.0, 1.0, 36, 18, jitter=0.3, seed=5)
    with warnings.catch_warnings():
        # quadric: 6 default balls reach round the tube, NaN since e459c2c (10-33% of the largest |k| off before);
        # the split mesh's one warning names them beside the weld
        warnings.filterwarnings(
            "ignore", "quadric: 6 vertices have a default ball that reaches round", MeshQualityWarning
        )
        welded = meshcurv.principal_curvatures(mesh.vertices, mesh.faces, method=method)
    vertices, faces, origin = split(mesh)
    with pytest.warns(MeshQualityWarning, match=r"welded \d+ coincident vertices") as record:
        r = meshcurv.principal_curvatures(vertices, faces, method=method)
    assert len(record) == 1
    assert r.n_vertices == vertices.shape[0] and r.parameters["n_welded_vertices"] > 0
    used = np.isin(np.arange(vertices.shape[0]), faces)
    assert (r.invalid_reason[~used] == INVALID_REASONS.index("unreferenced vertex (in no face)")).all()
    np.testing.assert_array_equal(r.valid[used], welded.valid[origin[used]])
    scale = np.nanmax(np.abs(welded.k_max))
    for field in ("k_min", "k_max", "mean", "gaussian"):
        np.testing.assert_allclose(
            getattr(r, field)[used], getattr(welded, field)[origin[used]], rtol=1e-9, atol=1e-9 * scale
        )


def test_weld_false_keeps_the_soup_as_given():
    mesh = shapes.icosphere(4)
    vertices, faces, _ = soup(mesh)
    with pytest.warns(MeshQualityWarning, match="boundary"):
        r = meshcurv.principal_curvatures(vertices, faces, method="normal_cycle", weld=False)
    assert not r.valid.any()
    # each face a part of its own: no vertex with a ring of faces (the defect before the boundary's)
    assert (r.invalid_reason == FRAGMENT).all()
    with pytest.raises(InvalidOptionError, match="`weld` must be True or False; got 'yes'"):
        meshcurv.principal_curvatures(vertices, faces, weld="yes")


def test_faces_wound_both_ways_are_oriented_by_default():
    sphere = shapes.icosphere(16, radius=2.0)
    faces = sphere.faces.copy()
    faces[::7] = faces[::7, [0, 2, 1]]
    with pytest.warns(MeshQualityWarning, match="reversed 732 of 5120 faces"):
        r = meshcurv.principal_curvatures(sphere.vertices, faces)
    assert r.valid.mean() >= 0.95
    assert np.median(r.mean) == pytest.approx(0.5, rel=1e-3)


def test_matgeom_keeps_the_faces_as_given():
    # matGeom's numbers: no welding, no reorientation unless asked
    sphere = shapes.icosphere(4)
    inward = sphere.faces[:, ::-1]
    r = meshcurv.principal_curvatures(sphere.vertices, inward, method="matgeom")
    assert r.parameters["orient"] == "keep" and r.parameters["n_welded_vertices"] == 0
    assert np.median(r.mean) < 0


def test_every_invalid_vertex_has_a_reason():
    torus = shapes.torus(3.0, 1.0, 24, 12)
    n = torus.vertices.shape[0]
    vertices = np.vstack([torus.vertices, [[10.0, 10.0, 10.0]]])  # one unreferenced vertex
    faces = np.vstack([torus.faces, [[0, 1, n - 1]], [[torus.faces[0, 0], torus.faces[0, 1], 5]]])
    with pytest.warns(MeshQualityWarning, match="invalid vertices by reason: ") as record:
        r = meshcurv.principal_curvatures(vertices, faces, method="normal_cycle")
    assert len(record) == 1
    assert ((r.invalid_reason == 0) == r.valid).all()
    assert r.invalid_reason[n] == INVALID_REASONS.index("unreferenced vertex (in no face)")
    nonmanifold = INVALID_REASONS.index("on a non-manifold edge (3+ faces)")
    assert r.invalid_reason[torus.faces[0, 0]] == nonmanifold
    counts = r.invalid_counts()
    assert sum(counts.values()) == int((~r.valid).sum())
    assert counts["unreferenced vertex (in no face)"] == 1
