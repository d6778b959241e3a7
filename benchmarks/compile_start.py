"""First use and warm start of the default method (issue 31): compile CPU on a cold cache, a fresh process on a warm one.

Cold: a fresh process with ``NUMBA_CACHE_DIR`` an empty directory reads the mesh and calls
``meshcurv.principal_curvatures`` once; numba's ``numba:compile`` events give each kernel's compile
CPU (``time.process_time``, the process's CPU over all its threads; nested compilations counted once,
in their caller's total and in their own exclusive line). Warm: fresh processes on the cache the cold
one wrote, each timing its own stages (import, read, the first call, a second call) and measured from
outside (wall and user + system CPU of the whole process, interpreter start and exit included).

Run from the repository root::

    python benchmarks/compile_start.py                      # spot.obj, 1 cold and 5 warm processes
    python benchmarks/compile_start.py --cold 3 --warm 9 --output /tmp/compile_start.md

Every child runs with Python's bytecode cache on (``PYTHONDONTWRITEBYTECODE`` removed: an installed
package has its ``.pyc`` files). CPU figures hold on a busy machine; wall figures do not (the load
average is printed beside them).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

MESH = str(Path(__file__).resolve().parents[2] / "shared" / "meshes" / "spot.obj")  # ../shared beside the repository

COLD = r"""
import json, sys, time
from numba.core import event

records, stack = [], []


class Listener(event.Listener):
    def on_start(self, ev):
        function = getattr((ev.data or {}).get("dispatcher"), "py_func", None)
        name = f"{getattr(function, '__module__', '?')}.{getattr(function, '__qualname__', '?')}"
        stack.append([name, time.process_time(), 0.0])

    def on_end(self, ev):
        name, start, inner = stack.pop()
        total = time.process_time() - start
        if stack:
            stack[-1][2] += total
        records.append((name, total, total - inner, len(stack)))


event.register("numba:compile", Listener())
start = time.process_time()
import meshcurv

mesh = meshcurv.read_mesh(sys.argv[1])
before = time.process_time()
meshcurv.principal_curvatures(mesh.vertices, mesh.faces)
after = time.process_time()
json.dump({"call_cpu": after - before, "process_cpu": after - start,
           "compile_cpu": sum(r[1] for r in records if r[3] == 0), "records": records}, sys.stdout)
"""

WARM = r"""
import json, sys, time
t0 = time.perf_counter()
import meshcurv
t1 = time.perf_counter()
mesh = meshcurv.read_mesh(sys.argv[1])
t2 = time.perf_counter()
meshcurv.principal_curvatures(mesh.vertices, mesh.faces)
t3 = time.perf_counter()
meshcurv.principal_curvatures(mesh.vertices, mesh.faces)
t4 = time.perf_counter()
json.dump({"import": t1 - t0, "read": t2 - t1, "first call": t3 - t2, "second call": t4 - t3}, sys.stdout)
"""

ALL = r"""
import json, sys, time, warnings
warnings.simplefilter("ignore")
import meshcurv

mesh = meshcurv.read_mesh(sys.argv[1])
cpu = {}
for method in meshcurv.METHODS:
    start = time.process_time()
    meshcurv.principal_curvatures(mesh.vertices, mesh.faces, method=method)
    cpu[method] = time.process_time() - start
json.dump(cpu, sys.stdout)
"""

PARTS = r"""
import json, sys, time
parts = {}
t = time.perf_counter(); import meshcurv; parts["import meshcurv"] = time.perf_counter() - t
parts["numba imported by import meshcurv"] = float("numba" in sys.modules)
t = time.perf_counter(); mesh = meshcurv.read_mesh(sys.argv[1]); parts["read"] = time.perf_counter() - t
t = time.perf_counter(); import numba; parts["import numba"] = time.perf_counter() - t
from numba.core import caching
from numba.core.registry import cpu_target
t = time.perf_counter(); cpu_target.target_context.refresh(); parts["numba's registries (once per process)"] = time.perf_counter() - t
loads = []
load = caching.Cache.load_overload


def timed(self, signature, context):
    t = time.perf_counter()
    found = load(self, signature, context)
    loads.append(time.perf_counter() - t)
    return found


