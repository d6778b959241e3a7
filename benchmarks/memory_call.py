"""Memory of one call of the default method: page faults, system time, peak RSS, what is alive at the peak (issue 31).

``meshcurv.principal_curvatures(vertices, faces)`` (default method and options) on icospheres of the given
sizes. For each size it prints

- **first call**: a fresh ``python`` process that loads the arrays, calls once and reports its user and
  system CPU seconds, minor page faults and peak RSS (``VmHWM``, as ``benchmarks/speed.py``: interpreter,
  libraries, kernels loaded from the numba cache and the input included), and that peak per vertex;
- **second call**: in one fresh process that loads the arrays, after a warm-up call on them, the same figures
  for a second call (``getrusage``; the peak RSS is that of the process, both calls included);
- with ``--largest N``: the N largest blocks alive (``tracemalloc``, NumPy's and numba's arrays) when the
  call's traced memory is at its peak, each with the line of meshcurv that allocated it.

Run::

    .venv/bin/python benchmarks/memory_call.py --sizes 1M --repeats 3 --largest 25
    .venv/bin/python benchmarks/memory_call.py --sizes 4M --repeats 1

The system time is mostly the kernel zeroing (and, on a virtual machine, the host backing) the pages of
fresh arrays: it varies with the machine and its load more than the user time does.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile
import time

import numpy as np

SIZES = {"100k": 100, "1M": 316, "4M": 632}


def _usage() -> tuple[float, float, int]:
    used = resource.getrusage(resource.RUSAGE_SELF)
    return used.ru_utime, used.ru_stime, used.ru_minflt


def _high_water_mark() -> int:
    """Peak resident memory of this process (bytes), ``VmHWM``."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith("VmHWM"):
                return int(line.split()[1]) * 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


def _call(path: str, warm: bool) -> dict:
    """The child process: one call on the arrays of ``path`` (after a warm-up call when ``warm``), its figures."""
    import meshcurv

    arrays = np.load(path)
    vertices, faces = arrays["vertices"], arrays["faces"]
    if warm:
        meshcurv.principal_curvatures(vertices, faces)
    before, start = _usage(), time.perf_counter()
    meshcurv.principal_curvatures(vertices, faces)
    wall, after = time.perf_counter() - start, _usage()
    return {
        "user": after[0] - before[0],
        "system": after[1] - before[1],
        "faults": after[2] - before[2],
        "wall": wall,
        "peak": _high_water_mark(),
    }


def calls(vertices: np.ndarray, faces: np.ndarray, repeats: int, *, warm: bool) -> list[dict]:
    """The figures of the calls of ``repeats`` fresh processes: each one's first call, or its second (``warm``)."""
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "mesh.npz")
        np.savez(path, vertices=vertices, faces=faces)
        runs = []
        for _ in range(repeats):
            command = [sys.executable, __file__, "--child", path] + (["--warm"] if warm else [])
            done = subprocess.run(command, capture_output=True, text=True, check=True)
            runs.append(json.loads(done.stdout.strip().splitlines()[-1]))
    return runs


def alive_at_peak(vertices: np.ndarray, faces: np.ndarray, largest: int) -> tuple[int, list[tuple[int, str]]]:
    """``(traced bytes, [(bytes, allocating line), ...])``: the ``largest`` blocks alive at the call's traced peak.

    A first traced call finds the peak; a second one takes a snapshot at the first line of meshcurv where the
    traced memory reaches 98% of it (the second call may peak a little lower).
    """
    import tracemalloc

    import meshcurv

    meshcurv.principal_curvatures(vertices, faces)
    state: dict = {"peak": 0, "snapshot": None, "target": None}

    def tracer(frame, event, arg):
        if "meshcurv" not in frame.f_code.co_filename:
            return None

        def local(frame, event, arg):
            current, peak = tracemalloc.get_traced_memory()
            if state["target"] is None:
                state["peak"] = max(state["peak"], peak)
            elif state["snapshot"] is None and peak >= state["target"]:
                state["snapshot"] = tracemalloc.take_snapshot()
            return local

        return local

    tracemalloc.start(16)
    for target in (None, "set"):
        if target is not None:
            state["target"] = 0.98 * state["peak"]
        tracemalloc.reset_peak()
        sys.settrace(tracer)
        try:
            meshcurv.principal_curvatures(vertices, faces)
        finally:
            sys.settrace(None)
    tracemalloc.stop()
    snapshot = state["snapshot"]
    if snapshot is None:
        return state["peak"], []
    rows = []
    for statistic in snapshot.statistics("traceback")[:largest]:
        frames = [frame for frame in statistic.traceback if "meshcurv" in frame.filename]
        where = frames[-1] if frames else statistic.traceback[-1]
        rows.append((statistic.size, f"{where.filename.split('meshcurv' + os.sep)[-1]}:{where.lineno}"))
    return sum(statistic.size for statistic in snapshot.statistics("filename")), rows


def _summary(label: str, n_vertices: int, runs: list[dict]) -> str:
    def span(key: str, scale: float = 1.0, digits: int = 2) -> str:
        values = sorted(run[key] * scale for run in runs)
        low, high = values[0], values[-1]
        return f"{low:.{digits}f}" if low == high else f"{low:.{digits}f}-{high:.{digits}f}"

    return (
        f"| {label} | {len(runs)} | {span('user')} | {span('system')} | {span('faults', 1e-3, 1)}k | "
        f"{span('wall')} | {span('peak', 2.0**-20, 0)} | {span('peak', 1.0 / n_vertices, 0)} |"
    )


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="1M", help="comma-separated: " + ", ".join(SIZES))
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--largest", type=int, default=0, help="list the N largest blocks alive at the peak")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    parser.add_argument("--warm", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(_call(args.child, args.warm)))
        return
    import meshcurv

    print(f"load average at start: {os.getloadavg()}")
    for label in args.sizes.split(","):
        mesh = meshcurv.shapes.icosphere(SIZES[label])
        vertices, faces = np.ascontiguousarray(mesh.vertices), np.ascontiguousarray(mesh.faces, dtype=np.int64)
        n = vertices.shape[0]
        print(f"\nicosphere({SIZES[label]}), {n:,} vertices")
        print("| call | runs | user s | system s | minor faults | wall s | peak RSS MiB | peak B/vertex |")
        print("|---|--:|--:|--:|--:|--:|--:|--:|")
        print(_summary("first call, fresh process", n, calls(vertices, faces, args.repeats, warm=False)))
        print(_summary("second call, fresh process", n, calls(vertices, faces, args.repeats, warm=True)))
        if args.largest:
            traced, rows = alive_at_peak(vertices, faces, args.largest)
            print(f"\ntraced at the call's peak: {traced / 2**20:.0f} MiB; the largest blocks alive:")
            for size, where in rows:
                print(f"  {size / 2**20:7.1f} MiB  {where}")
    print(f"\nload average at end: {os.getloadavg()}")


if __name__ == "__main__":
    main()
