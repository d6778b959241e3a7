"""The default call of icc on every family of ``benchmarks/scale_families.py``, before and after a change.

Issue 30 (a per-vertex default scale). Runs ``meshcurv.principal_curvatures(v, f)`` (no option) on each
mesh, and records per mesh: median and 95th percentile of ``|H - H_exact| / max|k|``, medians of the
k_min, k_max errors (same scale) and of ``|K - K_exact| / max|k|^2``, the same medians of H on the
``fine`` and ``coarse`` parts where the family has them, the radius used (median and 10-90% over the
vertices, in median edge lengths), and the CPU seconds of the call (after one warm-up call on the first
mesh: numba's compilation not counted). Families ``accuracy`` and ``voxel`` are the tuning ones,
``smoothed``, ``varying``, ``elongated`` and ``failing`` held out (see ``scale_families.py``).

    python benchmarks/scale_default.py --output /tmp/after.json            # every family (about 4 min)
    python benchmarks/scale_default.py --families varying --output /tmp/v.json
    python benchmarks/scale_default.py --compare /tmp/before.json /tmp/after.json   # markdown table

To measure the code of another commit, run the script from this checkout with ``PYTHONPATH`` set to that
commit's ``src`` (``git archive <commit> | tar -x -C /tmp/base``; ``PYTHONPATH=/tmp/base/src``).
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import meshcurv  # noqa: E402
import scale_families  # noqa: E402
from meshcurv.geometry import median_edge_length  # noqa: E402
from meshcurv.topology import MeshTopology  # noqa: E402


def measure(case) -> dict:
    """One default call on ``case``: errors (fractions), radius in median edges, CPU seconds."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.process_time()
        result = meshcurv.principal_curvatures(case.vertices, case.faces)
        cpu = time.process_time() - start
    scale = np.maximum(np.abs(case.k_min), np.abs(case.k_max))
    ok = result.valid & (scale > 0)

    def median(values, mask=None):
        keep = ok if mask is None else ok & mask
        return float(np.median(values[keep])) if keep.any() else float("nan")

    h_error = np.abs(result.mean - case.mean) / scale
    edge = median_edge_length(case.vertices, MeshTopology.from_faces(case.faces, case.vertices.shape[0]).edges)
    radius = np.asarray(result.radius, dtype=float)[ok] / edge
    row = {
        "name": case.name,
        "family": case.family,
        "tuning": case.tuning,
        "V": int(case.vertices.shape[0]),
        "H": median(h_error),
        "H95": float(np.percentile(h_error[ok], 95)),
        "k_min": median(np.abs(result.k_min - case.k_min) / scale),
        "k_max": median(np.abs(result.k_max - case.k_max) / scale),
        "K": median(np.abs(result.gaussian - case.gaussian) / scale**2),
        "radius": [float(np.percentile(radius, q)) for q in (10, 50, 90)],
        "cpu": cpu,
        "surface": result.parameters.get("surface"),
    }
    for part, mask in case.parts.items():
        row[f"H {part}"] = median(h_error, mask)
        row[f"radius {part}"] = float(np.median(np.asarray(result.radius)[ok & mask] / edge))
    return row


def run(families) -> list[dict]:
    cases = list(scale_families.cases(families))
    measure(cases[0])  # warm-up: compilation
    rows = []
    for case in cases:
        rows.append(measure(case))
        print(f"{rows[-1]['name']}: H {100 * rows[-1]['H']:.3g}%  cpu {rows[-1]['cpu']:.2f} s", file=sys.stderr)
    return rows


def _pct(x) -> str:
    return "-" if x is None or not np.isfinite(x) else f"{100 * x:.3g}%"


def compare(before_path: str, after_path: str) -> str:
    """Markdown: per family, each mesh's median H (p95), k_min / k_max, radius and CPU, before -> after."""
    with open(before_path) as f:
        before = {row["name"]: row for row in json.load(f)}
    with open(after_path) as f:
        after = json.load(f)
    lines = []
    family = None
    totals: dict = {}
    for row in after:
        old = before.get(row["name"])
        if old is None:
            continue
        if row["family"] != family:
            family = row["family"]
            kind = "tuning" if row["tuning"] else "held out"
            lines += [
                "",
                f"### {family} ({kind})",
                "",
                "| mesh | V | H (p95) before | H (p95) after | k_min / k_max before | k_min / k_max after "
                "| r/h before [10-90%] | r/h after [10-90%] | CPU s before / after | moved |",
                "|---|--:|--:|--:|--:|--:|--:|--:|--:|---|",
            ]
        worse = row["H"] > 1.1 * old["H"] + 1e-6
        better = row["H"] < old["H"] / 1.1 - 1e-6
        moved = "worse" if worse else "better" if better else ""
        parts = [p[2:] for p in row if p.startswith("H ") and p != "H95"]
        for part in parts:
            moved += f" {part} {_pct(old['H ' + part])} -> {_pct(row['H ' + part])}"
        lines.append(
            f"| {row['name']} | {row['V']:,} | {_pct(old['H'])} ({_pct(old['H95'])}) | {_pct(row['H'])} "
            f"({_pct(row['H95'])}) | {_pct(old['k_min'])} / {_pct(old['k_max'])} | {_pct(row['k_min'])} / "
            f"{_pct(row['k_max'])} | {old['radius'][1]:.2f} [{old['radius'][0]:.2f}-{old['radius'][2]:.2f}] | "
            f"{row['radius'][1]:.2f} [{row['radius'][0]:.2f}-{row['radius'][2]:.2f}] | "
            f"{old['cpu']:.2f} / {row['cpu']:.2f} | {moved.strip()} |"
        )
        total = totals.setdefault(family, [0.0, 0.0, [], [], 0])
        total[0] += old["cpu"]
        total[1] += row["cpu"]
        total[2].append(old["H"])
        total[3].append(row["H"])
        total[4] += worse
    summary = [
        "| family | meshes | geometric mean of median H, before -> after | worse by > 1/10 | CPU s before -> after |",
        "|---|--:|--:|--:|--:|",
    ]
    for family, (cpu_old, cpu_new, h_old, h_new, worse) in totals.items():
        geo = [float(np.exp(np.mean(np.log(np.maximum(h, 1e-9))))) for h in (h_old, h_new)]
        summary.append(
            f"| {family} | {len(h_old)} | {_pct(geo[0])} -> {_pct(geo[1])} | {worse} | "
            f"{cpu_old:.1f} -> {cpu_new:.1f} ({cpu_new / cpu_old:.2f}x) |"
        )
    return "\n".join(summary + lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--families", nargs="+", choices=list(scale_families.BUILDERS))
    parser.add_argument("--output", help="JSON file of the rows")
    parser.add_argument("--compare", nargs=2, metavar=("BEFORE", "AFTER"))
    args = parser.parse_args(argv)
    if args.compare:
        print(compare(*args.compare))
        return
    rows = run(args.families)
    if args.output:
        with open(args.output, "w") as f:
            json.dump(rows, f, indent=1)
    else:
        print(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
