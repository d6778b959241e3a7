"""A double-sided mesh with seams or cracks gives the curvatures of its one side (issue 29, "never lie").

The weld joins the vertices on boundary edges (seams of coincident copies, cracks between detached faces). On a
double-sided mesh an edge of a doubled face has a second face, its other side, and is no boundary: the weld saw
nothing there, and the side kept after the drop of the second faces had its seams and cracks open (fuzz_api
450/125: ogre with every face twice, 33 vertices of ``normal_cycle`` changed validity; a unit sphere a third of
whose faces were detached kept 41 of its 1,037 valid vertices). The one side is now welded as if it had been
given alone. The oracle: the one-sided mesh's own result (the same faces, so the same numbers, bit for bit), and
the same counts in the parameters; the warning says that the second faces were dropped.
"""

from __future__ import annotations

import os
import pathlib
import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes


def _arrays(mesh) -> tuple[np.ndarray, np.ndarray]:
    return np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces)


def _mean_edge(vertices: np.ndarray, faces: np.ndarray) -> float:
    return float(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1).mean())


def _seamed(vertices: np.ndarray, faces: np.ndarray):
    """The faces on the side x > 0 given copies of the vertices they share with the others: a split seam."""
    right = vertices[faces].mean(axis=1)[:, 0] > 0
    shared = np.intersect1d(faces[~right], faces[right])
    copy = np.full(vertices.shape[0], -1)
    copy[shared] = vertices.shape[0] + np.arange(shared.size)
    faces = faces.copy()
    moved = faces[right]
    on_seam = copy[moved] >= 0
    moved[on_seam] = copy[moved[on_seam]]
    faces[right] = moved
    return np.vstack([vertices, vertices[shared]]), faces


def _detached(vertices: np.ndarray, faces: np.ndarray, share: float = 0.3, gap: float = 1e-3, seed: int = 3):
    """A ``share`` of the faces given corners of their own, each moved ``gap`` mean edge lengths: cracks that the
    weld closes (``weld.CRACK_TOLERANCE_RATIO`` is 0.05)."""
    rng = np.random.default_rng(seed)
    edge = _mean_edge(vertices, faces)
    picked = rng.random(faces.shape[0]) < share
    corners = vertices[faces[picked]].reshape(-1, 3)
    directions = rng.normal(size=corners.shape)
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    faces = faces.copy()
    faces[picked] = vertices.shape[0] + np.arange(corners.shape[0]).reshape(-1, 3)
    return np.vstack([vertices, corners + directions * gap * edge]), faces


def _noisy_soup(vertices: np.ndarray, faces: np.ndarray, noise: float = 1e-3, seed: int = 1):
    """Every face with corners of its own, each moved by ``noise`` mean edge lengths (a soup written with
    rounding): welded across its cracks only."""
    corners = vertices[faces.ravel()]
    corners = corners + np.random.default_rng(seed).normal(size=corners.shape) * noise * _mean_edge(vertices, faces)
    return corners, np.arange(corners.shape[0]).reshape(-1, 3)


SPHERE = _arrays(shapes.icosphere(6))
TORUS = _arrays(shapes.torus(3.0, 1.0, 32, 16))
HEMISPHERE = _arrays(shapes.hemisphere(8))
MESHES = {
    "sphere with a seam": _seamed(*SPHERE),
    "torus with cracks": _detached(*TORUS),
    "hemisphere with cracks": _detached(*HEMISPHERE),
    "noisy soup": _noisy_soup(*SPHERE),
}


def stacked(faces: np.ndarray) -> np.ndarray:
    """Every face, then every face reversed."""
    return np.vstack([faces, faces[:, ::-1]])


def reversed_first(faces: np.ndarray) -> np.ndarray:
    """Every face reversed, then every face: the side kept is the outward one of a closed mesh, the first given of
    an open one (``orient='outward'`` keeps an open mesh's side): the first faces' result either way."""
    return np.vstack([faces[:, ::-1], faces])


def partly(faces: np.ndarray, share: float = 0.3, seed: int = 0) -> np.ndarray:
    """Every face, then a ``share`` of them reversed: a mesh double-sided in places."""
    picked = np.random.default_rng(seed).random(faces.shape[0]) < share
    return np.vstack([faces, faces[picked][:, ::-1]])


def _computed(vertices, faces, method):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        result = meshcurv.principal_curvatures(vertices, faces, method=method)
    return result, [str(warning.message) for warning in caught]


def _assert_one_side(vertices, faces, doubled, method, *, rows=None):
    """The result on ``doubled`` faces is the one of its first ``len(faces)`` faces (the first side given, on the
    rows of the caller's ``vertices``): the same valid vertices and curvatures, and one warning that says the
    second faces were dropped."""
    faces = doubled[: faces.shape[0]]
    one, _ = _computed(vertices, faces, method)
    both, messages = _computed(vertices if rows is None else rows, doubled, method)
    n_dropped = doubled.shape[0] - faces.shape[0]
    assert len(messages) == 1, messages
    assert f"dropped {n_dropped} faces that repeat another face's corners" in messages[0]
    assert both.parameters["n_double_sided_faces"] == n_dropped
    n = vertices.shape[0]
    np.testing.assert_array_equal(both.valid[:n], one.valid)
    np.testing.assert_array_equal(both.invalid_reason[:n], one.invalid_reason)
    # to round-off: the noise level is read over the faces in another order (the noisy soup reversed first:
    # 0.0012419044344732962 against ...2719 with numpy 2.4.6), which moves 6 of its 2,160 k_max by 2.5e-12
    for name in ("k_min", "k_max"):
        np.testing.assert_allclose(getattr(both, name)[:n], getattr(one, name), rtol=1e-9, atol=1e-12)
    return one, both


