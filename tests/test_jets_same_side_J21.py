"""``jets.fit_jets(agreement=)``: the fits of the points facing the centre's way (issue 29/30).

A ball that reaches the other side of a part thinner than it (a slab: two sheets of opposite normals) holds
points of both sheets; with ``agreement``, each centre's fit leaves out the points whose ``facing`` normal has
a cosine below the bound with its own. The oracle is the fit over the centre's own sheet alone (the other
sheet's points kept out of the balls by ``neighbours``): the same fits on both backends, over Euclidean and
surface-connected balls. A sheet tilted by a paraboloid gives fits that are not trivial.
"""

import importlib.util

import numpy as np
import pytest

from meshcurv import jets
from meshcurv._backend import use_backend
from meshcurv.errors import InvalidOptionError

BACKENDS = [
    "numpy",
    pytest.param(
        "numba", marks=pytest.mark.skipif(importlib.util.find_spec("numba") is None, reason="numba is not installed")
    ),
]


def _slab(n=21, thickness=0.3):
    """Two sheets of a grid over [-1, 1]^2: the paraboloid ``z = 0.2 (x^2 + 2 y^2)`` (normals up) and the same
    lowered by ``thickness`` (normals down), their points, normals, and the grid's edges within each sheet and
    across the rim (the first column joined to the other sheet: the walk can reach it)."""
    x, y = np.meshgrid(np.linspace(-1, 1, n), np.linspace(-1, 1, n), indexing="ij")
    x, y = x.ravel(), y.ravel()
    z = 0.2 * (x**2 + 2 * y**2)
    up = np.column_stack([-0.4 * x, -0.8 * y, np.ones_like(x)])
    up /= np.linalg.norm(up, axis=1, keepdims=True)
    points = np.vstack([np.column_stack([x, y, z]), np.column_stack([x, y, z - thickness])])
    normals = np.vstack([up, -up])
    m = n * n
    index = np.arange(m).reshape(n, n)
    pairs = [
        np.column_stack([index[:-1].ravel(), index[1:].ravel()]),
        np.column_stack([index[:, :-1].ravel(), index[:, 1:].ravel()]),
    ]
    edges = np.vstack([*pairs, *(p + m for p in pairs), np.column_stack([index[0], index[0] + m])])
    both = np.vstack([edges, edges[:, ::-1]])
    order = np.lexsort((both[:, 1], both[:, 0]))
    both = both[order]
    indptr = np.searchsorted(both[:, 0], np.arange(2 * m + 1))
    return points, normals, (indptr, both[:, 1].astype(np.int64))


@pytest.mark.parametrize("backend", BACKENDS)
@pytest.mark.parametrize("connected", [False, True])
def test_the_other_sheet_is_left_out(backend, connected):
    points, normals, adjacency = _slab()
    m = points.shape[0] // 2
    centres = np.arange(0, m, 7)  # on the upper sheet; balls of 0.5 reach the lower one (0.3 below)
    options = {"degree": 3, "iterations": 2, "centres": centres, "compact": True}
    if connected:
        options["adjacency"] = adjacency
    upper = np.arange(points.shape[0]) < m
    with use_backend(backend):
        mixed = jets.fit_jets(points, normals, 0.5, **options)[0]
        selected, _, counts = jets.fit_jets(points, normals, 0.5, facing=normals, agreement=0.7, **options)
        alone, _, alone_counts = jets.fit_jets(points, normals, 0.5, neighbours=upper, **options)
    assert np.isfinite(alone).all()
    np.testing.assert_array_equal(counts, alone_counts)
    # the same points in the same order, the others weighing 0: the sums differ by round-off at most
    np.testing.assert_allclose(selected, alone, rtol=0, atol=1e-12)
    # without the selection the lower sheet pulls fits down (the connected balls reach it round the rim only)
    assert np.max(np.abs(mixed[:, 0] - alone[:, 0])) > 0.05


def test_the_backends_agree():
    pytest.importorskip("numba")
    points, normals, _ = _slab()
    centres = np.arange(0, points.shape[0], 5)
    options = {"degree": 3, "iterations": 2, "centres": centres, "compact": True}
    out = {}
    for backend in ("numpy", "numba"):
        with use_backend(backend):
            coefficients, frame, _ = jets.fit_jets(points, normals, 0.6, facing=normals, agreement=0.5, **options)
            out[backend] = jets.jet_normals(coefficients, frame)  # (the frames' tangents may differ at the apex)
    np.testing.assert_allclose(out["numba"], out["numpy"], rtol=0, atol=1e-10)


@pytest.mark.parametrize("agreement", [1.5, -1.5, float("nan")])
def test_agreement_must_be_a_cosine(agreement):
    points, normals, _ = _slab(5)
    with pytest.raises(InvalidOptionError, match="agreement"):
        jets.fit_jets(points, normals, 0.5, facing=normals, agreement=agreement)


def test_agreement_needs_facing():
    points, normals, _ = _slab(5)
    with pytest.raises(InvalidOptionError, match="needs `facing`"):
        jets.fit_jets(points, normals, 0.5, agreement=0.7)
