"""Closed parts that cross another closed part are outward, whatever the order of the vertices (issue 29).

Fuzz round 23 (``--real-meshes``, the permutation relation): ``ogre.obj``'s small closed parts cross its body, and
nesting (a part inside an odd number of others is a cavity's wall, turned inward) was decided by the winding
number at one corner of the part, so that the vertex order picked the answer: after a permutation 17 of 18 came
out inside out, valid and without warning. Oracles: the exact mean curvature of the spheres (signed: positive
outward), and the invariance under re-indexing.
"""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from meshcurv import principal_curvatures, shapes


def _two_spheres(centre_x: float, small: float = 0.3):
    """A unit sphere and a sphere of radius ``small`` centred at ``(centre_x, 0, 0)``: one mesh of two closed parts."""
    big, little = shapes.icosphere(10), shapes.icosphere(6)
    vertices = np.concatenate([big.vertices, small * little.vertices + [centre_x, 0.0, 0.0]])
    faces = np.concatenate([big.faces, little.faces + len(big.vertices)])
    part = np.r_[np.zeros(len(big.vertices), dtype=int), np.ones(len(little.vertices), dtype=int)]
    return vertices, faces, part


def _median_mean_curvatures(vertices, faces, part, permutation):
    inverse = np.argsort(permutation)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = principal_curvatures(vertices[permutation], inverse[faces], method="meyer")
    mean = result.mean[inverse]
    valid = result.valid[inverse]
    return [float(np.median(mean[valid & (part == p)])) for p in (0, 1)]


@pytest.mark.parametrize("seed", range(6))
def test_a_part_through_another_is_outward_in_every_order(seed):
    # the small sphere's centre on the big one's surface: half of it inside, half outside; before, its side
    # followed the corner its first face put first (inside: a cavity, H < 0)
    vertices, faces, part = _two_spheres(1.0)
    permutation = np.random.default_rng(seed).permutation(len(vertices))
    big, small = _median_mean_curvatures(vertices, faces, part, permutation)
    assert big == pytest.approx(1.0, rel=0.05)
    assert small == pytest.approx(1.0 / 0.3, rel=0.05)


def test_a_part_inside_another_is_still_a_cavity():
    # wholly inside: the wall of a cavity, its normals into the cavity (out of the material): H < 0
    vertices, faces, part = _two_spheres(0.2)
    for seed in range(3):
        permutation = np.random.default_rng(seed).permutation(len(vertices))
        big, small = _median_mean_curvatures(vertices, faces, part, permutation)
        assert big == pytest.approx(1.0, rel=0.05)
        assert small == pytest.approx(-1.0 / 0.3, rel=0.05)
