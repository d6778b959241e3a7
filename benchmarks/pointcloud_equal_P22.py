"""``benchmarks/pointcloud_equal_P19.py`` with the clouds of issue 31's equality brief added.

Every field of ``point_cloud_curvatures`` (both methods) on P19's eight clouds and on a sphere, a noisy sphere
(noise of 0.1 spacings), a thin ellipsoid (3 x 3 x 0.15, 8,000 points: its two faces a ball apart) and two near
spheres (radius 1, 0.05 apart), saved to compare two trees to the bit; ``--large`` adds a 1M-point torus and a
1M-point sphere.

Usage::

    PYTHONPATH=<tree>/src python benchmarks/pointcloud_equal_P22.py --out before.npz [--backend numpy] [--large]
    python benchmarks/pointcloud_equal_P22.py --compare before.npz after.npz
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

import pointcloud_equal_P19 as base  # noqa: E402
from pointcloud import noisy, sample  # noqa: E402

p19_clouds = base.clouds


def clouds(large: bool):
    """P19's clouds and this brief's: ``name -> (points, normals or None)``."""
    out = p19_clouds(False)
    points, normals, *_, area = sample("sphere", 20_000)
    out["sphere_20k"] = (points, None)
    out["sphere_noise_0.1"] = (noisy(points, normals, area, 0.1), None)
    unit = sample("sphere", 8_000, seed=7)[0]
    out["thin_ellipsoid_3x3x0.15"] = (unit * [3.0, 3.0, 0.15], None)
    ball = sample("sphere", 6_000, seed=11)[0]
    out["two_spheres_0.05"] = (np.concatenate([ball, ball + [2.05, 0.0, 0.0]]), None)
    if large:
        out["torus_1M"] = (sample("torus", 1_000_000)[0], None)
        out["sphere_1M"] = (sample("sphere", 1_000_000)[0], None)
    return out


base.clouds = clouds

if __name__ == "__main__":
    raise SystemExit(base.main())
