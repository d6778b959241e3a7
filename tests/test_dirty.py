"""Dirty meshes through every method: a defined answer, the doubtful vertices marked, one warning.

The corpus (tests/test_dirty_corpus.py) puts one defect at one place of a clean
torus. Expectations come from the construction: the vertices the defect
touches are ``valid=False`` (NaN), every valid vertex is finite, vertices far
from the defect keep the values of the clean torus, and the call gives exactly
one MeshQualityWarning whose text names the defect.
"""

import functools
import warnings

import numpy as np
import pytest
from scipy.sparse.csgraph import shortest_path

import meshcurv
from meshcurv import shapes
from meshcurv.errors import MeshQualityWarning, TriangulationWarning
from meshcurv.estimators import ESTIMATORS
from meshcurv.topology import MeshTopology

from test_dirty_corpus import EDGE, TORUS, cases

METHODS = sorted(ESTIMATORS)
CASES = {case.name: case for case in cases()}
RADIUS = 2.5 * EDGE  # fixed ball radius: the default follows the global mean edge length
FAR_RINGS = 12  # more rings than any method's neighbourhood (smoothing 3 + 1, icc's jets and ball ~11 rings)

# What the warning must name, per kind of defect.
NAMED = {
    "boundary": "boundary",
    "nonmanifold": "non-manifold",
    "bowtie": "bow-tie",
    "inconsistent": "inconsistent",
    "degenerate": "zero-area|undefined tensors",
    "unreferenced": "unreferenced",
}

# matGeom's compatibility mode reproduces matGeom, which neither stops nor
# gives NaN on these defects; its values there are matGeom's (wrong) numbers and
# the vertices stay valid=True. Reported; strict so that a fix is noticed.
MATGEOM_KEEPS_VALID: set = set()

# Defects the default call repairs before computing (orient='auto' reverses faces, weld merges the copies
# of a vertex), for every method but matgeom: what the one warning says was done. The repaired mesh is
# the clean torus, so every vertex gets the clean torus's values.
REPAIRED = {"flipped": "reversed 2 of", "coincident": "welded 1 coincident vertices"}


def options(method):
    return {"radius": RADIUS} if "radius" in ESTIMATORS[method].options else {}


def run(vertices, faces, method, **extra):
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always")
        result = meshcurv.principal_curvatures(vertices, faces, method=method, **{**options(method), **extra})
    return result, [w for w in record]


@pytest.fixture(scope="module")
def clean():
    return {m: meshcurv.principal_curvatures(TORUS.vertices, TORUS.faces, method=m, **options(m)) for m in METHODS}


@functools.cache
def keeps_boundary(method):
    """Methods built on balls or fits keep boundary vertices valid (their documented choice)."""
    saddle = shapes.saddle(spacing=0.125)
    r, _ = run(saddle.vertices, saddle.faces, method, **({"radius": 0.3} if options(method) else {}))
    top = MeshTopology.from_faces(saddle.faces)
    return bool(r.valid[top.boundary_vertices].any())


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("name", sorted(CASES))
def test_dirty_mesh_gives_a_defined_answer(name, method, clean, request):
    case = CASES[name]
    if method == "matgeom" and name in MATGEOM_KEEPS_VALID:
        request.applymarker(pytest.mark.xfail(strict=True, reason="matGeom mode keeps doubtful vertices valid"))
    r, record = run(case.vertices, case.faces, method)
    quality = [w for w in record if issubclass(w.category, MeshQualityWarning)]
    assert [w.category for w in record if w not in quality] == []
    if name in REPAIRED and method != "matgeom":
        assert len(quality) == 1 and REPAIRED[name] in str(quality[0].message)
        reference = clean[method]
        np.testing.assert_array_equal(r.valid, reference.valid[case.clean_index])
        scale = np.nanmax(np.abs(reference.k_max))
        for field in ("k_min", "k_max"):
            np.testing.assert_allclose(
                getattr(r, field), getattr(reference, field)[case.clean_index], rtol=1e-9, atol=1e-9 * scale
            )
        return
    # one warning, naming the defect; none for a clean mesh in several pieces, and a
    # boundary is no defect to a method that keeps boundary vertices
    handled = case.kind == "boundary" and keeps_boundary(method)
    assert len(quality) == int(case.warns) or (handled and len(quality) <= 1)
    if case.warns and not handled:
        assert any(word in str(quality[0].message) for word in NAMED[case.kind].split("|"))
    # defined: finite where valid, NaN where not (matGeom's zeros at unreferenced vertices aside)
    for values in (r.k_min, r.k_max, r.mean, r.gaussian):
        assert np.isfinite(values[r.valid]).all()
        if method != "matgeom":
            assert np.isnan(values[~r.valid]).all()
    assert np.isfinite(r.normals[r.valid]).all()
    # the doubtful vertices are marked
    if case.kind == "boundary" and keeps_boundary(method):
        assert r.valid[case.core].sum() >= case.core.size - 1  # p itself is unreferenced in the hole
    else:
        assert not r.valid[case.core].any()
    assert r.diagnosis is not None and r.diagnosis.n_vertices == case.vertices.shape[0]


