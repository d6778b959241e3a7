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

``--walks`` adds a second table: inside the two kernels of the estimator, the
share of the breadth-first walks of the balls (issue 31, "one walk for both
balls"). It times, on the same meshes at the default radius ``r`` of the call,
the normal fits over ``3 r`` (:func:`meshcurv.jets.fit_jet_normals` with icc's
options), the walk of those balls alone (the compiled ``_connected_members``
over every vertex, nothing fitted), and the ball sums over ``r``
(:func:`meshcurv.neighborhoods.ball_face_sums`, ``connected=True``); CPU
seconds, the median of ``--repeats`` after a warm-up (``--fit-scales 3,6,12``: the
fits of ``multiscale_curvatures`` at ``h, 2 h, 4 h``)::

    .venv/bin/python benchmarks/profile_call.py --sizes 100k,1M --walks --fit-scales 3,6,12

``--preparation`` prints instead what the ball sums do besides their kernel (the checks,
the face centroids, the faces around each vertex, the scratch), each piece timed alone on
the default call's radius, the cost of one ``run_chunks`` call, and of one computation of the length scales
and of the needle vertices (found once per call, :mod:`meshcurv._once`) (CPU and wall s)::

    .venv/bin/python benchmarks/profile_call.py --sizes 1M --preparation --repeats 7
"""

from __future__ import annotations

import argparse
import functools
import os
import platform
import sys
import time
from typing import NamedTuple

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
    ("needle vertices (every caller)", "meshcurv.defects", "needle_vertices"),
    ("length scales (every caller)", "meshcurv._geometry", "vertex_length_scales"),
    ("length scales (every caller)", "meshcurv._geometry", "length_scales_and_median"),  # prepare_mesh's (ee8878f)
    ("radius: components", "meshcurv.radius", "component_radii"),
    ("radius: noise fits", "meshcurv.radius", "noise_level"),
    ("radius: voxel rule (lattice, pilot)", "meshcurv.radius", "voxel_surface_radius"),
    ("radius: local scale ratios", "meshcurv.radius", "local_scale_ratios"),
    # the trusting cores the estimators call since issue 33 (the public names above are their shells)
    ("radius: components", "meshcurv.radius", "_component_radii"),
    ("radius: noise fits", "meshcurv.radius", "_noise_level"),
    ("radius: voxel rule (lattice, pilot)", "meshcurv.radius", "_voxel_surface_radius"),
    ("radius: local scale ratios", "meshcurv.radius", "_local_scale_ratios"),
    ("vertex areas (icc)", "meshcurv.estimators.icc", "_vertex_areas"),
    ("normal fits (kernel)", "meshcurv.estimators.icc", "fitted_normals"),
    ("face measures", "meshcurv.measures", "face_measures"),
    ("face measures", "meshcurv._measures", "face_measures"),
    ("ball sums (kernel)", "meshcurv.neighborhoods", "ball_face_sums"),
    ("ball sums (kernel)", "meshcurv.neighborhoods", "_ball_face_sums"),
    ("curvatures from sums", "meshcurv.measures", "curvatures_from_measures"),
    ("curvatures from sums", "meshcurv._measures", "curvatures_from_measures"),
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
        self.main: dict[str, float] = {}  # CPU of the calling thread alone
        self.stack: list[list[float]] = []  # [nested wall, nested cpu, nested main] of each open stage

    def wrap(self, stage, function):
        @functools.wraps(function)
        def timed(*args, **kwargs):
            self.stack.append([0.0, 0.0, 0.0])
            wall, cpu, main = time.perf_counter(), time.process_time(), time.thread_time()
            try:
                return function(*args, **kwargs)
            finally:
                wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
                main = time.thread_time() - main
                nested = self.stack.pop()
                self.wall[stage] = self.wall.get(stage, 0.0) + wall - nested[0]
                self.cpu[stage] = self.cpu.get(stage, 0.0) + cpu - nested[1]
                self.main[stage] = self.main.get(stage, 0.0) + main - nested[2]
                if self.stack:
                    self.stack[-1][0] += wall
                    self.stack[-1][1] += cpu
                    self.stack[-1][2] += main

        timed.__wrapped_stage__ = True
        return timed

    def reset(self):
        self.wall.clear()
        self.cpu.clear()
        self.main.clear()


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


def profile(label: str, repeats: int) -> tuple[str, int, Run]:
    n = SIZES[label]
    mesh = meshcurv.shapes.icosphere(n)
    v = np.ascontiguousarray(mesh.vertices)
    f = np.ascontiguousarray(mesh.faces, dtype=np.int64)
    meshcurv.principal_curvatures(v, f)  # warm-up: kernels loaded, pages touched
    runs = []
    for _ in range(repeats):
        TIMERS.reset()
        wall, cpu, main = time.perf_counter(), time.process_time(), time.thread_time()
        meshcurv.principal_curvatures(v, f)
        wall, cpu, main = time.perf_counter() - wall, time.process_time() - cpu, time.thread_time() - main
        runs.append(Run(wall, cpu, main, dict(TIMERS.wall), dict(TIMERS.cpu), dict(TIMERS.main)))
    runs.sort(key=lambda run: run.wall)
    return f"icosphere({n})", v.shape[0], runs[len(runs) // 2]


class Run(NamedTuple):
    """One call: its wall, CPU and calling-thread CPU seconds, and the same per stage (exclusive)."""

    wall: float
    cpu: float
    main: float
    stage_wall: dict
    stage_cpu: dict
    stage_main: dict


def table(results) -> str:
    """The stage table. ``main CPU s``: the CPU seconds of the calling thread alone, the time the stage would take
    on otherwise idle cores (the other threads work while it does); a stage whose ``main`` equals its ``CPU``
    ran on one thread."""
    stages = list(dict.fromkeys(stage for stage, _, _ in STAGES))
    head = "| stage | " + " | ".join(f"{name} wall s | CPU s | main CPU s | us/vertex (CPU)" for name, *_ in results)
    rule = "|---|" + "--:|--:|--:|--:|" * len(results)
    lines = [head + " |", rule]
    for stage in [*stages, "other (Python around the stages)"]:
        cells = []
        for _name, n_vertices, run in results:
            if stage.startswith("other"):
                w = run.wall - sum(run.stage_wall.values())
                c = run.cpu - sum(run.stage_cpu.values())
                m = run.main - sum(run.stage_main.values())
            else:
                w, c, m = run.stage_wall.get(stage), run.stage_cpu.get(stage), run.stage_main.get(stage)
            cells.append("| | | " if w is None else f"{w:.3f} | {c:.3f} | {m:.3f} | {1e6 * c / n_vertices:.2f}")
        if any(cell != "| | | " for cell in cells):
            lines.append(f"| {stage} | " + " | ".join(cells) + " |")
    totals = [
        f"**{run.wall:.3f}** | **{run.cpu:.3f}** | **{run.main:.3f}** | **{1e6 * run.cpu / n:.2f}**"
        for _, n, run in results
    ]
    lines.append("| **whole call** | " + " | ".join(totals) + " |")
    return "\n".join(lines)


def _median_cpu(call, repeats: int) -> float:
    call()  # warm-up: compilation, pages touched
    seconds = []
    for _ in range(repeats):
        cpu = time.process_time()
        call()
        seconds.append(time.process_time() - cpu)
    return float(np.median(seconds))


def _walk_kernel():
    """A compiled pass of ``_connected_members`` (the normal fits' walk) over every vertex, nothing fitted."""
    import numba

    from meshcurv._kernels.neighborhoods import _connected_members

    @numba.njit(parallel=True, cache=False)
    def walk_all(vertices, indptr, indices, allowed, radius, n_chunks):
        n = vertices.shape[0]
        found = np.zeros(n_chunks, np.int64)
        for chunk in numba.prange(n_chunks):
            mark = np.full(n, -1, np.int64)
            members = np.empty(n, np.int64)
            queue = np.empty(n, np.int64)
            for v in range(chunk * n // n_chunks, (chunk + 1) * n // n_chunks):
                found[chunk] += _connected_members(
                    vertices, indptr, indices, allowed, v, radius, mark, v, members, queue
                )
        return found.sum()

    return walk_all


def walks(label: str, repeats: int, scales=(3.0,)) -> list[tuple]:
    """``(name, n_vertices, radius / h, fit radius / r, members per fit ball, fits s, walk s, sums s)`` (CPU
    seconds), one row per normal-fit radius ``scale * r`` (the sums at ``r`` timed once, in the first row)."""
    from meshcurv.estimators import icc
    from meshcurv.jets import NORMAL_MIN_SPREAD, fit_jet_normals
    from meshcurv.measures import face_measures
    from meshcurv.neighborhoods import ball_face_sums

    n = SIZES[label]
    mesh = meshcurv.shapes.icosphere(n)
    v = np.ascontiguousarray(mesh.vertices)
    f = np.ascontiguousarray(mesh.faces, dtype=np.int64)
    radius = float(meshcurv.principal_curvatures(v, f).parameters["radius"])
    topology = meshcurv.MeshTopology.from_faces(f)
    h = meshcurv.geometry.mean_edge_length(v, topology.edges)
    adjacency = topology.neighbour_lists
    normals = v / np.linalg.norm(v, axis=1, keepdims=True)
    walk_all = _walk_kernel()
    allowed = np.ones(v.shape[0], dtype=bool)
    measures = face_measures(v, f, normals)
    sums = _median_cpu(lambda: ball_face_sums(v, f, radius, measures, connected=True), repeats)
    rows = []
    for scale in scales:
        fit_radius = scale * radius
        fits = _median_cpu(
            lambda: fit_jet_normals(
                v,
                normals,
                fit_radius,
                degree=icc.NORMAL_DEGREE,
                iterations=icc.NORMAL_ITERATIONS,
                adjacency=adjacency,
                settled=icc.NORMAL_SETTLED,
                min_spread=NORMAL_MIN_SPREAD,
            ),
            repeats,
        )
        members = walk_all(v, *adjacency, allowed, fit_radius, _threads()) / v.shape[0]
        walk = _median_cpu(lambda: walk_all(v, *adjacency, allowed, fit_radius, _threads()), repeats)
        rows.append((f"icosphere({n})", v.shape[0], radius / h, scale, members, fits, walk, sums if not rows else None))
    return rows


def walks_table(results) -> str:
    lines = [
        f"CPU s, median of the calls after a warm-up; {_threads()} threads; load average {load()}",
        "",
        "| mesh | vertices | r / h | fit radius / r | vertices per fit ball | normal fits | their walk alone | "
        "walk / fits | ball sums (r) |",
        "|---|--:|--:|--:|--:|--:|--:|--:|--:|",
    ]
    for name, n_vertices, ratio, scale, members, fits, walk, sums in results:
        summed = "" if sums is None else f"{sums:.3f}"
        lines.append(
            f"| {name} | {n_vertices:,} | {ratio:.2f} | {scale:g} | {members:.1f} | {fits:.3f} | "
            f"{walk:.3f} | {walk / fits:.0%} | {summed} |"
        )
    return "\n".join(lines)


def _median_cpu_wall(call, repeats: int) -> tuple[float, float]:
    call()  # warm-up
    cpu, wall = [], []
    for _ in range(repeats):
        c, w = time.process_time(), time.perf_counter()
        call()
        cpu.append(time.process_time() - c)
        wall.append(time.perf_counter() - w)
    return float(np.median(cpu)), float(np.median(wall))


def preparation(label: str, repeats: int) -> list[tuple[str, float, float]]:
    """``(piece, CPU s, wall s)``: what :func:`meshcurv.neighborhoods.ball_face_sums` (``connected=True``, the
    default call's radius and face measures) does besides its kernel, each piece timed alone, and the cost of
    one :func:`meshcurv._kernels._common.run_chunks` call of a trivial kernel (the threads' hand-over)."""
    import numba

    from meshcurv import neighborhoods
    from meshcurv._kernels import _common
    from meshcurv._kernels import neighborhoods as compiled
    from meshcurv.measures import face_measures

    from meshcurv import _geometry, defects
    from meshcurv.topology import MeshTopology

    mesh = meshcurv.shapes.icosphere(SIZES[label])
    v = np.ascontiguousarray(mesh.vertices)
    topology = MeshTopology.from_faces(mesh.faces, v.shape[0])
    scales = _geometry.vertex_length_scales(v, topology)
    f = np.ascontiguousarray(mesh.faces, dtype=np.int64)
    n = v.shape[0]
    result = meshcurv.principal_curvatures(v, f)
    radius = float(result.parameters["radius"])
    measures = face_measures(v, f, result.normals)
    adjacency = meshcurv.MeshTopology.from_faces(f).neighbour_lists
    centres, reach = compiled.cell_centres(v, f)
    threads = _threads()
    pieces = {
        "faces and vertices checked (`_checked_cells`)": lambda: neighborhoods._checked_cells(v, f),
        "face centroids and reach (`cell_centres`)": lambda: compiled.cell_centres(v, f),
        "work estimate (`check_ball_work`)": lambda: neighborhoods.check_ball_work(
            centres, radius + float(reach.max()), n, centres=v
        ),
        "faces around each vertex (`vertex_face_lists`)": lambda: compiled.vertex_face_lists(f, n, threads),
        "scratch of the walks (`_face_sum_scratch`)": lambda: neighborhoods._face_sum_scratch(threads, n, f.shape[0]),
        "whole `ball_face_sums(connected=True)`": lambda: neighborhoods.ball_face_sums(
            v, f, radius, measures, connected=True
        ),
        "(normal fits) `checked_adjacency` of the neighbour lists": lambda: neighborhoods.checked_adjacency(
            adjacency, n
        ),
        # computed once per call since 3745c02 (meshcurv._once); 7 and 10 times per default call before
        "(call) one `vertex_length_scales`": lambda: _geometry.vertex_length_scales(v, topology),
        "(call) one `needle_vertices`": lambda: defects._needle_vertices(v, topology, scales),
    }
    rows = [(f"{name}, icosphere({SIZES[label]})", *_median_cpu_wall(call, repeats)) for name, call in pieces.items()]

    @numba.njit(nogil=True, cache=False)
    def fill(lo, hi, out):
        for i in range(lo, hi):
            out[i] = 2.0 * i

    out = np.zeros(1000)
    cpu, wall = _median_cpu_wall(lambda: [_common.run_chunks(fill, 1000, 8, out) for _ in range(1000)], repeats)
    rows.append(("one `run_chunks` call, trivial kernel, 8 ranges (per call)", cpu / 1000, wall / 1000))
    return rows


def preparation_table(rows) -> str:
    lines = [
        f"CPU and wall s, median of the calls after a warm-up; {_threads()} threads; load average {load()}",
        "",
        "| piece | CPU s | wall s |",
        "|---|--:|--:|",
    ]
    lines += [f"| {name} | {cpu:.2g} | {wall:.2g} |" for name, cpu, wall in rows]
    return "\n".join(lines)


TIMERS = Timers()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100k,1M,4M")
    parser.add_argument("--repeats", type=int, default=3, help="calls per size (the median by wall time is shown)")
    parser.add_argument("--markdown", help="write the table to this file")
    parser.add_argument(
        "--walks", action="store_true", help="only the table of the walks inside the kernels (see the module's doc)"
    )
    parser.add_argument(
        "--fit-scales",
        default="3",
        help="with --walks: the radii of the normal fits, in units of r (icc: 3; multiscale h, 2h, 4h: 3,6,12)",
    )
    parser.add_argument(
        "--preparation",
        action="store_true",
        help="only the table of what the ball sums do besides their kernel (see the module's doc)",
    )
    args = parser.parse_args(argv)
    if args.preparation:
        print(preparation_table([row for label in args.sizes.split(",") for row in preparation(label, args.repeats)]))
        return 0
    if args.walks:
        scales = [float(scale) for scale in args.fit_scales.split(",")]
        print(walks_table([row for label in args.sizes.split(",") for row in walks(label, args.repeats, scales)]))
        return 0
    install(TIMERS)
    start_load = load()
    results = []
    for label in args.sizes.split(","):
        results.append(profile(label, args.repeats))
        run = results[-1][2]
        print(
            f"{label}: {run.wall:.3f} s wall, {run.cpu:.3f} s CPU, {run.main:.3f} s on the calling thread",
            file=sys.stderr,
        )
    names = ", ".join(f"{name} ({n:,} vertices)" for name, n, *_ in results)
    text = "\n".join(
        [
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
            "every stage (argument checks, dataclass copies, Python between the stages). `main CPU s`: the CPU "
            "seconds of the calling thread alone, about the wall time on idle cores (it equals `CPU s` where a stage "
            "runs on one thread).",
            "",
            table(results),
            "",
        ]
    )
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
        return subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"],
            capture_output=True,
            text=True,
            cwd=os.path.dirname(os.path.abspath(__file__)),
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.CalledProcessError):
        return "unknown"


if __name__ == "__main__":
    sys.exit(main())
