"""Time against error: every meshcurv method and every peer on the families of ``accuracy.py``, one run.

For each family of ``benchmarks/accuracy.py`` (regular, irregular, and noisy
meshes of 0.1 and 0.3 mean edge lengths of normal noise; each over its
surfaces: sphere, torus, ellipsoid, open cylinder, saddle, and the hemisphere
for the first two) and each implementation (every meshcurv method with its
defaults but ``'matgeom'``, whose values are matGeom's dimensionless numbers,
and the installed peers: libigl, VTK, trimesh, MeshLab, trueform),
this measures in one process and one run:

- **time**: the sum over the family's surfaces of the median wall and CPU
  seconds of ``--repeats`` calls on the same arrays (meshcurv: the whole
  ``principal_curvatures`` call, topology included, after a warm-up call of
  every method on a small mesh; MeshLab in a forked child as ``accuracy.py``
  runs it, its CPU seconds counted from the child's);
- **error**: the median over the family's surfaces of each surface's median
  relative error of the mean curvature H at the interior vertices the
  implementation reports (``accuracy.errors``: ``|H - H_exact| / max(|k1|, |k2|)``);
  ``cover``: the share of interior vertices reported, the lowest over the surfaces.

An implementation is on the family's front when no other is both faster (CPU
seconds) and at least as accurate. For each peer, the meshcurv methods that are
at least as accurate and faster are listed. The figure ``benchmarks/pareto.png``
has one panel per family (log-log: CPU seconds against median H error, the
front joined). Run from the repository root::

    python benchmarks/pareto.py                     # level 2 (10k-12k vertices): pareto.md, pareto.png
    python benchmarks/pareto.py --level 1 --repeats 1 --output /tmp/p.md --figure /tmp/p.png   # quick

The machine's load average is printed with the table: other jobs on the cores
lengthen wall times; CPU seconds are less sensitive.
"""

from __future__ import annotations

import argparse
import datetime
import os
import resource
import statistics
import sys
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import accuracy  # noqa: E402 - the families, the peers and the error of accuracy.py

import meshcurv  # noqa: E402
from meshcurv.estimators import DEFAULT_METHOD, ESTIMATORS  # noqa: E402
from meshcurv.radius import edge_radius  # noqa: E402

OUTPUT = os.path.join(HERE, "pareto.md")
FIGURE = os.path.join(HERE, "pareto.png")
FAMILIES = ("regular", "irregular", "noise 0.1h", "noise 0.3h")
TRUEFORM = "trueform principal_curvatures(k=2, directions=True)"


def peer_trueform(v, f):
    import trueform

    k0, k1, d0, _ = trueform.principal_curvatures(
        (np.ascontiguousarray(f, dtype=np.int32), np.ascontiguousarray(v)), k=2, directions=True
    )
    # trueform: k0 the larger, positive on an outward sphere (as meshcurv); d0 its direction
    k_min, k_max = np.minimum(k0, k1), np.maximum(k0, k1)
    dir_max = np.where((k0 >= k1)[:, None], d0, np.nan)
    return k_min, k_max, np.full_like(dir_max, np.nan), dir_max


def implementations(selected=None):
    """name -> (function(v, f, topology, radius) -> (k_min, k_max, valid), package or None); and the missing peers."""
    found = {}
    for method in ESTIMATORS:
        name = f"meshcurv {method}"
        if method == "matgeom":  # matGeom's numbers: dimensionless, not curvatures (see the README)
            continue
        if accuracy._wanted(name, selected):
            found[name] = (_meshcurv_call(method), None)
    peers, missing = accuracy.peers(selected)
    for name, (function, package) in peers.items():
        found[name] = (_peer_call(function), package)
    if accuracy._wanted(TRUEFORM, selected):
        try:
            import importlib.metadata

            import trueform  # noqa: F401 - a benchmark peer only (non-commercial licence)

            found[TRUEFORM] = (
                _peer_call(lambda v, f, r: peer_trueform(v, f)),
                f"trueform {importlib.metadata.version('trueform')}",
            )
        except Exception as exc:  # noqa: BLE001 - any import failure: not installed
            missing[TRUEFORM] = f"trueform: not installed ({type(exc).__name__})"
    return found, missing


