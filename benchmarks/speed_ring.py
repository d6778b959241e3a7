"""normal_cycle and matgeom against trueform, each in its own child process, before and after a change (issue 31).

The child processes of ``benchmarks/speed.py`` (``--worker``: the arrays
loaded from .npy files, one call not counted, then ``--repeats`` calls timed
in that process; its peak RSS, ``VmHWM``, the whole process), for the two
ring methods with the topology built in the call, and trueform's
``principal_curvatures(k=2, directions=True)`` (a benchmark peer only, never
a dependency), on icospheres. ``--before SRC`` also times the meshcurv of
another source tree (e.g. ``git archive HEAD~1 | tar -x -C /tmp/before``,
then ``--before /tmp/before/src``) in the same rounds, interleaved, so that
both sides see the same load. Medians over ``--rounds`` x ``--repeats`` calls
(the first call of each child not counted); ``--after SRC`` times a tree other than the installed one
(e.g. ``git archive HEAD``, without a working tree's uncommitted edits)::

    .venv/bin/python benchmarks/speed_ring.py --sizes 1M,4M --rounds 3 --repeats 3 --before /tmp/before/src
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import speed  # noqa: E402  (the child-process harness, beside this file)

KEYS = ("meshcurv/normal_cycle/numba", "meshcurv/matgeom/numba", speed.TRUEFORM)


def _environment(source: str | None) -> dict:
    """The children's environment: meshcurv from ``source`` (a ``src`` directory) when given."""
    if source is None:
        return speed.user_environment()
    path = os.environ.get("PYTHONPATH")
    return speed.user_environment(PYTHONPATH=source if not path else source + os.pathsep + path)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="1M,4M")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--repeats", type=int, default=3, help="calls timed in each child after its first")
    parser.add_argument("--before", help="the src directory of another meshcurv to time beside this one")
    parser.add_argument("--after", help="the src directory of the meshcurv to time (default: the one installed)")
    parser.add_argument("--timeout", type=float, default=900.0)
    args = parser.parse_args(argv)
    trees = {"after": args.after} if args.before is None else {"before": args.before, "after": args.after}
    rows = []
    for label in args.sizes.split(","):
        name, v, f = speed.build_mesh(label)
        with tempfile.TemporaryDirectory() as mesh_dir:
            np.save(os.path.join(mesh_dir, "v.npy"), v)
            np.save(os.path.join(mesh_dir, "f.npy"), f)
            runs: dict = {}
            for _ in range(args.rounds):
                for key in KEYS:
                    for tree, source in trees.items():
                        if key == speed.TRUEFORM and tree != "after":
                            continue  # the peer does not depend on the tree
                        result = speed.run_child(
                            key, mesh_dir, args.repeats + 1, 1e9, 1e9, args.timeout, env=_environment(source)
                        )
                        if "cpu" not in result:
                            print(f"{name} {key} [{tree}]: {result}", file=sys.stderr)
                            continue
                        runs.setdefault((key, tree), []).append(result)
        for (key, tree), results in runs.items():
            wall = statistics.median(t for r in results for t in r["times"][1:])
            cpu = statistics.median(c for r in results for c in r["cpu"][1:])
            peak = statistics.median(r["peak_rss"] for r in results)
            base = statistics.median(r["base_rss"] for r in results)
            rows.append((name, v.shape[0], key, tree, wall, cpu, peak, base))
    trueform = {(row[0]): row[5] for row in rows if row[2] == speed.TRUEFORM}
    print(f"load average: {os.getloadavg()}")
    print()
    print(
        "| mesh | implementation | tree | wall s | CPU s | CPU us/vertex | CPU: trueform / this | peak RSS B/vertex | peak - input B/vertex |"
    )
    print("|---|---|---|--:|--:|--:|--:|--:|--:|")
    for name, n, key, tree, wall, cpu, peak, base in rows:
        tree_label = "" if key == speed.TRUEFORM else tree
        print(
            f"| {name} | {speed.label_of(key)} | {tree_label} | {wall:.3f} | {cpu:.3f} | {cpu / n * 1e6:.2f} | "
            f"{trueform.get(name, float('nan')) / cpu:.2f} | {peak / n:.0f} | {(peak - base) / n:.0f} |"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
