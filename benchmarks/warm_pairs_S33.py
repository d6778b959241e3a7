"""Warm start of the default call, two source trees alternating: each stage's CPU in a fresh process (issue 31).

``compile_pairs.py`` compares the cold compile of two trees; this compares their warm start. Each round starts
one fresh process per tree (the trees alternating, so both see the same load), each on its own warm
``NUMBA_CACHE_DIR`` (numba keys its cache on the source file's path: a tree per cache), and each process times
its own stages in CPU seconds (``time.process_time``): the interpreter's start, ``import numpy``, the rest of
``import meshcurv``, the read of the mesh, ``import numba``, ``numba.np.arraymath`` (numba's check for BLAS
imports ``scipy.linalg``), numba's registries (``refresh``, once per process), the loads from the cache, the
first call without them, a second call; and which of scipy's heavier modules the call imported. The whole
process's user + system CPU and wall are measured from outside. Medians over the rounds.

Run from the repository root, each tree a ``src`` directory (e.g. ``git archive <commit> src | tar -x -C <dir>``)::

    python benchmarks/warm_pairs_S33.py /tmp/old/src /tmp/new/src --rounds 5

The caches are warmed first by one untimed process per tree (a cold compile each: half a minute of CPU).
"""

from __future__ import annotations

import argparse
import os
import shutil
import statistics
import sys
import tempfile

from compile_start import MESH, _child, _environment

STAGES = r"""
import json, sys, time
c = time.process_time
parts = {"interpreter start": c()}
t = c(); import numpy; parts["import numpy"] = c() - t
t = c(); import meshcurv; parts["import meshcurv (the rest)"] = c() - t
t = c(); mesh = meshcurv.read_mesh(sys.argv[1]); parts["read"] = c() - t
t = c(); import numba; parts["import numba"] = c() - t
from numba.core import caching
from numba.core.registry import cpu_target
t = c(); import numba.np.arraymath; parts["numba.np.arraymath (scipy.linalg)"] = c() - t
t = c(); cpu_target.target_context.refresh(); parts["numba's registries"] = c() - t
loads = []
load = caching.Cache.load_overload


def timed(self, signature, context):
    t = c()
    found = load(self, signature, context)
    loads.append(c() - t)
    return found


caching.Cache.load_overload = timed
before = set(sys.modules)
t = c(); meshcurv.principal_curvatures(mesh.vertices, mesh.faces); first = c() - t
parts["loads from the cache"] = sum(loads)
parts["number of loads"] = len(loads)
parts["first call, the loads excluded"] = first - sum(loads)
t = c(); meshcurv.principal_curvatures(mesh.vertices, mesh.faces); parts["second call"] = c() - t
new = set(sys.modules) - before
for name in ("scipy.spatial", "scipy.special", "scipy.sparse.csgraph"):
    parts[name + " imported by the call"] = float(name in new)
json.dump(parts, sys.stdout)
"""


def _run(tree: str, cache: str, mesh: str) -> dict:
    env = _environment(cache)
    env["PYTHONPATH"] = tree
    data, wall, cpu = _child(STAGES, mesh, env)
    data["whole process CPU (user + system)"] = cpu
    data["whole process wall"] = wall
    data["load average (1 min)"] = os.getloadavg()[0]
    return data


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old", help="the first tree's src directory")
    parser.add_argument("new", help="the second tree's src directory")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--mesh", default=MESH)
    args = parser.parse_args(argv)
    trees = {"old": args.old, "new": args.new}
    caches = {label: tempfile.mkdtemp(prefix=f"meshcurv-warm-{label}-") for label in trees}
    runs: dict[str, list[dict]] = {label: [] for label in trees}
    try:
        for label, tree in trees.items():
            _run(tree, caches[label], args.mesh)  # untimed: the cache compiled, the bytecode written
        for _ in range(args.rounds):
            for label, tree in trees.items():
                runs[label].append(_run(tree, caches[label], args.mesh))
    finally:
        for cache in caches.values():
            shutil.rmtree(cache, ignore_errors=True)
    print(f"Warm fresh processes, CPU s unless named, median of {args.rounds} rounds (trees alternating):\n")
    print("| stage | old | new | new - old |")
    print("|---|--:|--:|--:|")
    for key in runs["old"][0]:
        old = statistics.median(r[key] for r in runs["old"])
        new = statistics.median(r[key] for r in runs["new"])
        print(f"| {key} | {old:.3f} | {new:.3f} | {new - old:+.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
