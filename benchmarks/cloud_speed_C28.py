"""Paired 1M-point cloud timings of two trees with the peak memory (issue 31: clouds at 1M in <= 5 s wall).

As ``benchmarks/pointcloud_speed_P24.py`` (one process per tree and run, the trees taken alternately, each warmed
on 70k points first, then ``point_cloud_curvatures`` of a torus sample, default method): the wall time, the CPU
time of the process (every thread) and of the calling thread (the wall time on idle cores: every serial part
and its share of the parallel ones), and the process's peak resident memory (``VmHWM``) above its memory just
before the call (``VmRSS``), per point.

Usage (the "before" a snapshot of the parent commit: ``git archive <commit> | tar -x -C <dir>``)::

    python benchmarks/cloud_speed_C28.py --trees <before> <after> --size 1000000 --runs 3
"""

from __future__ import annotations

import argparse
import collections
import json
import os
import statistics
import sys
import time
import warnings
from pathlib import Path

HERE = Path(__file__).resolve().parent


def _memory(field: str) -> int:
    """``field`` (``VmRSS``, ``VmHWM``) of this process in bytes (Linux)."""
    for line in Path("/proc/self/status").read_text().splitlines():
        if line.startswith(field + ":"):
            return int(line.split()[1]) * 1024
    return 0


def child(size: int) -> None:
    """Time one call at ``size`` points in this process; print one JSON line."""
    sys.path.insert(0, str(HERE))
    from pointcloud import sample

    from meshcurv.pointcloud import point_cloud_curvatures

    warm = sample("torus", 70_000)[0]
    warm[1] = warm[0] + 1e-9
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        point_cloud_curvatures(warm)
        points = sample("torus", size)[0]
        before = _memory("VmRSS")
        start = (time.perf_counter(), time.process_time(), time.thread_time())
        result = point_cloud_curvatures(points)
        end = (time.perf_counter(), time.process_time(), time.thread_time())
    wall, cpu, main = (b - a for a, b in zip(start, end))
    peak = _memory("VmHWM") - before
    row = {"wall": wall, "cpu": cpu, "main": main, "peak": peak, "valid": float(result.valid.mean())}
    print(json.dumps({**row, "load": os.getloadavg()[0]}))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trees", nargs="+", default=[], help="trees (each with a src/ directory), alternately")
    parser.add_argument("--size", type=int, default=1_000_000)
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        child(args.size)
        return 0
    sys.path.insert(0, str(HERE))
    from _tree_children_P29 import alternate_rows

    found: dict = collections.defaultdict(list)
    print("| tree | run | wall s | CPU s | calling thread CPU s | peak above the call's start, B/point | load |")
    print("|---|---|---|---|---|---|---|")
    for tree, run, row in alternate_rows(__file__, args.trees, args.runs, ["--size", args.size]):
        found[tree].append(row)
        print(
            f"| {tree} | {run} | {row['wall']:.2f} | {row['cpu']:.2f} | {row['main']:.2f} | "
            f"{row['peak'] / args.size:.0f} | {row['load']:.1f} |",
            flush=True,
        )
    print("\n| tree | wall s | CPU s | calling thread CPU s | peak B/point (medians of runs) |\n|---|---|---|---|---|")
    for tree, rows in found.items():
        medians = [statistics.median(r[key] for r in rows) for key in ("wall", "cpu", "main", "peak")]
        print(f"| {tree} | {medians[0]:.2f} | {medians[1]:.2f} | {medians[2]:.2f} | {medians[3] / args.size:.0f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
