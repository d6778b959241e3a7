"""CPU of the cloud's nearest-neighbour search and registration-error sample on a million points (issue 29, K24).

The k-NN rows take or drop a group tied at the cut (one neighbour more searched) and the registration error is
read on an intrinsic sample (keyed by each point's spacing) instead of one spread over the Morton order. Run it
against two trees for a paired comparison::

    PYTHONPATH=<tree>/src python benchmarks/knn_ties_K24.py

Prints the CPU seconds (``time.process_time``: every thread) of ``pointcloud._knn`` and of
``pointcloud._registration_gap`` on 1M points of a noisy unit sphere (in the pipeline's Morton order).
"""

from __future__ import annotations

import argparse
import time

import numpy as np


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--n", type=int, default=1_000_000, help="points of the cloud")
    args = parser.parse_args(argv)

    from scipy.spatial import cKDTree

    from meshcurv import pointcloud

    rng = np.random.default_rng(0)
    unit = rng.normal(size=(args.n, 3))
    unit /= np.linalg.norm(unit, axis=1, keepdims=True)
    points = unit * (1.0 + 0.05 * np.sqrt(4 * np.pi / args.n) * rng.normal(size=(args.n, 1)))
    points = points[pointcloud._spatial_order(points)[0]]
    tree = cKDTree(points)
    pointcloud._knn(tree, points[: pointcloud.KNN_GRID_POINTS + 1])  # (compiles the kernels)
    started = time.process_time()
    distances, _ = pointcloud._knn(tree, points)
    knn = time.process_time() - started
    started = time.process_time()
    if pointcloud._registration_gap.__code__.co_argcount == 3:
        pointcloud._registration_gap(tree, points, distances)
    else:  # (the code before K24)
        pointcloud._registration_gap(tree, points)
    gap = time.process_time() - started
    print(f"knn {knn:.3f} s registration_gap {gap:.3f} s")


if __name__ == "__main__":
    main()
