"""Time of meshcurv.multiscale_curvatures against the single calls: ``python benchmarks/multiscale.py``.

Three radii ``h, 2h, 4h`` (``h`` the mean edge length) on icospheres, icc:
the multi-scale call against the largest radius alone and against three
separate calls (issue 30's target: at most 1.3 times the largest alone). Each
figure is the median of ``--repeats`` calls after a warm-up call (numba's
compilation not counted); wall and CPU seconds.

    python benchmarks/multiscale.py --sizes 100k,1M --repeats 3
"""

from __future__ import annotations

import argparse
import os
import time
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes

SIZES = {"10k": 32, "100k": 100, "1M": 316}  # icosphere subdivisions: 10 n^2 + 2 vertices


def timed(call, repeats):
    call()  # warm-up: compilation, caches
    walls, cpus = [], []
    for _ in range(repeats):
        wall, cpu = time.perf_counter(), time.process_time()
        call()
        walls.append(time.perf_counter() - wall)
        cpus.append(time.process_time() - cpu)
    return float(np.median(walls)), float(np.median(cpus))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100k")
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
    print(
        f"meshcurv {meshcurv.__version__}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; "
        f"median of {args.repeats} calls, wall s (CPU s)\n"
    )
    print("| vertices | icc at 4h alone | 3 calls h, 2h, 4h | multiscale h, 2h, 4h | multiscale / 4h alone |")
    print("|--:|--:|--:|--:|--:|")
    for size in args.sizes.split(","):
        sphere = shapes.icosphere(SIZES[size])
        v, f = sphere.vertices, sphere.faces
        h = meshcurv.geometry.mean_edge_length(v, meshcurv.MeshTopology.from_faces(f).edges)
        radii = [h, 2 * h, 4 * h]
        alone = timed(lambda: meshcurv.principal_curvatures(v, f, radius=4 * h), args.repeats)
        separate = timed(lambda: [meshcurv.principal_curvatures(v, f, radius=r) for r in radii], args.repeats)
        multi = timed(lambda: meshcurv.multiscale_curvatures(v, f, radii), args.repeats)
        print(
            f"| {v.shape[0]:,} | {alone[0]:.3f} ({alone[1]:.2f}) | {separate[0]:.3f} ({separate[1]:.2f}) | "
            f"{multi[0]:.3f} ({multi[1]:.2f}) | {multi[0] / alone[0]:.2f}x ({multi[1] / alone[1]:.2f}x) |"
        )


if __name__ == "__main__":
    main()
