"""``benchmarks/pointcloud_equal_P22.py`` with the vertices of ``../shared/meshes/nefertiti.obj`` read as a cloud.

Every field of ``point_cloud_curvatures`` (both methods) on P19's and P22's clouds (a torus of 100k points, a
sphere under noise of 0.1 spacings, ...) and on nefertiti's 49,971 vertices, saved to compare two trees to the
bit; ``--large`` adds a 1M-point torus and a 1M-point sphere.

Usage::

    PYTHONPATH=<tree>/src python benchmarks/pointcloud_equal_P23.py --out before.npz [--backend numpy] [--large]
    python benchmarks/pointcloud_equal_P23.py --compare before.npz after.npz
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

import pointcloud_equal_P19 as base  # noqa: E402
import pointcloud_equal_P22 as p22  # noqa: E402

NEFERTITI = Path(__file__).resolve().parents[2] / "shared" / "meshes" / "nefertiti.obj"


def clouds(large: bool):
    """P22's clouds and nefertiti's vertices: ``name -> (points, normals or None)``."""
    from meshcurv.io import read_mesh

    out = p22.clouds(large)
    out["nefertiti_vertices"] = (read_mesh(NEFERTITI)[0], None)
    return out


base.clouds = clouds

if __name__ == "__main__":
    raise SystemExit(base.main())
