"""Warm start of the default call, two source trees alternating: each stage's CPU in a fresh process (issue 31).

``compile_pairs.py`` compares the cold compile of two trees; this compares their warm start. Each round starts
fresh processes per tree (the trees alternating, so both see the same load), each on its own warm
``NUMBA_CACHE_DIR`` (numba keys its cache on the source file's path: a tree per cache). A plain process (import,
read, one call: nothing timed inside) gives the headline, its user + system CPU and wall measured from outside,
with its CPU at the call's return (``os.times``: the rest is the interpreter's exit). A staged process times its
own stages in CPU seconds (``time.process_time``): the interpreter's start, ``import numpy``, the rest of
``import meshcurv``, the read of the mesh, ``import numba``, numba's registries (``refresh``, once per process:
meshcurv's ``_kernels._common`` loads them where it does, else an explicit ``refresh``), the loads from the
cache, the first call without them, a second call; and which of scipy's heavier modules were imported (numba's
own check for BLAS imports ``scipy.linalg``). Medians over the rounds.

Run from the repository root, each tree a ``src`` directory (e.g. ``git archive <commit> src | tar -x -C <dir>``)::

    python benchmarks/warm_pairs_S33.py /tmp/old/src /tmp/new/src --rounds 5

The caches are warmed first by one untimed process per tree (a cold compile each: half a minute of CPU), in
temporary directories, or given (``--caches OLD NEW``: kept, warmed where they are not).
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
t = c(); import meshcurv._kernels._common; cpu_target.target_context.refresh(); parts["numba's registries"] = c() - t
parts["scipy.linalg imported by the registries"] = float("scipy.linalg" in sys.modules)
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
for name in ("scipy.linalg", "scipy.spatial", "scipy.special", "scipy.sparse.csgraph"):
    parts[name + " imported by the call"] = float(name in new)
json.dump(parts, sys.stdout)
"""

PLAIN = r"""
import json, os, sys
import meshcurv
mesh = meshcurv.read_mesh(sys.argv[1])
meshcurv.principal_curvatures(mesh.vertices, mesh.faces)
times = os.times()
json.dump({"at the return": times.user + times.system}, sys.stdout)
"""


def _run(tree: str, cache: str, mesh: str) -> dict:
    env = _environment(cache)
    env["PYTHONPATH"] = tree
    plain, plain_wall, plain_cpu = _child(PLAIN, mesh, env)
    data = {
        "plain process CPU (user + system)": plain_cpu,
        "plain process CPU at the call's return": plain["at the return"],
        "plain process: the interpreter's exit": plain_cpu - plain["at the return"],
        "plain process wall": plain_wall,
    }
    staged, wall, cpu = _child(STAGES, mesh, env)
    data.update(staged)
    data["staged process CPU (user + system)"] = cpu
    data["staged process wall"] = wall
    data["load average (1 min)"] = os.getloadavg()[0]
    return data


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old", help="the first tree's src directory")
    parser.add_argument("new", help="the second tree's src directory")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--mesh", default=MESH)
    parser.add_argument("--caches", nargs=2, metavar=("OLD", "NEW"), help="warm caches to use (and keep)")
    args = parser.parse_args(argv)
    trees = {"old": args.old, "new": args.new}
    given = dict(zip(trees, args.caches)) if args.caches else {}
    caches = {label: given.get(label) or tempfile.mkdtemp(prefix=f"meshcurv-warm-{label}-") for label in trees}
    runs: dict[str, list[dict]] = {label: [] for label in trees}
    try:
        for label, tree in trees.items():
            _run(tree, caches[label], args.mesh)  # untimed: the cache compiled, the bytecode written
        for _ in range(args.rounds):
            for label, tree in trees.items():
                runs[label].append(_run(tree, caches[label], args.mesh))
    finally:
        for label, cache in caches.items():
            if label not in given:
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
