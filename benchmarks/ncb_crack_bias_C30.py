"""``normal_cycle_ball`` at its default radius on meshes whose faces are detached near the crack weld's tolerance.

A share of the faces given corners of their own, each moved ``gap`` mean edge lengths in a random direction (the
fuzzer's ``_detach``), then measured at the default radius. For each shape, share, gap and seed it prints the valid
vertices and those whose H is off the exact one by more than half (and a quarter) of the shape's largest ``|k|``
(the fuzzer's bar, ``DETACHED_TOLERANCE``), and the median error of H at the valid vertices. Issue 29, fuzz
602/100: the 64 x 32 uv sphere half detached by 0.048 edges read H 0.42-0.79 for 1 at every valid vertex.

    python benchmarks/ncb_crack_bias_C30.py [--shapes uv,ico,torus,ellipsoid] [--seeds 0,1]

Run it on two source trees (``PYTHONPATH=<tree>/src``) to compare them.
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import meshcurv
from fuzz_api import _detach
from meshcurv import shapes

SHAPES = {
    "uv": lambda: shapes.uv_sphere(n_longitude=64, n_latitude=32),
    "ico": lambda: shapes.icosphere(24),
    "torus": lambda: shapes.torus(3.0, 1.0, 96, 32),
    "ellipsoid": lambda: shapes.ellipsoid((3.0, 2.0, 1.0), subdivisions=24),
}
GAPS = (0.02, 0.035, 0.045, 0.048, 0.055, 0.06, 0.08)
SHARES = (0.2, 0.5, 1.0)


def detached(vertices, faces, share: float, gap: float, seed: int):
    """``(vertices, faces, source)``: a ``share`` of the faces given corners of their own (after the vertices), each
    moved ``gap`` mean edge lengths in a random direction (the fuzzer's ``_detach``); ``source`` the original vertex of
    every row."""
    moved_vertices, moved = _detach(np.random.default_rng(seed), vertices, faces, share, gap)
    picked = moved[:, 0] >= len(vertices)
    return moved_vertices, moved, np.concatenate([np.arange(len(vertices)), faces[picked].ravel()])


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shapes", default="uv,ico,torus,ellipsoid")
    parser.add_argument("--seeds", default="0,1")
    parser.add_argument("--shares", default=",".join(f"{s:g}" for s in SHARES))
    parser.add_argument("--gaps", default=",".join(f"{g:g}" for g in GAPS))
    args = parser.parse_args(argv)
    seeds = [int(s) for s in args.seeds.split(",")]
    totals = {"valid": 0, "off_half": 0, "off_quarter": 0}
    start = time.process_time()
    for name in args.shapes.split(","):
        mesh = SHAPES[name]()
        exact = mesh.mean
        largest = float(np.max(np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))))
        for share in (float(s) for s in args.shares.split(",")):
            for gap in (float(g) for g in args.gaps.split(",")):
                row = []
                for seed in seeds:
                    vertices, faces, source = detached(mesh.vertices, mesh.faces, share, gap, seed)
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        result = meshcurv.principal_curvatures(vertices, faces, method="normal_cycle_ball")
                    valid = result.valid
                    mean = result.mean[valid]
                    truth = exact[source[valid]]
                    side = np.sign(np.median(mean * truth)) if mean.size else 1.0  # either winding
                    error = np.abs(side * mean - truth) / largest
                    half, quarter = int((error > 0.5).sum()), int((error > 0.25).sum())
                    totals["valid"] += int(valid.sum())
                    totals["off_half"] += half
                    totals["off_quarter"] += quarter
                    median = float(np.median(error)) if error.size else float("nan")
                    row.append(f"{int(valid.sum()):6d} {half:4d} {quarter:4d} {median:.3f}")
                print(f"{name:9s} share {share:<4g} gap {gap:<6g} | " + " | ".join(row), flush=True)
    print(
        f"total: valid {totals['valid']}, off by > 0.5 of the largest |k| {totals['off_half']}, > 0.25 "
        f"{totals['off_quarter']}; CPU {time.process_time() - start:.1f} s"
    )


if __name__ == "__main__":
    main()
