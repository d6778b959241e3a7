"""``quadric``'s valid wrong values (issue 29): the vertices off the exact curvature that it reports as valid.

Run from the repository root::

    python benchmarks/quadric_default_off.py                     # every family, tuning draws
    python benchmarks/quadric_default_off.py --held-out          # the draws not tuned on
    python benchmarks/quadric_default_off.py --families holey --seeds 0 1 2

Families (each at ``method="quadric"``, the default radius unless a radius is named):

- ``holey``: a unit ``shapes.icosphere(40)`` with half of its faces detached (each face given its own three
  corners moved by 0.054 mean edge lengths in random directions: ``tests/test_orient_holey_inward._holey``);
- ``gauss``: sphere (icosphere 8, 16), torus (R 3, r 1; 48 x 16, 96 x 32) and ellipsoid (3, 2, 1) of
  ``benchmarks/accuracy.py``, each vertex moved along its exact normal by Gaussian noise of standard deviation
  0.3 mean edge lengths (``numpy.random.default_rng(seed)``); held out: random_sphere, random_ellipsoid, the
  cylinder, other seeds;
- ``saddle``: ``z = (x^2 - y^2) / 2`` over the unit disc (a triangular lattice of step h, jittered by ``seed``
  inside) and ``shapes.saddle`` (``z = x^2 - y^2`` over ``[-1, 1]^2``; steps 0.1 and 0.05, held out: 0.08 and
  0.125 jittered by 0.3), clean, at a given radius of 1.5 h and at the default.

A vertex is *off* when its H is off the exact one by more than half of the largest exact ``|k|`` at the vertex
(unit sphere: ``|H - 1| > 0.5``). Each row: valid vertices, the valid ones off, their share of the referenced
vertices (cover). The figures are in ``benchmarks/quadric_noise.md``.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings

import numpy as np
from scipy.spatial import Delaunay

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests"))

from test_orient_holey_inward import _holey  # noqa: E402 - the test's own detached half

import meshcurv  # noqa: E402
from meshcurv import shapes  # noqa: E402
from meshcurv.shapes import _implicit  # noqa: E402 - the exact curvatures of a level set

NOISE = 0.3


def _mean_edge(vertices, faces) -> float:
    return float(np.mean(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)))


def _gaussian(mesh, seed):
    edge = _mean_edge(mesh.vertices, mesh.faces)
    t = np.random.default_rng(seed).normal(0.0, NOISE * edge, size=mesh.vertices.shape[0])
    return mesh.vertices + t[:, None] * mesh.normals


def disc_saddle(step: float, seed: int):
    """``z = (x^2 - y^2) / 2`` over the unit disc: a triangular lattice of ``step`` (jittered inside by a fifth of
    it for ``seed`` > 0) and a ring of boundary points; exact curvatures by :func:`meshcurv.shapes._implicit`."""
    rows = np.arange(-1.0, 1.0 + step, step * np.sqrt(3) / 2)
    points = [(x + (i % 2) * step / 2, y) for i, y in enumerate(rows) for x in np.arange(-1.0 - step, 1.0 + step, step)]
    points = np.array(points)
    inside = np.linalg.norm(points, axis=1) < 1.0 - step / 2
    points = points[inside]
    if seed:
        points = points + np.random.default_rng(seed).uniform(-step / 5, step / 5, points.shape)
    count = int(round(2 * np.pi / step))
    angle = np.linspace(0.0, 2 * np.pi, count, endpoint=False)
    points = np.concatenate([points, np.stack([np.cos(angle), np.sin(angle)], axis=1)])
    faces = Delaunay(points).simplices
    x, y = points.T
    vertices = np.stack([x, y, (x**2 - y**2) / 2], axis=1)
    gradient = np.stack([-x, y, np.ones_like(x)], axis=1)
    hessian = np.zeros((x.size, 6))
    hessian[:, 0], hessian[:, 1] = -1.0, 1.0
    k_min, k_max, *_ = _implicit(vertices, gradient, hessian)
    return vertices, faces.astype(np.int64), k_min, k_max


def count(vertices, faces, k_min, k_max, radius=None):
    """``(valid, off, cover, largest error)`` of quadric on the mesh (exact ``k_min``, ``k_max`` per vertex)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = meshcurv.principal_curvatures(vertices, faces, method="quadric", radius=radius)
    referenced = np.zeros(len(vertices), dtype=bool)
    referenced[faces.ravel()] = True
    scale = np.maximum(np.abs(k_min), np.abs(k_max))
    error = np.abs(result.mean - (k_min + k_max) / 2) / scale
    valid = result.valid & referenced
    off = valid & (error > 0.5)
    worst = float(error[valid].max()) if valid.any() else np.nan
    return int(valid.sum()), int(off.sum()), valid.sum() / referenced.sum(), worst


