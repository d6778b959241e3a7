"""Every method at its default on meshes whose faces are detached near the crack weld's tolerance (issue 29, W31).

A share of the faces given corners of their own, each moved ``gap`` mean edge lengths in a random direction (the
fuzzer's ``_detach``), then measured by each method at its default. For each shape, share, gap and seed it prints
the weld's selection (of the cracks' sides, the share welded back among the shorter and the longer half of them:
a weld that follows the local length scale closes both alike) and, per method, the valid vertices, those whose H
is off the exact one by more than half (and a quarter) of the shape's largest ``|k|`` (the fuzzer's bar,
``DETACHED_TOLERANCE``), and the median error of H at the valid vertices over that ``|k|``. Issue 29, fuzz 602/100
(the 64 x 32 uv sphere half detached by 0.048: the weld closed the quads' diagonals only) and 647/28
(``voxel_sphere(10)`` a fifth detached by 0.045).

    python benchmarks/crack_weld_W31.py [--shapes uv,voxel10,torus] [--methods icc,normal_cycle_ball] [--seeds 0]

Tuned on ``uv``, ``voxel10`` and ``torus`` (the failing families); ``ico``, ``ellipsoid``, ``cylinder``,
``voxel_ellipsoid`` and ``random`` held out. Run it on two source trees (``PYTHONPATH=<tree>/src``) to compare them.
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import meshcurv
from meshcurv import MeshTopology, shapes
from meshcurv.weld import weld_vertices
from ncb_crack_bias_C30 import detached

SHAPES = {
    "uv": lambda: shapes.uv_sphere(n_longitude=64, n_latitude=32),
    "voxel10": lambda: shapes.voxel_sphere(10.0),
    "torus": lambda: shapes.torus(3.0, 1.0, 96, 32),
    "ico": lambda: shapes.icosphere(24),
    "ellipsoid": lambda: shapes.ellipsoid((3.0, 2.0, 1.0), subdivisions=24),
    "cylinder": lambda: shapes.cylinder(1.0, 8.0, 64, 16),
    "voxel_ellipsoid": lambda: shapes.voxel_ellipsoid((10.0, 7.0, 5.0)),
    "random": lambda: shapes.random_sphere(4000, seed=1),
}
METHODS = ("icc", "normal_cycle", "normal_cycle_ball", "quadric", "matgeom", "meyer", "rusinkiewicz")
GAPS = (0.02, 0.035, 0.045, 0.048, 0.055)
SHARES = (0.2, 0.5, 1.0)


def welded_by_length(vertices, faces) -> tuple[float, float]:
    """The share of the cracks' sides (the boundary edges) welded back, among the shorter and the longer half."""
    topology = MeshTopology.from_faces(faces, len(vertices))
    welding = weld_vertices(vertices, topology)
    sides = topology.edges[topology.boundary_edges]
    if not sides.size:
        return float("nan"), float("nan")
    lengths = np.linalg.norm(vertices[sides[:, 0]] - vertices[sides[:, 1]], axis=1)
    after = np.sort(welding.index[sides], axis=1)
    interior = welding.topology.edges[welding.topology.edge_face_counts == 2]
    n = len(welding.vertices) + 1
    closed = np.isin(after[:, 0] * n + after[:, 1], np.sort(interior, axis=1) @ [n, 1])
    short = lengths <= np.median(lengths)
    return float(closed[short].mean()), float(closed[~short].mean()) if (~short).any() else float("nan")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shapes", default="uv,voxel10,torus")
    parser.add_argument("--methods", default=",".join(METHODS))
    parser.add_argument("--seeds", default="0")
    parser.add_argument("--shares", default=",".join(f"{s:g}" for s in SHARES))
    parser.add_argument("--gaps", default=",".join(f"{g:g}" for g in GAPS))
    args = parser.parse_args(argv)
    methods = args.methods.split(",")
    totals = {m: np.zeros(3, dtype=np.int64) for m in methods}
    start = time.process_time()
    for name in args.shapes.split(","):
        mesh = SHAPES[name]()
        exact = 0.5 * (mesh.k_min + mesh.k_max)
        largest = float(np.max(np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))))
        for share in (float(s) for s in args.shares.split(",")):
            for gap in (float(g) for g in args.gaps.split(",")):
                for seed in (int(s) for s in args.seeds.split(",")):
                    vertices, faces, source = detached(mesh.vertices, mesh.faces, share, gap, seed)
                    short, long = welded_by_length(vertices, faces)
                    print(
                        f"{name:15s} share {share:<4g} gap {gap:<6g} seed {seed} | welded short {short:.2f} long {long:.2f}"
                    )
                    for method in methods:
                        with warnings.catch_warnings():
                            warnings.simplefilter("ignore")
                            result = meshcurv.principal_curvatures(vertices, faces, method=method)
                        valid = result.valid
                        mean = result.mean[valid]
                        truth = exact[source[valid]]
                        side = np.sign(np.median(mean * truth)) if mean.size else 1.0  # either winding
                        error = np.abs(side * mean - truth) / largest
                        counts = np.array([valid.sum(), (error > 0.5).sum(), (error > 0.25).sum()])
                        totals[method] += counts
                        median = float(np.median(error)) if error.size else float("nan")
                        print(
                            f"    {method:18s} valid {counts[0]:6d} off>0.5 {counts[1]:5d} off>0.25 {counts[2]:5d} "
                            f"median {median:.3f}",
                            flush=True,
                        )
    for method in methods:
        valid, half, quarter = totals[method].tolist()
        print(f"total {method:18s} valid {valid}, off by > 0.5 of the largest |k| {half}, > 0.25 {quarter}")
    print(f"CPU {time.process_time() - start:.1f} s")


if __name__ == "__main__":
    main()
