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


@pytest.mark.parametrize("method", sorted(ESTIMATORS))
def test_finite_at_every_valid_vertex(mesh, method):
    name, vertices, topology = mesh
    with warnings.catch_warnings(record=True) as record:
        warnings.simplefilter("always", MeshQualityWarning)
        r = meshcurv.principal_curvatures(vertices, topology, method=method)
    assert len(record) <= 1
    for values in (r.k_min, r.k_max, r.mean, r.gaussian):
        assert np.isfinite(values[r.valid]).all()
    assert r.valid.mean() > 0.9, f"{name}: only {r.valid.mean():.1%} valid"
    if name == "ogre.obj":  # the README's counts of its defects
        d = r.diagnosis
        assert (d.n_components, d.n_boundary_edges, d.n_degenerate_faces) == (44, 236, 4)
        assert len(record) == 1
