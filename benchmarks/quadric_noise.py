"""``quadric``'s default radius on the noisy meshes of ``benchmarks/accuracy.py``: a sweep of its noise rule.

Run from the repository root::

    python benchmarks/quadric_noise.py                       # the rule as it is, noisy rows, levels 0 and 1
    python benchmarks/quadric_noise.py --configs 20:1:10 30:1.4:10 --families "sphere:noise 0.3h"

Each config is ``gain:cap:hessian``: ``meshcurv.radius.JET_RADIUS_RULE = (2.5, gain)``,
``JET_CURVATURE_CAP = cap``, ``JET_NOISE_HESSIAN = hessian`` (``--gate`` sets ``quadric.NOISE_GATE``). Each cell
is the share of interior vertices reported (cover), the median / 95th percentile of the H error and the
median k_max error (``accuracy.errors``: relative to the largest exact |k| at the vertex). The figures and the
choice are in ``benchmarks/quadric_noise.md``.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import accuracy  # noqa: E402 - the benchmark's meshes and errors

import meshcurv  # noqa: E402
from meshcurv import radius as radius_rules  # noqa: E402
from meshcurv.estimators import quadric  # noqa: E402

NOISY = [
    f"{name}:noise {noise}h" for name in ("sphere", "torus", "ellipsoid", "cylinder", "saddle") for noise in (0.1, 0.3)
]


def cell(mesh, topology, config, gate) -> str:
    gain, cap, hessian = config
    radius_rules.JET_RADIUS_RULE = (radius_rules.DEFAULT_RADIUS_FACTOR, gain)
    radius_rules.JET_CURVATURE_CAP = cap
    radius_rules.JET_NOISE_HESSIAN = hessian
    quadric.NOISE_GATE = gate
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = meshcurv.principal_curvatures(mesh.vertices, topology, method="quadric")
    inner = ~topology.boundary_vertices
    mask = result.valid & inner
    errors = accuracy.errors(mesh, result.k_min, result.k_max, result.dir_max, mask)
    return (
        f"{mask.sum() / inner.sum():.0%}, H {errors['H'][0]:.1%} / {errors['H'][1]:.0%}, k_max {errors['k_max'][0]:.1%}"
    )


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--configs", nargs="+", default=None, help="gain:cap:hessian (default: the rule as it is)")
    parser.add_argument("--gate", type=float, default=quadric.NOISE_GATE)
    parser.add_argument("--families", nargs="+", default=NOISY)
    parser.add_argument("--levels", nargs="+", type=int, default=[0, 1])
    args = parser.parse_args(argv)
    configs = (
        [tuple(float(x) for x in text.split(":")) for text in args.configs]
        if args.configs
        else [(radius_rules.JET_RADIUS_RULE[1], radius_rules.JET_CURVATURE_CAP, radius_rules.JET_NOISE_HESSIAN)]
    )
    names = [":".join(f"{x:g}" for x in config) for config in configs]
    sys.stdout.write("| surface | variant | V | " + " | ".join(names) + " |\n")
    sys.stdout.write("|---|---|---|" + "---|" * len(names) + "\n")
    for surface, variant, _, mesh in accuracy.surfaces(args.levels, args.families):
        topology = meshcurv.MeshTopology.from_faces(mesh.faces, mesh.vertices.shape[0])
        cells = [cell(mesh, topology, config, args.gate) for config in configs]
        sys.stdout.write(f"| {surface} | {variant} | {mesh.vertices.shape[0]} | " + " | ".join(cells) + " |\n")
        sys.stdout.flush()
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