@pytest.mark.parametrize("method", meshcurv.METHODS)
@pytest.mark.parametrize("layout", [stacked, partly], ids=lambda layout: layout.__name__)
def test_a_cracked_mesh_doubled_gives_its_one_side(method, layout):
    vertices, faces = MESHES["torus with cracks"]
    one, both = _assert_one_side(vertices, faces, layout(faces), method)
    if method != "matgeom":  # its default is no weld: the cracks stay open on both
        assert both.parameters["n_welded_vertices"] == one.parameters["n_welded_vertices"] > 0
        assert both.valid.mean() > 0.2  # doubled, the cracks stayed open: 28 of 1,424 rows valid (normal_cycle)


@pytest.mark.parametrize("method", ["normal_cycle", "icc", "quadric"])
@pytest.mark.parametrize("name", ["sphere with a seam", "hemisphere with cracks", "noisy soup"])
@pytest.mark.parametrize("layout", [stacked, reversed_first, partly], ids=lambda layout: layout.__name__)
def test_seams_cracks_and_soups_doubled_give_their_one_side(method, name, layout):
    vertices, faces = MESHES[name]
    one, both = _assert_one_side(vertices, faces, layout(faces), method)
    assert both.parameters["n_welded_vertices"] == one.parameters["n_welded_vertices"] > 0


def test_a_doubled_soup_with_corners_of_its_own_gives_its_one_side():
    # the second side stored with corners of its own (each the copy of a first side's corner): its vertices get
    # the values of the corners they repeat
    vertices, faces = MESHES["noisy soup"]
    n = vertices.shape[0]
    doubled = np.vstack([faces, faces[:, ::-1] + n])
    one, both = _assert_one_side(vertices, faces, doubled, "normal_cycle", rows=np.vstack([vertices, vertices]))
    assert one.valid.all()
    np.testing.assert_array_equal(both.k_max[n:], both.k_max[:n])
    assert both.parameters["n_welded_vertices"] == one.parameters["n_welded_vertices"] + n


@pytest.mark.parametrize("method", ["normal_cycle", "icc", "quadric"])
@pytest.mark.parametrize("name", ["sphere with a seam", "torus with cracks", "hemisphere with cracks"])
def test_a_second_side_with_vertices_of_its_own_gives_the_one_side(method, name):
    # the second side stored with vertices of its own (at the same points): the weld glued the two sides along
    # their seams, cracks and rims, and their faces never shared their corners (a cracked hemisphere: 293 of 820
    # valid vertices changed for normal_cycle, curvatures off by 5.8 at the rim); each copy gets its twin's values
    vertices, faces = MESHES[name]
    n = vertices.shape[0]
    doubled = np.vstack([faces, faces[:, ::-1] + n])
    one, both = _assert_one_side(vertices, faces, doubled, method, rows=np.vstack([vertices, vertices]))
    np.testing.assert_array_equal(both.valid[n:], both.valid[:n])
    np.testing.assert_array_equal(both.k_max[n:], both.k_max[:n])
    # each copy of a vertex of the first side is welded (the unreferenced ones are left alone)
    assert both.parameters["n_welded_vertices"] == one.parameters["n_welded_vertices"] + np.unique(faces).size


def test_the_gauss_bonnet_total_of_a_doubled_cracked_sphere_is_4_pi():
    # the welded sphere, counted once: 2 pi chi exactly (the angle defects), not twice that nor a cracked total
    vertices, faces = _detached(*SPHERE)
    result, _ = _computed(vertices, stacked(faces), "meyer")
    assert result.integral("gaussian") == pytest.approx(4 * np.pi, abs=1e-9)


FOLDER = pathlib.Path(
    os.environ.get("MESHCURV_SHARED_MESHES", pathlib.Path(__file__).resolve().parents[2] / "shared" / "meshes")
)


@pytest.mark.slow
@pytest.mark.skipif(not os.environ.get("MESHCURV_RUN_SLOW"), reason="slow: set MESHCURV_RUN_SLOW=1")
@pytest.mark.skipif(not (FOLDER / "ogre.obj").is_file(), reason=f"no ogre.obj at {FOLDER}")
@pytest.mark.parametrize("method", ["normal_cycle", "icc"])
def test_ogre_doubled_gives_its_one_side(method):
    # fuzz_api 450/125: ogre's 9 seams (coincident vertices on boundary edges) stayed open when doubled
    io = pytest.importorskip("meshcurv.io")
    vertices, faces = io.read_mesh(FOLDER / "ogre.obj")
    vertices, faces = np.asarray(vertices, dtype=float), np.asarray(faces)
    one, both = _assert_one_side(vertices, faces, stacked(faces), method)
    assert both.parameters["n_welded_vertices"] == one.parameters["n_welded_vertices"] == 9
