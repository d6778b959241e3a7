"""Cold compile CPU of the default call, two source trees side by side (issue 31).

On a shared machine the compile CPU of one cold process moves by several seconds from one minute to the
next; two processes started together (one per tree, each on its own empty ``NUMBA_CACHE_DIR``) see the same
load, so the difference of a pair holds where the totals do not. Each pair prints both totals (numba's
``numba:compile`` events, as ``compile_start.py``), their difference and the number of compilations, then
the functions whose own compile CPU differs most between the two trees (summed over the pairs).

Run from the repository root, each tree a ``src`` directory (e.g. ``git archive <commit> src | tar -x -C
<dir>``)::

    python benchmarks/compile_pairs.py /tmp/old/src /tmp/new/src --pairs 3
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
from collections import defaultdict

from compile_start import COLD, MESH, _environment


def _start(tree: str, mesh: str, cache: str) -> subprocess.Popen:
    env = _environment(cache)
    env["PYTHONPATH"] = tree
    return subprocess.Popen([sys.executable, "-c", COLD, mesh], stdout=subprocess.PIPE, text=True, env=env)


def _own_times(records: list) -> dict[str, float]:
    """Each function's own compile CPU (its callees' compilations excluded), summed over its compilations."""
    own: dict[str, float] = defaultdict(float)
    for name, _, alone, _ in records:
        own[name] += alone
    return own


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old", help="the first tree's src directory")
    parser.add_argument("new", help="the second tree's src directory")
    parser.add_argument("--pairs", type=int, default=3)
    parser.add_argument("--mesh", default=MESH)
    parser.add_argument("--lines", type=int, default=12, help="functions listed at the end")
    args = parser.parse_args(argv)
    differences: dict[str, float] = defaultdict(float)
    for pair in range(args.pairs):
        caches = [tempfile.mkdtemp(prefix="meshcurv-pair-") for _ in range(2)]
        load = os.getloadavg()[0]
        try:
            runs = [_start(tree, args.mesh, cache) for tree, cache in zip((args.old, args.new), caches)]
            data = [json.loads(run.communicate()[0]) for run in runs]
        finally:
            for cache in caches:
                shutil.rmtree(cache, ignore_errors=True)
        old, new = data
        print(
            f"pair {pair + 1} (load {load:.1f}): old {old['compile_cpu']:.2f} s ({len(old['records'])} compilations), "
            f"new {new['compile_cpu']:.2f} s ({len(new['records'])}), new - old {new['compile_cpu'] - old['compile_cpu']:+.2f}"
        )
        before, after = _own_times(old["records"]), _own_times(new["records"])
        for name in set(before) | set(after):
            differences[name] += after.get(name, 0.0) - before.get(name, 0.0)
    print(f"\nown compile CPU, new - old, summed over {args.pairs} pairs (largest changes):")
    for name, change in sorted(differences.items(), key=lambda item: -abs(item[1]))[: args.lines]:
        print(f"  {change:+6.2f}  {name}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