def _meshcurv_call(method):
    def call(v, f, radius):
        r = meshcurv.principal_curvatures(v, f, method=method)  # the faces as given: topology in the call
        return r.k_min, r.k_max, r.valid

    return call


def _peer_call(function):
    def call(v, f, radius):
        k_min, k_max, _, _ = function(v, f, radius)
        return k_min, k_max, np.isfinite(k_min) & np.isfinite(k_max)

    return call


def timed(call, repeats):
    """``(result, median wall s, median CPU s)`` of ``repeats`` calls (CPU: this process and its children)."""
    walls, cpus, result = [], [], None
    for _ in range(repeats):
        children = resource.getrusage(resource.RUSAGE_CHILDREN)
        c0, t0 = time.process_time(), time.perf_counter()
        result = call()
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(
            time.process_time() - c0 + (after.ru_utime - children.ru_utime) + (after.ru_stime - children.ru_stime)
        )
        walls.append(wall)
    return result, statistics.median(walls), statistics.median(cpus)


def run(level: int, repeats: int, selected=None):
    found, missing = implementations(selected)
    small = meshcurv.shapes.icosphere(4)
    with warnings.catch_warnings():  # warm-up: kernels loaded (or compiled), libraries imported
        warnings.simplefilter("ignore")
        for name, (call, _) in found.items():
            if name.startswith("meshcurv"):
                call(small.vertices, small.faces, 0.1)
    rows = []  # one per (family, surface, implementation)
    for surface, variant, _, mesh in accuracy.surfaces([level]):
        if variant not in FAMILIES:
            continue
        v, f = np.ascontiguousarray(mesh.vertices), np.ascontiguousarray(mesh.faces, dtype=np.int64)
        topology = meshcurv.MeshTopology.from_faces(f, v.shape[0])
        interior = ~topology.boundary_vertices
        radius = edge_radius(v, topology)
        for name, (call, _) in found.items():
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                try:
                    (k_min, k_max, valid), wall, cpu = timed(lambda: call(v, f, radius), repeats)  # noqa: B023
                except Exception as exc:  # noqa: BLE001 - a failure on a mesh is a result
                    print(f"  {name} failed on {mesh.name}: {exc}", file=sys.stderr)
                    continue
            mask = interior & valid
            error = accuracy.errors(mesh, k_min, k_max, np.full((v.shape[0], 3), np.nan), mask)["H"][0]
            rows.append(
                {
                    "family": variant,
                    "surface": surface,
                    "n": v.shape[0],
                    "method": name,
                    "wall": wall,
                    "cpu": cpu,
                    "error": float(error),
                    "cover": float(mask.sum() / max(interior.sum(), 1)),
                }
            )
        print(f"{variant:10s} {surface:10s} ({v.shape[0]} vertices) done", file=sys.stderr)
    return rows, found, missing


def summarise(rows):
    """{family: {implementation: {wall, cpu, error, cover, surfaces}}}."""
    out: dict = {}
    for row in rows:
        entry = out.setdefault(row["family"], {}).setdefault(
            row["method"], {"wall": 0.0, "cpu": 0.0, "errors": [], "covers": [], "surfaces": 0}
        )
        entry["wall"] += row["wall"]
        entry["cpu"] += row["cpu"]
        entry["errors"].append(row["error"])
        entry["covers"].append(row["cover"])
        entry["surfaces"] += 1
    for family in out.values():
        for entry in family.values():
            errors = [e for e in entry["errors"] if np.isfinite(e)]
            entry["error"] = statistics.median(errors) if errors else float("nan")
            entry["cover"] = min(entry["covers"])
    return out