@pytest.mark.parametrize("method", [m for m in METHODS if m != "matgeom"])
@pytest.mark.parametrize("name", sorted(CASES))
def test_far_from_the_defect_nothing_changes(name, method, clean):
    # matgeom is left out: its values are divided by the mean edge length of the
    # whole mesh (matGeom's dimensionless normalisation), so any defect rescales them all.
    case = CASES[name]
    r, _ = run(case.vertices, case.faces, method)
    top = MeshTopology.from_faces(np.asarray(case.faces), case.vertices.shape[0])
    old = case.clean_index >= 0
    if case.core.size:
        rings = shortest_path(top.adjacency, unweighted=True, indices=case.core).min(axis=0)
        distance = np.linalg.norm(case.vertices[:, None] - case.vertices[case.core][None], axis=2).min(axis=1)
        # icc's normals come from jets over 3 x RADIUS, its measures from RADIUS further on
        far = old & (rings >= FAR_RINGS) & (distance > 5 * RADIUS)
    else:
        far = old
    assert far.sum() > 200
    reference = clean[method]
    index = case.clean_index[far]
    np.testing.assert_array_equal(r.valid[far], reference.valid[index])
    scale = np.nanmax(np.abs(reference.k_max))
    # rounding only; quadric solves normal equations (condition number squared), whose
    # chunked sums change with the number of vertices: it keeps about 6 digits
    tolerance = 1e-5 if method == "quadric" else 1e-9
    for field in ("k_min", "k_max", "mean", "gaussian"):
        np.testing.assert_allclose(
            getattr(r, field)[far],
            getattr(reference, field)[index],
            rtol=tolerance,
            atol=tolerance * scale,
            err_msg=field,
        )


@pytest.mark.parametrize("method", METHODS)
def test_polygons_planar_or_not_are_fan_triangulated(method):
    # fine enough that quadric's default ball (2.5 edge lengths) stays on one side of the tube
    torus = shapes.torus(n_major=48, n_minor=32)
    bent = torus.vertices.copy()
    bent[::5] *= 1.03  # the quads through these vertices are no longer planar
    for vertices in (torus.vertices, bent):
        with pytest.warns(TriangulationWarning, match="forces triangulation"):
            r = meshcurv.principal_curvatures(vertices, torus.quads, method=method)
        tri = meshcurv.principal_curvatures(vertices, torus.faces, method=method)
        np.testing.assert_array_equal(r.k_max, tri.k_max)  # the fan is the torus's own split
        assert r.valid.all() and np.isfinite(r.k_max).all()


