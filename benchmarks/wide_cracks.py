"""Faces detached by cracks wider than the weld: valid vertices off the exact sphere (issue 29, fuzz round 18).

A share of a unit sphere's faces get corners of their own, moved ``--gap`` mean edge lengths in random
directions: two of them (``hanging``: the face keeps one corner, a bow-tie vertex) or all three
(``detached``). For each method and radius the table gives the valid vertices and those whose H is off
the exact 1 by more than half the curvature (the fuzzer's bar), summed over the seeds, and the largest
``|H - 1|``; ``clean``: the sphere itself (its own errors, counted once a seed). Run it on a snapshot (``PYTHONPATH=<snapshot>/src``) to compare two commits.

    python benchmarks/wide_cracks.py [--seeds 6] [--share 0.2] [--gap 0.1]
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes


def moved_corners(vertices, faces, share: float, gap: float, seed: int, *, keep_one: bool):
    """``(vertices, faces)`` with ``share`` of the faces given corners of their own (all three, or all but one
    kept at random), moved ``gap`` mean edge lengths in random directions; the copies after the vertices."""
    rng = np.random.default_rng(seed)
    edge = float(np.mean(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)))
    picked = np.flatnonzero(rng.random(len(faces)) < share)
    moved = np.ones((picked.size, 3), dtype=bool)
    if keep_one:
        moved[np.arange(picked.size), rng.integers(3, size=picked.size)] = False
    rows, columns = np.nonzero(moved)
    corners = faces[picked[rows], columns]
    directions = rng.normal(size=(corners.size, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    faces = faces.copy()
    faces[picked[rows], columns] = len(vertices) + np.arange(corners.size)
    return np.concatenate([vertices, vertices[corners] + gap * edge * directions]), faces


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=6)
    parser.add_argument("--share", type=float, default=0.2, help="share of the faces moved")
    parser.add_argument("--gap", type=float, default=0.1, help="the corners' move, in mean edge lengths")
    options = parser.parse_args(argv)
    meshes = {
        "icosphere(8)": shapes.icosphere(8),
        "random_sphere(500)": shapes.random_sphere(500),
        "random_sphere(642)": shapes.random_sphere(642),
    }
    calls = [("rusinkiewicz", None)] + [("quadric", edges) for edges in (None, 1.5, 2.2, 3.0)]
    print("| mesh | faces | method | radius (edges) | valid | off > 0.5 | max abs(H - 1) |")
    print("|---|---|---|--:|--:|--:|--:|")
    for name, mesh in meshes.items():
        edge = float(
            np.median(np.linalg.norm(mesh.vertices[mesh.faces[:, 0]] - mesh.vertices[mesh.faces[:, 1]], axis=1))
        )
        for kind in ("clean", "hanging", "detached"):
            for method, edges in calls:
                valid = off = 0
                largest = 0.0
                for seed in range(options.seeds):
                    share = 0.0 if kind == "clean" else options.share  # clean: the same mesh each seed
                    vertices, faces = moved_corners(
                        mesh.vertices, mesh.faces, share, options.gap, seed, keep_one=kind == "hanging"
                    )
                    radius = None if edges is None else edges * edge
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        result = meshcurv.principal_curvatures(vertices, faces, method=method, radius=radius)
                    error = np.abs(result.mean[result.valid] - 1.0)
                    valid += int(result.valid.sum())
                    off += int((error > 0.5).sum())
                    largest = max(largest, float(error.max(initial=0.0)))
                shown = "default" if edges is None else f"{edges:g}"
                print(f"| {name} | {kind} | {method} | {shown} | {valid} | {off} | {largest:.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