def front(family: dict) -> set:
    """The implementations no other beats in CPU time without being less accurate (and not NaN)."""
    kept = set()
    for name, entry in family.items():
        if not np.isfinite(entry["error"]):
            continue
        beaten = any(
            other != name and np.isfinite(o["error"]) and o["cpu"] < entry["cpu"] and o["error"] <= entry["error"]
            for other, o in family.items()
        )
        if not beaten:
            kept.add(name)
    return kept


def dominating(family: dict, peer: str) -> list:
    """meshcurv methods at least as accurate as ``peer`` and faster (CPU seconds), fastest first."""
    p = family.get(peer)
    if p is None or not np.isfinite(p["error"]):
        return []
    better = [
        (e["cpu"], name)
        for name, e in family.items()
        if name.startswith("meshcurv") and np.isfinite(e["error"]) and e["error"] <= p["error"] and e["cpu"] < p["cpu"]
    ]
    return [name for _, name in sorted(better)]


def more_accurate(family: dict, peer: str):
    """``(name, CPU ratio)`` of the fastest meshcurv method more accurate than ``peer``, or None."""
    p = family.get(peer)
    if p is None or not np.isfinite(p["error"]):
        return None
    better = sorted(
        (e["cpu"], name)
        for name, e in family.items()
        if name.startswith("meshcurv") and np.isfinite(e["error"]) and e["error"] < p["error"]
    )
    return (better[0][1], better[0][0] / p["cpu"]) if better else None


def in_short(summary, peer: str) -> str:
    """One sentence: where a meshcurv method is at least as accurate and faster than ``peer``; elsewhere, the
    fastest more accurate one and its CPU time as a multiple of the peer's."""
    wins, slower = {}, {}
    for family, entries in summary.items():
        if peer not in entries:
            continue
        best = dominating(entries, peer)
        if best:
            wins.setdefault(best[0].removeprefix("meshcurv "), []).append(family)
            continue
        found = more_accurate(entries, peer)
        if found:
            slower.setdefault(found[0].removeprefix("meshcurv "), []).append((family, found[1]))
    parts = []
    if wins:
        parts.append(
            "at least as accurate and faster: "
            + "; ".join(f"{method} ({', '.join(families)})" for method, families in wins.items())
        )
    if slower:
        parts.append(
            "more accurate but slower: "
            + "; ".join(
                f"{method} ({', '.join(f'{family}: {r:.2g}x the CPU time' for family, r in found)})"
                for method, found in slower.items()
            )
        )
    if not parts:
        parts.append("no meshcurv method at least as accurate")
    return f"**{peer}**: " + "; ".join(parts) + "."


def _source_commit() -> str:
    """The commit of the meshcurv imported (its source tree may be another checkout than this script's)."""
    import subprocess

    try:
        return (
            subprocess.run(
                ["git", "rev-parse", "--short", "HEAD"],
                capture_output=True,
                text=True,
                timeout=10,
                cwd=os.path.dirname(os.path.abspath(meshcurv.__file__)),
            ).stdout.strip()
            or "?"
        )
    except (OSError, subprocess.SubprocessError):
        return "?"


