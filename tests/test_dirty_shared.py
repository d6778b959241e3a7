"""Every real mesh of ../shared/meshes through every method: finite at every valid vertex.

Slow (the largest mesh has 134k vertices), so outside the default suite: run with
``MESHCURV_RUN_SLOW=1 python -m pytest tests/test_dirty_shared.py``. Skipped
cleanly when the shared folder is absent (``MESHCURV_SHARED_MESHES`` overrides its path).
"""

import os
import pathlib
import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv.errors import MeshQualityWarning
from meshcurv.estimators import ESTIMATORS

FOLDER = pathlib.Path(
    os.environ.get("MESHCURV_SHARED_MESHES", pathlib.Path(__file__).resolve().parents[2] / "shared" / "meshes")
)
MESHES = sorted(FOLDER.glob("*.obj")) if FOLDER.is_dir() else []

pytestmark = [
    pytest.mark.slow,
    pytest.mark.skipif(not os.environ.get("MESHCURV_RUN_SLOW"), reason="slow: set MESHCURV_RUN_SLOW=1"),
    pytest.mark.skipif(not MESHES, reason=f"no shared meshes at {FOLDER}"),
]


@pytest.fixture(scope="module", params=[p.name for p in MESHES] or ["none"])
def mesh(request):
    io = pytest.importorskip("meshcurv.io")
    vertices, faces = io.read_mesh(FOLDER / request.param)
    return request.param, vertices, meshcurv.MeshTopology.from_faces(faces, vertices.shape[0])


#: Valid shares below 0.9 measured on 17e2e25 and since (stop 61), open: losses, not wrong values (the finiteness
#: of every valid value is asserted first). ``quadric``'s balls over both sides of thin parts (ogre's limbs, spot's
#: horns and ears: "a ball ... that holds the other side of the surface") and fandisk's creases.
KNOWN_LOSSES = {
    ("ogre.obj", "quadric"): "25.5% valid: balls of its grown radius (up to 1.0) hold the other side of thin parts",
    ("spot.obj", "quadric"): "77% valid: 665 balls hold the other side of the surface (horns, ears)",
    ("fandisk.obj", "quadric"): "80% valid on a CAD part's creases",
    ("fandisk.obj", "matgeom"): "82% valid on a CAD part's creases",
}


def _boundary_edges(faces: np.ndarray, vertices: np.ndarray, welded: bool) -> int:
    """The edges of one face, counted from the file's faces (with its coincident vertices merged when ``welded``)."""
    if welded:
        faces = np.unique(vertices, axis=0, return_inverse=True)[1].ravel()[faces]
    edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
    return int((np.unique(edges, axis=0, return_counts=True)[1] == 1).sum())


@pytest.mark.parametrize("method", sorted(ESTIMATORS))
def test_finite_at_every_valid_vertex(mesh, method):
    name, vertices, topology = mesh
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always", MeshQualityWarning)
        r = meshcurv.principal_curvatures(vertices, topology, method=method)
    assert len(record) <= 1
    for values in (r.k_min, r.k_max, r.mean, r.gaussian):
        assert np.isfinite(values[r.valid]).all()
    if name == "ogre.obj":  # its defects: 44 parts, 4 zero-area faces, and its boundary edges counted here
        d = r.diagnosis
        welded = r.parameters.get("n_welded_vertices", 0) > 0  # (9 coincident vertices: 236 -> 200 boundary edges)
        expected = (44, _boundary_edges(topology.faces, vertices, welded), 4)
        assert (d.n_components, d.n_boundary_edges, d.n_degenerate_faces) == expected
        assert len(record) == 1
    if r.valid.mean() <= 0.9 and (name, method) in KNOWN_LOSSES:
        pytest.xfail(KNOWN_LOSSES[name, method])
    assert r.valid.mean() > 0.9, f"{name}: only {r.valid.mean():.1%} valid"
