"""The prepared mesh: the caller's arrays checked once, then trusted (issue 33)."""

import collections
import importlib.util
import re
import sys
import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import _prepared, _validation, shapes
from meshcurv._backend import use_backend
from meshcurv.errors import InvalidMeshError, InvalidOptionError
from meshcurv.topology import MeshTopology


def _validation_entries(call) -> collections.Counter:
    """``(function, caller's module)`` of each entry into :mod:`meshcurv._validation` from outside it during
    ``call()``, and ``("coerced", name)`` for each run of :func:`~meshcurv._validation.as_vertices` and
    :func:`~meshcurv._validation.polygon_arrays`, whoever calls them."""
    found: collections.Counter = collections.Counter()
    coercions = {_validation.as_vertices.__code__: "as_vertices", _validation.polygon_arrays.__code__: "faces"}

    def profile(frame, event, arg):
        if event != "call" or frame.f_globals.get("__name__") != "meshcurv._validation":
            return
        if frame.f_code in coercions:
            found["coerced", coercions[frame.f_code]] += 1
        caller = frame.f_back
        if caller is not None and caller.f_globals.get("__name__") != "meshcurv._validation":
            found[frame.f_code.co_name, caller.f_globals.get("__name__")] += 1

    _profiled(profile, call)
    return found


def _profiled(profile, call) -> None:
    """``call()`` under ``sys.setprofile(profile)``."""
    sys.setprofile(profile)
    try:
        call()
    finally:
        sys.setprofile(None)


#: What a default call on an array mesh passes through ``_validation``: ``as_mesh``, once, at the door.
THE_DOOR = {("as_mesh", "meshcurv._prepared"): 1, ("coerced", "as_vertices"): 1, ("coerced", "faces"): 1}


@pytest.mark.parametrize("method", meshcurv.METHODS)
def test_a_default_call_checks_the_vertices_and_faces_once_at_the_door(method):
    # before (9840e16): as_vertices, as_faces and check_choice at the door, and for normal_cycle and matgeom
    # check_int_option of the registry's default smoothing_steps; jets and neighborhoods: none since c1fe141.
    # defects' public rules re-checked the prepared needles (2 entries, icc 7) and icc, quadric and
    # normal_cycle_ball called the checked radius.vertex_radii (2 entries, icc 4): they call the cores now.
    sphere = shapes.icosphere(3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # meyer: no directions
        entries = _validation_entries(
            lambda: meshcurv.principal_curvatures(sphere.vertices, sphere.faces.tolist(), method=method)
        )
    assert entries == THE_DOOR


def test_a_given_topology_is_not_checked_again():
    # its faces were checked when it was built: the door coerces the vertices only
    sphere = shapes.icosphere(3)
    topology = MeshTopology.from_faces(sphere.faces, len(sphere.vertices))
    entries = _validation_entries(
        lambda: meshcurv.principal_curvatures(sphere.vertices, topology, method="normal_cycle")
    )
    assert entries == {
        ("as_vertices", "meshcurv._prepared"): 1,
        ("coerced", "as_vertices"): 1,
    }


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"orient": "inward"}, "unknown orient 'inward'; choose one of 'auto', 'outward'"),
        ({"orient": None}, "unknown orient None"),
        ({"method": "normal_cycle", "smoothing_steps": -1}, "`smoothing_steps` must be an integer >= 0"),
        ({"method": "matgeom", "smoothing_steps": 2.5}, "`smoothing_steps` must be an integer >= 0"),
    ],
)
def test_the_options_the_door_no_longer_enters_validation_for_are_still_refused(options, message):
    sphere = shapes.icosphere(1)
    with pytest.raises(InvalidOptionError, match=re.escape(message)):
        meshcurv.principal_curvatures(sphere.vertices, sphere.faces, **options)


def test_a_prepared_mesh_holds_the_checked_arrays_and_leaves_the_callers_alone():
    sphere = shapes.icosphere(3)
    given = sphere.vertices.astype(np.float32)
    mesh = _prepared.prepare_mesh(given, sphere.faces.astype(np.int32), orient="keep", weld=False)
    assert mesh.vertices.dtype == np.float64 and mesh.vertices.flags.c_contiguous
    assert mesh.topology.faces.dtype == np.int64
    assert mesh.vertices is not given and given.dtype == np.float32
    np.testing.assert_array_equal(mesh.topology.faces, sphere.faces)


def test_a_given_topology_is_taken_once_its_vertex_count_matches():
    sphere = shapes.icosphere(3)
    topology = MeshTopology.from_faces(sphere.faces, len(sphere.vertices))
    mesh = _prepared.prepare_mesh(sphere.vertices, topology, orient="keep", weld=False)
    assert mesh.topology is topology
    n = len(sphere.vertices)
    with pytest.raises(InvalidMeshError, match=f"is a MeshTopology of {n} vertices but `vertices` has {n - 1} rows"):
        _prepared.prepare_mesh(sphere.vertices[:-1], topology, orient="keep", weld=False)


