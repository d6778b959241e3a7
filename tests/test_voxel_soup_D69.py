"""``icc`` (the default) on a voxel surface stored as a triangle soup: every face its own corners, moved 0.031 edges.

Issue 29 (fuzz 750/289): ``voxel_sphere(10)`` with every face detached by 0.031 edges (the fuzzer's ``_detach``). The
weld joins the corners whose copies lie within the crack tolerance and leaves most faces apart: about a thousand
pieces, most of them isolated faces and strips (undefined: no interior vertex). A few larger pieces keep interior
vertices, and a ball on such a piece holds a part of the staircase cut by cracks: its sum carries the sphere's
curvature only with the steps around, so a piece of the flat top plateau read H -0.018 for -0.1 (12 valid vertices,
all off the clean shape's H by more than half of its largest ``|k|``). ``icc._stair_pieces`` left them valid: their
balls held 0.403 to 0.407 of their disc, just above its bar of 0.4, and a plateau's faces lie along their normals,
so the per-ball tilt test does not see a staircase there. Now a mesh welded across cracks that reads a voxel grid as
a soup (``quadric``'s reading, ``meshcurv.radius.soup_voxel_grid``) leaves undefined the balls near holes on a piece
smaller than two of their discs (``icc.STAIR_PIECE_DISCS``): the piece cannot hold the steps around. These tests
fail on c578a21.

Oracles: the exact mean curvature of the voxelised ball (``1 / R``, signed by the returned normal against the
outward one), with the fuzzer's bar (a valid vertex off by more than half of it is a wrong number marked valid);
half of the faces detached keeps most vertices valid and right (the rule is not a blanket refusal); both backends.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from conftest import chosen_backend
from meshcurv import principal_curvatures, shapes

from test_quadric_soups_Q23 import _voxel_soup  # the fuzzer's _detach on voxel_sphere(10), as marching cubes winds it

pytest.importorskip("skimage")

#: The fuzzer's bar, in units of the exact ``|k|`` (``1 / R``).
OFF = 0.5

RADIUS = 10.0


def _errors(mesh, vertices, faces, backend: str):
    """``(valid, errors)``: the number of valid vertices and their ``|H - 1/R|`` in units of ``1/R``."""
    with chosen_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the weld, the fragments and the undefined pieces are counted in warnings
        result = principal_curvatures(vertices, faces, method="icc", orient="consistent")
    outward = vertices - mesh.center
    side = np.sign(np.einsum("ij,ij->i", result.normals, outward))
    exact = side / RADIUS
    return int(result.valid.sum()), np.abs(result.mean - exact)[result.valid] * RADIUS


@pytest.mark.parametrize("backend", ["numba", pytest.param("numpy", marks=pytest.mark.slow)])
@pytest.mark.parametrize("seed", [0, 3])
def test_full_voxel_soup_never_lies(backend, seed):
    """Every face detached by 0.031 edges (fuzz 750/289's soup; on c578a21 89 of 116 and 6 of 67 valid vertices
    off, up to 0.97 and 0.55 of ``1/R``): no valid vertex off the sphere's H by half of it."""
    mesh = shapes.voxel_sphere(RADIUS)
    vertices, faces = _voxel_soup(1.0, 0.031, seed)
    _, errors = _errors(mesh, vertices, faces, backend)
    assert (errors <= OFF).all(), f"{int((errors > OFF).sum())} of {errors.size} valid off (up to {errors.max():.3g})"


@pytest.mark.parametrize("backend", ["numba", pytest.param("numpy", marks=pytest.mark.slow)])
def test_half_voxel_soup_keeps_its_values(backend):
    """Half of the faces detached by 0.031 edges: the intact half's pieces hold most of their discs and stay valid."""
    mesh = shapes.voxel_sphere(RADIUS)
    vertices, faces = _voxel_soup(0.5, 0.031, 0)
    valid, errors = _errors(mesh, vertices, faces, backend)
    assert valid > 0.4 * vertices.shape[0]
    assert (errors <= OFF).all(), f"{int((errors > OFF).sum())} of {errors.size} valid off (up to {errors.max():.3g})"
