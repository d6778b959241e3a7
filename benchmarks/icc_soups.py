"""icc on fine soups and half-detached shapes (issue 29, fuzz 395/99): ``python benchmarks/icc_soups.py``.

Each case is a fine closed shape with a share of its faces given corners of their own, each moved ``gap`` mean
edge lengths in a random direction (``benchmarks/fuzz_api.py``'s ``_detach``), measured by ``icc`` (its default,
or a given radius in edge lengths) and compared with the clean shape's ``icc`` at the nearest clean vertex, as the
fuzzer's detached relation does: a valid vertex is *off* when its H differs by more than half of the clean
shape's largest |k|. Prints one row per case: valid vertices, off ones, the largest error, the share of the
vertices undefined (the scattered pieces among them), and the CPU time of the call.
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
from meshcurv.result import INVALID_REASONS

from fuzz_api import _detach as detach  # (python benchmarks/icc_soups.py: its folder on the path)

TOLERANCE = 0.5


def bases() -> dict:
    """The fine closed shapes, by name (as ``benchmarks/fuzz_api.py --fine-cracks`` draws them, and a few more)."""
    return {
        "icosphere_12": lambda: shapes.icosphere(subdivisions=12),
        "icosphere_16": lambda: shapes.icosphere(subdivisions=16),
        "icosphere_24": lambda: shapes.icosphere(subdivisions=24),
        "icosphere_40": lambda: shapes.icosphere(subdivisions=40),
        "uv_sphere": lambda: shapes.uv_sphere(n_longitude=64, n_latitude=32),
        "ellipsoid_16": lambda: shapes.ellipsoid(subdivisions=16),
        "ellipsoid_24": lambda: shapes.ellipsoid(subdivisions=24),
        "voxel_sphere_10": lambda: shapes.voxel_sphere(radius=10.0),
        "voxel_sphere_6": lambda: shapes.voxel_sphere(radius=6.0),
        "voxel_torus": lambda: shapes.voxel_torus(),
    }


def run_case(name, share, gap, seed, *, inward=False, radius_edges=None):
    """One row: ``(valid in both, off, largest error, undefined, cpu)``."""
    mesh = bases()[name]()
    vertices, faces = np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)
    if inward:
        faces = faces[:, [0, 2, 1]]
    edge = float(np.mean(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)))
    options = {"method": "icc"}
    if radius_edges is not None:
        options["radius"] = radius_edges * edge
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        clean = meshcurv.principal_curvatures(vertices, faces, **options)
        soup_vertices, soup_faces = detach(np.random.default_rng(seed), vertices, faces, share, gap)
        start = time.process_time()
        result = meshcurv.principal_curvatures(soup_vertices, soup_faces, **options)
        cpu = time.process_time() - start
    nearest = cKDTree(vertices).query(soup_vertices)[1]
    both = result.valid & clean.valid[nearest]
    size = max(np.abs(clean.k_min[clean.valid]).max(), np.abs(clean.k_max[clean.valid]).max())
    error = np.abs(result.mean[both] - clean.mean[nearest][both]) / size
    undefined = int((result.invalid_reason == len(INVALID_REASONS) - 1).sum())  # (the scattered pieces among them)
    return int(both.sum()), int((error > TOLERANCE).sum()), float(error.max(initial=0.0)), undefined, cpu


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bases", default="icosphere_24", help="comma-separated names of bases()")
    parser.add_argument("--shares", default="1.0,0.5")
    parser.add_argument("--gaps", default="0.03,0.06,0.1,0.15")
    parser.add_argument("--seeds", default="0")
    parser.add_argument("--radius", type=float, default=None, help="a given radius in mean edge lengths")
    parser.add_argument("--windings", default="out,in")
    options = parser.parse_args(argv)
    print("| base | winding | share | gap | seed | valid | off | largest | undefined | CPU s |")
    print("|---|---|--:|--:|--:|--:|--:|--:|--:|--:|")
    grid = itertools.product(
        options.bases.split(","),
        options.windings.split(","),
        map(float, options.shares.split(",")),
        map(float, options.gaps.split(",")),
        map(int, options.seeds.split(",")),
    )
    for name, winding, share, gap, seed in grid:
        valid, off, largest, scatter, cpu = run_case(
            name, share, gap, seed, inward=winding == "in", radius_edges=options.radius
        )
        cells = [name, winding, f"{share:g}", f"{gap:g}", seed, valid, off, f"{largest:.3g}", scatter, f"{cpu:.2f}"]
        print("| " + " | ".join(map(str, cells)) + " |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
