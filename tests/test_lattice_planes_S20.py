"""The lattice of repeated coordinates (``lattice._plane_lattice``) gives up a candidate origin once the planes it
missed leave it short of the share asked for (issue 31: a smooth mesh's 100,000 repeated coordinates were read
against each of 64 candidates in full, 0.02 CPU s of the voxel rule of a default call at 1M vertices; since S20 a
quarter of them). The answer must be the one of reading every plane: checked against that definition, written
out here, on lattices holding just below, at and just above the share, with the planes off the lattice first,
last or spread among the others.
"""

from __future__ import annotations

import numpy as np
import pytest

from meshcurv import lattice


def _every_plane(planes, candidates, share):
    """The definition: each candidate's share of the planes on its lattice, read on all of them."""
    gaps = np.diff(planes)
    gaps = gaps[gaps > 0]
    smallest = float(np.min(gaps))
    near = gaps[gaps < 1.5 * smallest]
    spacing = float(np.median(near if near.size >= 0.5 * gaps.size else gaps))
    held = np.zeros(candidates.size)
    for j, candidate in enumerate(candidates):
        steps = (planes - candidate) / spacing
        held[j] = np.count_nonzero(np.abs(steps - np.round(steps)) <= 1e3 * lattice._ON_GRID) / planes.size
    if held.max() < share:
        return None
    return spacing, float(candidates[np.argmax(held)])


def _planes(n_on, n_off, where, rng):
    on = 0.3 + 0.25 * np.arange(n_on)  # a lattice of step 0.25 through 0.3
    extent = 0.25 * n_on
    if where == "first":
        off = -extent + extent * rng.random(n_off)
    elif where == "last":
        off = 2 * extent + extent * rng.random(n_off)
    else:
        off = extent * rng.random(n_off) + 0.1
    return np.unique(np.concatenate([on, off]))


@pytest.mark.parametrize("where", ["first", "last", "spread"])
@pytest.mark.parametrize("share", [0.8, 1.0])
def test_candidates_given_up_early_give_the_lattice_of_every_plane(where, share):
    rng = np.random.default_rng(7)
    found = []
    for n_on in (10, 3000, 20000):
        for off_share in (0.0, 0.05, 0.19, 0.2, 0.21, 0.5, 0.95):
            n_off = int(round(off_share * n_on / (1 - off_share))) if off_share < 1 else 0
            planes = _planes(n_on, n_off, where, rng)
            picks = rng.choice(planes.size, size=min(64, planes.size), replace=False)
            for candidates in (planes[:1], planes[picks], planes[np.sort(picks)]):
                expected = _every_plane(planes, candidates, share)
                assert lattice._plane_lattice(planes, candidates, share) == expected, (n_on, off_share)
                found.append(expected is not None)
    assert any(found) and not all(found)  # both answers were met


def test_a_smooth_axis_has_no_lattice_and_a_grid_has_its_own():
    rng = np.random.default_rng(3)
    smooth = np.unique(np.round(rng.normal(size=200_000), 5))  # repeated, but no lattice of theirs holds 80%
    assert _every_plane(smooth, smooth[:64], 0.8) is None
    assert lattice._plane_lattice(smooth, smooth[:64], 0.8) is None
    grid = 0.5 * np.arange(-400, 400) + 0.125
    spacing, origin = lattice._plane_lattice(grid, grid[::13], 1.0)
    assert spacing == pytest.approx(0.5) and (origin - 0.125) / 0.5 == pytest.approx(round((origin - 0.125) / 0.5))
