"""Double-sided meshes (every face twice, with opposite windings): computed on one side (issue 29, class 7).

Before, every edge of such a mesh had four faces (all vertices NaN) and its
total Gaussian curvature counted the surface twice or more (8 pi to 17 x 4 pi on a
sphere, by the order of the faces). The oracles: the analytic curvatures of the
sphere and torus, Gauss-Bonnet (4 pi and 0 exactly, whatever the normals), and
the one-sided mesh's own result (the same faces, so the same numbers).
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import MeshTopology, shapes
from meshcurv.weld import drop_double_sided

SPHERE = shapes.icosphere(10, radius=2.0)
TORUS = shapes.torus(3.0, 1.0, 64, 32)
TOTAL_GAUSSIAN = {SPHERE.name: 4 * np.pi, TORUS.name: 0.0}  # 2 pi chi


def stacked(faces):
    """Every face, then every face reversed (a second side appended)."""
    return np.vstack([faces, faces[:, ::-1]])


def shuffled(faces, seed=0):
    """Both sides of every face, the pairs in a random order and either side first."""
    rng = np.random.default_rng(seed)
    both = stacked(faces)
    return both[rng.permutation(both.shape[0])]


def one_warning(vertices, faces, **options):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = meshcurv.principal_curvatures(vertices, faces, **options)
    assert len(caught) == 1, [str(w.message) for w in caught]
    assert issubclass(caught[0].category, meshcurv.MeshQualityWarning)
    return result, str(caught[0].message)


@pytest.mark.parametrize("method", meshcurv.METHODS)
@pytest.mark.parametrize("mesh", [SPHERE, TORUS], ids=lambda m: m.name)
@pytest.mark.parametrize("layout", [stacked, shuffled])
def test_a_double_sided_mesh_gives_the_curvatures_of_its_one_side(method, mesh, layout):
    single = meshcurv.principal_curvatures(mesh.vertices, mesh.faces, method=method)
    result, message = one_warning(mesh.vertices, layout(mesh.faces), method=method)
    n = mesh.faces.shape[0]
    assert f"dropped {n} faces that repeat another face's corners with the opposite winding" in message
    assert result.parameters["n_double_sided_faces"] == n
    assert result.valid.all()
    # Gauss-Bonnet, exact whatever the normals: 2 pi chi, not twice that
    assert result.integral("gaussian") == pytest.approx(TOTAL_GAUSSIAN[mesh.name], abs=1e-9)
    assert result.integral("area") == pytest.approx(single.integral("area"), rel=1e-12)
    if method != "matgeom":  # matGeom's numbers are dimensionless: only the one-sided comparison below
        # coarse meshes: the median errors of the one-sided mesh are below 0.012 (H) and 0.03 (K)
        assert np.median(np.abs(result.mean - mesh.mean)) < 0.02
        assert np.median(np.abs(result.gaussian - mesh.k_min * mesh.k_max)) < 0.04
    # the side kept is the outward one (matgeom's orient='keep' too): the one-sided mesh's numbers, up to
    # the round-off of sums over faces in another order (quadric's fits: 7e-8 relative on the torus)
    tolerance = {"rtol": 1e-12, "atol": 1e-12} if layout is stacked else {"rtol": 1e-6, "atol": 1e-9}
    np.testing.assert_allclose(result.k_min, single.k_min, **tolerance)
    np.testing.assert_allclose(result.k_max, single.k_max, **tolerance)


def test_a_double_sided_triangle_soup_is_welded_then_made_one_sided():
    corners = np.vstack([SPHERE.faces, SPHERE.faces[:, ::-1]]).ravel()
    soup = SPHERE.vertices[corners]
    result, message = one_warning(soup, np.arange(corners.size).reshape(-1, 3), method="normal_cycle")
    assert "welded" in message and f"dropped {SPHERE.faces.shape[0]} faces" in message
    assert result.valid.all()
    assert np.median(np.abs(result.mean - 0.5)) < 0.01
    assert result.integral("gaussian") == pytest.approx(4 * np.pi, abs=1e-9)


def test_an_open_double_sided_patch_keeps_its_boundary():
    # a hemisphere-like cap of the sphere, both sides: its rim edges have 2 faces, its inner edges 4
    used, cap = np.unique(SPHERE.faces[(SPHERE.vertices[SPHERE.faces][:, :, 2] > 0.5).all(axis=1)], return_inverse=True)
    cap, vertices = cap.reshape(-1, 3), SPHERE.vertices[used]
    one = meshcurv.principal_curvatures(vertices, cap, method="icc")
    result, message = one_warning(vertices, stacked(cap), method="icc")
    assert f"dropped {cap.shape[0]} faces" in message
    np.testing.assert_array_equal(result.valid, one.valid)
    np.testing.assert_allclose(result.mean[one.valid], one.mean[one.valid], rtol=1e-12)
    assert result.integral("gaussian") == pytest.approx(one.integral("gaussian"), rel=1e-12)


def test_the_side_kept_is_outward_whatever_the_order_of_the_faces():
    # every pair with its inward face first: the outward copies are kept, nothing is reversed after
    result, message = one_warning(SPHERE.vertices, stacked(SPHERE.faces[:, ::-1]), method="meyer")
    assert "reversed" not in message
    assert np.median(result.mean) == pytest.approx(0.5, rel=1e-3)


def test_a_clean_mesh_drops_nothing():
    result = meshcurv.principal_curvatures(SPHERE.vertices, SPHERE.faces)
    assert result.parameters["n_double_sided_faces"] == 0


def test_drop_double_sided_keeps_the_first_winding_and_same_winding_copies():
    faces = np.array([[0, 1, 2], [2, 1, 0], [1, 2, 0], [0, 2, 1], [0, 1, 3], [0, 1, 3]])
    one = drop_double_sided(np.eye(4, 3), MeshTopology.from_faces(faces, 4))
    # group {0,1,2}: faces 0 and 2 are wound as face 0, faces 1 and 3 the other way; {0,1,3}: one winding
    np.testing.assert_array_equal(one.dropped, [False, True, False, True, False, False])
    assert one.n_dropped == 2
    np.testing.assert_array_equal(one.topology.faces, faces[[0, 2, 4, 5]])
    # faces with a repeated corner have no winding: kept
    flat = np.array([[0, 1, 1], [1, 1, 0], [0, 1, 2], [0, 1, 2], [0, 1, 2]])
    assert drop_double_sided(np.eye(3), MeshTopology.from_faces(flat, 3)).n_dropped == 0


def test_drop_double_sided_with_vertices_beyond_the_one_key_range():
    # more than 2**20 vertices: the vertex sets are sorted column by column instead of as one key
    n = 2**20 + 10
    faces = np.array([[n - 3, n - 2, n - 1], [n - 1, n - 2, n - 3], [n - 3, n - 1, n - 2], [0, 1, 2]])
    vertices = np.zeros((n, 3))
    vertices[[1, 2, n - 2, n - 1], [0, 1, 0, 1]] = 1.0
    one = drop_double_sided(vertices, MeshTopology.from_faces(faces, n))
    np.testing.assert_array_equal(one.dropped, [False, True, True, False])


def test_the_batch_table_totals_a_double_sided_sphere_once(tmp_path):
    from meshcurv import batch

    source = tmp_path / "double.obj"
    lines = [f"v {x:.17g} {y:.17g} {z:.17g}" for x, y, z in SPHERE.vertices]
    lines += [f"f {a + 1} {b + 1} {c + 1}" for a, b, c in stacked(SPHERE.faces)]
    source.write_text("\n".join(lines) + "\n")
    row = batch.process_mesh(
        source, tmp_path / "out" / "double.npz", tmp_path / "out" / ".double.json", method="normal_cycle"
    )
    assert row["status"] == "computed", row
    assert row["total_gaussian"] == pytest.approx(4 * np.pi, abs=1e-9)
    assert row["n_invalid"] == 0
    assert f"dropped {SPHERE.faces.shape[0]} faces" in row["warnings"]


# ---- closed parts stored twice, with vertices of their own (coincident copies) ----


def _stored_twice(mesh, *, reverse: bool, seed: int = 0):
    """``mesh`` and a coincident copy: its vertices shuffled and moved by round-off, its faces in another order."""
    rng = np.random.default_rng(seed)
    n = mesh.vertices.shape[0]
    permutation = rng.permutation(n)
    inverse = np.argsort(permutation)
    copy_vertices = mesh.vertices[permutation] * (1.0 + 1e-13)
    copy_faces = inverse[mesh.faces][rng.permutation(mesh.faces.shape[0])]
    if reverse:
        copy_faces = copy_faces[:, ::-1]
    return (np.vstack([mesh.vertices, copy_vertices]), np.vstack([mesh.faces, copy_faces + n]), permutation)


@pytest.mark.parametrize("reverse", [False, True])
@pytest.mark.parametrize("method", ["icc", "normal_cycle", "quadric", "meyer"])
def test_a_closed_part_stored_twice_is_measured_once(method, reverse):
    sphere = shapes.icosphere(3, radius=2.0)
    vertices, faces, permutation = _stored_twice(sphere, reverse=reverse)
    n = sphere.vertices.shape[0]
    with pytest.warns(
        meshcurv.errors.MeshQualityWarning, match=rf"closed parts stored twice.*\({n} vertices of copies\)"
    ):
        result = meshcurv.principal_curvatures(vertices, faces, method=method)
    assert result.parameters["n_copy_vertices"] == n
    assert result.valid.all()
    # the sphere's curvature everywhere, and each copy's vertex has the value of the vertex it repeats
    np.testing.assert_allclose(result.mean, 0.5, rtol=0.05)
    np.testing.assert_array_equal(result.mean[n:], result.mean[permutation])
    # Gauss-Bonnet counts the surface once: 4 pi, not 8 pi
    assert result.integral("gaussian") == pytest.approx(4.0 * np.pi, rel=1e-9)
    # and every figure is that of the sphere stored once
    once = meshcurv.principal_curvatures(sphere.vertices, sphere.faces, method=method)
    assert result.integral("area") == pytest.approx(once.integral("area"), rel=1e-9)
    np.testing.assert_allclose(result.mean[:n], once.mean, rtol=1e-9)


def test_near_copies_and_distinct_parts_are_not_merged():
    sphere = shapes.icosphere(3)
    # a second sphere of the same mesh moved by a tenth of an edge: a distinct part, not a copy
    moved = sphere.vertices + [0.05, 0.0, 0.0]
    vertices = np.vstack([sphere.vertices, moved])
    faces = np.vstack([sphere.faces, sphere.faces + sphere.vertices.shape[0]])
    with warnings.catch_warnings():
        warnings.simplefilter(
            "ignore", meshcurv.errors.MeshQualityWarning
        )  # two intersecting spheres: other warnings may come
        result = meshcurv.principal_curvatures(vertices, faces)
    assert result.parameters["n_copy_vertices"] == 0
    assert result.integral("gaussian") == pytest.approx(8.0 * np.pi, rel=1e-9)
    # two spheres far apart: no copy either, and no warning at all
    far = np.vstack([sphere.vertices, sphere.vertices + [10.0, 0.0, 0.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = meshcurv.principal_curvatures(far, faces)
    assert result.parameters["n_copy_vertices"] == 0


def test_weld_false_keeps_the_copies_each_outward():
    # weld=False: both copies measured, neither taken for a cavity of the other (the corner tested for
    # nesting lies on the other copy's surface): H = +1/R on both, and totals count the surface twice
    sphere = shapes.icosphere(2)
    vertices, faces, _ = _stored_twice(sphere, reverse=False, seed=3)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        result = meshcurv.principal_curvatures(vertices, faces, weld=False)
    assert result.parameters["n_copy_vertices"] == 0
    assert (result.mean[result.valid] > 0).all() and result.valid.all()
    assert result.integral("gaussian") == pytest.approx(8.0 * np.pi, rel=1e-9)
