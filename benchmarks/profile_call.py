"""Where one call of the default method spends its time, stage by stage (issue 31).

Times ``meshcurv.principal_curvatures(vertices, faces)`` (default method,
default options) on icospheres of the given sizes, after a warm-up call on the
same mesh (kernels loaded, pages touched). Every stage below is a function of
meshcurv wrapped with a timer that records its *exclusive* wall and CPU time
(the time of the stages it calls is counted in theirs, not twice); what no
stage covers is ``other`` (the Python around them). Topology properties
computed on first use (bow-ties, components, neighbour lists ...) are counted
as "topology: <property>" wherever they are first asked for. The call's total is
measured around the whole call, outside the wrappers. Run::

    .venv/bin/python benchmarks/profile_call.py --sizes 100k,1M,4M --markdown benchmarks/speed_profile.md

Numbers depend on the load of the machine; the script prints ``uptime``'s
load averages before and after.
"""

from __future__ import annotations

import argparse
import functools
import os
import platform
import sys
import time

import numpy as np

import meshcurv
from meshcurv import _backend

SIZES = {"10k": 32, "100k": 100, "250k": 158, "1M": 316, "4M": 632}

#: (stage, module, attribute): the functions timed, in the order of a call. An attribute ``A.b``
#: is an attribute of a class; a ``cached_property`` is wrapped in its getter.
STAGES = (
    ("validate vertices", "meshcurv._validation", "as_vertices"),
    ("validate faces", "meshcurv._validation", "as_faces"),
    ("mesh object", "meshcurv._adapters", "mesh_arrays"),
    ("locality (scattered order)", "meshcurv._locality", "is_scattered"),
    ("locality (scattered order)", "meshcurv._locality", "reordering"),
    ("topology build", "meshcurv.topology", "MeshTopology._build"),
    ("weld", "meshcurv.weld", "weld_vertices"),
    ("double-sided faces", "meshcurv.weld", "drop_double_sided"),
    ("orientation", "meshcurv.orient", "oriented_topology"),
    ("topology: bowtie_vertices", "meshcurv.topology", "MeshTopology.bowtie_vertices"),
    ("topology: vertex_components", "meshcurv.topology", "MeshTopology.vertex_components"),
    ("topology: n_components", "meshcurv.topology", "MeshTopology.n_components"),
    ("topology: neighbour_lists", "meshcurv.topology", "MeshTopology.neighbour_lists"),
    ("topology: referenced_vertices", "meshcurv.topology", "MeshTopology.referenced_vertices"),
    ("topology: inconsistent_edges", "meshcurv.topology", "MeshTopology.inconsistent_edges"),
    ("topology: boundary_vertices", "meshcurv.topology", "MeshTopology.boundary_vertices"),
    ("topology: n_boundary_loops", "meshcurv.topology", "MeshTopology.n_boundary_loops"),
    ("face cross products", "meshcurv._prepared", "PreparedMesh.cross"),
    ("zero-area faces", "meshcurv._prepared", "PreparedMesh.degenerate"),
    ("vertex normals (face means)", "meshcurv._prepared", "PreparedMesh.vertex_normals"),
    ("defects", "meshcurv.defects", "defect_codes"),
    ("radius: components", "meshcurv.radius", "component_radii"),
    ("radius: noise fits", "meshcurv.radius", "noise_level"),
    ("radius: voxel rule (lattice, pilot)", "meshcurv.radius", "voxel_surface_radius"),
    ("normal fits (kernel)", "meshcurv.estimators.icc", "fitted_normals"),
    ("face measures", "meshcurv.measures", "face_measures"),
    ("ball sums (kernel)", "meshcurv.neighborhoods", "ball_face_sums"),
    ("curvatures from sums", "meshcurv.measures", "curvatures_from_measures"),
    ("finish (NaN, result)", "meshcurv.estimators._support", "finish"),
    ("diagnosis", "meshcurv.diagnosis", "diagnose"),
    ("diagnosis", "meshcurv.diagnosis", "mesh_diagnosis"),
    ("result: reasons, expand, warning", "meshcurv.curvature", "_finished"),
)


class Timers:
    """Exclusive wall and CPU seconds per stage (a stack subtracts the nested stages)."""

    def __init__(self):
        self.wall: dict[str, float] = {}
        self.cpu: dict[str, float] = {}
        self.stack: list[list[float]] = []  # [nested wall, nested cpu] of each open stage

    def wrap(self, stage, function):
        @functools.wraps(function)
        def timed(*args, **kwargs):
            self.stack.append([0.0, 0.0])
            wall, cpu = time.perf_counter(), time.process_time()
            try:
                return function(*args, **kwargs)
            finally:
                wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
                nested = self.stack.pop()
                self.wall[stage] = self.wall.get(stage, 0.0) + wall - nested[0]
                self.cpu[stage] = self.cpu.get(stage, 0.0) + cpu - nested[1]
                if self.stack:
                    self.stack[-1][0] += wall
                    self.stack[-1][1] += cpu
        timed.__wrapped_stage__ = True
        return timed

    def reset(self):
        self.wall.clear()
        self.cpu.clear()


