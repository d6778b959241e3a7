"""``benchmarks/pointcloud_equal_P23.py`` with voxel clouds (points at one distance: the ball cuts' ties) added.

Every field of ``point_cloud_curvatures`` (both methods) on P23's clouds (a torus of 100k points, a sphere under
noise, nefertiti's vertices, ...) and on the vertices of a voxel sphere and a voxel torus, as given and turned by a
rotation, saved to compare two trees to the bit (issue 31: the measures' balls searched, cut and turned in one
pass, ``pointcloud.measured_balls``).

Usage::

    PYTHONPATH=<tree>/src python benchmarks/pointcloud_equal_B26.py --out before.npz [--backend numpy] [--large]
    python benchmarks/pointcloud_equal_B26.py --compare before.npz after.npz
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

import pointcloud_equal_P19 as base  # noqa: E402
import pointcloud_equal_P23 as p23  # noqa: E402

P23_CLOUDS = p23.clouds


def clouds(large: bool):
    """P23's clouds and voxel clouds, as given and turned: ``name -> (points, normals or None)``."""
    from scipy.spatial.transform import Rotation

    from meshcurv import shapes

    out = P23_CLOUDS(large)
    turn = Rotation.from_rotvec([0.3, -0.5, 0.7]).as_matrix()
    for name, mesh in (("voxel_sphere_14", shapes.voxel_sphere(14.0)), ("voxel_torus", shapes.voxel_torus(8.0, 3.0))):
        points = np.asarray(mesh.vertices, dtype=np.float64)
        out[name] = (points, None)
        out[f"{name}_turned"] = (points @ turn.T, None)
    return out


base.clouds = clouds

if __name__ == "__main__":
    raise SystemExit(base.main())
