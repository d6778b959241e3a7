"""Rims on tight bends and voxel staircases with detached faces: valid vertices off the exact shape (issue 29).

Two classes of the fuzzer's wide cracks (``fuzz_api.py --wide-cracks 1``), on analytic shapes with exact
curvatures (``meshcurv.shapes``):

- ``rusinkiewicz`` on the lower half of a coarse ellipsoid (3, 2, 1) (its rim on the equator, where the
  radius of curvature across the rim is one or two edges) and on the ellipsoid of 252 vertices with half of
  its faces detached by a tenth of an edge (fuzz 402/396);
- ``normal_cycle_ball`` on a voxel sphere of radius 4 with half of its faces detached by 0.06 voxels (fuzz
  480/968).

For each mesh the table gives the valid vertices, those whose H is off the exact one by more than half the
largest exact |k| (the fuzzer's bar), the largest such error, and for the rims the largest angle between the
result's normal and the exact one, summed over the seeds. Run it on a snapshot (``PYTHONPATH=<snapshot>/src``)
to compare two commits.

    python benchmarks/wide_cracks_bends.py [--seeds 4]
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes


def half_detached(mesh, seed: int, gap: float):
    """``(vertices, faces, source)``: half of the faces given three corners of their own, each moved ``gap``
    mean edge lengths in a random direction; vertex ``i`` copies vertex ``source[i]``."""
    rng = np.random.default_rng(seed)
    sides = mesh.vertices[mesh.faces[:, 1]] - mesh.vertices[mesh.faces[:, 0]]
    step = gap * float(np.mean(np.linalg.norm(sides, axis=1)))
    picked = rng.random(len(mesh.faces)) < 0.5
    n = len(mesh.vertices)
    source = np.concatenate([np.arange(n), mesh.faces[picked].ravel()])
    offsets = rng.normal(size=(source.size - n, 3))
    offsets *= step / np.linalg.norm(offsets, axis=1, keepdims=True)
    faces = mesh.faces.copy()
    faces[picked] = np.arange(n, source.size).reshape(-1, 3)
    return np.concatenate([mesh.vertices, mesh.vertices[source[n:]] + offsets]), faces, source


def row(name: str, method: str, runs) -> str:
    """One table row over ``runs``: ``(mesh, vertices, faces, source)`` each."""
    valid = off = 0
    largest = angle = 0.0
    for mesh, vertices, faces, source in runs:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = meshcurv.principal_curvatures(vertices, faces, method=method)
        exact = ((mesh.k_min + mesh.k_max) / 2)[source]
        scale = float(np.max(np.abs(np.concatenate([mesh.k_min, mesh.k_max]))))
        error = np.abs(result.mean - exact)[result.valid] / scale
        cosines = np.einsum("ij,ij->i", result.normals, mesh.normals[source])[result.valid]
        valid += int(result.valid.sum())
        off += int((error > 0.5).sum())
        largest = max(largest, float(error.max(initial=0.0)))
        angle = max(angle, float(np.degrees(np.arccos(np.clip(cosines, -1.0, 1.0))).max(initial=0.0)))
    return f"| {name} | {method} | {valid} | {off} | {largest:.2f} | {angle:.1f} |"


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=4)
    options = parser.parse_args(argv)
    print("| mesh | method | valid | off > 0.5 | max abs(H - exact) / max abs(k) | max normal angle (deg) |")
    print("|---|---|--:|--:|--:|--:|")
    for subdivisions in (4, 5, 6, 8):
        mesh = shapes.ellipsoid(subdivisions=subdivisions)
        lower = mesh.faces[mesh.vertices[mesh.faces].mean(axis=1)[:, 2] < 0]
        runs = [(mesh, mesh.vertices, lower, np.arange(len(mesh.vertices)))]
        print(row(f"ellipsoid({subdivisions}) lower half", "rusinkiewicz", runs), flush=True)
    mesh = shapes.ellipsoid(subdivisions=5)
    runs = [(mesh, *half_detached(mesh, seed, 0.1)) for seed in range(options.seeds)]
    print(row("ellipsoid(5) half detached by 0.1", "rusinkiewicz", runs), flush=True)
    mesh = shapes.voxel_sphere(4.0)
    runs = [(mesh, *half_detached(mesh, seed, 0.06)) for seed in range(options.seeds)]
    print(row("voxel_sphere(4) half detached by 0.06", "normal_cycle_ball", runs), flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
