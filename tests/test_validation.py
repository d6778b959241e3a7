"""Every error path of the public entry point, with its message."""

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.errors import InvalidMeshError, InvalidOptionError

TRI = np.array([[0, 1, 2], [0, 2, 3]])
QUAD_VERTICES = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])


def call(vertices=QUAD_VERTICES, faces=TRI, **options):
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
        return meshcurv.principal_curvatures(vertices, faces, **options)


@pytest.mark.parametrize(
    "vertices, match",
    [
        (np.zeros((4, 2)), r"`vertices` must have shape \(V, 3\); got \(4, 2\)"),
        (np.zeros(12), r"`vertices` must have shape \(V, 3\); got \(12,\)"),
        (np.zeros((0, 3)), "`vertices` is empty"),
        (np.array([["a", "b", "c"]] * 4), "must hold real numbers"),
        (np.zeros((4, 3), dtype=complex), "must hold real numbers"),
        ([[0, 0, 0], [1, 0], [1, 1, 0], [0, 1, 0]], "could not be converted"),
        (
            np.where(np.arange(12).reshape(4, 3) == 4, np.nan, 0.0),
            r"NaN or infinite coordinates at 1 vertices \(first at index 1\)",
        ),
        (np.where(np.arange(12).reshape(4, 3) == 11, np.inf, 0.0), "NaN or infinite"),
    ],
)
def test_bad_vertices(vertices, match):
    with pytest.raises(InvalidMeshError, match=match):
        call(vertices=vertices)


@pytest.mark.parametrize(
    "faces, match",
    [
        (np.array([0, 1, 2]), r"`faces` must have shape \(F, 3\) or \(F, k\) with k >= 3; got \(3,\)"),
        (np.zeros((0, 3), dtype=int), "`faces` is empty"),
        (np.array([[0, 1], [1, 2]]), "at least 3 columns"),
        (np.array([[0, 1, 2], [0, 2, -1]]), r"negative vertex indices \(smallest -1\)"),
        (np.array([[0, 1, 2], [0, 2, 7]]), "vertex index 7 out of range for 4 vertices"),
        (TRI + 1, "look 1-based: indices run from 1 to 4 with 4 vertices.*faces - 1"),
        (np.array([[0, 1, 2.5]]), "non-integer values"),
        (np.array([[0, 1, np.nan]]), "NaN or infinite values"),
        (np.array([[True, False, True]]), "must hold integer vertex indices; got dtype bool"),
        (np.array([["0", "1", "2"]]), "must hold integer vertex indices"),
        ([[0, 1, 2], [0, 2]], "fewer than 3 vertices"),
        ([[0, 1, 2], 5], "items are not sequences"),
    ],
)
def test_bad_faces(faces, match):
    with pytest.raises(InvalidMeshError, match=match):
        call(faces=faces)


def test_integral_float_faces_are_accepted():
    r = call(faces=TRI.astype(float))
    assert r.n_vertices == 4


@pytest.mark.parametrize(
    "options, match",
    [
        (
            {"method": "rusinkiewicz_typo"},
            "unknown method 'rusinkiewicz_typo'; choose one of 'normal_cycle', 'matgeom'",
        ),
        ({"method": None}, "unknown method None"),
        ({"method": "normal_cycle", "smoothing_steps": -1}, "`smoothing_steps` must be an integer >= 0; got -1"),
        ({"method": "normal_cycle", "smoothing_steps": 2.5}, r"`smoothing_steps` must be an integer >= 0; got 2.5"),
        ({"method": "matgeom", "smoothing_steps": True}, "`smoothing_steps` must be an integer"),
        ({"smoothing_steps": 2}, "method 'icc' does not take the option `smoothing_steps`"),
    ],
)
def test_bad_options(options, match):
    with pytest.raises(InvalidOptionError, match=match):
        call(**options)


def test_errors_are_value_errors():
    assert issubclass(InvalidMeshError, ValueError) and issubclass(InvalidOptionError, ValueError)


def test_topology_must_match_the_vertices():
    top = meshcurv.MeshTopology.from_faces(TRI, n_vertices=5)
    with pytest.raises(InvalidMeshError, match="MeshTopology of 5 vertices but `vertices` has 4 rows"):
        call(faces=top)


def test_inputs_are_never_modified():
    torus = shapes.torus(n_major=12, n_minor=8)
    vertices, faces = torus.vertices.copy(), torus.faces.copy()
    meshcurv.principal_curvatures(vertices, faces)
    meshcurv.principal_curvatures(vertices, faces, method="matgeom")
    np.testing.assert_array_equal(vertices, torus.vertices)
    np.testing.assert_array_equal(faces, torus.faces)


def test_shape_generator_options_are_checked():
    with pytest.raises(InvalidOptionError, match="`subdivisions` must be an integer >= 1; got 0"):
        shapes.icosphere(0)


