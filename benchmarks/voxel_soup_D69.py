"""icc on voxel soups (issue 29, fuzz 750/289): ``python benchmarks/voxel_soup_D69.py [--set tune|held-out|smooth]``.

Each case is a closed shape with a share of its faces given corners of their own, each moved ``gap`` mean edge
lengths in a random direction (``benchmarks/fuzz_api.py``'s ``_detach``), in either winding, measured by ``icc`` at
its default with ``orient="consistent"`` and compared with the clean shape's estimate with the same options at the
nearest clean vertex, as the fuzzer's detached relation does: a valid vertex is *off* when its H differs by more
than half of the clean shape's largest ``|k|``. Prints one row per case (valid vertices in both, off ones, the
largest error, the CPU seconds of the call) and the totals. Run it with ``PYTHONPATH`` on the tree to measure.
"""

from __future__ import annotations

import argparse
import itertools
import time
import warnings

import numpy as np
from scipy.spatial import cKDTree

import meshcurv
from meshcurv import shapes

from fuzz_api import _detach as detach  # (python benchmarks/voxel_soup_D69.py: its folder on the path)

TOLERANCE = 0.5

SETS = {
    # (bases, shares, gaps, seeds): the draws the rule was set on
    "tune": (("voxel_sphere_10", "voxel_sphere_6"), (1.0, 0.5), (0.031, 0.045), (0, 3)),
    # other shapes, gaps and seeds
    "held-out": (("voxel_sphere_8", "voxel_torus", "voxel_ellipsoid"), (1.0, 0.5), (0.025, 0.035), (5,)),
    # soups of smooth meshes: the voxel soup's rule must not read them
    "smooth": (("uv_sphere_12x8", "icosphere_4", "icosphere_12", "ellipsoid_16"), (1.0, 0.5), (0.031, 0.065), (5,)),
}


def bases() -> dict:
    return {
        "voxel_sphere_10": lambda: shapes.voxel_sphere(radius=10.0),
        "voxel_sphere_8": lambda: shapes.voxel_sphere(radius=8.0),
        "voxel_sphere_6": lambda: shapes.voxel_sphere(radius=6.0),
        "voxel_torus": lambda: shapes.voxel_torus(),
        "voxel_ellipsoid": lambda: shapes.voxel_ellipsoid(),
        "uv_sphere_12x8": lambda: shapes.uv_sphere(n_longitude=12, n_latitude=8),
        "icosphere_4": lambda: shapes.icosphere(subdivisions=4),
        "icosphere_12": lambda: shapes.icosphere(subdivisions=12),
        "ellipsoid_16": lambda: shapes.ellipsoid(subdivisions=16),
    }


def _icc(vertices, faces):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return meshcurv.principal_curvatures(vertices, faces, method="icc", orient="consistent")


def run_case(vertices, faces, clean, share, gap, seed):
    """One row: ``(valid in both, off, largest error, cpu)``."""
    soup_vertices, soup_faces = detach(np.random.default_rng(seed), vertices, faces, share, gap)
    start = time.process_time()
    result = _icc(soup_vertices, soup_faces)
    cpu = time.process_time() - start
    nearest = cKDTree(vertices).query(soup_vertices)[1]
    both = result.valid & clean.valid[nearest]
    size = max(np.abs(clean.k_min[clean.valid]).max(), np.abs(clean.k_max[clean.valid]).max())
    error = np.abs(result.mean - clean.mean[nearest])[both] / size
    return int(both.sum()), int((error > TOLERANCE).sum()), float(error.max(initial=0.0)), cpu


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--set", default="tune", choices=sorted(SETS))
    options = parser.parse_args(argv)
    names, shares, gaps, seeds = SETS[options.set]
    print("| base | winding | share | gap | seed | valid | off | largest | CPU s |")
    print("|---|---|--:|--:|--:|--:|--:|--:|--:|")
    totals = np.zeros(3)
    for name in names:
        mesh = bases()[name]()
        vertices, given = np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)
        for winding in ("given", "reversed"):
            faces = given if winding == "given" else given[:, ::-1]
            clean = _icc(vertices, faces)
            for share, gap, seed in itertools.product(shares, gaps, seeds):
                valid, off, largest, cpu = run_case(vertices, faces, clean, share, gap, seed)
                totals += (valid, off, cpu)
                print(
                    f"| {name} | {winding} | {share:g} | {gap:g} | {seed} | {valid} | {off} | {largest:.3f} | {cpu:.2f} |"
                )
    print(f"\ntotal: {int(totals[0])} valid, {int(totals[1])} off, {totals[2]:.1f} CPU s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
