"""method="matgeom" against outputs of the real matGeom run under GNU Octave.

Tolerances and masks: tests/data/matgeom/README.md.
"""

import importlib.util
import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv._backend import use_backend
from meshcurv.errors import MeshQualityWarning, TriangulationWarning
from meshcurv.estimators._eigen import sorted_by_magnitude
from meshcurv.estimators.matgeom import matgeom_tensors
from meshcurv.topology import MeshTopology

from conftest import DATA

CASES = sorted(p.stem for p in (DATA / "matgeom").glob("*.npz"))
# mask sizes stated in the reference README (rules 2 and 3)
UMBILIC_COUNTS = {
    "cube_sub4": 38,
    "fandisk": 954,
    "icosphere_r1_sub4": 12,
    "icosphere_r1_sub16": 12,
    "icosphere_r5_sub8": 12,
    "icosphere_flipped": 12,
    "isolated_vertex": 13,
    "uvsphere_r1_32x16": 2,
}
FLAT_COUNTS = {"cube_sub4": 32, "fandisk": 1101, "isolated_vertex": 1}


def load(name):
    with np.load(DATA / "matgeom" / f"{name}.npz") as z:
        return {k: z[k] for k in z.files}


def run_matgeom(case):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", TriangulationWarning)
        warnings.simplefilter("ignore", MeshQualityWarning)
        return meshcurv.principal_curvatures(
            case["vertices"],
            case["faces"],
            method="matgeom",
            smoothing_steps=int(case["smoothing_steps"]),
        )


def misalignment(a, b):
    """1 - |a . b| per row: 0 when the unit vectors agree up to sign."""
    return 1 - np.abs(np.sum(a * b, axis=1))


def test_all_reference_cases_are_present():
    assert len(CASES) == 17


BACKENDS = ["numpy"] + (["numba"] if importlib.util.find_spec("numba") else [])


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("name", CASES)
def test_matgeom_parity(name, backend):
    case = load(name)
    with use_backend(backend):
        result = run_matgeom(case)
    C1, C2, U1, U2, H, K, N = result.as_matgeom()
    scale = max(np.abs(case["C1"]).max(), np.abs(case["C2"]).max())

    np.testing.assert_allclose(C1, case["C1"], rtol=0, atol=1e-10 * scale)
    np.testing.assert_allclose(C2, case["C2"], rtol=0, atol=1e-10 * scale)
    np.testing.assert_allclose(H, case["H"], rtol=0, atol=1e-10 * scale)
    np.testing.assert_allclose(K, case["K"], rtol=0, atol=1e-10 * scale**2)

    umbilic = np.abs(case["C2"] - case["C1"]) <= 1e-8 * scale
    tensors, *_ = matgeom_tensors(
        np.asarray(case["vertices"], float),
        MeshTopology._build(meshcurv.triangulate_faces(case["faces"]), case["vertices"].shape[0]),
        int(case["smoothing_steps"]),
    )
    with use_backend(backend):
        values, _ = sorted_by_magnitude(tensors)
    flat = np.abs(values[:, 1]) - np.abs(values[:, 0]) <= 1e-8 * scale
    assert misalignment(U1, case["U1"])[~umbilic].max(initial=0) <= 1e-8
    assert misalignment(U2, case["U2"])[~(umbilic | flat)].max(initial=0) <= 1e-8
    assert misalignment(N, case["N"])[~flat].max(initial=0) <= 1e-8
    # the masks are the ones the reference README counts, no wider
    assert umbilic.sum() == UMBILIC_COUNTS.get(name, 0)
    assert flat.sum() == FLAT_COUNTS.get(name, 0)


def test_quads_are_triangulated_with_matgeoms_warning():
    case = load("torus_quads")
    with pytest.warns(TriangulationWarning, match="forces triangulation"):
        result = meshcurv.principal_curvatures(case["vertices"], case["faces"], method="matgeom")
    triangles = load("torus_tri")
    np.testing.assert_array_equal(meshcurv.triangulate_faces(case["faces"]), triangles["faces"])
    np.testing.assert_allclose(result.k_min, triangles["C1"], rtol=0, atol=1e-12)