@pytest.mark.parametrize("method", METHODS)
@pytest.mark.parametrize("scale", [1e-9, 1e9])
def test_extreme_scales_give_the_same_answer_in_their_units(method, scale):
    sphere = shapes.icosphere(8)
    unit = meshcurv.principal_curvatures(sphere.vertices, sphere.faces, method=method)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        r = meshcurv.principal_curvatures(sphere.vertices * scale, sphere.faces, method=method)
    np.testing.assert_array_equal(r.valid, unit.valid)
    power = 0 if method == "matgeom" else 1  # matGeom's values are dimensionless
    np.testing.assert_allclose(r.k_max * scale**power, unit.k_max, rtol=1e-6)
    np.testing.assert_allclose(r.k_min * scale**power, unit.k_min, rtol=1e-6)
    assert r.diagnosis.n_degenerate_faces == 0 and r.diagnosis.n_zero_length_edges == 0


@pytest.mark.parametrize("method", METHODS)
def test_a_vertex_of_valence_1000(method):
    # a double cone over a 1000-gon: the two apexes have 1000 neighbours each
    n = 1000
    angle = 2 * np.pi * np.arange(n) / n
    vertices = np.vstack([np.c_[np.cos(angle), np.sin(angle), np.zeros(n)], [[0, 0, 1.0], [0, 0, -1.0]]])
    i, j = np.arange(n), (np.arange(n) + 1) % n
    faces = np.vstack([np.c_[i, j, np.full(n, n)], np.c_[j, i, np.full(n, n + 1)]])
    radius = {"radius": 1.5} if options(method) else {}  # the default follows the tiny rim edges
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        if method == "quadric":  # the rim vertices see two lines of points: no quadric through them;
            # the apexes' balls (the rim at 1.41, nothing nearer) hold both cones: no height function
            warnings.filterwarnings("ignore", "quadric: .* pass a (larger|smaller) `radius`", MeshQualityWarning)
        if method == "normal_cycle_ball":  # 1.5 is about one spoke (1.41, the median edge): named as small
            warnings.filterwarnings(
                "ignore", "normal_cycle_ball: `radius` 1.5 is 1.1 of the median edge length", MeshQualityWarning
            )
        r = meshcurv.principal_curvatures(vertices, faces, method=method, **radius)
    assert r.diagnosis.is_clean and r.diagnosis.genus == 0
    for apex in (n, n + 1):
        if r.valid[apex]:
            assert np.isfinite([r.k_min[apex], r.k_max[apex]]).all()
            # by symmetry the apex normal is the axis (matGeom's is unoriented)
            assert abs(r.normals[apex, 2]) == pytest.approx(1.0, abs=1e-9)
    assert (r.valid[n] and r.valid[n + 1]) or method == "quadric"


@pytest.mark.parametrize("method", ["normal_cycle", "icc"])
def test_every_defect_at_once(method):
    # the hole, the fin and a collinear face together, far apart on the torus; icc keeps
    # the rim of the hole (a boundary is no defect to it), normal_cycle marks it
    V, F = TORUS.vertices.copy(), TORUS.faces
    n = V.shape[0]
    hole_faces = np.flatnonzero((F == 0).any(axis=1))
    far = 600  # a vertex on the other side
    a, b, c = F[np.flatnonzero((F == far).any(axis=1))[0]]
    V[c] = (V[a] + V[b]) / 2
    keep = np.ones(F.shape[0], dtype=bool)
    keep[hole_faces] = False
    fin = [[F[hole_faces[0] + 100][0], F[hole_faces[0] + 100][1], n]]
    vertices = np.vstack([V, V[fin[0][0]] + [0, 0, 5.0]])
    faces = np.vstack([F[keep], fin])
    with pytest.warns(MeshQualityWarning) as record:
        r = meshcurv.principal_curvatures(vertices, faces, method=method)
    assert len(record) == 1
    message = str(record[0].message)
    for word in ("non-manifold", "zero-area", "unreferenced"):
        assert word in message
    assert ("boundary" in message) == (method == "normal_cycle")
    d = r.diagnosis
    assert d.n_nonmanifold_edges == 1 and d.n_degenerate_faces == 1 and d.n_unreferenced_vertices == 1
    assert d.n_boundary_edges == 6 + 2 and d.n_boundary_loops == 2
    assert not r.valid[[a, b, c]].any()
