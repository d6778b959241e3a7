"""Where a call of ``normal_cycle`` or ``matgeom`` spends its time, stage by stage, beside trueform (issue 31).

The stage timers of ``benchmarks/profile_call.py`` (exclusive wall and CPU
seconds of each wrapped function; ``other`` is the call minus every stage),
with the compiled kernels of the two methods and the topology's parts added
as stages, on icospheres, the topology built inside the call. trueform's
``principal_curvatures(k=2, directions=True)`` (a benchmark peer only, never
a dependency) is timed in the same process on the same arrays when it is
installed, and the ratios printed. Medians by CPU time of ``--repeats`` calls
after a warm-up call on the same mesh::

    .venv/bin/python benchmarks/profile_ring.py --sizes 1M --repeats 5
"""

from __future__ import annotations

import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import profile_call  # noqa: E402  (the stage timers, beside this file)

import meshcurv  # noqa: E402

#: Stages added to those of ``profile_call`` (the same format: stage, module, attribute).
RING_STAGES = (
    ("normal_cycle kernel: edge sums", "meshcurv._kernels.normal_cycle", "normal_cycle_sums"),
    ("normal_cycle kernel: smoothing, curvatures", "meshcurv._kernels.normal_cycle", "normal_cycle_finish"),
    ("matgeom kernel: edge tensors", "meshcurv._kernels.matgeom", "matgeom_vertex_tensors"),
    ("matgeom kernel: edge tensors", "meshcurv._kernels.matgeom", "matgeom_vertex_sums"),
    ("matgeom kernel: smoothing, eigenvectors", "meshcurv._kernels.matgeom", "matgeom_finish"),
    ("matgeom: pairing (open meshes)", "meshcurv.estimators.matgeom", "matgeom_pairing"),
    ("topology: bow-tie walks (twin sides)", "meshcurv._kernels.topology", "bowtie_from_twins"),
    ("topology: bow-tie walks (twin sides)", "meshcurv._kernels.topology", "bowtie_walks"),
    ("topology: degenerate_faces", "meshcurv.topology", "MeshTopology.degenerate_faces"),
    ("topology: interior_edges", "meshcurv.topology", "MeshTopology.interior_edges"),
    ("validate faces: triangles", "meshcurv._validation", "checked_triangles"),
    ("length scales", "meshcurv._prepared", "PreparedMesh.length_scales"),
)


def _median_call(call, repeats: int) -> tuple[float, float, dict, dict]:
    call()  # warm-up: kernels loaded, pages touched
    runs = []
    for _ in range(repeats):
        profile_call.TIMERS.reset()
        wall, cpu = time.perf_counter(), time.process_time()
        call()
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        runs.append((wall, cpu, dict(profile_call.TIMERS.wall), dict(profile_call.TIMERS.cpu)))
    runs.sort(key=lambda run: run[1])
    return runs[len(runs) // 2]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="1M")
    parser.add_argument("--methods", default="normal_cycle,matgeom")
    parser.add_argument("--repeats", type=int, default=5, help="calls per size and method (the median by CPU)")
    args = parser.parse_args(argv)
    profile_call.STAGES = profile_call.STAGES + RING_STAGES
    profile_call.install(profile_call.TIMERS)
    print(f"load average at start: {profile_call.load()}")
    for label in args.sizes.split(","):
        n = profile_call.SIZES[label]
        mesh = meshcurv.shapes.icosphere(n)
        v = np.ascontiguousarray(mesh.vertices)
        f = np.ascontiguousarray(mesh.faces, dtype=np.int64)
        results = []
        for method in args.methods.split(","):
            wall, cpu, stage_wall, stage_cpu = _median_call(
                lambda method=method: meshcurv.principal_curvatures(v, f, method=method), args.repeats
            )
            results.append((f"{method} icosphere({n})", v.shape[0], wall, cpu, stage_wall, stage_cpu))
        print()
        print(profile_call.table(results))
        try:
            import trueform
        except ImportError:
            print("\ntrueform is not installed: no ratios")
            continue
        profile_call.TIMERS.reset()
        tf_wall, tf_cpu, _, _ = _median_call(
            lambda: trueform.principal_curvatures((f, v), k=2, directions=True), args.repeats
        )
        print(f"\ntrueform principal_curvatures(k=2, directions=True): {tf_wall:.3f} s wall, {tf_cpu:.3f} s CPU")
        for name, _, wall, cpu, _, _ in results:
            print(f"- {name}: trueform / this = {tf_wall / wall:.2f}x wall, {tf_cpu / cpu:.2f}x CPU")
    print(f"\nload average at end: {profile_call.load()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