caching.Cache.load_overload = timed
t = time.perf_counter(); meshcurv.principal_curvatures(mesh.vertices, mesh.faces); first = time.perf_counter() - t
parts["kernels loaded from the cache"] = sum(loads)
parts["number of kernels loaded"] = len(loads)
parts["first call, the loads excluded"] = first - sum(loads)
json.dump(parts, sys.stdout)
"""


def _environment(cache: str) -> dict:
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    env["NUMBA_CACHE_DIR"] = cache
    env.pop("MESHCURV_BACKEND", None)
    return env


def _child(code: str, mesh: str, env: dict) -> tuple[dict, float, float]:
    """``(its JSON, wall s, user + system CPU s)`` of a fresh interpreter running ``code``."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    run = subprocess.run([sys.executable, "-c", code, mesh], capture_output=True, text=True, env=env, check=False)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if run.returncode:
        raise RuntimeError(f"child failed:\n{run.stderr}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return json.loads(run.stdout), wall, cpu


def _kernels_table(records: list) -> list[str]:
    """Markdown rows: each function compiled, its CPU including what it compiled inside, and without."""
    totals: dict[str, list] = {}
    for name, total, own, depth in records:
        row = totals.setdefault(name, [0, 0.0, 0.0, depth == 0])
        row[0] += 1
        row[1] += total
        row[2] += own
    lines = ["| function compiled | times | CPU s with its callees | CPU s alone |", "|---|--:|--:|--:|"]
    for name, (count, total, own, top) in sorted(totals.items(), key=lambda item: -item[1][2]):
        if own < 0.05:
            continue
        label = f"**{name}**" if top else name
        lines.append(f"| {label} | {count} | {total:.2f} | {own:.2f} |")
    return lines


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", default=MESH)
    parser.add_argument("--cold", type=int, default=1, help="cold processes (each on an empty cache)")
    parser.add_argument("--warm", type=int, default=5, help="warm processes (after one untimed)")
    parser.add_argument("--output", default=None, help="write the markdown there (default: stdout only)")
    parser.add_argument(
        "--all-methods",
        action="store_true",
        help="also every method's first call in one more cold process (about a minute of CPU)",
    )
    args = parser.parse_args(argv)

    lines = [
        f"Generated {time.strftime('%Y-%m-%d %H:%M', time.gmtime())} UTC by "
        f"`python benchmarks/compile_start.py {' '.join(argv if argv is not None else sys.argv[1:])}`".rstrip(),
        "",
        f"Machine: {platform.machine()}, {os.cpu_count()} CPUs, Python {platform.python_version()}; mesh {args.mesh}.",
        "",
    ]
    import numba
    import numpy

    source = os.environ.get("PYTHONPATH")
    lines.append(
        f"numba {numba.__version__}, numpy {numpy.__version__}; meshcurv "
        f"{'from PYTHONPATH=' + source if source else 'as installed'}."
    )
    lines.append("")
    colds = []
    caches = []
    try:
        if not args.cold:  # the warm processes' cache, written by their untimed first run
            caches.append(tempfile.mkdtemp(prefix="meshcurv-cold-"))
        for _ in range(args.cold):
            caches.append(tempfile.mkdtemp(prefix="meshcurv-cold-"))
            data, wall, cpu = _child(COLD, args.mesh, _environment(caches[-1]))
            colds.append((data, wall, cpu, os.getloadavg()[0]))
        text = _report(args, lines, colds, _environment(caches[-1]))
    finally:
        for cache in caches:
            shutil.rmtree(cache, ignore_errors=True)
    print(text)
    if args.output:
        Path(args.output).write_text(text)
    return 0


def _report(args, lines: list[str], colds: list, env: dict) -> str:
    """The markdown of the cold runs, then of the warm processes run on ``env``'s cache."""
    if colds:
        _cold_report(lines, colds)
    if args.all_methods:
        _all_methods_report(args, lines)
    if args.warm:
        _warm_report(args, lines, env)
    return "\n".join(lines) + "\n"


def _cold_report(lines: list[str], colds: list) -> None:
    lines.append("## Cold cache: compile CPU of the default call")
    lines.append("")
    lines.append("| run | compile CPU s (numba events) | first call CPU s | process CPU s | process wall s | load |")
    lines.append("|--:|--:|--:|--:|--:|--:|")
    for k, (data, wall, cpu, load) in enumerate(colds):
        lines.append(
            f"| {k + 1} | {data['compile_cpu']:.2f} | {data['call_cpu']:.2f} | {cpu:.2f} | {wall:.1f} | {load:.1f} |"
        )
    lines.append("")
    lines.append(
        "Each function compiled in the first cold run (bold: compiled at a call from Python; the others "
        "inside their caller's compilation); functions under 0.05 s alone left out:"
    )
    lines.append("")
    lines.extend(_kernels_table(colds[0][0]["records"]))
    lines.append("")


def _all_methods_report(args, lines: list[str]) -> None:
    cache = tempfile.mkdtemp(prefix="meshcurv-cold-")
    try:
        cpu = _child(ALL, args.mesh, _environment(cache))[0]
    finally:
        shutil.rmtree(cache, ignore_errors=True)
    lines.append(
        "Every method's first call, in the order of `meshcurv.METHODS`, in one more fresh process on an "
        "empty cache (CPU s; a method finds compiled the kernels it shares with those before it):"
    )
    lines.append("")
    lines.append("| " + " | ".join(cpu) + " | all |")
    lines.append("|" + "--:|" * (len(cpu) + 1))
    lines.append("| " + " | ".join(f"{v:.2f}" for v in cpu.values()) + f" | {sum(cpu.values()):.2f} |")
    lines.append("")


def _warm_report(args, lines: list[str], env: dict) -> None:
    _child(WARM, args.mesh, env)  # untimed: the bytecode cache written, the pages warm
    warms = [(*_child(WARM, args.mesh, env), os.getloadavg()[0]) for _ in range(args.warm)]
    lines.append(f"## Warm cache: a fresh process, median of {args.warm}")
    lines.append("")
    lines.append("| | median | runs |")
    lines.append("|---|--:|---|")
    rows = [
        ("process wall s (whole process)", [w for _, w, _, _ in warms]),
        ("process CPU s (user + system)", [c for _, _, c, _ in warms]),
    ]
    for key in ("import", "read", "first call", "second call"):
        rows.append((f"{key} wall s (inside)", [d[key] for d, _, _, _ in warms]))
    for label, values in rows:
        lines.append(f"| {label} | {statistics.median(values):.3f} | {', '.join(f'{v:.2f}' for v in values)} |")
    lines.append(f"| load average (1 min) | {statistics.median(load for *_, load in warms):.1f} | |")
    lines.append("")
    parts = [_child(PARTS, args.mesh, env)[0] for _ in range(3)]
    lines.append(
        "Where the warm process's time goes (wall s inside the process, median of 3 more processes; "
        "numba imported and its registries loaded before the call, then each load from the cache timed):"
    )
    lines.append("")
    lines.append("| stage | median | runs |")
    lines.append("|---|--:|---|")
    for key in parts[0]:
        values = [p[key] for p in parts]
        lines.append(f"| {key} | {statistics.median(values):.3f} | {', '.join(f'{v:.3f}' for v in values)} |")


if __name__ == "__main__":
    sys.exit(main())
