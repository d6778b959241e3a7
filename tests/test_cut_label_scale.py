"""A label cut by the image border under a change of spacing (issue 29; fuzz_labels round 25, seed 452 case 190).

The default radius of a cut label comes from a pilot over the vertices farther than ``CUT_PILOT_RIM`` voxels from
the image faces. At exactly 2 voxels, a distance of the lattice (marching cubes' vertices lie at whole and half
voxels from the faces), the last bits of the spacing decided which vertices were read: a ball of radius 11.26
voxels cut by two faces got a radius of 3.9987 voxels at unit spacing and 3.9155 at 1e-3. Every column of the
table scales with the spacing.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest

from meshcurv import volume
from meshcurv.volume import label_curvatures

pytest.importorskip("skimage")

DATA = Path(__file__).parent / "data" / "cut_ball_452_190.npz"


def _image() -> np.ndarray:
    stored = np.load(DATA)
    shape = tuple(int(n) for n in stored["shape"])
    return np.unpackbits(stored["bits"])[: np.prod(shape)].reshape(shape)


def _row(scale: float):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return label_curvatures(_image(), spacing=[scale] * 3).iloc[0]


def test_the_rim_and_floor_are_off_the_lattice():
    for voxels in (volume.CUT_PILOT_RIM, volume.CUT_RADIUS_FLOOR):
        assert abs(2.0 * voxels - round(2.0 * voxels)) > 0.01  # whole and half voxels from the image faces


@pytest.mark.parametrize("scale", [1e-3, 2.0**-10, 0.7, 1e3])
def test_a_cut_balls_radius_and_curvatures_scale_with_the_spacing(scale):
    row, scaled = _row(1.0), _row(scale)
    assert scaled["radius"] == pytest.approx(row["radius"] * scale, rel=1e-9)
    assert scaled["area"] == pytest.approx(row["area"] * scale**2, rel=1e-9)
    # (the curvature columns of a ball cut this close to its reach are NaN, with the reason: NaN at every spacing)
    for column in ("mean_weighted", "mean_median", "gaussian_weighted", "total_mean", "total_gaussian"):
        power = {"gaussian_weighted": 2, "total_mean": -1, "total_gaussian": 0}.get(column, 1)
        assert scaled[column] * scale**power == pytest.approx(row[column], rel=1e-7, nan_ok=True), column
