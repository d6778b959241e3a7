"""Peak memory of ``point_cloud_curvatures(..., method="corrected_measures")`` per backend and size (issue 29).

The clouds are the vertices of voxel spheres in voxels of 2 x 1 x 1
(``meshcurv.shapes.voxel_sphere(radius, spacing=(2.0, 1.0, 1.0), seed=238)``, the class of the fuzzer's memory
findings 320/7 and 325/19 in ``benchmarks/fuzz_api.md``, round 18), with their exact normals given or (with
``--estimated-normals``) estimated by the call. The radius is chosen for about the asked number of points
(1k: 8.9, 10k: 28.2, 32k: 50.5, 100k: 89.3; 1k shows the fixed cost).

Each backend and size runs in fresh ``python`` processes (the ``MESHCURV_BACKEND`` of the child) that load the
cloud from a file, report their resident memory just before the call (``VmRSS``: interpreter, NumPy, SciPy,
meshcurv, the cloud), call once, and report their peak resident memory (``VmHWM``: with numba, its runtime and
the kernels loaded from the cache are in it) and the call's CPU seconds (user + system, ``getrusage``). The
figure the fuzzer caps is the peak above the parent's memory; "above" here is the peak above the child's own
memory before the call, and "per point" that divided by the points.

Run (the "before" of a change on a snapshot of its parent commit: ``PYTHONPATH=<snapshot>/src``)::

    .venv/bin/python benchmarks/memory_pointcloud.py --sizes 10k,32k,100k --backends numpy,numba
    .venv/bin/python benchmarks/memory_pointcloud.py --sizes 32k --backends numpy --estimated-normals
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
import warnings

import numpy as np

RADII = {"1k": 8.9, "10k": 28.2, "32k": 50.5, "100k": 89.3}
SPACING = (2.0, 1.0, 1.0)
SEED = 238


def _status(field: str) -> int:
    """A field of ``/proc/self/status`` in bytes (``VmRSS``, ``VmHWM``)."""
    with open("/proc/self/status") as status:
        for line in status:
            if line.startswith(field):
                return int(line.split()[1]) * 1024
    raise RuntimeError(f"no {field} in /proc/self/status")


def _call(path: str) -> dict:
    """The child process: one call on the cloud of ``path``, its figures."""
    from meshcurv import point_cloud_curvatures

    arrays = np.load(path)
    points = arrays["points"]
    normals = arrays["normals"] if "normals" in arrays.files else None
    before = _status("VmRSS")
    start, wall = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # (the counts of NaN points: the valid count is reported)
        result = point_cloud_curvatures(points, method="corrected_measures", normals=normals)
    end, wall = resource.getrusage(resource.RUSAGE_SELF), time.perf_counter() - wall
    return {
        "before": before,
        "peak": _status("VmHWM"),
        "cpu": end.ru_utime - start.ru_utime + end.ru_stime - start.ru_stime,
        "wall": wall,
        "valid": int(np.count_nonzero(result.valid)),
    }


def runs(points: np.ndarray, normals: np.ndarray | None, backend: str, repeats: int) -> list[dict]:
    """The figures of ``repeats`` fresh processes, each calling once on ``backend``."""
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "cloud.npz")
        arrays = {"points": points} if normals is None else {"points": points, "normals": normals}
        np.savez(path, **arrays)
        out = []
        for _ in range(repeats):
            env = dict(os.environ, MESHCURV_BACKEND=backend)
            done = subprocess.run(
                [sys.executable, __file__, "--child", path], capture_output=True, text=True, check=True, env=env
            )
            out.append(json.loads(done.stdout.strip().splitlines()[-1]))
        return out


def _span(values, digits: int = 0) -> str:
    low, high = min(values), max(values)
    return f"{low:.{digits}f}" if f"{low:.{digits}f}" == f"{high:.{digits}f}" else f"{low:.{digits}f}-{high:.{digits}f}"


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default="10k,32k,100k", help="comma-separated: " + ", ".join(RADII))
    parser.add_argument("--backends", default="numpy,numba", help="comma-separated: numpy, numba")
    parser.add_argument("--repeats", type=int, default=1)
    parser.add_argument("--estimated-normals", action="store_true", help="let the call estimate the normals")
    parser.add_argument("--child", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.child:
        print(json.dumps(_call(args.child)))
        return
    from meshcurv import shapes

    import meshcurv

    print(f"meshcurv from {os.path.dirname(meshcurv.__file__)}; load average at start: {os.getloadavg()}")
    print(f"normals: {'estimated' if args.estimated_normals else 'exact, given'}\n")
    print(
        "| backend | cloud | points | runs | RSS before MiB | peak RSS MiB | peak above MiB | KiB/point | CPU s | valid |"
    )
    print("|---|---|--:|--:|--:|--:|--:|--:|--:|--:|")
    mebi = 2.0**-20
    for label in args.sizes.split(","):
        mesh = shapes.voxel_sphere(RADII[label], spacing=SPACING, seed=SEED)
        points = np.ascontiguousarray(mesh.vertices)
        normals = None if args.estimated_normals else np.ascontiguousarray(mesh.normals)
        n = points.shape[0]
        for backend in args.backends.split(","):
            found = runs(points, normals, backend, args.repeats)
            above = [run["peak"] - run["before"] for run in found]
            print(
                f"| {backend} | voxel_sphere({RADII[label]:g}, 2x1x1) | {n:,} | {len(found)} | "
                f"{_span([run['before'] * mebi for run in found])} | {_span([run['peak'] * mebi for run in found])} | "
                f"{_span([a * mebi for a in above])} | {_span([a / 1024 / n for a in above], 1)} | "
                f"{_span([run['cpu'] for run in found], 2)} | {_span([run['valid'] for run in found])} |",
                flush=True,
            )
    print(f"\nload average at end: {os.getloadavg()}")


if __name__ == "__main__":
    main()
