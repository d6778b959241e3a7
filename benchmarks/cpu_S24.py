"""User and system CPU seconds of default calls, and their peak memory (issue 31, helper S24).

Times ``meshcurv.principal_curvatures(v, f)`` on an icosphere after a warm-up call: the process's user and
system CPU seconds of each call (``resource.getrusage``: every thread), their medians, and with ``--peak`` the
peak resident memory of a fresh process making one call (bytes per vertex over what the mesh itself holds
before it). Run old and new code in turns (``PYTHONPATH=<snapshot>/src`` for the old)::

    .venv/bin/python benchmarks/cpu_S24.py --size 1M --repeats 5
    .venv/bin/python benchmarks/cpu_S24.py --size 4M --peak
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
    parser.add_argument("--peak", action="store_true", help="one call without a warm-up: its peak memory")
    args = parser.parse_args(argv)
    mesh = meshcurv.shapes.icosphere(SIZES[args.size])
    v = np.ascontiguousarray(mesh.vertices)
    f = np.ascontiguousarray(mesh.faces, dtype=np.int64)
    n = v.shape[0]
    if args.peak:
        del mesh
        before = _rss_kb()
        meshcurv.principal_curvatures(v[:100], f[:10])  # kernels loaded (a small call): not the big call's memory
        base = max(_rss_kb(), before)
        meshcurv.principal_curvatures(v, f)
        peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
        print(f"{args.size}: {n:,} vertices, peak RSS {peak / 1024:.0f} MB, {1024 * (peak - base) / n:.0f} B/vertex")
        return 0
    meshcurv.principal_curvatures(v, f)
    user, system = [], []
    for _ in range(args.repeats):
        start = resource.getrusage(resource.RUSAGE_SELF)
        wall = time.perf_counter()
        meshcurv.principal_curvatures(v, f)
        wall = time.perf_counter() - wall
        end = resource.getrusage(resource.RUSAGE_SELF)
        user.append(end.ru_utime - start.ru_utime)
        system.append(end.ru_stime - start.ru_stime)
        print(f"  user {user[-1]:.3f} sys {system[-1]:.3f} total {user[-1] + system[-1]:.3f} wall {wall:.3f}")
    total = np.add(user, system)
    print(
        f"{args.size}: median user {np.median(user):.3f} sys {np.median(system):.3f} "
        f"user+sys {np.median(total):.3f} s ({os.getloadavg()[0]:.1f} load)"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
