"""The ring methods on fine soups (issue 29): ``python benchmarks/ring_soups.py``.

``meyer``, ``rusinkiewicz`` and ``normal_cycle`` at their defaults on a fine closed shape with a share of its faces
given corners of their own, each moved ``gap`` mean edge lengths in a random direction (the fuzzer's
``--wide-cracks --fine-cracks`` families), compared with the same method on the clean shape at the nearest clean
vertex, as ``benchmarks/icc_soups.py`` does for ``icc``: a valid vertex is *off* when its H differs by more than half
of the clean shape's largest |k|. Where the clean shape is undefined (a voxel sphere: the ring methods refuse its
staircase), against the sphere's H = 1 / radius (outward: the default orientation). One row per case: valid vertices (valid on the clean shape too), off ones, the
largest error, the vertices invalid, the CPU time of the call.
"""

from __future__ import annotations

import argparse
import itertools
import time
import warnings

import numpy as np
from scipy.spatial import cKDTree

import meshcurv

from fuzz_api import _detach as detach  # (python benchmarks/ring_soups.py: its folder on the path)
from icc_soups import TOLERANCE, bases


def run_case(method, name, share, gap, seed, *, inward=False):
    """One row: ``(valid (in both), off, largest error, invalid, cpu)``."""
    mesh = bases()[name]()
    vertices, faces = np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)
    if inward:
        faces = faces[:, [0, 2, 1]]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        clean = meshcurv.principal_curvatures(vertices, faces, method=method)
        soup_vertices, soup_faces = detach(np.random.default_rng(seed), vertices, faces, share, gap)
        start = time.process_time()
        result = meshcurv.principal_curvatures(soup_vertices, soup_faces, method=method)
        cpu = time.process_time() - start
    nearest = cKDTree(vertices).query(soup_vertices)[1]
    if name.startswith("voxel_sphere_"):  # the truth
        truth = 1.0 / float(name.rsplit("_", 1)[1])
        both, size, expected = result.valid, truth, np.full(len(soup_vertices), truth)
    else:
        both = result.valid & clean.valid[nearest]  # (a voxel torus: undefined on the clean shape, none compared)
        size = max(np.abs(clean.k_min[clean.valid]).max(initial=0), np.abs(clean.k_max[clean.valid]).max(initial=0))
        expected = clean.mean[nearest]
    error = np.abs(result.mean[both] - expected[both]) / size
    return (
        int(both.sum()),
        int((error > TOLERANCE).sum()),
        float(error.max(initial=0.0)),
        int((~result.valid).sum()),
        cpu,
    )


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    defaults = {  # comma-separated lists; bases: names of icc_soups.bases()
        "methods": "meyer,rusinkiewicz,normal_cycle",
        "bases": "voxel_sphere_10",
        "windings": "out,in",
        "shares": "1.0,0.5",
        "gaps": "0.03,0.06,0.1",
        "seeds": "0",
    }
    for name, default in defaults.items():
        parser.add_argument(f"--{name}", default=default)
    options = vars(parser.parse_args(argv))
    kinds = {"shares": float, "gaps": float, "seeds": int}
    lists = [[kinds.get(name, str)(item) for item in options[name].split(",")] for name in defaults]
    print("| method | base | winding | share | gap | seed | valid | off | largest | invalid | CPU s |")
    print("|---|---|---|--:|--:|--:|--:|--:|--:|--:|--:|")
    grid = itertools.product(*lists)
    for method, name, winding, share, gap, seed in grid:
        valid, off, largest, invalid, cpu = run_case(method, name, share, gap, seed, inward=winding == "in")
        cells = [method, name, winding, f"{share:g}", f"{gap:g}", seed, valid, off, f"{largest:.3g}", invalid]
        print("| " + " | ".join(map(str, cells)) + f" | {cpu:.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
