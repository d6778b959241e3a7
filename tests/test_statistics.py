"""FreeSurfer's per-object curvature statistics (meshcurv.statistics), on meshes and on label images.

Expected values are those of the smooth surfaces: a sphere of radius R has
k1 = k2 = 1/R, so BE = int (k1^2 + k2^2) dA = 8 pi, ICIp = 1, ICIn = 0, FI = 0,
int H dA = 4 pi R, shape index 1; a torus of radii R > r has k1 = 1/r and
k2 = cos t / (R + r cos t) with dA = r (R + r cos t) dt dp, integrated by
quadrature below (int H dA = 2 pi^2 R, int K+ = int |K-| = 4 pi); a closed
surface of genus g has int K dA = 4 pi (1 - g) (Gauss-Bonnet). Label images
are marching cubes of voxelised shapes with anisotropic voxels: the
tolerances (3% for spheres, 5% for tori, as issue 34 asks) are those of the
voxel staircase averaged out by the estimator.
"""

import warnings

import numpy as np
import pytest
from scipy import integrate

import meshcurv
from meshcurv.errors import InvalidOptionError, MeshQualityWarning
from meshcurv.statistics import COLUMNS, FIELDS, MOMENTS, curvature_statistics

pytest.importorskip("skimage")
pytest.importorskip("pandas")

from meshcurv.volume import COLUMNS as TABLE_COLUMNS  # noqa: E402
from meshcurv.volume import label_curvatures  # noqa: E402

OFFSET = np.array([0.23, -0.17, 0.11])  # off the voxel grid's symmetry


def _grid(extent, spacing, offset=OFFSET):
    spacing = np.asarray(spacing, dtype=float)
    counts = np.ceil(np.asarray(extent) / spacing).astype(int) + 4
    axes = [np.arange(n) * s - (n - 1) * s / 2 - o for n, s, o in zip(counts, spacing, offset)]
    return np.meshgrid(*axes, indexing="ij")


def ball_image(radius, spacing):
    z, y, x = _grid([2 * radius] * 3, spacing)
    return (z**2 + y**2 + x**2 <= radius**2).astype(np.uint8)


def torus_inside(z, y, x, major, minor):
    return (np.sqrt(x**2 + y**2) - major) ** 2 + z**2 <= minor**2


def torus_image(major, minor, spacing, offset=OFFSET):
    z, y, x = _grid([2 * minor, 2 * (major + minor), 2 * (major + minor)], spacing, offset)
    return torus_inside(z, y, x, major, minor).astype(np.uint8)


def torus_truth(major, minor):
    """Bending energy and folding index of a torus, by quadrature over the tube angle t."""

    def around(f):  # int f dA, dA = r (R + r cos t) dt dp
        value, _ = integrate.quad(lambda t: f(t) * minor * (major + minor * np.cos(t)), 0, 2 * np.pi, limit=200)
        return 2 * np.pi * value

    k2 = lambda t: np.cos(t) / (major + minor * np.cos(t))  # noqa: E731
    bending = around(lambda t: 1 / minor**2 + k2(t) ** 2)
    folding = around(lambda t: (1 / minor) * (1 / minor - abs(k2(t)))) / (4 * np.pi)
    return bending, folding


