"""Speed against the vertex order of the mesh (issue 15): the same icosphere in its own order and shuffled.

Run from the repository root: ``python benchmarks/order.py [--sizes 100k,1M] [--output benchmarks/order.md]``.

Each implementation runs in a fresh child process fed the same arrays
(``speed.py``'s worker: the median of ``--repeats`` calls after a first one),
on four orders of the same icosphere: its own (rows of each icosahedron
face), shuffled within blocks of 256 and of 4,096 vertices, and shuffled
whole (vertices and faces). meshcurv computes a mesh in a scattered order in
the Morton order of its vertices (``meshcurv._locality``); the table shows
what that costs and what it saves, and the peers on the same arrays.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import speed  # noqa: E402  (the child-process runner and the mesh sizes of the speed table)

from meshcurv import _locality  # noqa: E402

ORDERS = (("own", None), ("blocks of 256", 256), ("blocks of 4,096", 4096), ("shuffled", 0))
IMPLEMENTATIONS = ("meshcurv/icc/numba", "meshcurv/normal_cycle/numba", "trueform/directions", "vtk")


def shuffled(vertices, faces, block, seed=0):
    """The mesh with its vertices permuted within blocks of ``block`` (0: all) and, when all, its faces too."""
    if block is None:
        return vertices, faces
    rng = np.random.default_rng(seed)
    n = vertices.shape[0]
    if block == 0:
        order = rng.permutation(n)
    else:
        order = np.concatenate([start + rng.permutation(min(block, n - start)) for start in range(0, n, block)])
    index = np.empty_like(order)
    index[order] = np.arange(n)
    faces = index[faces]
    return vertices[order], faces[rng.permutation(faces.shape[0])] if block == 0 else faces


def machine_line() -> str:
    info = speed.machine_info()
    versions = ", ".join(f"{name} {version}" for name, version in info["versions"].items())
    return (
        f"- Machine: {info['cpu']}, {info['cores']} cores; load average at start {tuple(round(x, 1) for x in info['load_start'])}; "
        f"{versions}; meshcurv at commit {info['commit']}"
    )


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100k,1M")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--output", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "order.md"))
    args = parser.parse_args(argv)
    installed, _ = speed.peers_installed()
    keys = [key for key in IMPLEMENTATIONS if key.startswith("meshcurv/") or key in installed]
    lines = [
        "# Speed against the vertex order (issue 15)",
        "",
        f"Generated {time.strftime('%Y-%m-%d %H:%M')} by `python benchmarks/order.py --sizes {args.sizes} "
        f"--repeats {args.repeats}`",
        "",
        machine_line(),
        "",
        "Wall seconds, median of the calls after the first, each implementation in a fresh process "
        "on the same arrays. `span`: the median over the faces of the smallest index difference along "
        f"a side (meshcurv reorders from {_locality.SPAN_LIMIT}, at {_locality.MIN_VERTICES:,} vertices "
        "or more).",
        "",
    ]
    for label in args.sizes.split(","):
        _, vertices, faces = speed.build_mesh(label)
        lines += [
            f"## {label}: {vertices.shape[0]:,} vertices",
            "",
            "| order | span | reordered | " + " | ".join(speed.label_of(k) for k in keys) + " |",
            "|---|--:|---|" + "--:|" * len(keys),
        ]
        for name, block in ORDERS:
            v, f = shuffled(vertices, faces, block)
            span = _locality.median_side_span(f)
            cells = []
            with tempfile.TemporaryDirectory() as mesh_dir:
                np.save(os.path.join(mesh_dir, "v.npy"), np.ascontiguousarray(v))
                np.save(os.path.join(mesh_dir, "f.npy"), np.ascontiguousarray(f))
                for key in keys:
                    found = speed.run_child(key, mesh_dir, args.repeats + 1, 120.0, 600.0, 1800)
                    times = found.get("times", [])[1:] or found.get("times", [])
                    cells.append(f"{np.median(times):.2f}" if times else str(found)[:40])
                    print(label, name, key, cells[-1], flush=True)
            lines.append(
                f"| {name} | {span:,} | {'yes' if _locality.is_scattered(v.shape[0], f) else 'no'} | "
                + " | ".join(cells)
                + " |"
            )
        lines.append("")
    text = "\n".join(lines)
    partial = args.output + ".partial"
    with open(partial, "w") as out:
        out.write(text)
    os.replace(partial, args.output)  # the table appears whole or not at all
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
