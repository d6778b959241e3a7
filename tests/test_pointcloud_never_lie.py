"""meshcurv.pointcloud never gives a valid wrong number (issue 29, classes 1, 2 and 3).

Oracles: unit spheres (H = +1 with outward normals), a flat ellipsoid's exact
normals. Tolerances: clouds of 2000-3000 random samples, whose median H error
is below 1% (benchmarks/pointcloud.md); a point counts as wrong when its H is
off by more than 50% (a sign error is off by 200%), and no valid point may be.
"""

import warnings

import numpy as np
import pytest

from meshcurv import _pointcloud_normals as normals_module
from meshcurv.errors import InvalidMeshError, MeshQualityWarning
from meshcurv.pointcloud import COPY_GAP, POINT_CLOUD_METHODS, point_cloud_curvatures
from meshcurv.result import INVALID_REASONS


def sphere(n, radius=1.0, centre=(0.0, 0.0, 0.0), seed=0):
    u = np.random.default_rng(seed).normal(size=(n, 3))
    return radius * u / np.linalg.norm(u, axis=1, keepdims=True) + np.asarray(centre)


def quiet(points, **options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        return point_cloud_curvatures(points, **options)


@pytest.mark.parametrize("method", POINT_CLOUD_METHODS)
@pytest.mark.parametrize("gap, n", [(1.0, 3000), (1.5, 3000), (2.0, 3000), (1.0, 1000)])
def test_two_spheres_a_spacing_or_two_apart_are_both_outward(method, gap, n):
    # class 1: the orientation's tree crossed the gap and turned one sphere inside out (H = -1, valid);
    # at 1000 points a sphere, two edges across the gap lay within 0.4 of both tangent planes
    spacing = np.sqrt(4 * np.pi / n)
    points = np.concatenate([sphere(n), sphere(n, centre=(2 + gap * spacing, 0, 0), seed=1)])
    r = quiet(points, method=method)
    centres = np.where(np.arange(2 * n)[:, None] < n, 0.0, 2 + gap * spacing) * np.array([1.0, 0, 0])
    outward = np.einsum("ij,ij->i", r.normals, points - centres) > 0
    for part in (slice(0, n), slice(n, 2 * n)):
        assert np.mean(outward[part][r.valid[part]]) > 0.99
        assert np.median(r.mean[part][r.valid[part]]) == pytest.approx(1.0, rel=0.02)
        # (the points beside the gap whose larger ball, or neighbours, hold the other sphere are NaN: unsteady)
        assert r.valid[part].mean() > 0.85
    # beside the gap: jets refuse every two-sided ball; the measures keep a few rough points where the
    # two spheres' neighbourhoods mix (16 of 6000 off by more than 50% at 1 spacing; 3000 inverted before)
    wrong = np.abs(r.mean[r.valid] - 1.0) > 0.5
    assert wrong.mean() < (0.005 if method == "corrected_measures" else 1e-3)
    # the points left out say why
    assert (r.invalid_reason[~r.valid] > 0).all()


def test_oriented_signs_passes_the_sign_reversed_across_a_gap():
    # the building block: two parallel planes 1.2 spacings apart, PCA normals all +z; the planes are two
    # sheets (edges between them stacked), so the lower one is turned to face the upper (outward normals
    # of a gap point apart)
    g = np.stack(np.meshgrid(np.arange(30.0), np.arange(30.0)), axis=-1).reshape(-1, 2)
    points = np.concatenate([np.c_[g, np.zeros(900)], np.c_[g + 0.5, np.full(900, 1.2)]])
    from scipy.spatial import cKDTree

    distances, indices = normals_module.knn(cKDTree(points), points)
    normals = np.tile([0.0, 0.0, 1.0], (1800, 1))
    signs, labels, doubtful, sheets, _ = normals_module.oriented_signs(
        points, normals, indices, np.ones(1800, bool), normals_module.local_spacing(distances)
    )
    assert np.unique(labels).size == 1
    assert np.all(signs[:900] == signs[0]) and np.all(signs[900:] == -signs[0])
    assert not doubtful.any()
    # two sheets: a ball of one never takes the other's points
    assert np.unique(sheets[:900]).size == 1 and np.unique(sheets[900:]).size == 1 and sheets[0] != sheets[900]


@pytest.mark.parametrize("copies", [5, 10, 30])
def test_near_duplicates_are_merged_with_one_warning(copies):
    # class 2: each point several times with round-off differences: H ~ 1e13 at 99% of points, valid
    n = 1500
    base = sphere(n)
    rng = np.random.default_rng(4)
    points = np.concatenate(
        [base * (1 + 1e-12 * rng.normal(size=(n, 1))) + 1e-13 * rng.normal(size=base.shape) for _ in range(copies)]
    )
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        r = point_cloud_curvatures(points)
    messages = [str(w.message) for w in record]
    assert len(messages) == 1
    assert f"{(copies - 1) * n} points are near copies of others" in messages[0]
    assert r.valid.all()
    assert np.abs(r.mean - 1.0).max() < 0.1
    # the copies carry their representative's values, and the radius comes from the spacing of the distinct points
    assert np.array_equal(r.mean[:n], r.mean[n : 2 * n])
    single = quiet(base)
    assert r.parameters["radius"] == pytest.approx(single.parameters["radius"], rel=1e-6)


def test_a_close_pair_of_a_random_sample_is_not_merged_unless_below_the_gap():
    points = sphere(2000)
    spacing = np.sqrt(4 * np.pi / 2000)
    near = points[:1] + [[spacing * COPY_GAP * 10, 0, 0]]  # 100 times above the copy gap: a point of its own
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        point_cloud_curvatures(np.concatenate([points, near]))
    assert not any("copies" in str(w.message) for w in record)


def test_jets_with_a_given_radius_that_reaches_the_other_side_refit_on_one_side():
    # class 3: a sphere of radius 0.2 with a ball of 0.3 (its whole far side inside): H was 7.7, not 5, valid
    points = sphere(3000, radius=0.2)
    with pytest.warns(MeshQualityWarning, match="the ball of the given radius 0.3 held the other side"):
        r = point_cloud_curvatures(points, method="jets", radius=0.3)
    assert r.parameters["shrunk"] == 1.0
    valid = r.valid
    # the one-sided ball is still as wide as the sphere's radius: a biased but one-sided fit (not doubled)
    assert np.all(np.abs(r.mean[valid] - 5.0) < 0.3 * 5.0)


def test_jets_with_a_given_radius_on_a_thin_plate_never_fit_both_faces():
    rng = np.random.default_rng(5)
    g = rng.uniform(-3, 3, size=(6000, 2))
    # faces 0.6 apart, spacing about 0.11: a ball of 0.9 holds the other face, one of 3 spacings does not
    top = np.c_[g[:3000], np.full(3000, 0.3)]
    bottom = np.c_[g[3000:], np.full(3000, -0.3)]
    normals = np.concatenate([np.tile([0, 0, 1.0], (3000, 1)), np.tile([0, 0, -1.0], (3000, 1))])
    with pytest.warns(MeshQualityWarning, match="the ball of the given radius 0.9 held the other side"):
        r = point_cloud_curvatures(np.concatenate([top, bottom]), normals=normals, method="jets", radius=0.9)
    # flat faces: H = 0 wherever valid (a jet through both faces bends between them)
    inside = np.abs(np.concatenate([top, bottom])[:, :2]).max(axis=1) < 2.0
    assert r.valid[inside].all()
    assert np.abs(r.mean[inside]).max() < 0.05


def test_jets_on_a_plate_thinner_than_any_ball_are_invalid_with_the_reason():
    rng = np.random.default_rng(5)
    g = rng.uniform(-3, 3, size=(6000, 2))
    points = np.c_[g, np.where(np.arange(6000) < 3000, 0.1, -0.1)]
    normals = np.zeros((6000, 3))
    normals[:, 2] = np.where(np.arange(6000) < 3000, 1.0, -1.0)
    r = quiet(points, normals=normals, method="jets", radius=0.5)
    inside = np.abs(g).max(axis=1) < 2.0
    assert not r.valid[inside].any()
    assert (
        r.invalid_reason[inside]
        == INVALID_REASONS.index("point cloud: every ball held the other side of a thin part or a neighbouring part")
    ).all()


# ----------------------------------------------------------------------------- the side of whole parts (winding)


def _outward_or_invalid(r, points, centres, expected_mean):
    """Valid points: normal on the exact side, H within 20% of the exact value (never the opposite sign)."""
    side = np.einsum("ij,ij->i", r.normals, points - centres) * np.sign(expected_mean)
    valid = r.valid
    assert (side[valid] > 0).all()
    assert (np.abs(r.mean[valid] - expected_mean[valid]) < 0.5 * np.abs(expected_mean[valid])).mean() > 0.99
    assert (np.sign(r.mean[valid]) == np.sign(expected_mean[valid])).mean() > 0.995
    assert (r.invalid_reason[~valid] > 0).all()


@pytest.mark.parametrize("method", POINT_CLOUD_METHODS)
@pytest.mark.parametrize(
    "n, gap, seed", [(400, 1.0, 3), (400, 1.0, 5), (1000, 1.0, 2), (1000, 1.5, 29), (1000, 1.5, 0)]
)
def test_two_spheres_of_different_sizes_close_together_are_outward_or_invalid(method, n, gap, seed):
    # class 1 (the fuzzer's last 17 cases): spheres of radii 1 and 1.5, 1-1.5 spacings apart; one came out
    # inside out (H = -1/R at every point, valid): with these seeds (found by sampling; seed 0 was right), the
    # orientation's forest crosses the gap by flat edges. Exact: outward normals, H = +1/R
    spacing = np.sqrt(4 * np.pi / n)
    gap_centre = 2.5 + gap * spacing
    points = np.concatenate(
        [sphere(n, seed=seed), sphere(int(2.25 * n), radius=1.5, centre=(gap_centre, 0, 0), seed=seed + 100)]
    )
    first = np.arange(points.shape[0]) < n
    centres = np.where(first[:, None], 0.0, np.array([gap_centre, 0.0, 0.0]))
    r = quiet(points, method=method)
    _outward_or_invalid(r, points, centres, np.where(first, 1.0, 1 / 1.5))
    # (beside the gap, estimates a larger ball or the neighbours do not reproduce are NaN: 20-21% at 400 points)
    assert r.valid[first].mean() > 0.75 and r.valid[~first].mean() > 0.75


@pytest.mark.parametrize("method", POINT_CLOUD_METHODS)
def test_the_inner_wall_of_a_hollow_ball_is_a_cavity(method):
    # nested parts: the inner sphere bounds a cavity: its normals point into the cavity (towards the centre),
    # H = -1/r there, as for meshes (orient_faces); it was turned outward of itself (H = +2, valid)
    outer, inner = sphere(4000, seed=6), sphere(1000, radius=0.5, seed=7)
    points = np.concatenate([outer, inner])
    r = quiet(points, method=method)
    expected = np.concatenate([np.ones(4000), np.full(1000, -2.0)])
    _outward_or_invalid(r, points, np.zeros((5000, 3)), expected)
    assert r.valid.mean() > 0.9


def test_the_faces_of_a_flat_ellipsoid_are_outward_or_invalid():
    # a 3 x 3 x 0.15 ellipsoid of 8000 points: the orientation passed around the rim (thinner than the spacing)
    # as over one sheet and one face came out inward, valid. Away from the rim (faces more than 1.5 spacings
    # apart) every valid normal is on the exact side
    rng = np.random.default_rng(8)
    axes = np.array([3.0, 3.0, 0.15])
    u = rng.normal(size=(48000, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    weight = np.linalg.norm(u / axes, axis=1)  # area element of the map u -> axes * u, up to a constant
    points = (u[rng.random(u.shape[0]) < weight / weight.max()][:8000]) * axes
    exact = points / axes**2
    r = quiet(points)
    away = np.linalg.norm(points[:, :2], axis=1) < 2.0
    side = np.einsum("ij,ij->i", r.normals, exact)
    assert (side[away & r.valid] > 0).all()
    assert r.valid[away].mean() > 0.8


def test_winding_number_of_a_sphere_is_one_half_on_it_and_its_backends_agree():
    # Barill et al. 2018: the winding number is 1/2 on a closed surface, -1/2 with its normals inward; the
    # NumPy path sums the same terms as the compiled one (a sampled far field: 1500 sources of 6000 points)
    pytest.importorskip("numba")  # the two backends compared
    from scipy.spatial import cKDTree

    from meshcurv._backend import use_backend

    points = sphere(6000, seed=9)
    tree = cKDTree(points)
    spacing = normals_module.local_spacing(normals_module.knn(tree, points)[0])
    usable = np.ones(6000, dtype=bool)
    queries, sources = np.arange(0, 6000, 7), np.arange(0, 6000, 4)
    values = {}
    for backend in ("numpy", "numba"):
        with use_backend(backend):
            values[backend] = normals_module.winding_numbers(points, points, spacing**2, usable, tree, queries, sources)
    np.testing.assert_allclose(values["numba"], values["numpy"], rtol=1e-9, atol=1e-12)
    # the areas d_8^2 pi / 8 of random samples sum to the sphere's area within a few percent
    assert np.abs(values["numpy"] - 0.5).max() < 0.05
    inward = normals_module.winding_numbers(points, -points, spacing**2, usable, tree, queries, sources)
    np.testing.assert_allclose(inward, -values["numpy"], rtol=1e-12)


# ----------------------------------------------------------------------------- thin plates (issue 29, class 1 gap)


def thin_ellipsoid(n, axes, seed, noise=0.0):
    """``n`` samples of the ellipsoid ``axes``, uniform by area, moved along the exact normal by uniform noise of
    ``noise`` median spacings; with the exact outward normals."""
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(seed)
    axes = np.asarray(axes, dtype=float)
    u = rng.normal(size=(8 * n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    weight = np.linalg.norm(u / axes, axis=1)  # area element of the map u -> axes * u, up to a constant
    points = u[rng.random(u.shape[0]) < weight / weight.max()][:n] * axes
    gradient = points / axes**2
    length = np.linalg.norm(gradient, axis=1)
    exact = gradient / length[:, None]
    # the largest principal curvature: of the shape operator P diag(1 / a^2) P / |grad| on the tangent plane
    projector = np.eye(3)[None] - exact[:, :, None] * exact[:, None, :]
    largest = np.linalg.eigvalsh(projector @ np.diag(1 / axes**2)[None] @ projector / length[:, None, None])[:, -1]
    spacing = np.median(cKDTree(points).query(points, k=9)[0][:, 8]) * np.sqrt(np.pi / 8)
    # as benchmarks/fuzz_api.py: a radius of curvature below 4 spacings (the rim) is resolved by no estimator
    resolved = largest * spacing <= 0.25
    return points + rng.uniform(-noise, noise, size=(n, 1)) * spacing * exact, exact, resolved


@pytest.mark.parametrize(
    "n, axes, seed, noise, method",
    [
        (2000, (1.0, 1.0, 0.02), 17, 0.0, "corrected_measures"),  # faces 0-0.97 spacings apart
        (2000, (1.0, 1.0, 0.02), 5, 0.2, "corrected_measures"),
        (4000, (1.0, 0.5, 0.02), 2, 0.0, "corrected_measures"),  # 0-1.7 spacings
        (1000, (1.0, 0.5, 0.1), 36, 0.0, "corrected_measures"),  # 0-3.6 spacings: a face turned with the other
        (2000, (1.0, 0.5, 0.05), 8, 0.2, "corrected_measures"),
        (400, (1.0, 1.0, 0.05), 27, 0.0, "jets"),
    ],
)
def test_the_faces_of_thin_plates_are_never_inward_and_valid(n, axes, seed, noise, method):
    # the fuzzer's thin ellipsoids (seed 29: 91 of 1488 cases with more than 50 inward valid points): a patch of a
    # face, or a whole face, turned with the other face, consistent with itself, valid. Exact: outward normals;
    # points within 4 spacings of the rim's radius of curvature (which no estimator resolves) are not checked
    points, exact, resolved = thin_ellipsoid(n, axes, seed, noise)
    r = quiet(points, method=method)
    inward = r.valid & resolved & (np.einsum("ij,ij->i", r.normals, exact) < 0)
    assert inward.sum() <= 10  # before: 82-590 (of 400-4000), a face or patches of it
    undecided = INVALID_REASONS.index(next(t for t in INVALID_REASONS if t.startswith("point cloud: side undecided")))
    assert (r.invalid_reason[~r.valid] > 0).all()
    assert (r.invalid_reason == undecided).any()


def test_a_plate_thinner_than_the_spacing_is_undecided_with_one_warning():
    # faces 0-0.97 spacings apart everywhere: the two faces' points mix in every neighbourhood; the side of each
    # point is a coin's toss (one face came out inward, valid): the part is NaN, and the warning says why
    points, _, _ = thin_ellipsoid(2000, (1.0, 1.0, 0.02), 17)
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        r = point_cloud_curvatures(points)
    messages = [str(w.message) for w in record]
    assert len(messages) == 1
    assert "between two sheets closer than the spacing" in messages[0]
    assert r.valid.mean() < 0.05


def two_planes(gap, top_normal, bottom_normal, noise=0.0, seed=0):
    """Random samples of two parallel squares ``gap`` spacings apart (spacing about 1), with the given normals."""
    rng = np.random.default_rng(seed)
    g = rng.uniform(0, 40, size=(3200, 2))
    z = np.where(np.arange(3200) < 1600, gap, 0.0) + rng.uniform(-noise, noise, 3200)
    normals = np.where(np.arange(3200)[:, None] < 1600, top_normal, bottom_normal).astype(float)
    points = np.c_[g, z]
    return points, normals


def _sheets_of(points, normals):
    from scipy.spatial import cKDTree

    tree = cKDTree(points)
    spacing = normals_module.local_spacing(normals_module.knn(tree, points)[0])
    return normals_module.two_sheets(points, normals, np.ones(points.shape[0], dtype=bool), spacing, tree)


@pytest.mark.parametrize("gap", [0.7, 1.5, 3.0])
def test_two_sheets_stacked_with_normals_the_same_way_are_flagged(gap):
    # one of the two is inside out: both faces of a thin part, or two parts, have opposite outward normals
    inner = None
    for top, bottom, expected in (
        ((0, 0, 1), (0, 0, 1), True),
        ((0, 0, 1), (0, 0, -1), False),
        ((0, 0, -1), (0, 0, 1), False),
    ):
        points, normals = two_planes(gap, top, bottom)
        alike, _ = _sheets_of(points, normals)
        inner = (np.abs(points[:, :2] - 20) < 15).all(axis=1)
        assert alike[inner].all() if expected else not alike.any()


def test_two_sheets_closer_than_the_spacing_are_interleaved_but_one_noisy_sheet_is_not():
    points, normals = two_planes(0.4, (0, 0, 1), (0, 0, -1))
    spacing_squared = 40.0**2 / 3200  # two sheets of 1600 points on 40 x 40: the spacing of one is about 1
    assert spacing_squared == pytest.approx(0.5)
    _, interleaved = _sheets_of(points, normals)
    inner = (np.abs(points[:, :2] - 20) < 15).all(axis=1)
    assert interleaved[inner].mean() > 0.25
    # one sheet under noise of 0.2 spacings (uniform): no point has two sheets
    rng = np.random.default_rng(3)
    g = rng.uniform(0, 40, size=(1600, 2))
    single = np.c_[g, rng.uniform(-0.2, 0.2, 1600)]
    alike, interleaved = _sheets_of(single, np.tile([0.0, 0.0, 1.0], (1600, 1)))
    assert not alike.any() and not interleaved.any()


def test_between_sides_turns_the_faces_of_a_thin_part_that_face_each_other():
    # a stretch of a flat ellipsoid with both faces turned (facing each other as across a gap): the winding number
    # between them is about -1, not the 0 of a gap: both are turned back; the rest is left alone
    from scipy.spatial import cKDTree

    points, exact, _ = thin_ellipsoid(4000, (1.0, 1.0, 0.1), 4)
    turned = points[:, 0] > 0.3
    normals = np.where(turned[:, None], -exact, exact)
    tree = cKDTree(points)
    distances, indices = normals_module.knn(tree, points)
    flips = normals_module.between_sides(
        points, normals, np.ones(4000, dtype=bool), normals_module.local_spacing(distances), tree, indices
    )
    # where the faces are 1 to 3 spacings apart (the other face among the 48 nearest neighbours)
    spacing = np.median(normals_module.local_spacing(distances))
    apart = 0.2 * np.sqrt(np.maximum(1 - np.linalg.norm(points[:, :2], axis=1) ** 2, 0)) / spacing
    thick = (apart >= 1) & (apart <= 3)
    assert (flips[turned & thick] < 0).mean() > 0.8  # the others: no stacked neighbour among the 48 nearest
    # the faces left alone stay (but within a few spacings of the cut, whose winding numbers the turned part sways)
    assert (flips[points[:, 0] < 0.3 - 4 * spacing] > 0).all()


def test_two_spheres_a_gap_apart_are_not_turned_between():
    # across a gap the winding number between the two sheets is about 0 (outside both): nothing is turned
    from scipy.spatial import cKDTree

    n = 2000
    spacing = np.sqrt(4 * np.pi / n)
    points = np.concatenate([sphere(n), sphere(n, centre=(2 + 1.5 * spacing, 0, 0), seed=1)])
    centres = np.where(np.arange(2 * n)[:, None] < n, 0.0, 2 + 1.5 * spacing) * np.array([1.0, 0, 0])
    normals = points - centres
    tree = cKDTree(points)
    distances, indices = normals_module.knn(tree, points)
    flips = normals_module.between_sides(
        points, normals, np.ones(2 * n, dtype=bool), normals_module.local_spacing(distances), tree, indices
    )
    assert (flips > 0).all()


def test_a_plate_thinner_than_the_spacing_beside_a_coarser_part_is_never_inward_and_valid():
    # the fuzzer's "mixed" clouds: a 0.02 plate of 400 points beside a sphere of 400 (its spacing about 1.4 times the
    # plate's): the plate was judged with the median spacing of the whole cloud, the sphere's, and its faces, 0.3
    # spacings apart, kept one face inward and valid (183 points, case 451 of seed 29)
    plate, exact, resolved = thin_ellipsoid(400, (1.0, 1.0, 0.02), 451, noise=0.05)
    ball = sphere(400, seed=451)
    points = np.concatenate([ball, plate + [0.0, 3.0, 0.0]])
    r = quiet(points)
    on_plate = np.arange(800) >= 400
    inward = r.valid[on_plate] & resolved & (np.einsum("ij,ij->i", r.normals[on_plate], exact) < 0)
    assert inward.sum() <= 10
    assert r.valid[~on_plate].mean() > 0.95
    assert np.median(r.mean[~on_plate][r.valid[~on_plate]]) == pytest.approx(1.0, rel=0.05)


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_a_sphere_at_1e75_gives_the_curvatures_of_the_unit_sphere_scaled(backend):
    # fuzz seed 41 case 5535: the NumPy test of flat balls overflowed (RuntimeWarnings are errors here); and
    # the compiled PCA normals' rank test overflowed from 1e60 on (75% of the points invalid, the rest 27% off);
    # scaling the points by s scales the curvatures by 1/s and changes nothing else
    from meshcurv._backend import use_backend

    if backend == "numba":
        pytest.importorskip("numba")
    points = sphere(800, seed=3)
    with use_backend(backend):
        unit, big = quiet(points), quiet(points * 1e75)
    np.testing.assert_array_equal(big.valid, unit.valid)
    assert unit.valid.mean() > 0.9
    np.testing.assert_allclose(big.mean[big.valid] * 1e75, unit.mean[unit.valid], rtol=1e-6)


def test_a_cloud_whose_bulk_is_below_the_smallest_scale_is_refused_before_any_work():
    # fuzz seed 42 case 996: an outlier at 1e75 let a cloud of scale 1e-125 through the check of the largest
    # coordinate; the refusal came late, after RuntimeWarnings of the orientation
    points = sphere(400, seed=4) * 1e-125
    points[7] = (1e75, 0.0, 0.0)
    with pytest.raises(InvalidMeshError, match=r"90% of the coordinates are below 9.*e-126 .*rescale the points"):
        point_cloud_curvatures(points)


def flat_ellipsoid_samples(n, axes, rng):
    """``n`` samples (uniform by area) of the ellipsoid with these ``axes`` and their exact outward normals."""
    u = rng.normal(size=(8 * n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    weight = np.linalg.norm(u / axes, axis=1)
    x = u[rng.random(u.shape[0]) < weight / weight.max()][:n] * axes
    normal = x / axes**2
    return x, normal / np.linalg.norm(normal, axis=1, keepdims=True)


def test_a_plate_thinner_than_half_a_spacing_is_undecided_not_inward():
    # fuzzer seed 42 case 973: a 1 x 1 x 0.02 ellipsoid of 400 points (faces 0.44 spacings apart) beside a sphere,
    # noise of 0.05 spacings: 15 points of the plate valid with their normal inward. Its faces' points face the
    # same way as the sheet stacked on theirs (one of the two is inside out), closer than the 0.45 spacings that
    # noise of 0.2 spacings calls for; the noise measured here (0.03) lets 0.19 spacings count
    rng = np.random.default_rng(973)
    plate, plate_normals = flat_ellipsoid_samples(400, np.array([1.0, 1.0, 0.02]), rng)
    plate += np.array([0.0, 3.0, 0.0])
    ball = sphere(400, seed=5)
    points = np.concatenate([ball, plate])
    exact = np.concatenate([ball, plate_normals])
    spacing = 0.09  # the plate's (both faces)
    points += rng.uniform(-0.05, 0.05, (800, 1)) * spacing * exact
    r = quiet(points)
    assert not (r.valid & (np.einsum("ij,ij->i", r.normals, exact) < 0)).any()
    undecided = next(
        code for code, text in enumerate(INVALID_REASONS) if text.startswith("point cloud: side undecided")
    )
    assert (r.invalid_reason[400:] == undecided).mean() > 0.9  # the whole plate: its sides are a coin's toss
    assert r.valid[:400].mean() > 0.9  # the sphere is measured
    assert np.abs(r.mean[:400][r.valid[:400]] - 1.0).max() < 0.5


def test_a_part_spaced_too_finely_for_products_of_four_lengths_is_left_out():
    # mesh fuzzer seed 61 case 8724: a part spaced about 1e-144 beside one at 1e12; the winding number's cubed
    # distances underflowed to 0 (RuntimeWarning: invalid value in divide) and the noise fit refused the cloud
    # ("no coordinate larger than 1.05e-143") although its other part is measurable
    tiny = sphere(500, radius=1e-140, seed=1)
    big = sphere(500, centre=(3.0, 0.0, 0.0), seed=2)
    with pytest.warns(MeshQualityWarning, match=r"500 points are spaced below 1e-74 \(products of four"):
        r = point_cloud_curvatures(np.concatenate([tiny, big]))  # (a RuntimeWarning would fail: warnings are errors)
    assert not r.valid[:500].any()
    assert r.valid[500:].mean() > 0.9
    assert np.abs(r.mean[500:][r.valid[500:]] - 1.0).max() < 0.5
