"""Paired speed runs of two trees on torus clouds (issue 31), with the calling thread's CPU time.

Each run is one process per tree (``PYTHONPATH=<tree>/src``), the trees taken alternately (A, B, A, B, ...),
each process warmed on 70k points first (as ``benchmarks/pointcloud_speed.py``), then timing
``point_cloud_curvatures`` (default method) at each size: the wall time, the CPU time of the process (every
thread) and that of the calling thread. The kernels run on the calling thread and on helper threads; every
serial part runs on the calling thread, which also takes its share of the parallel ones: its CPU time is the
wall time the call would take on idle cores (what a shared machine's wall time no longer tells). Stages as
``benchmarks/pointcloud_speed.py`` (the log messages), with the calling thread's CPU too.

Usage::

    python benchmarks/pointcloud_speed_P24.py --trees <before> <after> --sizes 100000 1000000 --runs 3
    python benchmarks/pointcloud_speed_P24.py --trees <tree> --runs 1 --stages   # stage table too
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import statistics
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent


def child(sizes) -> None:
    """Time each size in this process; print one JSON line per size."""
    sys.path.insert(0, str(HERE))
    from pointcloud import sample

    from pointcloud_speed import timed  # the same clocks and stages as the older script

    warm = sample("torus", 70_000)[0]
    warm[1] = warm[0] + 1e-9
    timed(warm)
    for n in sizes:
        _, (wall, cpu, main), stages = timed(sample("torus", n)[0])
        stages = {label.replace("point cloud: ", ""): times for label, times in stages.items()}
        print(
            json.dumps({"n": n, "wall": wall, "cpu": cpu, "main": main, "load": os.getloadavg()[0], "stages": stages})
        )


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trees", nargs="+", help="trees (each with a src/ directory), run alternately")
    parser.add_argument("--sizes", type=int, nargs="+", default=[100_000, 1_000_000])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--stages", action="store_true", help="the stages of each tree's median run too")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child(args.sizes)
        return 0
    sys.path.insert(0, str(HERE))
    from _tree_children_P29 import alternate_rows

    found: dict = collections.defaultdict(list)
    for tree, run, row in alternate_rows(__file__, args.trees, args.runs, ["--sizes", *args.sizes]):
        found[tree, row["n"]].append(row)
        print(
            f"| {tree} | run {run} | {row['n']} | {row['wall']:.2f} | {row['cpu']:.2f} | "
            f"{row['main']:.2f} | {row['load']:.1f} |",
            flush=True,
        )
    print(
        "\n| tree | points | wall s | CPU s | calling thread CPU s (median of runs; min-max) |\n|---|---|---|---|---|"
    )
    for (tree, n), rows in found.items():
        parts = [f"{statistics.median(r[key] for r in rows):.2f}" for key in ("wall", "cpu")]
        main_times = [r["main"] for r in rows]
        spread = f"{statistics.median(main_times):.2f} ({min(main_times):.2f}-{max(main_times):.2f})"
        print(f"| {tree} | {n} | {' | '.join(parts)} | {spread} |")
    if args.stages:
        for (tree, n), rows in found.items():
            middle = sorted(rows, key=lambda r: r["main"])[len(rows) // 2]
            detail = "; ".join(
                f"{label} {c:.2f} ({m:.2f})" for label, (w, c, m) in middle["stages"].items() if c >= 0.005
            )
            print(f"\n{tree}, {n} points, stages: CPU s (calling thread CPU s): {detail}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