def test_a_welded_vertex_stands_on_the_first_of_its_rows():
    # a triangle soup of an octahedron: every vertex given 4 times, welded into 6
    octahedron = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
    faces = np.array([[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]])
    soup = octahedron[faces.ravel()]
    with pytest.warns(meshcurv.MeshQualityWarning, match="welded 18 coincident vertices"):
        result = meshcurv.principal_curvatures(soup, np.arange(24).reshape(8, 3), method="normal_cycle")
    surface = result._surface
    rows = np.asarray(surface.rows)
    np.testing.assert_array_equal(surface.vertices, soup[rows])  # each welded vertex is its first row's
    np.testing.assert_array_equal(surface.index[rows], np.arange(6))  # row rows[w] stands for vertex w ...
    assert all(rows[w] == np.flatnonzero(surface.index == w).min() for w in range(6))  # ... and is its first
    area = result.vertex_integrals("area")
    # the octahedron's area, 8 equilateral triangles of side sqrt(2), once: on the first rows, 0 on copies
    assert area.sum() == pytest.approx(8 * np.sqrt(3) / 4 * 2)
    assert (area[np.setdiff1d(np.arange(24), rows)] == 0).all() and (area[rows] > 0).all()


def test_the_vertex_areas_share_out_the_area_of_the_faces_that_weigh():
    # each face gives a third of its area to each corner: the vertex areas add up to the area of the faces
    # kept (an identity), a zero-area face gives nothing, and they come from the pass of the vertex normals
    sphere = shapes.icosphere(6)
    vertices = sphere.vertices.copy()
    faces = np.asarray(sphere.faces)
    vertices[faces[0, 1]] = vertices[faces[0, 0]]  # face 0 (and its neighbour across that side) of zero area
    mesh = _prepared.prepare_mesh(vertices, faces, orient="keep", weld=False)
    areas = np.linalg.norm(mesh.cross, axis=1) / 2
    assert mesh.dropped.sum() == 2 and not mesh.vertex_areas.flags.writeable
    np.testing.assert_allclose(mesh.vertex_areas.sum(), areas[~mesh.dropped].sum(), rtol=1e-12)
    np.testing.assert_allclose(mesh.vertex_areas.sum(), 4 * np.pi, rtol=0.05)  # inscribed in the unit sphere
    backends = ("numpy", "numba") if importlib.util.find_spec("numba") else ("numpy",)
    for backend in backends:
        with use_backend(backend):
            again = _prepared.prepare_mesh(vertices, faces, orient="keep", weld=False)
            np.testing.assert_allclose(again.vertex_areas, mesh.vertex_areas, rtol=1e-14)
            np.testing.assert_allclose(again.vertex_normals, mesh.vertex_normals, rtol=1e-14, equal_nan=True)


def _entered(code, call) -> int:
    """How many times the function of ``code`` is entered during ``call()``, whoever holds it under which name."""
    entries = []

    def profile(frame, event, arg):
        if event == "call" and frame.f_code is code:
            entries.append(1)

    _profiled(profile, call)
    return len(entries)


@pytest.mark.parametrize("method", ["icc", "normal_cycle", "matgeom", "quadric"])
def test_the_length_scales_and_needle_vertices_are_found_once_per_call(method):
    # the orientation, the defects, the radius rules and the diagnosis all read them (10 and 7 passes before)
    sphere = shapes.icosphere(6)
    vertices = sphere.vertices.copy()
    vertices[5] *= 10.0  # a needle: the scale rules leave it out, the defects mark it
    faces = np.asarray(sphere.faces)[:, ::-1]  # wound inward: the orientation reads the needles too
    from meshcurv import _geometry, defects

    found = []

    def call():
        with pytest.warns(meshcurv.MeshQualityWarning, match="1 needle vertices"):
            found.append(meshcurv.principal_curvatures(vertices, faces, method=method))

    n_needles = _entered(defects._needle_vertices.__code__, call)  # the core: the checked shell is not called
    # every computation of the scales enters their core (prepare_mesh keeps the median edge found with them)
    n_scales = _entered(_geometry.length_scales_and_median.__code__, call)
    assert (n_needles, n_scales) == (1, 1)
    assert found[0].invalid_reason[5] == defects.NEEDLE and found[0].diagnosis.n_needle_vertices == 1


@pytest.mark.parametrize("orient", ["outward", "keep"])
def test_the_prepared_length_scales_and_needles_are_those_of_the_mesh_computed_on(orient):
    # found before the orientation, they are those of the oriented mesh too: reversing faces keeps the edges
    from meshcurv.defects import needle_vertices
    from meshcurv.geometry import vertex_length_scales

    sphere = shapes.icosphere(4)
    vertices = sphere.vertices.copy()
    vertices[3] *= 10.0
    faces = np.asarray(sphere.faces).copy()
    faces[::3] = faces[::3, ::-1]  # a third of the faces reversed
    mesh = _prepared.prepare_mesh(vertices, faces, orient=orient, weld=False)
    assert mesh.n_flipped == (len(faces[::3]) if orient == "outward" else 0)
    scales = vertex_length_scales(mesh.vertices, mesh.topology)
    np.testing.assert_array_equal(mesh.length_scales, scales)
    np.testing.assert_array_equal(mesh.needles, needle_vertices(mesh.vertices, mesh.topology, scales))
    assert np.flatnonzero(mesh.needles).tolist() == [3] and not mesh.needles.flags.writeable
    assert mesh.length_scales.flags.writeable  # the compiled kernels are compiled for writable arrays
