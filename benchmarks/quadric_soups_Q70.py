"""``quadric`` on fine soups and near-clean welds: valid vertices off the truth (issue 29, fuzz 400/78, 690/72, 730/1).

``python benchmarks/quadric_soups_Q70.py [--set tuned|sweep|held-out|tori|all] [--quick]``: closed shapes of
:mod:`meshcurv.shapes` (icosphere, ellipsoid, torus) with a share of their faces detached (given corners of their
own, each moved a gap of mean edge lengths in a random direction: the fuzzer's ``_detach``), at the default options,
welded as ``principal_curvatures`` welds them (across cracks up to 0.05 edges). Shares 0.2-1, gaps 0.001-0.1 edges.
The ``tuned`` and ``sweep`` sets are those the rule was tuned on, ``held-out`` other shapes, sizes, gaps and draws, ``tori`` the
near-clean welds (``torus(3, 1, 32, 16)`` with 30% of its faces detached by 1e-3 edges, as
``tests/test_double_sided_welds_D24.py``) that must stay as they were. For each case: the caller's vertices valid,
the valid ones whose H is off the exact H (of the corner each row copies) by more than 0.5 and 0.35 of the largest
exact ``|k|`` (the fuzzer's bar is 0.5), the largest such error and the CPU seconds of the call.
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes

from fuzz_api import _detach  # the fuzzer's detached faces (its draws)

SETS = {  # (shape, share, gap in edges, seed)
    "tuned": [
        ("icosphere(40)", 1.0, 0.096, 0),
        ("icosphere(40)", 1.0, 0.059, 1),
        ("icosphere(40)", 0.5, 0.031, 2),
        ("icosphere(24)", 0.5, 0.01, 3),
        ("icosphere(24)", 1.0, 0.003, 4),
        ("ellipsoid(24)", 0.5, 0.038, 5),
        ("torus(3, 1, 96, 48)", 0.5, 0.02, 6),
    ],
    "held-out": [
        ("icosphere(32)", 1.0, 0.07, 10),
        ("icosphere(32)", 0.2, 0.045, 11),
        ("icosphere(40)", 0.5, 0.005, 12),
        ("ellipsoid(20)", 1.0, 0.04, 13),
        ("ellipsoid(20)", 0.5, 0.002, 14),
        ("torus(3, 1, 80, 40)", 1.0, 0.05, 15),
        ("torus(2, 1, 64, 32)", 0.2, 0.1, 16),
        ("torus(2, 1, 64, 32)", 1.0, 0.001, 17),
        ("icosphere(20)", 1.0, 0.02, 18),
        ("icosphere(48)", 0.5, 0.008, 19),
        ("ellipsoid(32)", 1.0, 0.01, 20),
        ("torus(2, 1, 128, 64)", 1.0, 0.012, 21),
        ("torus(2, 1, 128, 64)", 0.5, 0.025, 22),
    ],
    "tori": [
        ("torus(3, 1, 32, 16)", 0.3, 0.001, 3),
        ("torus(3, 1, 32, 16)", 0.3, 0.001, 30),
        ("torus(3, 1, 48, 24)", 0.3, 0.002, 31),
        ("icosphere(6)", 1.0, 0.001, 32),
    ],
}


# the sweep the rule was tuned on (quadric.WELDED_GAP): gaps below and within the weld's tolerance
SETS["sweep"] = [
    (name, share, gap, 100 + 12 * k + 6 * j + i)
    for k, name in enumerate(("icosphere(24)", "ellipsoid(20)", "torus(3, 1, 96, 48)"))
    for j, share in enumerate((0.5, 1.0))
    for i, gap in enumerate((0.002, 0.004, 0.006, 0.008, 0.012, 0.016))
]


def base(name: str):
    """The clean shape of a case's name."""
    inside = name[name.index("(") + 1 : -1]
    numbers = [float(x) for x in inside.split(",")]
    if name.startswith("icosphere"):
        return shapes.icosphere(int(numbers[0]))
    if name.startswith("ellipsoid"):
        return shapes.ellipsoid(subdivisions=int(numbers[0]))
    major, minor, ring, tube = numbers
    return shapes.torus(major, minor, int(ring), int(tube))


def run(name, share, gap, seed):
    """``(n, valid, off 0.5, off 0.35, worst, cpu)`` of one case."""
    mesh = base(name)
    vertices, faces = np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces)
    soup, soup_faces = _detach(np.random.default_rng(seed), vertices, faces, share, gap)
    corner = np.concatenate([np.arange(len(vertices)), faces[soup_faces != faces]])  # the clean corner of each row
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.process_time()
        result = meshcurv.principal_curvatures(soup, soup_faces, method="quadric")
        cpu = time.process_time() - start
    used = np.zeros(len(soup), dtype=bool)
    used[soup_faces.ravel()] = True
    valid = result.valid & used
    size = float(np.max(np.abs(np.concatenate([mesh.k_min, mesh.k_max]))))
    error = np.abs(result.mean - mesh.mean[corner])[valid] / size
    worst = float(error.max()) if error.size else 0.0
    return int(used.sum()), int(valid.sum()), int((error > 0.5).sum()), int((error > 0.35).sum()), worst, cpu


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--set", choices=[*SETS, "all"], default="all")
    parser.add_argument("--quick", action="store_true", help="the first two cases of each set")
    args = parser.parse_args(argv)
    names = list(SETS) if args.set == "all" else [args.set]
    print("| set | shape | detached | gap (edges) | seed | valid | off > 0.5 | off > 0.35 | worst | CPU s |")
    print("|---|---|--:|--:|--:|--:|--:|--:|--:|--:|")
    for set_name in names:
        totals = np.zeros(4, dtype=int)
        for name, share, gap, seed in SETS[set_name][:2] if args.quick else SETS[set_name]:
            n, valid, off, loose, worst, cpu = run(name, share, gap, seed)
            totals += (n, valid, off, loose)
            print(
                f"| {set_name} | {name} | {share:g} | {gap:g} | {seed} | {valid:,} of {n:,} | {off} | {loose} | "
                f"{worst:.3f} | {cpu:.1f} |",
                flush=True,
            )
        print(
            f"| **{set_name}** | total | | | | {totals[1]:,} of {totals[0]:,} | {totals[2]} | {totals[3]} | | |",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