@pytest.mark.parametrize(
    "vertices, faces, match",
    [
        (QUAD_VERTICES * 1e120, TRI, r"coordinates as large as 1e\+120.*rescale the mesh"),
        (np.ones((4, 3), dtype=np.longdouble) * np.finfo(np.longdouble).max, TRI, "NaN or infinite coordinates"),
        (QUAD_VERTICES, np.array([[0, 1, 2], [0, 2, 2.0**63]]), "indices too large for int64"),
        (QUAD_VERTICES, [[0, 1, 2], [[0], 1, 2, 3]], "could not be converted|nested lists"),
        (QUAD_VERTICES, [[0, 1, 2, 3], [[0, 1], 2, 3]], "could not be converted|nested lists"),
        (QUAD_VERTICES, [[], [0, 1, 2]], "fewer than 3 vertices"),
        (QUAD_VERTICES, "0 1 2", "got a str"),
        (QUAD_VERTICES, ["012", "023"], "items are not sequences"),
    ],
)
def test_bad_input_found_by_fuzzing(vertices, faces, match):
    with pytest.raises(InvalidMeshError, match=match):
        call(vertices=vertices, faces=faces)


def test_every_entry_point_checks_its_input():
    from meshcurv.orient import orient_faces

    with pytest.raises(InvalidMeshError, match="look 1-based"):
        meshcurv.MeshTopology.from_faces(TRI + 1, n_vertices=4)
    with pytest.raises(InvalidMeshError, match=r"`vertices` must have shape \(V, 3\)"):
        orient_faces(np.zeros((4, 2)), TRI)
    with pytest.raises(InvalidMeshError, match="negative vertex indices"):
        orient_faces(QUAD_VERTICES, -TRI)


@pytest.mark.parametrize("rule", ["edge_radius", "component_radii", "local_scale_ratios", "scale_centres"])
def test_the_public_radius_rules_check_their_vertices(rule):
    # their cores trust a prepared mesh (principal_curvatures checks once); the public rules check what they get
    from meshcurv import radius

    sphere = shapes.icosphere(2)
    topology = meshcurv.MeshTopology.from_faces(sphere.faces)
    vertices = sphere.vertices.copy()
    vertices[3, 1] = np.nan
    extra = (np.ones(len(vertices), dtype=bool), sphere.vertices) if rule == "scale_centres" else ()
    with pytest.raises(InvalidMeshError, match="NaN or infinite"):
        getattr(radius, rule)(vertices, topology, *extra)


# ------------------------------------------------------------- hints for faces given the wrong way (issue 29)


SPHERE = shapes.icosphere(4)


@pytest.mark.parametrize(
    "faces", [SPHERE.faces.T, SPHERE.faces.T.tolist(), SPHERE.faces.T.astype(float)], ids=["array", "list", "float"]
)
def test_transposed_faces_are_refused_with_the_transpose_suggested(faces):
    with pytest.raises(
        InvalidMeshError,
        match=r"`faces` has shape \(3, 320\) and looks transposed: .* pass "
        r"`faces.T`",
    ):
        meshcurv.principal_curvatures(SPHERE.vertices, faces)


def test_three_polygons_of_many_corners_are_not_taken_for_transposed_faces():
    # (3, k) faces whose rows repeat no vertex are three k-gons, as before (fan-triangulated)
    assert meshcurv.topology.triangulate_faces(np.arange(24).reshape(3, 8)).shape == (18, 3)


def test_vertices_and_faces_swapped_are_named():
    with pytest.raises(
        InvalidMeshError,
        match=r"`faces` has non-integer values; .*\(a float64 array of shape "
        r"\(162, 3\): coordinates\? were `vertices` and `faces` swapped\?",
    ):
        meshcurv.principal_curvatures(SPHERE.faces, SPHERE.vertices)


@pytest.mark.parametrize(
    "alone, match",
    [
        (
            SPHERE.faces,
            r"`faces` is missing: `vertices` is an int64 array of shape \(320, 3\), not a mesh object; "
            r"pass `principal_curvatures\(vertices, faces\)` \(integer indices: it looks like the faces",
        ),
        (
            SPHERE.vertices,
            r"`faces` is missing: `vertices` is a float64 array of shape \(162, 3\), not a mesh object; "
            r".*for points without faces use meshcurv.point_cloud_curvatures",
        ),
        (SPHERE.vertices.tolist(), r"`faces` is missing: `vertices` is a float64 array of shape \(162, 3\)"),
    ],
)
def test_an_array_alone_is_told_to_come_with_its_faces(alone, match):
    with pytest.raises(InvalidMeshError, match=match):
        meshcurv.principal_curvatures(alone)


def test_a_subnormal_radius_is_refused_by_name():
    # 5e-324 > 0, but 1 / 5e-324 is inf: the balls' offsets became inf * 0 = NaN deep in the fits
    sphere = meshcurv.shapes.icosphere(2)
    with pytest.raises(meshcurv.errors.InvalidOptionError, match=r"`radius` must be at least 2\.23e-308 .*got 5e-324"):
        meshcurv.principal_curvatures(sphere.vertices, sphere.faces, radius=5e-324)
    with pytest.raises(meshcurv.errors.InvalidOptionError, match=r"`radius` must be at least 2\.23e-308"):
        meshcurv.point_cloud_curvatures(sphere.vertices, radius=5e-324)