def markdown(summary, found, missing, args, load_start, load_end, n_by_family) -> str:
    packages = "; ".join(sorted({package for _, package in found.values() if package})) or "none"
    lines = [
        "# Time against error: the Pareto table (issue 31)",
        "",
        f"Generated {datetime.datetime.now().strftime('%Y-%m-%d %H:%M')} by `python benchmarks/pareto.py "
        + " ".join(sys.argv[1:])
        + f"`, meshcurv at commit {_source_commit()}.",
        "",
        f"- Meshes: level {args.level} of `benchmarks/accuracy.py` ("
        + "; ".join(f"{family}: {n}" for family, n in n_by_family.items())
        + " vertices); meshcurv's default method: "
        f"{DEFAULT_METHOD}; peers: {packages}" + ("; not run: " + "; ".join(missing.values()) if missing else ""),
        f"- Load average (1, 5, 15 min) at start {load_start}, at end {load_end} (2 cores; other jobs "
        "lengthen wall times, CPU seconds less)",
        "",
        "Time: the sum over a family's surfaces of the median of "
        f"{args.repeats} calls (wall and CPU seconds; meshcurv's whole call, topology included). Error: the "
        "median over the surfaces of each one's median relative error of H at the interior vertices reported. "
        "`cover`: the lowest share of interior vertices reported. `front`: no implementation is both faster "
        "(CPU) and at least as accurate.",
        "",
        "These meshes are small (the vertex counts above): the fixed cost of a call (meshcurv's: checks of the "
        "input and of the mesh, topology, orientation) weighs more in these times than on large meshes; "
        "`speed.md` has the times at 100k to 4M vertices.",
        "",
    ]
    for family, entries in summary.items():
        kept = front(entries)
        lines += [
            f"## {family}",
            "",
            "| implementation | wall s | CPU s | median H error | cover | front |",
            "|---|--:|--:|--:|--:|:-:|",
        ]
        for name, e in sorted(entries.items(), key=lambda item: item[1]["cpu"]):
            lines.append(
                f"| {name} | {e['wall']:.3f} | {e['cpu']:.3f} | {100 * e['error']:.3g}% | "
                f"{100 * e['cover']:.0f}% | {'yes' if name in kept else ''} |"
            )
        lines.append("")
    lines += [
        "## For each peer: the meshcurv methods at least as accurate and faster",
        "",
        "| peer | " + " | ".join(summary) + " |",
        "|---|" + "---|" * len(summary),
    ]
    peers = [name for name in found if not name.startswith("meshcurv")]
    for peer in peers:
        cells = [
            ", ".join(m.removeprefix("meshcurv ") for m in dominating(entries, peer)) or "none"
            for entries in summary.values()
        ]
        lines.append(f"| {peer} | " + " | ".join(cells) + " |")
    lines += ["", "In short, for each peer (the fastest such meshcurv method; CPU seconds):", ""]
    lines += [f"- {in_short(summary, peer)}" for peer in peers]
    lines.append("")
    return "\n".join(lines)


def _place_labels(ax, points, fontsize=7):
    """Label ``points`` [(x, y, text)] where a label covers no other label, no marker, and stays in the axes.

    Places are tried near the point first (right or left of it, above or below), then further up or down
    (a grey line then joins label and point); the positions are computed in pixels of the final layout.
    """
    to_px = ax.transData.transform
    to_data = ax.transData.inverted().transform
    dpi = ax.figure.dpi
    char, line = 0.6 * fontsize / 72 * dpi, 1.25 * fontsize / 72 * dpi
    box = ax.bbox
    markers = [to_px((x, y)) for x, y, _ in points]
    placed = []  # (left, right, bottom, top) in pixels

    def free(left, bottom, width):
        right, top = left + width, bottom + line
        if left < box.x0 or right > box.x1 or bottom < box.y0 or top > box.y1:
            return False
        if any(left < r and right > lft and bottom < t and top > b for lft, r, b, t in placed):
            return False
        return not any(left - 4 < mx < right + 4 and bottom - 4 < my < top + 4 for mx, my in markers)

    for x, y, text in sorted(points, key=lambda p: -p[1]):
        px, py = to_px((x, y))
        width = char * len(text)
        near = [(px + 6, py + 2), (px + 6, py - line - 2), (px - 6 - width, py + 2), (px - 6 - width, py - line - 2)]
        tries = [
            (k, (lx, ly + sign * k * line)) for k in range(8) for sign in ((1, -1) if k else (1,)) for lx, ly in near
        ]
        k, (lx, ly) = next(((k, spot) for k, spot in tries if free(*spot, width)), tries[0])
        placed.append((lx, lx + width, ly, ly + line))
        ax.annotate(
            text,
            (x, y),
            xytext=to_data((lx, ly)),
            textcoords="data",
            fontsize=fontsize,
            ha="left",
            va="bottom",
            arrowprops={"arrowstyle": "-", "color": "0.6", "lw": 0.5} if k else None,
        )