def one_row(image, spacing, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        table, surfaces = label_curvatures(image, spacing=spacing, return_meshes=True, **options)
    assert len(table) == 1 and table.status[0] == "ok"
    return table.iloc[0], surfaces[int(table.label[0])]


def assert_integrals_add_up(stats):
    for name in ("mean_integral", "gaussian_integral"):
        positive, negative = stats[f"{name}_positive"], stats[f"{name}_negative"]
        assert stats[name] == pytest.approx(positive + negative, rel=1e-12, abs=1e-12)
        assert stats[f"{name}_rectified"] == pytest.approx(positive - negative, rel=1e-12, abs=1e-12)


# ---------------------------------------------------------------- label images, anisotropic voxels


@pytest.mark.parametrize("spacing, radius", [((0.7, 0.5, 0.4), 6.0), ((2.0, 1.0, 1.0), 20.0)])
def test_label_sphere_matches_the_analytic_values(spacing, radius):
    row, _ = one_row(ball_image(radius, spacing), spacing)
    assert row.bending_energy == pytest.approx(8 * np.pi, rel=0.03)
    assert row.ici_positive == pytest.approx(1.0, rel=0.03)
    assert abs(row.ici_negative) < 0.01
    assert row.mean_integral == pytest.approx(4 * np.pi * radius, rel=0.03)
    assert row.mean_integral_negative == pytest.approx(0.0, abs=0.01 * row.mean_integral)
    assert row.shape_index_mean == pytest.approx(1.0, rel=0.03)
    assert row.curvedness_mean == pytest.approx(1 / radius, rel=0.03)
    assert row.mean_mean == pytest.approx(1 / radius, rel=0.03)
    assert row.gaussian_integral == pytest.approx(4 * np.pi, rel=1e-9)  # Gauss-Bonnet, genus 0
    # FI >= 0 pointwise, so the estimator's k_max - k_min (a few % of 1/R) leaves a small positive FI;
    # measured 0.07-0.09 on these spheres, against 6 for the tori below
    assert 0.0 <= row.folding_index < 0.1
    assert row.k_min_min <= row.k_min_mean <= row.k_min_max
    assert row.k_max_std < 0.05 / radius
    assert_integrals_add_up(row)
    assert "folds" not in row.warnings


@pytest.mark.parametrize("spacing, major, minor", [((0.7, 0.5, 0.4), 8.0, 3.5), ((2.0, 1.0, 1.0), 20.0, 10.0)])
def test_label_torus_matches_the_analytic_values(spacing, major, minor):
    row, _ = one_row(torus_image(major, minor, spacing), spacing)
    assert row.ici_positive == pytest.approx(1.0, rel=0.05)
    assert row.ici_negative == pytest.approx(1.0, rel=0.05)
    assert row.mean_integral == pytest.approx(2 * np.pi**2 * major, rel=0.05)
    assert row.gaussian_integral == pytest.approx(0.0, abs=1e-9)  # Gauss-Bonnet, genus 1
    bending, folding = torus_truth(major, minor)
    assert row.bending_energy == pytest.approx(bending, rel=0.05)
    assert row.folding_index == pytest.approx(folding, rel=0.05)
    assert row.k_max_mean == pytest.approx(1 / minor, rel=0.05)
    assert row.shape_index_mean == pytest.approx(0.5, abs=0.05)  # a symmetric mix of ridges (1/2) and saddles
    assert_integrals_add_up(row)
    assert "folds" not in row.warnings


def test_folded_gauss_image_is_flagged():
    # a torus of tube radius 5 voxels along the coarse axis, its equator half a voxel off the grid (z offset
    # 0.999 of a 2-unit voxel): the top and bottom terraces are one voxel wide. At the default scale the
    # positive Gaussian curvature integrates to that of a torus, 4 pi (ICIp 1; it was 2.1 before the pilot's
    # centres were chosen by position); over balls of 1.5 units, below a voxel's 2, the fitted normals wobble
    # along the terraces and the Gauss image folds (ICIp 2.4)
    spacing = (2.0, 1.0, 1.0)
    image = torus_image(20.0, 10.0, spacing, offset=(0.999, 0.0, 0.0))
    row, _ = one_row(image, spacing)
    assert row.ici_positive == pytest.approx(1.0, abs=0.05)
    assert "questionable" not in row.warnings
    row, surface = one_row(image, spacing, radius=1.5)
    assert row.ici_positive > 1.15
    assert (
        "ici_positive, ici_negative and the rectified, positive and negative integrals of K are questionable"
        in row.warnings
    )
    with pytest.warns(MeshQualityWarning, match="the Gauss image of the fitted normals folds"):
        stats = curvature_statistics(surface.result)
    assert stats["ici_positive"] == pytest.approx(row.ici_positive, rel=1e-9)


def test_label_of_genus_two_has_total_gaussian_curvature_minus_4_pi():
    spacing = (0.7, 0.5, 0.4)
    z, y, x = _grid([4.0, 24.0, 13.0], spacing)
    image = (torus_inside(z, y - 5.0, x, 4.0, 1.6) | torus_inside(z, y + 5.0, x, 4.0, 1.6)).astype(np.uint8)
    row, _ = one_row(image, spacing)
    assert row.euler_characteristic == -2  # the shape is a double torus
    assert row.gaussian_integral == pytest.approx(4 * np.pi * (1 - 2), rel=1e-9)
    assert row.ici_positive - row.ici_negative == pytest.approx(-1.0, rel=1e-9)


def test_mesh_function_gives_the_numbers_of_the_label_table():
    spacing = (0.7, 0.5, 0.4)
    row, surface = one_row(ball_image(5.0, spacing), spacing)
    stats = curvature_statistics(surface.result)
    for name in COLUMNS:
        assert stats[name] == pytest.approx(row[name], rel=1e-9, abs=1e-12), name


def test_table_has_every_statistic_and_freesurfer_aliases():
    assert set(COLUMNS) <= set(TABLE_COLUMNS)
    for name in (
        "bending_energy",
        "folding_index",
        "ici_positive",
        "ici_negative",
        "mean_integral",
        "shape_index_mean",
        "curvedness_mean",
    ):
        assert name in COLUMNS
    spacing = (0.7, 0.5, 0.4)
    row, _ = one_row(ball_image(5.0, spacing), spacing)
    for field in FIELDS:  # FreeSurfer's mean is the existing area-weighted mean
        assert row[f"{field}_mean"] == row[f"{field}_weighted"], field
    assert row.mean_integral == row.total_mean
    assert row.gaussian_integral == row.total_gaussian


def test_label_cut_by_the_border_summarises_the_part_away_from_it():
    spacing, radius = (1.2, 1.0, 1.0), 18.0
    whole = ball_image(radius, spacing)
    cut = whole[whole.shape[0] // 4 :]  # cut by the image face a little above its bottom
    row, surface = one_row(cut, spacing)
    assert row.touches_border and 0 < row.n_used < row.n_vertices
    # only the vertices out of reach of the cap count: a spherical cap, less than the ball's Gauss image
    assert 0.1 < row.ici_positive < 0.8
    assert row.mean_mean == pytest.approx(1 / radius, rel=0.03)
    # on any region of a sphere k1 = k2 = 1/R: BE = 2 A / R^2 = 8 pi ICIp
    assert row.bending_energy == pytest.approx(8 * np.pi * row.ici_positive, rel=0.03)
    # the mesh function on the same vertices: the same sums, up to the areas of the faces near the cap
    # (whose normals the table fits again without the cap)
    stats = curvature_statistics(surface.result, where=surface.used)
    assert stats["bending_energy"] == pytest.approx(row.bending_energy, rel=1e-4)
    assert stats["folding_index"] == pytest.approx(row.folding_index, rel=1e-4)


def test_sliver_cut_by_the_border_has_nan_statistics_and_says_why():
    spacing = (1.0, 1.0, 1.0)
    whole = ball_image(8.0, spacing)
    sliver = whole[:6]  # a cap of a few voxels' height, cut by the image face
    row, _ = one_row(sliver, spacing)
    for name in COLUMNS:
        assert np.isnan(row[name]), name
    assert "curvature columns NaN" in row.warnings


# ---------------------------------------------------------------- meshes


def test_icosphere_matches_the_analytic_values():
    radius = 2.0
    sphere = meshcurv.shapes.icosphere(subdivisions=12, radius=radius)
    stats = curvature_statistics(meshcurv.principal_curvatures(sphere.vertices, sphere.faces))
    assert stats["bending_energy"] == pytest.approx(8 * np.pi, rel=0.01)
    assert stats["ici_positive"] == pytest.approx(1.0, rel=1e-9)
    assert stats["ici_negative"] == 0.0
    assert stats["folding_index"] == pytest.approx(0.0, abs=0.01)
    assert stats["mean_integral"] == pytest.approx(4 * np.pi * radius, rel=0.01)
    assert stats["shape_index_mean"] == pytest.approx(1.0, rel=0.01)
    for field, power in {"k_min": 1, "k_max": 1, "mean": 1, "gaussian": 2, "curvedness": 1}.items():
        value = radius**-power  # 1/R, and 1/R^2 for K
        for moment in ("mean", "min", "max"):
            assert stats[f"{field}_{moment}"] == pytest.approx(value, rel=0.02), (field, moment)
        assert stats[f"{field}_std"] < 0.01 * value


def test_torus_mesh_matches_the_analytic_values():
    major, minor = 30.0, 10.0
    torus = meshcurv.shapes.torus(major_radius=major, minor_radius=minor, n_major=120, n_minor=60)
    stats = curvature_statistics(meshcurv.principal_curvatures(torus.vertices, torus.faces))
    bending, folding = torus_truth(major, minor)
    assert stats["ici_positive"] == pytest.approx(1.0, rel=0.02)
    assert stats["ici_negative"] == pytest.approx(1.0, rel=0.02)
    assert stats["gaussian_integral"] == pytest.approx(0.0, abs=1e-9)
    assert stats["mean_integral"] == pytest.approx(2 * np.pi**2 * major, rel=0.01)
    assert stats["bending_energy"] == pytest.approx(bending, rel=0.02)
    assert stats["folding_index"] == pytest.approx(folding, rel=0.02)
    assert stats["k_max_mean"] == pytest.approx(1 / minor, rel=0.01)
    assert stats["k_min_min"] == pytest.approx(-1 / (major - minor), rel=0.05)
    assert stats["k_min_max"] == pytest.approx(1 / (major + minor), rel=0.05)
    assert_integrals_add_up(stats)


def test_where_restricts_to_a_region():
    radius = 2.0
    sphere = meshcurv.shapes.icosphere(subdivisions=12, radius=radius)
    result = meshcurv.principal_curvatures(sphere.vertices, sphere.faces)
    upper = np.asarray(sphere.vertices)[:, 2] > 0
    whole = curvature_statistics(result)
    parts = [curvature_statistics(result, where=where) for where in (upper, ~upper)]
    for name in ("ici_positive", "gaussian_integral", "bending_energy", "folding_index"):  # sums over vertices
        assert parts[0][name] + parts[1][name] == pytest.approx(whole[name], rel=1e-9, abs=1e-12), name
    # the upper vertices stand for the upper half, less a third of the faces along the equator (3% here)
    assert parts[0]["ici_positive"] == pytest.approx(0.5, rel=0.04)
    assert parts[0]["bending_energy"] == pytest.approx(4 * np.pi, rel=0.04)
    # int H dA over the faces all of whose corners are upper: less than half, by the faces along the equator
    assert 0.85 * 2 * np.pi * radius < parts[0]["mean_integral"] < 2 * np.pi * radius
    assert parts[0]["mean_integral"] + parts[1]["mean_integral"] < whole["mean_integral"]


def test_scaling_and_flipping_invariances():
    ellipsoid = meshcurv.shapes.ellipsoid(semi_axes=(3.0, 2.0, 1.0), subdivisions=10)
    base = curvature_statistics(meshcurv.principal_curvatures(ellipsoid.vertices, ellipsoid.faces))
    scaled = curvature_statistics(meshcurv.principal_curvatures(3.0 * ellipsoid.vertices, ellipsoid.faces))
    for name in ("bending_energy", "folding_index", "ici_positive", "ici_negative", "shape_index_mean"):
        assert scaled[name] == pytest.approx(base[name], rel=1e-6, abs=1e-9), name
    assert scaled["mean_integral"] == pytest.approx(3.0 * base["mean_integral"], rel=1e-6)
    flipped = curvature_statistics(
        meshcurv.principal_curvatures(ellipsoid.vertices, ellipsoid.faces[:, ::-1], orient="keep")
    )
    assert flipped["mean_integral"] == pytest.approx(-base["mean_integral"], rel=1e-6)
    assert flipped["mean_integral_negative"] == pytest.approx(-base["mean_integral_positive"], rel=1e-6)
    assert flipped["gaussian_integral"] == pytest.approx(base["gaussian_integral"], rel=1e-6)
    assert flipped["ici_positive"] == pytest.approx(base["ici_positive"], rel=1e-6)
    assert flipped["shape_index_mean"] == pytest.approx(-base["shape_index_mean"], rel=1e-6)


def test_keys_are_the_columns_in_order():
    sphere = meshcurv.shapes.icosphere(subdivisions=4)
    stats = curvature_statistics(meshcurv.principal_curvatures(sphere.vertices, sphere.faces))
    assert tuple(stats) == COLUMNS
    assert len(COLUMNS) == len(FIELDS) * len(MOMENTS) + 12
    assert all(isinstance(value, float) for value in stats.values())


# ---------------------------------------------------------------- errors and warnings


def test_rejects_what_is_not_a_curvature_result():
    with pytest.raises(InvalidOptionError, match="`result` must be a CurvatureResult.*got dict"):
        curvature_statistics({"k_min": np.zeros(3)})


def test_rejects_a_result_without_a_mesh():
    points = meshcurv.shapes.icosphere(subdivisions=6).vertices
    result = meshcurv.point_cloud_curvatures(points)
    with pytest.raises(InvalidOptionError, match="needs the triangles of a mesh"):
        curvature_statistics(result)


@pytest.mark.parametrize(
    "where, found", [(np.ones(5, dtype=bool), "bool of shape \\(5,\\)"), ("ones", "int64 of shape")]
)
def test_rejects_a_bad_where(where, found):
    sphere = meshcurv.shapes.icosphere(subdivisions=4)
    result = meshcurv.principal_curvatures(sphere.vertices, sphere.faces)
    if isinstance(where, str):
        where = np.ones(result.n_vertices, dtype=np.int64)
    with pytest.raises(InvalidOptionError, match=f"`where` must be a bool array of shape .*got {found}"):
        curvature_statistics(result, where=where)


def test_empty_region_gives_nan_and_one_warning():
    sphere = meshcurv.shapes.icosphere(subdivisions=4)
    result = meshcurv.principal_curvatures(sphere.vertices, sphere.faces)
    with pytest.warns(MeshQualityWarning, match="no valid vertex to summarise") as caught:
        stats = curvature_statistics(result, where=np.zeros(result.n_vertices, dtype=bool))
    assert len(caught) == 1
    assert all(np.isnan(value) for value in stats.values())


def test_public_name():
    assert meshcurv.curvature_statistics is curvature_statistics
    assert "curvature_statistics" in meshcurv.__all__