def install(timers: Timers) -> None:
    """Wrap every function of :data:`STAGES`, wherever a meshcurv module holds it by name."""
    import importlib
    from functools import cached_property

    for stage, module_name, attribute in STAGES:
        module = importlib.import_module(module_name)
        if "." in attribute:
            owner_name, name = attribute.split(".")
            owner = getattr(module, owner_name)
            value = owner.__dict__.get(name)
            if value is None:  # not in this version of meshcurv
                continue
            if isinstance(value, cached_property):
                value.func = timers.wrap(stage, value.func)
            elif isinstance(value, classmethod):
                setattr(owner, name, classmethod(timers.wrap(stage, value.__func__)))
            else:
                setattr(owner, name, timers.wrap(stage, value))
            continue
        original = getattr(module, attribute, None)
        if original is None:  # not in this version of meshcurv
            continue
        timed = timers.wrap(stage, original)
        for loaded in list(sys.modules.values()):
            if getattr(loaded, "__name__", "").startswith("meshcurv") and getattr(loaded, attribute, None) is original:
                setattr(loaded, attribute, timed)


def load() -> str:
    return ", ".join(f"{x:.2f}" for x in os.getloadavg())


def profile(label: str, repeats: int) -> tuple[str, int, float, float, dict, dict]:
    n = SIZES[label]
    mesh = meshcurv.shapes.icosphere(n)
    v = np.ascontiguousarray(mesh.vertices)
    f = np.ascontiguousarray(mesh.faces, dtype=np.int64)
    meshcurv.principal_curvatures(v, f)  # warm-up: kernels loaded, pages touched
    runs = []
    for _ in range(repeats):
        TIMERS.reset()
        wall, cpu = time.perf_counter(), time.process_time()
        meshcurv.principal_curvatures(v, f)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
        runs.append((wall, cpu, dict(TIMERS.wall), dict(TIMERS.cpu)))
    runs.sort(key=lambda run: run[0])
    wall, cpu, stage_wall, stage_cpu = runs[len(runs) // 2]
    return f"icosphere({n})", v.shape[0], wall, cpu, stage_wall, stage_cpu


def table(results) -> str:
    stages = list(dict.fromkeys(stage for stage, _, _ in STAGES))
    head = "| stage | " + " | ".join(f"{name} wall s | CPU s | us/vertex (CPU)" for name, *_ in results) + " |"
    rule = "|---|" + "--:|--:|--:|" * len(results)
    lines = [head, rule]
    for stage in [*stages, "other (Python around the stages)"]:
        cells = []
        for _name, n_vertices, wall, cpu, stage_wall, stage_cpu in results:
            if stage.startswith("other"):
                w, c = wall - sum(stage_wall.values()), cpu - sum(stage_cpu.values())
            else:
                w, c = stage_wall.get(stage), stage_cpu.get(stage)
            cells.append("| | " if w is None else f"{w:.3f} | {c:.3f} | {1e6 * c / n_vertices:.2f}")
        if any(cell != "| | " for cell in cells):
            lines.append(f"| {stage} | " + " | ".join(cells) + " |")
    totals = [f"**{wall:.3f}** | **{cpu:.3f}** | **{1e6 * cpu / n:.2f}**" for _, n, wall, cpu, _, _ in results]
    lines.append("| **whole call** | " + " | ".join(totals) + " |")
    return "\n".join(lines)


TIMERS = Timers()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100k,1M,4M")
    parser.add_argument("--repeats", type=int, default=3, help="calls per size (the median by wall time is shown)")
    parser.add_argument("--markdown", help="write the table to this file")
    args = parser.parse_args(argv)
    install(TIMERS)
    start_load = load()
    results = []
    for label in args.sizes.split(","):
        results.append(profile(label, args.repeats))
        print(f"{label}: {results[-1][2]:.3f} s wall, {results[-1][3]:.3f} s CPU", file=sys.stderr)
    names = ", ".join(f"{name} ({n:,} vertices)" for name, n, *_ in results)
    text = "\n".join([
        "# Where the default's time goes, stage by stage (issue 31)",
        "",
        f"Generated {time.strftime('%Y-%m-%d %H:%M')} by `python benchmarks/profile_call.py --sizes {args.sizes} "
        f"--repeats {args.repeats}`: `meshcurv.principal_curvatures(v, f)` (method {meshcurv.estimators.DEFAULT_METHOD!r}, "
        f"backend {_backend.backend_name()}, {_threads()} threads) on {names}; the call of median wall time of "
        f"{args.repeats} after a warm-up call on the same mesh.",
        "",
        f"- Machine: {platform.platform()}, {os.cpu_count()} cores; load average (1, 5, 15 min) at start "
        f"({start_load}), at end ({load()}) (other jobs share the cores: wall times vary, CPU seconds less)",
        f"- meshcurv at commit {_commit()}",
        "",
        "Exclusive times: a stage's own time, without the stages it calls. `other`: the call's total minus "
        "every stage (argument checks, dataclass copies, Python between the stages).",
        "",
        table(results),
        "",
    ])
    print(text)
    if args.markdown:
        with open(args.markdown, "w", encoding="utf-8") as handle:
            handle.write(text)
    return 0


def _threads() -> int:
    import numba

    return numba.get_num_threads()


def _commit() -> str:
    import subprocess

    try:
        return subprocess.run(["git", "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              cwd=os.path.dirname(os.path.abspath(__file__)), check=True).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


if __name__ == "__main__":
    sys.exit(main())
