"""The walks of ``multiscale_curvatures``' normal fits alone (issue 30, helper D31): the nested walk of 3, 6 and 12
mean edges (``_kernels/neighborhoods._connected_walk_levels``, one walk of the largest ball that also ranks each
point by the smallest ball it was reached through) against the plain walk of the largest ball
(``_connected_members``, what ``principal_curvatures(radius=4 h)``'s fits walk), over every vertex of an icosphere
of 100,002 vertices, nothing fitted; CPU seconds of one thread, each the best of ``--repeats``::

    python benchmarks/walk_levels_D31.py --repeats 3
"""

from __future__ import annotations

import argparse
import os
import time

import numba as nb
import numpy as np

import meshcurv
from meshcurv import shapes
from meshcurv._kernels.neighborhoods import _connected_members, _connected_walk_levels, _vertex_spans


@nb.njit
def _plain(vertices, indptr, indices, allowed, cutoff, spans):
    n = vertices.shape[0]
    mark = np.full(n, -1, np.int64)
    members, queue = np.empty(n, np.int64), np.empty(n, np.int64)
    total = 0
    for v in range(n):
        total += _connected_members(vertices, indptr, indices, allowed, v, cutoff, mark, v, members, queue, spans)
    return total


@nb.njit
def _levels(vertices, indptr, indices, allowed, cutoffs2, spans):
    n = vertices.shape[0]
    mark = np.full(n, -1, np.int64)
    members = np.empty(n, np.int64)
    walk = (np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n, np.int64), np.empty(n))
    total, inner = 0, 0
    for v in range(n):
        size, n_inner = _connected_walk_levels(
            vertices, indptr, indices, allowed, v, cutoffs2, mark, v, walk, members, spans
        )
        total += size
        inner += n_inner
    return total, inner


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)
    sphere = shapes.icosphere(100)
    vertices = np.ascontiguousarray(sphere.vertices, dtype=np.float64)
    topology = meshcurv.MeshTopology.from_faces(sphere.faces)
    indptr, indices = topology.neighbour_lists
    h = meshcurv.geometry.mean_edge_length(vertices, topology.edges)
    allowed = np.ones(vertices.shape[0], np.bool_)
    spans = _vertex_spans(vertices, indptr, indices)
    cutoffs2 = np.array([3.0 * h, 6.0 * h, 12.0 * h]) ** 2
    best = {"plain": np.inf, "levels": np.inf}
    counts = {}
    for round_ in range(args.repeats + 1):  # the first compiles
        for name in best:
            start = time.process_time()
            if name == "plain":
                counts[name] = _plain(vertices, indptr, indices, allowed, 12.0 * h, spans)
            else:
                counts[name] = _levels(vertices, indptr, indices, allowed, cutoffs2, spans)
            if round_:
                best[name] = min(best[name], time.process_time() - start)
    n = vertices.shape[0]
    print(
        f"plain walk at 12 h: {best['plain']:.3f} CPU s ({counts['plain'] / n:.0f} members a ball); nested walk at 3, "
        f"6, 12 h: {best['levels']:.3f} CPU s ({counts['levels'][0] / n:.0f} members, {counts['levels'][1] / n:.0f} "
        f"within 6 h); load {os.getloadavg()[0]:.1f}"
    )


if __name__ == "__main__":
    main()