def _short(name: str) -> str:
    """The label of an implementation in the figure."""
    if name.startswith("meshcurv"):
        return name.removeprefix("meshcurv ")
    return name.split(" (")[0].replace(" principal_curvatures", "").replace(" principal_curvature", "")


def figure(summary, path: str, n_by_family=None) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    fig, axes = plt.subplots(2, 2, figsize=(13, 10.5))
    for ax, (family, entries) in zip(axes.ravel(), summary.items()):
        kept = front(entries)
        shown = {name: e for name, e in entries.items() if np.isfinite(e["error"]) and e["error"] > 0}
        for name, e in shown.items():
            ours = name.startswith("meshcurv")
            ax.scatter(
                e["cpu"],
                100 * e["error"],
                color="tab:blue" if ours else "tab:orange",
                marker="o" if ours else "s",
                s=40,
                zorder=3,
            )
        points = sorted((entries[n]["cpu"], 100 * entries[n]["error"]) for n in kept)
        if points:
            ax.step(*zip(*points), where="post", color="gray", lw=1, zorder=1)
        ax.set_xscale("log")
        ax.set_yscale("log")
        cpus = [e["cpu"] for e in shown.values()]
        errors = [100 * e["error"] for e in shown.values()]
        if cpus:
            ax.set_xlim(min(cpus) / 1.6, max(cpus) * 6)  # room for the labels right of the points
            ax.set_ylim(min(errors) / 2.5, max(errors) * 2.5)
        size = f" ({n_by_family[family]} vertices)" if n_by_family and family in n_by_family else ""
        ax.set_title(f"{family}{size}")
        ax.set_xlabel("CPU seconds, log scale (sum over the family's surfaces)")
        ax.set_ylabel("median relative error of H (%), log scale")
        ax.grid(True, which="both", alpha=0.3)
    handles = [
        Line2D([], [], color="tab:blue", marker="o", ls="", label="meshcurv methods"),
        Line2D([], [], color="tab:orange", marker="s", ls="", label="peers"),
        Line2D([], [], color="gray", lw=1, label="front: nothing faster and at least as accurate"),
    ]
    fig.legend(handles=handles, loc="upper center", ncol=3, bbox_to_anchor=(0.5, 0.965), frameon=False)
    fig.suptitle("Time against error, one run: lower left is better (benchmarks/pareto.md)")
    fig.tight_layout(rect=(0, 0, 1, 0.94))
    for ax, entries in zip(axes.ravel(), summary.values()):  # in the final layout: positions in pixels hold
        _place_labels(
            ax,
            [
                (e["cpu"], 100 * e["error"], _short(name))
                for name, e in entries.items()
                if np.isfinite(e["error"]) and e["error"] > 0
            ],
        )
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--level",
        type=int,
        default=2,
        choices=(0, 1, 2),
        help="resolution of accuracy.py's meshes (default: %(default)s, the finest)",
    )
    parser.add_argument("--repeats", type=int, default=3, help="calls per mesh and implementation (median)")
    parser.add_argument("--methods", nargs="*", help="only the implementations whose name contains one of these")
    parser.add_argument("--output", default=OUTPUT)
    parser.add_argument("--figure", default=FIGURE)
    args = parser.parse_args(argv)
    load_start = tuple(round(x, 1) for x in os.getloadavg())
    rows, found, missing = run(args.level, args.repeats, args.methods)
    load_end = tuple(round(x, 1) for x in os.getloadavg())
    summary = summarise(rows)
    n_by_family = {}
    for row in rows:
        n_by_family.setdefault(row["family"], set()).add(row["n"])
    n_by_family = {family: f"{min(ns):,}-{max(ns):,}" for family, ns in n_by_family.items()}
    text = markdown(summary, found, missing, args, load_start, load_end, n_by_family)
    with open(args.output, "w", encoding="utf-8") as handle:
        handle.write(text)
    figure(summary, args.figure, n_by_family)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
