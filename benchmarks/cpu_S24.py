"""User and system CPU seconds of default calls, and their peak memory (issue 31, helper S24).

Times ``meshcurv.principal_curvatures(v, f)`` on an icosphere after a warm-up call: the process's user and
system CPU seconds of each call (``resource.getrusage``: every thread), their medians, and with ``--peak`` the
peak resident memory of a fresh process making one call (bytes per vertex over what the mesh itself holds
before it). Run old and new code in turns (``PYTHONPATH=<snapshot>/src`` for the old)::

    .venv/bin/python benchmarks/cpu_S24.py --size 1M --repeats 5
    .venv/bin/python benchmarks/cpu_S24.py --size 4M --peak
    .venv/bin/python benchmarks/cpu_S24.py --size 1M --repeats 5 --trueform
    .venv/bin/python benchmarks/cpu_S24.py --size 1M --repeats 5 --trueform --method normal_cycle

(helper S30: ``--method``, and the wall medians and their ratio beside the CPU ones.)
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import time

import numpy as np

import meshcurv

SIZES = {"10k": 32, "100k": 100, "250k": 158, "1M": 316, "4M": 632}


def _rss_kb() -> int:
    with open("/proc/self/status", encoding="ascii") as handle:
        for line in handle:
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    return 0


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="1M", choices=sorted(SIZES))
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--method", default=None, help="a meshcurv method (default: the default method)")
    parser.add_argument("--peak", action="store_true", help="one call without a warm-up: its peak memory")
    parser.add_argument(
        "--trueform",
        action="store_true",
        help="also time trueform.principal_curvatures(k=2, directions=True) in turns with each call (the peer of issue 31)",
    )
    args = parser.parse_args(argv)
    mesh = meshcurv.shapes.icosphere(SIZES[args.size])
    v = np.ascontiguousarray(mesh.vertices)
    f = np.ascontiguousarray(mesh.faces, dtype=np.int64)
    n = v.shape[0]
    if args.peak:
        del mesh
        before = _rss_kb()
        small = meshcurv.shapes.icosphere(4)
        meshcurv.principal_curvatures(small.vertices, small.faces)  # kernels loaded: not the big call's memory
        base = max(_rss_kb(), before)
        meshcurv.principal_curvatures(v, f)
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        print(f"{args.size}: {n:,} vertices, peak RSS {peak / 1024:.0f} MB, {1024 * (peak - base) / n:.0f} B/vertex")
        return 0
    options = {} if args.method is None else {"method": args.method}
    calls = {"meshcurv": lambda: meshcurv.principal_curvatures(v, f, **options)}
    if args.trueform:
        import trueform  # a benchmark peer only (non-commercial licence), as in benchmarks/speed.py

        calls["trueform"] = lambda: trueform.principal_curvatures((f, v), k=2, directions=True)
    for call in calls.values():
        call()  # warm-up
    spent: dict[str, list] = {name: [] for name in calls}
    walls: dict[str, list] = {name: [] for name in calls}
    for _ in range(args.repeats):
        for name, call in calls.items():
            start = resource.getrusage(resource.RUSAGE_SELF)
            wall = time.perf_counter()
            call()
            wall = time.perf_counter() - wall
            end = resource.getrusage(resource.RUSAGE_SELF)
            spent[name].append((end.ru_utime - start.ru_utime, end.ru_stime - start.ru_stime))
            walls[name].append(wall)
            user, system = spent[name][-1]
            print(f"  {name}: user {user:.3f} sys {system:.3f} total {user + system:.3f} wall {wall:.3f}")
    medians, wall_medians = {}, {}
    for name, pairs in spent.items():
        user, system = np.median(pairs, axis=0)
        medians[name] = float(np.median(np.sum(pairs, axis=1)))
        wall_medians[name] = float(np.median(walls[name]))
        print(
            f"{args.size} {name}: median user {user:.3f} sys {system:.3f} user+sys {medians[name]:.3f} s "
            f"wall {wall_medians[name]:.3f} s ({os.getloadavg()[0]:.1f} load)"
        )
    if args.trueform:
        print(
            f"{args.size}: meshcurv / trueform (user+sys medians) {medians['meshcurv'] / medians['trueform']:.2f}, "
            f"(wall medians) {wall_medians['meshcurv'] / wall_medians['trueform']:.2f}"
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
