"""``quadric`` on fine soups welded back across their cracks (issue 29, Q70; fuzz 400/78, 690/72, 730/1).

A soup's faces have corners of their own, moved a gap of a few hundredths of an edge (the fuzzer's detached faces);
the weld joins the copies back across the cracks, each group at one copy's point. On a fine mesh such a gap is large
beside what a ball of a few edges bends by (``h^2 k``), and the degree-4 jets over the 19 points of a default ball
followed the copies' offsets: ``icosphere(16)`` with every face detached by 0.02 edges had 600 of its 15,360 rows
valid and off the exact H by more than half of it. A weld across a crack that is narrow for the curvature (a coarse
torus whose faces moved by 1e-3 edges) is no crack for the fits: every vertex there stays valid and right.

Expected values: the exact mean curvatures of :mod:`meshcurv.shapes` at the corner each row copies (the unit
sphere's H is 1); the clean torus's validity (every vertex valid at its default).
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv._prepared import prepare_mesh

from conftest import chosen_backend
from test_normal_cycle_ball_holes import _detached


def _soup(mesh, share: float, gap: float, seed: int):
    """``(vertices, faces, corners)``: a ``share`` of the faces of ``mesh`` given corners of their own, each moved
    ``gap`` mean edge lengths in a random direction (the fuzzer's ``_detach``), and the clean corner of each row."""
    vertices, faces = _detached(mesh, share, gap, seed)
    clean = np.asarray(mesh.faces)
    return vertices, faces, np.concatenate([np.arange(len(mesh.vertices)), clean[faces != clean]])


def _errors(mesh, share, gap, seed, backend="numba"):
    """``(valid, referenced, error)``: the valid rows, the rows in a face, and ``|H - H_exact|`` over the largest
    exact ``|k|`` at the valid rows."""
    vertices, faces, corners = _soup(mesh, share, gap, seed)
    referenced = np.bincount(faces.ravel(), minlength=len(vertices)) > 0
    with chosen_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the weld's note
        result = meshcurv.principal_curvatures(vertices, faces, method="quadric")
    valid = result.valid & referenced
    largest = float(np.max(np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))))
    error = np.abs(result.mean - np.asarray(mesh.mean)[corners])[valid] / largest
    return valid, referenced, error


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_a_fine_soup_welded_back_is_right_or_invalid(backend):
    """``icosphere(16)``, every face detached by 0.02 edges (every crack welded): before, 600 of 15,360 valid rows off
    the exact H by more than half of it (up to 0.84); now none, every row still valid."""
    sphere = shapes.icosphere(16)
    valid, referenced, error = _errors(sphere, 1.0, 0.02, 1, backend)
    assert valid.sum() > 0.9 * referenced.sum()
    assert error.max() < 0.35, f"{int((error > 0.35).sum())} valid rows off by more than 0.35 (up to {error.max():.2f})"


@pytest.mark.parametrize(
    ("share", "gap", "seed"),
    [
        (0.5, 0.024, 1),  # before: 24 of 10,203 valid rows off by more than half of H (up to 0.54)
        (1.0, 0.012, 2),  # ... a gap nearer the weld's own tolerance at a finer mesh: see below
    ],
)
def test_fine_soups_of_narrow_gaps_are_right_or_invalid(share, gap, seed):
    """Half of ``icosphere(16)``'s faces detached by 0.024 edges, and every face of ``icosphere(24)`` by 0.012 (before:
    1,206 of 34,560 valid rows off by more than half of H): the gap that matters is the one beside ``h^2 k``."""
    sphere = shapes.icosphere(16 if share < 1 else 24)
    valid, referenced, error = _errors(sphere, share, gap, seed)
    assert valid.sum() > 0.9 * referenced.sum()
    assert error.max() < 0.35, f"{int((error > 0.35).sum())} valid rows off by more than 0.35 (up to {error.max():.2f})"


@pytest.mark.parametrize("backend", ["numba", "numpy"])
def test_a_near_clean_weld_keeps_every_vertex(backend):
    """``torus(3, 1, 32, 16)``, 30% of its faces detached by 1e-3 edges and welded back (as
    tests/test_double_sided_welds_D24.py): as on the clean torus, every row valid and its H within 0.2 of the largest
    ``|k|`` (Q69's rule, every welded vertex a crack's corner, left 272 of 1,424 valid)."""
    torus = shapes.torus(3.0, 1.0, 32, 16)
    valid, referenced, error = _errors(torus, 0.3, 1e-3, 3, backend)
    assert valid.sum() == referenced.sum()
    assert error.max() < 0.2


def test_crack_gaps_are_the_copies_distances():
    """``PreparedMesh.crack_gaps``: None on a closed mesh and on a soup of coincident copies; on a soup welded across
    cracks, at each vertex the largest distance of a copy joined into it (every copy ``gap`` from its clean corner:
    at most twice that, and that exactly where the clean corner kept a face)."""
    sphere = shapes.icosphere(6)
    vertices, faces = np.asarray(sphere.vertices, dtype=float), np.asarray(sphere.faces)
    assert prepare_mesh(vertices, faces, orient="auto", weld=True).crack_gaps is None
    soup = vertices[faces.ravel()]
    coincident = prepare_mesh(soup, np.arange(soup.shape[0]).reshape(-1, 3), orient="auto", weld=True)
    assert coincident.n_welded > 0 and coincident.crack_gaps is None
    soup, soup_faces, corners = _soup(sphere, 0.5, 0.03, 4)
    mesh = prepare_mesh(soup, soup_faces, orient="auto", weld=True)
    assert mesh.n_cracked > 0
    edge = float(np.mean(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)))
    gaps = np.asarray(mesh.crack_gaps)
    assert gaps.shape == (mesh.vertices.shape[0],)
    assert (gaps >= 0).all() and gaps.max() <= 2 * 0.03 * edge * (1 + 1e-9)
    kept = np.zeros(len(soup), dtype=bool)
    kept[soup_faces.ravel()] = True
    moved = kept & (np.arange(len(soup)) >= len(vertices))  # the copies
    in_place = kept[corners] & (np.arange(len(soup)) < len(vertices))  # clean corners that kept a face
    joined = mesh.index[np.flatnonzero(in_place)]
    with_copies = np.isin(joined, mesh.index[np.flatnonzero(moved)])
    np.testing.assert_allclose(gaps[joined[with_copies]], 0.03 * edge, rtol=1e-9)
