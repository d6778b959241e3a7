"""``quadric`` on fine soups: valid vertices off the truth (issue 29, fuzz 400/78, 690/72, 730/1).

``python benchmarks/quadric_soups_Q69.py [--quick]``: fine closed shapes of :mod:`meshcurv.shapes` with a share of
their faces detached (given corners of their own, each moved a gap of mean edge lengths in a random direction: the
fuzzer's ``_detach``), at the default options and at a given ball, welded as ``principal_curvatures`` welds them.
For each case it prints the share of the vertices valid, the valid vertices whose H is off the exact H (at the
nearest point of the clean shape, whose vertices lie on the surface) by more than 0.5 and 0.35 of the largest
exact ``|k|`` (the fuzzer's bar is 0.5, against the clean mesh's estimate), the median H error over the valid
vertices in that unit and the CPU seconds of the call.
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes

from fuzz_api import _detach  # the fuzzer's detached faces (its draws)


CASES = [  # (shape, share, gap, seed, options)
    ("icosphere(40)", 1.0, 0.096, 0, {}),
    ("icosphere(40)", 1.0, 0.059, 1, {}),
    ("icosphere(40)", 0.5, 0.031, 2, {}),
    ("icosphere(40)", 0.5, 0.045, 3, {}),
    ("icosphere(24)", 1.0, 0.055, 4, {}),
    ("icosphere(24)", 1.0, 0.1, 5, {}),
    ("icosphere(24)", 0.5, 0.035, 6, {}),
    ("ellipsoid(24)", 0.5, 0.038, 7, {}),
    ("ellipsoid(24)", 1.0, 0.07, 8, {}),
    ("uv_sphere(64, 32)", 0.5, 0.05, 9, {}),
    ("icosphere(40)", 1.0, 0.08, 10, {"radius": "3 edges"}),
    ("ellipsoid(24)", 0.5, 0.038, 11, {"radius": "1.3 edges"}),
]


def base(name):
    if name.startswith("icosphere"):
        return shapes.icosphere(int(name[10:-1]))
    if name.startswith("ellipsoid"):
        return shapes.ellipsoid(subdivisions=int(name[10:-1]))
    return shapes.uv_sphere(64, 32)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the first four cases only")
    parser.add_argument("--seeds", type=int, default=1, help="draws per case (seed offsets)")
    args = parser.parse_args(argv)
    print(
        "| shape | detached | gap (edges) | options | seed | valid | off > 0.5 | off > 0.35 | median H error | CPU s |"
    )
    print("|---|--:|--:|---|--:|--:|--:|--:|--:|--:|")
    totals = np.zeros(3, dtype=int)
    for name, share, gap, seed, options in CASES[:4] if args.quick else CASES:
        mesh = base(name)
        vertices, faces = mesh.vertices, mesh.faces
        edge = float(np.mean(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)))
        kwargs = dict(options)
        if "radius" in kwargs:
            kwargs["radius"] = float(kwargs["radius"].split()[0]) * edge
        for draw in range(args.seeds):
            rng = np.random.default_rng(1000 * seed + draw)
            soup, soup_faces = _detach(rng, vertices, faces, share, gap)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                start = time.process_time()
                result = meshcurv.principal_curvatures(soup, soup_faces, method="quadric", **kwargs)
                cpu = time.process_time() - start
            from scipy.spatial import cKDTree

            nearest = cKDTree(vertices).query(soup)[1]
            exact_mean = mesh.mean[nearest]
            size = float(np.max(np.abs(np.concatenate([mesh.k_min, mesh.k_max]))))
            error = np.abs(result.mean - exact_mean)[result.valid] / size
            off = int((error > 0.5).sum()), int((error > 0.35).sum())
            totals += (result.valid.sum(), *off)
            median = float(np.median(error)) if error.size else float("nan")
            print(
                f"| {name} | {share:g} | {gap:g} | {options or 'default'} | {1000 * seed + draw} | "
                f"{result.valid.mean():.1%} | {off[0]} | {off[1]} | {median:.3f} | {cpu:.1f} |",
                flush=True,
            )
    print(f"\ntotal: {totals[0]} valid vertices, {totals[1]} off by more than 0.5, {totals[2]} by more than 0.35")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
