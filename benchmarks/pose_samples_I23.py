"""CPU of the default estimates on a million vertices or points, and their noise levels (issue 29, I23).

The samples behind the default radii (``radius._intrinsic_sample``, icc's median edge over every edge) are
chosen by an intrinsic key; this times the calls they serve. Run it against two trees for a paired comparison::

    PYTHONPATH=<tree>/src python benchmarks/pose_samples_I23.py --mesh    # 1M-vertex icosphere, principal_curvatures
    PYTHONPATH=<tree>/src python benchmarks/pose_samples_I23.py --cloud   # 1M points of a noisy sphere

Prints one line: the CPU seconds of the call (``time.process_time``: every thread), the radius and the noise level.
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", action="store_true", help="principal_curvatures on icosphere(316)")
    parser.add_argument("--cloud", action="store_true", help="point_cloud_curvatures on 1M points")
    parser.add_argument("--n", type=int, default=1_000_000, help="points of the cloud")
    args = parser.parse_args(argv)

    import meshcurv
    from meshcurv import shapes

    if args.mesh:
        mesh = shapes.icosphere(316)
        started = time.process_time()
        result = meshcurv.principal_curvatures(mesh.vertices, mesh.faces)
    else:
        rng = np.random.default_rng(0)
        normals = rng.normal(size=(args.n, 3))
        normals /= np.linalg.norm(normals, axis=1, keepdims=True)
        points = normals * (1.0 + 0.05 * np.sqrt(4 * np.pi / args.n) * rng.normal(size=(args.n, 1)))
        started = time.process_time()
        result = meshcurv.point_cloud_curvatures(points)
    spent = time.process_time() - started
    print(f"cpu {spent:.3f} radius {result.parameters.get('radius')} noise {result.parameters.get('noise')}")


if __name__ == "__main__":
    main()