def test_open_mesh_warns_with_the_mispairing_counts():
    case = load("saddle_grid")
    with pytest.warns(MeshQualityWarning, match=r"drops 40 edges and pairs 39 edges") as record:
        meshcurv.principal_curvatures(case["vertices"], case["faces"], method="matgeom")
    assert len(record) == 1
    assert "normal_cycle" in str(record[0].message)


def test_open_mesh_values_near_the_boundary_are_kept_but_marked_invalid():
    case = load("saddle_grid")
    with pytest.warns(MeshQualityWarning):
        result = meshcurv.principal_curvatures(case["vertices"], case["faces"], method="matgeom")
    np.testing.assert_allclose(result.k_min, case["C1"], rtol=0, atol=1e-12)  # matGeom's numbers
    x, y = case["vertices"][:, 0], case["vertices"][:, 1]
    rim = np.maximum(np.abs(x), np.abs(y)) > 1 - 1e-9  # 21 x 21 grid, spacing 0.1
    assert not result.valid[rim].any()
    # boundary ends plus three smoothing rings are doubtful; the centre is not
    inner = np.maximum(np.abs(x), np.abs(y)) < 0.55
    assert result.valid[inner].all()


def test_unreferenced_vertex_keeps_matgeoms_zeros_and_is_invalid():
    case = load("isolated_vertex")
    with pytest.warns(MeshQualityWarning, match="1 unreferenced vertices"):
        result = meshcurv.principal_curvatures(case["vertices"], case["faces"], method="matgeom")
    assert not result.valid[100] and result.valid.sum() == 642
    assert result.k_min[100] == 0 and result.k_max[100] == 0
    np.testing.assert_array_equal(result.dir_min[100], case["U1"][100])


def test_trailing_unreferenced_vertex_with_smoothing_is_defined():
    # matGeom stops with "nonconformant arguments" here
    case = load("icosphere_r1_sub4")
    vertices = np.vstack([case["vertices"], [[5.0, 5.0, 5.0]]])
    with pytest.warns(MeshQualityWarning, match="unreferenced"):
        result = meshcurv.principal_curvatures(vertices, case["faces"], method="matgeom")
    assert not result.valid[-1]
    np.testing.assert_allclose(result.k_min[:-1], case["C1"], rtol=0, atol=1e-12)


def test_zero_area_face_gives_nan_and_one_warning_instead_of_matgeoms_eig_error():
    case = load("icosphere_r1_sub4")
    vertices = case["vertices"].copy()
    a, b, c = case["faces"][0]
    vertices[c] = vertices[a]  # face 0 loses its area, edge (a, c) its length
    with pytest.warns(MeshQualityWarning, match="EIG") as record:
        result = meshcurv.principal_curvatures(vertices, case["faces"], method="matgeom")
    assert len(record) == 1
    assert not result.valid[c] and np.isnan(result.k_min[c])
    assert result.valid.sum() > 100  # NaN spreads over the smoothing rings only


@pytest.mark.parametrize("defect", ["flipped_face", "fin"])
def test_nonmanifold_or_flipped_input_does_not_crash(defect):
    case = load("icosphere_r1_sub4")
    faces = case["faces"].copy()
    if defect == "flipped_face":
        faces[-1] = faces[-1, ::-1]  # summed face ids exceed the face count
    else:
        a, b = faces[-1, :2]
        vertices = np.vstack([case["vertices"], [[2.0, 2.0, 2.0]]])
        faces = np.vstack([faces, [a, b, vertices.shape[0] - 1]])
        case["vertices"] = vertices
    with pytest.warns(MeshQualityWarning, match="non-manifold or inconsistently oriented"):
        result = meshcurv.principal_curvatures(case["vertices"], faces, method="matgeom")
    assert np.isnan(result.k_min[faces[-1]]).all()
    assert not result.valid[faces[-1]].any()
    # where valid, the numbers are the clean sphere's up to matGeom's division by
    # the mean edge length (the fin adds edges, so that mean changes)
    clean = load("icosphere_r1_sub4")["C2"]
    ratio = result.k_max[: clean.size][result.valid[: clean.size]] / clean[result.valid[: clean.size]]
    assert ratio.size > 10
    np.testing.assert_allclose(ratio, ratio[0], rtol=1e-12)