def rows(family, seeds, held_out):
    if family == "holey":
        sphere = shapes.icosphere(40)
        for seed in seeds:
            vertices, faces = _holey(sphere.vertices, sphere.faces, seed=seed, detach=True)
            ones = np.ones(len(vertices))
            yield f"holey icosphere(40) seed {seed}", count(vertices, faces, ones, ones)
    elif family == "gauss":
        builds = (
            [
                ("random_sphere(2562)", lambda s: shapes.random_sphere(2562, seed=s)),
                ("random_ellipsoid(2562)", lambda s: shapes.random_ellipsoid((3.0, 2.0, 1.0), 2562, seed=s)),
                ("cylinder(48 x 32)", lambda s: shapes.cylinder(1.0, 4.0, 48, 32)),
                ("icosphere(24)", lambda s: shapes.icosphere(24)),
                ("torus(64 x 24)", lambda s: shapes.torus(3.0, 1.0, 64, 24)),
            ]
            if held_out
            else [
                ("icosphere(8)", lambda s: shapes.icosphere(8)),
                ("icosphere(16)", lambda s: shapes.icosphere(16)),
                ("torus(48 x 16)", lambda s: shapes.torus(3.0, 1.0, 48, 16)),
                ("torus(96 x 32)", lambda s: shapes.torus(3.0, 1.0, 96, 32)),
                ("ellipsoid(8)", lambda s: shapes.ellipsoid((3.0, 2.0, 1.0), 8)),
                ("ellipsoid(16)", lambda s: shapes.ellipsoid((3.0, 2.0, 1.0), 16)),
            ]
        )
        for name, build in builds:
            for seed in seeds:
                mesh = build(seed)
                vertices = _gaussian(mesh, seed)
                yield f"{name} gauss {NOISE}h seed {seed}", count(vertices, mesh.faces, mesh.k_min, mesh.k_max)
    elif family == "saddle":
        steps = (0.04, 0.07) if held_out else (0.05, 0.1)
        meshes = [(f"disc saddle h {step:g} seed {seed}", step, seed) for step in steps for seed in seeds]
        squares = [(0.08, 0.3), (0.125, 0.3)] if held_out else [(0.1, 0.0), (0.05, 0.0)]
        meshes += [
            (f"square saddle h {step:g} jitter {jitter:g} seed {seed}", step, (jitter, seed))
            for step, jitter in squares
            for seed in (seeds if jitter else seeds[:1])
        ]
        for label, step, seed in meshes:
            if isinstance(seed, tuple):
                mesh = shapes.saddle(1.0, step, jitter=seed[0], seed=seed[1])
                vertices, faces, k_min, k_max = mesh.vertices, mesh.faces, mesh.k_min, mesh.k_max
            else:
                vertices, faces, k_min, k_max = disc_saddle(step, seed)
            edge = _mean_edge(vertices, faces)
            for factor in (1.5, None):
                radius = None if factor is None else factor * edge
                shown = "default" if factor is None else f"{factor:g} h"
                yield f"{label} {shown}", count(vertices, faces, k_min, k_max, radius)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--families", nargs="+", default=["holey", "gauss", "saddle"])
    parser.add_argument("--seeds", nargs="+", type=int, default=None, help="default: 0 1 2 (held out: 3 to 8)")
    parser.add_argument("--held-out", action="store_true", help="the draws and shapes not tuned on")
    args = parser.parse_args(argv)
    seeds = args.seeds if args.seeds is not None else (list(range(3, 9)) if args.held_out else [0, 1, 2])
    sys.stdout.write("| mesh | valid | off | cover | largest error |\n|---|---|---|---|---|\n")
    for family in args.families:
        total = [0, 0]
        for label, (valid, off, cover, worst) in rows(family, seeds, args.held_out):
            total[0] += valid
            total[1] += off
            sys.stdout.write(f"| {label} | {valid} | {off} | {cover:.1%} | {worst:.3g} |\n")
            sys.stdout.flush()
        sys.stdout.write(f"| **{family} total** | {total[0]} | {total[1]} | | |\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
