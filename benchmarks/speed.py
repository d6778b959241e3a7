"""Speed and memory of every meshcurv method and of the peers, on the same meshes (issue 4).

Run from the repository root (peers: libigl, vtk, trimesh, pymeshlab and trueform
from PyPI; those not installed are listed as such. trueform's licence is
non-commercial: it is a benchmark peer only, imported here when installed, never
a dependency of meshcurv)::

    python benchmarks/speed.py                          # 10k, 100k, igea, 1M, 4M; writes benchmarks/speed.md
    python benchmarks/speed.py --sizes 10k,100k         # a quick check
    python benchmarks/speed.py --no-peers --budget 600  # meshcurv only, slow methods allowed 10 min per call
    python benchmarks/speed.py --sizes 100k,655k,1M --methods icc,normal_cycle,matgeom --backends numba
    # speed_rounds.md (speed.md is still the run of --repeats 3 without rounds that the README quotes):
    python benchmarks/speed.py --sizes 100k,1M,4M --methods icc,normal_cycle,matgeom --backends numba \
        --radius-sizes none --rounds 3 --repeats 1 --long 30 --output benchmarks/speed_rounds.md

Meshes: ``meshcurv.shapes.icosphere(n)`` (10 n^2 + 2 vertices: 10k n=32, 100k
n=100, 1M n=316, 4M n=632) and ``../shared/meshes/igea.obj`` (beside the repository) (134k vertices)
when present.

How each figure is measured:

- **time**: median of ``--repeats`` calls (at most 3 from 2M vertices; a single
  call when the first takes more than ``--long`` seconds) in each of ``--rounds``
  passes through all the implementations of a mesh (speed_rounds.md: 3 rounds
  of one call, so that a slow spell of this shared VM, which can last seconds,
  slows one call of several implementations rather than every call of one), in this process, on the
  same in-memory arrays, after a warm-up of every implementation on a small mesh
  (numba kernels loaded from the cache). meshcurv runs in this process; every
  peer (libigl, VTK, trueform, trimesh, pymeshlab) runs in a child process
  (pymeshlab can abort its process; trimesh is stopped at ``--trimesh-budget``)
  fed the same arrays through .npy files, the repeats in that child. With
  ``--children`` (the default), every meshcurv row runs so too, one child
  process per implementation and round, its first call (the kernels loaded
  from the numba cache) not counted: meshcurv and the peers on the same footing.
- **first call, fresh process** and **peak RSS**: each implementation once in a
  fresh ``python`` process that loads the arrays from .npy files (its peak RSS,
  ``VmHWM`` of /proc/self/status after the call: the whole process, interpreter,
  libraries and input included; ``ru_maxrss`` is not used because Linux carries
  the parent's value over ``execve``). For numba rows the first
  call includes loading the compiled kernels from the numba cache.
- **lower bound**: one reduction over vertices and faces plus writing arrays of the
  output size (k_min, k_max, dir_min, dir_max, normals, valid).
- an implementation whose time, extrapolated linearly from the previous size,
  exceeds ``--budget`` seconds per call is not run at that size ("est.").
"""

from __future__ import annotations

import argparse
import contextlib
import cProfile
import datetime
import importlib.metadata
import io
import json
import math
import os
import platform
import pstats
import re
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
OUTPUT = os.path.join(HERE, "speed.md")
IGEA = os.path.join(os.path.dirname(ROOT), "shared", "meshes", "igea.obj")  # ../shared beside the repository
GIB = 1024**3
MIB = 1024**2

# size label -> icosphere subdivisions
NAMED_SIZES = {"10k": 32, "100k": 100, "1M": 316, "4M": 632}
MESHLAB_METHODS = ("Quadric Fitting", "Taubin approximation", "Normal Cycles")
RADIUS_FACTORS = (1.0, 2.0, 4.0)

TARGETS = {
    "time_1m": 1.0,  # s at 1M, the default method and matgeom
    "vs_libigl": 10.0,  # libigl / the default method at 1M (issue 31)
    "vs_vtk": 1.0,  # VTK / meshcurv at 1M (> 1)
    "vs_trueform": 0.4,  # trueform (k=2, directions) / default method at 1M: within 2.5x (issue 31)
    "vs_trueform_ring": 1.5,  # trueform (k=2, directions) / normal_cycle and matgeom, topology inside (issue 31)
    "bytes_4m": 976,  # the default's peak RSS per vertex at 4M: not above issue 31's measure
    "vs_lower": 10.0,  # meshcurv / lower bound at 1M
    "growth": 4.5,  # t(4M) / t(1M)
    "rss_4m": 6 * GIB,  # peak RSS at 4M
    "radius_vs_ring": 3.0,  # default-radius time / normal_cycle time
    "import": 0.3,  # s
    "compile_cpu": 15.0,  # CPU s of the default's first call on a cold numba cache, less a warm call (issue 31)
    "spot": 1.0,  # s, `meshcurv compute spot.obj` in a fresh process on a warm cache (issue 31)
}


# -- meshes -----------------------------------------------------------------------


def subdivisions_for(label: str) -> int:
    if label in NAMED_SIZES:
        return NAMED_SIZES[label]
    match = re.fullmatch(r"(\d+(?:\.\d+)?)([kKmM]?)", label)
    if not match:
        raise SystemExit(f"--sizes: cannot read {label!r} (e.g. 10k, 100k, 1M, 4M, 250k)")
    value = float(match.group(1)) * {"": 1, "k": 1e3, "m": 1e6}[match.group(2).lower()]
    return max(1, round(math.sqrt(max(value - 2, 10) / 10)))


def read_obj(path: str):
    """Vertices and triangles of an OBJ file: meshcurv.read_mesh when there, else a numpy parse."""
    import meshcurv

    if hasattr(meshcurv, "read_mesh"):
        v, f = meshcurv.read_mesh(path)
        return np.ascontiguousarray(v, dtype=np.float64), np.ascontiguousarray(f, dtype=np.int64)
    verts, faces = [], []
    with open(path) as handle:
        for line in handle:
            if line.startswith("v "):
                verts.append(line.split()[1:4])
            elif line.startswith("f "):
                idx = [int(tok.split("/")[0]) for tok in line.split()[1:]]
                faces.extend([idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1))
    v = np.array(verts, dtype=np.float64)
    f = np.array(faces, dtype=np.int64)
    f = np.where(f < 0, f + v.shape[0], f - 1)
    return v, f


def build_mesh(label: str):
    """(name, vertices, faces)."""
    if label == "igea":
        v, f = read_obj(IGEA)
        return "igea.obj", v, f
    import meshcurv

    n = subdivisions_for(label)
    m = meshcurv.shapes.icosphere(n)
    return f"icosphere({n})", np.ascontiguousarray(m.vertices), np.ascontiguousarray(m.faces, dtype=np.int64)


# -- implementations ----------------------------------------------------------------


def numba_available() -> bool:
    try:
        import numba  # noqa: F401
    except ImportError:
        return False
    return True


def backends() -> tuple:
    return ("numpy", "numba") if numba_available() else ("numpy",)


def default_backend() -> str:
    from meshcurv._backend import backend_name

    return backend_name()


def meshcurv_keys(methods=None, chosen_backends=None) -> list:
    """Keys of the meshcurv rows: ``methods`` and ``chosen_backends`` (default: all) that exist."""
    from meshcurv.estimators import ESTIMATORS

    keys = []
    for backend in backends():
        if chosen_backends and backend not in chosen_backends:
            continue
        keys.append(f"topology/{backend}")
        for method in ESTIMATORS:
            if methods and method not in methods:
                continue
            keys.append(f"meshcurv/{method}/{backend}")
            if method in ("normal_cycle", "matgeom"):
                keys.append(f"meshcurv/{method}/{backend}/topo")
    return keys


def radius_methods() -> list:
    from meshcurv.estimators import ESTIMATORS

    return [name for name, est in ESTIMATORS.items() if "radius" in est.options]


PEERS = {
    # key: (label, import name, distribution, where it runs)
    "libigl": ("libigl principal_curvature (quadric, radius 5 rings)", "igl", "libigl", "child process"),
    "vtk": ("VTK vtkCurvatures mean + Gaussian (1-ring, no directions)", "vtk", "vtk", "child process"),
    # trueform: non-commercial licence, a benchmark peer only (never a dependency of meshcurv)
    "trueform": (
        "trueform principal_curvatures(k=2) (k-ring quadric, no directions)",
        "trueform",
        "trueform",
        "child process",
    ),
    "trueform/directions": (
        "trueform principal_curvatures(k=2, directions=True)",
        "trueform",
        "trueform",
        "child process",
    ),
    "trimesh": (
        "trimesh ball measures, mean + Gaussian (r = 2 mean edges, no directions)",
        "trimesh",
        "trimesh",
        "child process",
    ),
    **{
        f"meshlab/{m}": (f"pymeshlab principal directions, {m}", "pymeshlab", "pymeshlab", "child process")
        for m in MESHLAB_METHODS
    },
}
#: Every peer runs in a child process fed the same arrays (its repeats inside it): a peer's threads,
#: allocator and crashes (pymeshlab can abort) stay out of meshcurv's measurements.
SUBPROCESS_PEERS = set(PEERS)
#: The peer with directions that the default method is compared with (issue 15).
TRUEFORM = "trueform/directions"


def in_child(key: str, args) -> bool:
    """Whether ``key`` is timed in a child process (every peer; meshcurv too with ``--children``)."""
    return key in SUBPROCESS_PEERS or (getattr(args, "children", False) and key != "lower_bound")


def peers_installed():
    found, missing = {}, {}
    for key, (_label, module, dist, _) in PEERS.items():
        try:
            __import__(module)
            found[key] = f"{dist} {importlib.metadata.version(dist)}"
        except Exception as exc:  # noqa: BLE001 - any import failure: not available
            missing[key] = f"{dist}: not available ({type(exc).__name__}: {exc})"[:160]
    return found, missing


def label_of(key: str) -> str:
    if key == "lower_bound":
        return "lower bound (read input once, write outputs once)"
    if key in PEERS:
        return PEERS[key][0]
    parts = key.split("/")
    if parts[0] == "topology":
        return f"meshcurv MeshTopology.from_faces [{parts[1]}]"
    text = f"meshcurv {parts[1]} [{parts[2]}]"
    for extra in parts[3:]:
        if extra == "topo":
            text += ", topology given"
        elif extra.startswith("r="):
            text += f", radius {extra[2:]} x mean edge"
    return text


def make_call(key: str, v: np.ndarray, f: np.ndarray):
    """A zero-argument callable that runs ``key`` once on (v, f); setup is not timed."""
    if key == "lower_bound":
        return lambda: lower_bound(v, f)
    if key == "libigl":
        import igl

        return lambda: igl.principal_curvature(v, f)
    if key == "vtk":
        return lambda: run_vtk(v, f)
    if key in ("trueform", "trueform/directions"):
        import trueform

        directions = key.endswith("/directions")
        return lambda: trueform.principal_curvatures((f, v), k=2, directions=directions)
    if key == "trimesh":
        import trimesh
        from meshcurv.geometry import mean_edge_length
        from meshcurv.topology import MeshTopology

        radius = 2.0 * mean_edge_length(v, MeshTopology.from_faces(f, v.shape[0]).edges)

        def call():
            mesh = trimesh.Trimesh(v, f, process=False)
            return (
                trimesh.curvature.discrete_mean_curvature_measure(mesh, v, radius),
                trimesh.curvature.discrete_gaussian_curvature_measure(mesh, v, radius),
            )

        return call
    if key.startswith("meshlab/"):
        return lambda: run_meshlab(v, f, key.split("/", 1)[1])

    import meshcurv
    from meshcurv._backend import use_backend

    parts = key.split("/")
    if parts[0] == "topology":
        backend = parts[1]

        def call():
            with use_backend(backend):
                return meshcurv.MeshTopology.from_faces(f, v.shape[0])

        return call
    _, method, backend, *extras = parts
    faces, options = f, {}
    for extra in extras:
        if extra == "topo":
            with use_backend(backend):
                faces = meshcurv.MeshTopology.from_faces(f, v.shape[0])
        elif extra.startswith("r="):
            from meshcurv.geometry import mean_edge_length

            edges = meshcurv.MeshTopology.from_faces(f, v.shape[0]).edges
            options["radius"] = float(extra[2:]) * mean_edge_length(v, edges)

    def call():
        with use_backend(backend), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return meshcurv.principal_curvatures(v, faces, method=method, **options)

    return call


def lower_bound(v, f):
    """Touch the input once and write arrays of the output's size once."""
    s = float(v.sum()) + float(f.sum())
    n = v.shape[0]
    out = []
    for shape in ((n,), (n,), (n, 3), (n, 3), (n, 3)):
        a = np.empty(shape)
        a.fill(s)
        out.append(a)
    valid = np.empty(n, dtype=bool)
    valid.fill(True)
    out.append(valid)
    return out


def run_vtk(v, f):
    import vtk
    from vtk.util.numpy_support import numpy_to_vtk, numpy_to_vtkIdTypeArray, vtk_to_numpy

    points = vtk.vtkPoints()
    points.SetData(numpy_to_vtk(v, deep=True))
    cells = vtk.vtkCellArray()
    cells.SetData(
        numpy_to_vtkIdTypeArray(np.arange(0, 3 * len(f) + 1, 3, dtype=np.int64), deep=True),
        numpy_to_vtkIdTypeArray(f.ravel(), deep=True),
    )
    data = vtk.vtkPolyData()
    data.SetPoints(points)
    data.SetPolys(cells)
    values = []
    for kind in ("Mean", "Gaussian"):
        filt = vtk.vtkCurvatures()
        filt.SetInputData(data)
        getattr(filt, f"SetCurvatureTypeTo{kind}")()
        filt.Update()
        values.append(vtk_to_numpy(filt.GetOutput().GetPointData().GetScalars()).astype(float))
    return values


def run_meshlab(v, f, method):
    import pymeshlab

    ms = pymeshlab.MeshSet()
    ms.add_mesh(pymeshlab.Mesh(v, f))
    with contextlib.redirect_stdout(io.StringIO()):
        ms.compute_curvature_principal_directions_per_vertex(
            method=method, curvcolormethod="Min Curvature", autoclean=False
        )
    mesh = ms.current_mesh()
    return mesh.vertex_scalar_array(), mesh.vertex_curvature_principal_dir1_matrix()


# -- measuring ----------------------------------------------------------------------


def current_rss() -> int:
    with open("/proc/self/statm") as handle:
        return int(handle.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def peak_rss() -> int:
    """Peak resident memory of this process (bytes).

    ``VmHWM`` of /proc/self/status: the high-water mark of this process's own
    address space. ``getrusage(RUSAGE_SELF).ru_maxrss`` would be the same figure
    except that Linux carries it over ``execve`` from the parent (a child of a
    large process reports at least the parent's size), so it is the fallback only.
    """
    with contextlib.suppress(OSError, ValueError):
        with open("/proc/self/status") as handle:
            for line in handle:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024  # KiB on Linux


def prefault(nbytes: int) -> None:
    """Touch ``nbytes`` of fresh memory once and free it.

    This machine is a Firecracker VM with a balloon device that reports free
    memory back to the host: the first touch of a page the host has taken back
    costs about 2.5 s per GiB (against 0.1 s per GiB for a page already
    backed), and freed memory is handed back after a few seconds. Without this
    step, the time of an implementation depends on how much memory the process
    held just before it (up to 3x at 4M vertices). Touching enough memory
    immediately before each measurement puts every implementation, peers
    included, on backed memory, as on an ordinary computer.
    """
    if nbytes > 0:
        block = np.ones(nbytes // 8)
        del block


def time_calls(call, repeats: int, long: float, budget: float, cpu: list | None = None) -> list:
    """Wall seconds of up to ``repeats`` calls; the CPU seconds of each (all threads) appended to ``cpu``."""
    times = []
    spent = 0.0
    for _ in range(repeats):
        c0 = time.process_time()
        t0 = time.perf_counter()
        call()
        dt = time.perf_counter() - t0
        if cpu is not None:
            cpu.append(time.process_time() - c0)
        times.append(dt)
        spent += dt
        if dt > long or spent > budget:
            break
    return times


def worker(args) -> int:
    """Child process: load the arrays, run one implementation, print one RESULT line."""
    warnings.simplefilter("ignore")
    v = np.load(os.path.join(args.mesh_dir, "v.npy"))
    f = np.load(os.path.join(args.mesh_dir, "f.npy"))
    if args.impl.startswith("meshcurv/") or args.impl.startswith("topology/"):
        import meshcurv  # noqa: F401 - the import is part of a user's process
    call = make_call(args.impl, v, f)
    base_rss, base_peak = current_rss(), peak_rss()
    c0 = time.process_time()
    t0 = time.perf_counter()
    call()
    first = time.perf_counter() - t0
    cpu = [time.process_time() - c0]
    peak = peak_rss()
    times = [first]
    if args.repeats > 1 and first <= args.long:
        times += time_calls(call, args.repeats - 1, args.long, args.budget, cpu)
    print(
        "RESULT "
        + json.dumps(
            {"first": first, "times": times, "cpu": cpu, "peak_rss": peak, "base_rss": base_rss, "base_peak": base_peak}
        ),
        flush=True,
    )
    return 0


def user_environment(**extra) -> dict:
    """The environment of the fresh processes: this one's, with Python's default bytecode cache.

    A sandbox or CI job may set ``PYTHONDONTWRITEBYTECODE`` (this machine's sessions do); every
    fresh process would then compile meshcurv's sixty modules from source again, 0.1-0.2 s that a
    user's installation does once (pip writes the ``.pyc`` files of a regular install, Python those of
    an editable one on first import). The figures are those of a user's second and later processes.
    """
    env = {name: value for name, value in os.environ.items() if name != "PYTHONDONTWRITEBYTECODE"}
    env.update(extra)
    return env


def run_child(key, mesh_dir, repeats, long, budget, timeout, env=None):
    """Run the worker in a fresh process; returns the RESULT dict, or {'error': ...}."""
    cmd = [
        sys.executable,
        os.path.abspath(__file__),
        "--worker",
        "--impl",
        key,
        "--mesh-dir",
        mesh_dir,
        "--repeats",
        str(repeats),
        "--long",
        str(long),
        "--budget",
        str(budget),
    ]
    try:
        proc = subprocess.run(
            cmd, capture_output=True, text=True, timeout=timeout, env=user_environment() if env is None else env
        )
    except subprocess.TimeoutExpired:
        return {"timeout": timeout}
    for line in reversed(proc.stdout.splitlines()):
        if line.startswith("RESULT "):
            return json.loads(line[7:])
    tail = (proc.stderr or proc.stdout).strip().splitlines()[-3:]
    return {"error": f"exit {proc.returncode}: " + " | ".join(tail)[:300]}


# -- import and compile costs -------------------------------------------------------

IMPORT_SNIPPET = (
    "import time, sys; t0 = time.perf_counter(); import meshcurv; "
    "print(time.perf_counter() - t0, 'numba' in sys.modules)"
)

COMPILE_SNIPPET = r"""
import json, sys, time, warnings
warnings.simplefilter("ignore")
t0 = time.perf_counter()
import meshcurv
from meshcurv.estimators import DEFAULT_METHOD, ESTIMATORS
from meshcurv._backend import use_backend
t_import = time.perf_counter() - t0
m = meshcurv.shapes.icosphere(32)
out = {"import": t_import}
with use_backend("numba"):
    t0 = time.perf_counter(); import meshcurv._kernels; out["kernels_import"] = time.perf_counter() - t0
    for name in dict.fromkeys((DEFAULT_METHOD, *ESTIMATORS)):  # the default first
        c0, t0 = time.process_time(), time.perf_counter()
        meshcurv.principal_curvatures(m.vertices, m.faces, method=name)
        first, first_cpu = time.perf_counter() - t0, time.process_time() - c0
        c0, t0 = time.process_time(), time.perf_counter()
        meshcurv.principal_curvatures(m.vertices, m.faces, method=name)
        out[name] = [first, time.perf_counter() - t0, first_cpu, time.process_time() - c0]
print("RESULT " + json.dumps(out))
"""


def measure_import(n=5):
    runs, numba_loaded = [], False
    env = user_environment()
    subprocess.run([sys.executable, "-c", "import meshcurv"], env=env, check=True)  # writes the bytecode
    for _ in range(n):
        proc = subprocess.run([sys.executable, "-c", IMPORT_SNIPPET], capture_output=True, text=True, env=env)
        t, loaded = proc.stdout.split()
        runs.append(float(t))
        numba_loaded |= loaded == "True"
    proc = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", "import meshcurv"], capture_output=True, text=True, env=env
    )
    top = []
    for line in proc.stderr.splitlines():
        match = re.match(r"import time:\s+(\d+)\s+\|\s+(\d+)\s+\|( *)(\S+)", line)
        if match:
            depth = (len(match.group(3)) - 1) // 2  # 0: imported by the -c line
            top.append((int(match.group(2)), depth, match.group(4)))
    # the heaviest imports made by meshcurv and its modules (nesting depth 1 to 3)
    heavy = sorted((t for t in top if 1 <= t[1] <= 3), reverse=True)[:10]
    return {
        "runs": runs,
        "median": statistics.median(runs),
        "numba_loaded": numba_loaded,
        "heavy": [(name, us / 1e6) for us, _, name in heavy],
    }


def measure_compile():
    if not numba_available():
        return None
    cache = tempfile.mkdtemp(prefix="meshcurv-numba-cache-")
    env = user_environment(NUMBA_CACHE_DIR=cache, MESHCURV_BACKEND="numba")
    results = []
    for _ in range(2):  # empty cache, then the cache the first process filled
        proc = subprocess.run(
            [sys.executable, "-c", COMPILE_SNIPPET], capture_output=True, text=True, env=env, timeout=1800
        )
        line = [x for x in proc.stdout.splitlines() if x.startswith("RESULT ")]
        if not line:
            shutil.rmtree(cache, ignore_errors=True)
            return {"error": proc.stderr.strip().splitlines()[-1:]}
        results.append(json.loads(line[0][7:]))
    n_files = sum(len(files) for _, _, files in os.walk(cache))
    shutil.rmtree(cache, ignore_errors=True)
    return {"cold": results[0], "warm": results[1], "cache_files": n_files}


CLI_MESHES = ("spot.obj", "igea.obj")


def measure_cli(n=3):
    """Wall time of ``python -m meshcurv compute MESH`` (default method, summary printed) in fresh processes.

    The numba cache is the default one, warm after the warm-up of this run: what a user's second
    and later commands cost. Returns {mesh name: {"runs": [...], "vertices": V} or {"error": ...}}.
    """
    import meshcurv

    out = {}
    for name in CLI_MESHES:
        path = os.path.join(os.path.dirname(IGEA), name)
        if not os.path.exists(path):
            continue
        v, _ = read_obj(path)
        runs = []
        env = user_environment()
        subprocess.run(
            [sys.executable, "-m", "meshcurv", "compute", path], capture_output=True, env=env, timeout=600
        )  # untimed: writes the bytecode of the command-line modules
        for _ in range(n):
            t0 = time.perf_counter()
            proc = subprocess.run(
                [sys.executable, "-m", "meshcurv", "compute", path],
                capture_output=True,
                text=True,
                timeout=600,
                env=env,
            )
            runs.append(time.perf_counter() - t0)
            if proc.returncode != 0:
                out[name] = {"error": (proc.stderr.strip().splitlines() or ["?"])[-1][:200]}
                break
        else:
            out[name] = {"runs": runs, "vertices": int(v.shape[0])}
    del meshcurv
    return out


# -- machine ------------------------------------------------------------------------


def machine_info():
    cpu = platform.processor() or "unknown CPU"
    with contextlib.suppress(OSError):
        with open("/proc/cpuinfo") as handle:
            for line in handle:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    mem = 0
    with contextlib.suppress(OSError):
        with open("/proc/meminfo") as handle:
            for line in handle:
                if line.startswith("MemTotal"):
                    mem = int(line.split()[1]) * 1024
    versions = {}
    for dist in (
        "meshcurv",
        "numpy",
        "scipy",
        "numba",
        "llvmlite",
        "libigl",
        "vtk",
        "trimesh",
        "rtree",
        "pymeshlab",
        "trueform",
    ):
        with contextlib.suppress(importlib.metadata.PackageNotFoundError):
            versions[dist] = importlib.metadata.version(dist)
    commit = ""
    with contextlib.suppress(Exception):
        commit = subprocess.run(
            ["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "-C", ROOT, "status", "--porcelain", "--", "src"], capture_output=True, text=True
        ).stdout.strip()
        if dirty:
            commit += " (with uncommitted changes in src/)"
    cores = os.cpu_count()
    with contextlib.suppress(AttributeError):
        cores = len(os.sched_getaffinity(0))
    return {
        "cpu": cpu,
        "cores": cores,
        "memory": mem,
        "python": platform.python_version(),
        "platform": platform.platform(),
        "versions": versions,
        "commit": commit,
        "load_start": os.getloadavg(),
    }


# -- the run ------------------------------------------------------------------------


def log(*items):
    print(*items, file=sys.stderr, flush=True)


class Bench:
    def __init__(self, args):
        self.args = args
        self.rates = {}  # key -> seconds per vertex (last measured)
        self.rows = {}  # mesh label -> list of row dicts
        self.meshes = []  # (label, name, n_vertices, n_faces)
        self.radius = {}  # (label, method, factor) -> row
        self.profiles = {}
        self.mesh_load = {}  # mesh label -> [load average at its start, at its end]

    def predicted(self, key, n):
        rate = self.rates.get(key)
        return None if rate is None else rate * n

    def record(self, key, n, seconds):
        self.rates[key] = seconds / n

    def measure(self, key, label, v, f, mesh_dir, repeats, memory=True):
        """Time ``key`` on (v, f) and measure its peak RSS in a fresh process: a row dict."""
        args, n = self.args, v.shape[0]
        row = {"key": key, "label": label_of(key)}
        predicted = self.predicted(key, n)
        budget = args.trimesh_budget if key == "trimesh" else args.budget
        if predicted is not None and predicted > budget:
            row["skipped"] = f"est. {predicted:.0f} s > budget {budget:.0f} s"
            self.rates[key] = predicted / n
            log(f"  {row['label']}: skipped ({row['skipped']})")
            return row
        touch = int(args.prefault * n)
        if in_child(key, args):
            timeout = budget if key == "trimesh" else max(600.0, 10 * budget)
            prefault(touch)
            # with rounds, a child's first call (its libraries' start-up) is left out, as meshcurv's warm-up
            # call is: else every timed call of a peer would be a first call when --repeats is 1; a meshcurv
            # child's first call (the kernels loaded from the cache) is always left out
            extra = 1 if args.rounds > 1 or key not in SUBPROCESS_PEERS else 0
            res = run_child(key, mesh_dir, repeats + extra, args.long, budget, timeout)
            if extra and len(res.get("times", [])) > 1:
                res["times"], res["cpu"] = res["times"][1:], res.get("cpu", [])[1:]
            if "timeout" in res:
                row["skipped"] = f"> {budget:.0f} s (stopped)"
                self.rates[key] = budget / n
            elif "error" in res:
                row["error"] = res["error"]
            else:
                row.update(
                    times=res["times"],
                    cpu=res.get("cpu", []),
                    first_fresh=res["first"],
                    peak_rss=res["peak_rss"],
                    base_rss=res["base_rss"],
                    where="child",
                )
                self.record(key, n, min(res["times"]))
            log(f"  {row['label']}: {summary(row)}")
            return row
        try:
            call = make_call(key, v, f)
            prefault(touch)
            cpu = []
            times = time_calls(call, repeats, args.long, budget * max(repeats, 1), cpu)
            del call
        except Exception as exc:  # noqa: BLE001 - a failing implementation is a result
            row["error"] = f"{type(exc).__name__}: {exc}"[:300]
            log(f"  {row['label']}: {row['error']}")
            return row
        row.update(times=times, cpu=cpu, where="in-process")
        self.record(key, n, min(times))
        if memory and args.memory:
            prefault(touch)
            res = run_child(key, mesh_dir, 1, args.long, budget, timeout=max(600.0, 20 * max(times) + 120))
            if "peak_rss" in res:
                row.update(first_fresh=res["first"], peak_rss=res["peak_rss"], base_rss=res["base_rss"])
            else:
                row["memory_error"] = str(res)[:200]
        log(f"  {row['label']}: {summary(row)}")
        return row

    def warm_up(self, keys):
        """Every implementation once on a small mesh: numba kernels loaded, libraries imported."""
        import meshcurv

        m = meshcurv.shapes.icosphere(8)
        v, f = np.ascontiguousarray(m.vertices), np.ascontiguousarray(m.faces, dtype=np.int64)
        first = {}
        for key in keys:
            if in_child(key, self.args):
                continue
            t0 = time.perf_counter()
            try:
                make_call(key, v, f)()
            except Exception as exc:  # noqa: BLE001
                log(f"  warm-up of {key} failed: {exc}")
            first[key] = time.perf_counter() - t0
        return first

    def run(self):
        args = self.args
        import meshcurv  # noqa: F401

        self.info = machine_info()
        self.default_backend = default_backend()
        from meshcurv.estimators import DEFAULT_METHOD

        self.default_method = DEFAULT_METHOD
        self.default_key = f"meshcurv/{DEFAULT_METHOD}/{self.default_backend}"
        found, missing = peers_installed() if args.peers else ({}, {})
        self.found, self.missing = found, missing
        methods = [m for m in args.methods.split(",") if m] if args.methods else None
        chosen = [b for b in args.backends.split(",") if b] if args.backends else None
        keys = ["lower_bound"] + meshcurv_keys(methods, chosen) + list(found)
        log(f"implementations: {len(keys)}; default: {self.default_key}")

        log("import time ...")
        self.import_time = measure_import()
        log(f"  import meshcurv: median {self.import_time['median']:.3f} s")
        if args.compile:
            log("numba compile cost (empty cache) ...")
            self.compile = measure_compile()
        else:
            self.compile = None
        log("warm-up ...")
        self.warm = self.warm_up(keys)
        log("meshcurv compute in fresh processes ...")
        self.cli = measure_cli() if args.cli else {}

        labels = [s.strip() for s in args.sizes.split(",") if s.strip()]
        if args.igea and os.path.exists(IGEA) and "igea" not in labels:
            labels.append("igea")
        built = []
        for label in labels:
            n = 134345 if label == "igea" else 10 * subdivisions_for(label) ** 2 + 2
            built.append((n, label))
        built.sort()
        work = tempfile.mkdtemp(prefix="meshcurv-speed-")
        try:
            for _n_expected, label in built:
                name, v, f = build_mesh(label)
                n = v.shape[0]
                self.meshes.append((label, name, n, f.shape[0]))
                mesh_dir = os.path.join(work, label)
                os.makedirs(mesh_dir, exist_ok=True)
                np.save(os.path.join(mesh_dir, "v.npy"), v)
                np.save(os.path.join(mesh_dir, "f.npy"), f)
                repeats = args.repeats if n < 2_000_000 else min(args.repeats, 3)
                log(f"{label}: {name}, {n} vertices, {f.shape[0]} faces, {repeats} repeats")
                self.mesh_load[label] = [os.getloadavg()]
                rows = []
                for key in keys:
                    if key == "trimesh" and n > args.trimesh_max:
                        rows.append(
                            {
                                "key": key,
                                "label": label_of(key),
                                "skipped": f"not run above {args.trimesh_max} vertices",
                            }
                        )
                        continue
                    rows.append(self.measure(key, label, v, f, mesh_dir, repeats))
                for round_ in range(1, args.rounds):  # again through every implementation: times only
                    log(f"{label}: round {round_ + 1} of {args.rounds}")
                    for row in rows:
                        if "times" not in row or max(row["times"]) > args.long:
                            continue  # not run, failed, or too long to repeat (as within a round)
                        again = self.measure(row["key"], label, v, f, mesh_dir, repeats, memory=False)
                        row["times"] = row["times"] + again.get("times", [])
                        row["cpu"] = row.get("cpu", []) + again.get("cpu", [])
                self.rows[label] = rows
                self.mesh_load[label].append(os.getloadavg())
                if label in args.radius_sizes.split(","):
                    self.radius_sweep(label, v, f, mesh_dir, min(repeats, 3))
                if args.profile and label == args.profile_size:
                    self.profile(v, f)
                shutil.rmtree(mesh_dir, ignore_errors=True)
                del v, f
        finally:
            shutil.rmtree(work, ignore_errors=True)
        self.info["load_end"] = os.getloadavg()

    def radius_sweep(self, label, v, f, mesh_dir, repeats):
        log(f"{label}: radius sweep")
        for method in radius_methods():
            for factor in RADIUS_FACTORS:
                key = f"meshcurv/{method}/{self.default_backend}/r={factor:g}"
                base = self.rates.get(f"meshcurv/{method}/{self.default_backend}")
                if key not in self.rates and base is not None:
                    # ball cost grows with the number of vertices in the ball (~ r^2)
                    self.rates[key] = base * max(factor / 2.5, 0.4) ** 2
                self.radius[(label, method, factor)] = self.measure(key, label, v, f, mesh_dir, repeats, memory=False)

    def profile(self, v, f):
        for method in dict.fromkeys((self.default_method, "normal_cycle", "matgeom")):
            key = f"meshcurv/{method}/{self.default_backend}"
            call = make_call(key, v, f)
            prof = cProfile.Profile()
            prof.enable()
            call()
            prof.disable()
            buf = io.StringIO()
            stats = pstats.Stats(prof, stream=buf)
            top = self.args.profile_top
            stats.sort_stats("tottime").print_stats(top)
            text = buf.getvalue()
            lines = [ln.replace(ROOT + "/src/", "") for ln in text.splitlines()]
            start = next((i for i, ln in enumerate(lines) if ln.strip().startswith("ncalls")), 0)
            total = next((ln.strip() for ln in lines if "function calls" in ln), "")
            self.profiles[method] = (total, "\n".join(ln for ln in lines[start : start + top + 1] if ln.strip()))


# -- report -------------------------------------------------------------------------


def median(row):
    return statistics.median(row["times"]) if row.get("times") else None


def summary(row):
    if "skipped" in row:
        return f"skipped: {row['skipped']}"
    if "error" in row:
        return f"error: {row['error']}"
    text = f"median {median(row):.3f} s over {len(row['times'])}"
    if "peak_rss" in row:
        text += f", peak RSS {row['peak_rss'] / MIB:.0f} MiB"
    return text


def fmt_s(x):
    if x is None:
        return "—"
    return f"{x:.3g}" if x < 100 else f"{x:.0f}"


def fmt_ratio(x):
    if x is None or not math.isfinite(x):
        return "—"
    return f"{x:.2g}x" if x < 10 else f"{x:.0f}x"


def met(ok):
    return "—" if ok is None else ("**met**" if ok else "**not met**")


def markdown(bench) -> str:
    args, info = bench.args, bench.info
    gib = info["memory"] / GIB
    v = info["versions"]
    peer_versions = "; ".join(sorted(set(bench.found.values()))) or "none"
    lines = [
        "# Speed and memory (issues 4, 15 and 31)",
        "",
        f"Generated {bench.generated} by `{bench.command}`",
        "",
        f"- Machine: {info['cpu']}, {info['cores']} cores, {gib:.1f} GiB; {info['platform']}",
        f"- Load average (1, 5, 15 min) at start {tuple(round(x, 1) for x in info['load_start'])}, "
        f"at end {tuple(round(x, 1) for x in info.get('load_end', (0, 0, 0)))}"
        + (
            " — **shared machine: other jobs were running, timings are noisy**"
            if max(info["load_start"][0], info.get("load_end", (0,))[0]) > 0.5 * info["cores"]
            else " (the load at the end is the benchmark's own)"
        ),
        f"- Python {info['python']}, numpy {v.get('numpy', '—')}, scipy {v.get('scipy', '—')}, "
        f"numba {v.get('numba', 'not installed')} (llvmlite {v.get('llvmlite', '—')}); "
        f"meshcurv {v.get('meshcurv', '—')} at commit {info['commit'] or '?'}",
        f"- Peers: {peer_versions}" + (f" (rtree {v['rtree']})" if "rtree" in v else ""),
        f"- meshcurv default backend: {bench.default_backend}; default method: {bench.default_method} "
        f"(`{label_of(bench.default_key)}` is the reference of the ratios)",
    ]
    if bench.missing:
        lines.append("- Not run (not installed): " + "; ".join(bench.missing.values()))
    lines += [
        "",
        "Time: median of the calls in one process on the same in-memory arrays, after a warm-up on a small "
        "mesh ("
        + (
            "meshcurv and every peer each in a child process fed the same arrays through .npy files, its repeats "
            "inside it, its first call there not counted for meshcurv (the kernels loaded from the numba cache)"
            if args.children
            else "meshcurv in this process; every peer in a child process fed the same arrays through .npy "
            "files, its repeats inside it"
        )
        + ", `fresh` its first call there). `runs`: calls in the median"
        + (
            f", {args.rounds} rounds through all the implementations of a mesh, each of up to {args.repeats} "
            "call(s) in a row, a peer's first call in its child process not counted (a slow spell of the machine "
            "then falls on one round of several implementations, not on every call of one)"
            if args.rounds > 1
            else ""
        )
        + ". `fresh`: the same call once in a fresh "
        "process (numba rows: kernels loaded from the numba cache). Peak RSS: the high-water mark (`VmHWM`, "
        "what `ru_maxrss` reports without the value Linux carries over from the parent process) of that fresh "
        "process after the call (interpreter, libraries and the input arrays included); bytes/vertex = peak "
        "RSS / V. `÷ lower` = time / lower bound; `÷ default` = time / meshcurv's default method "
        f"({bench.default_method}, default backend); `libigl ÷`, `VTK ÷`, `trueform ÷` = their time / this time (how many times "
        "faster than them; trueform: `principal_curvatures(k=2, directions=True)`). `CPU s`: median of the "
        "process CPU seconds of the same calls (all threads; the work done, whatever the other jobs on the "
        "machine take of its cores), `CPU: trueform ÷` = trueform's CPU seconds / this row's. "
        f"Budget: {args.budget:.0f} s per call (trimesh {args.trimesh_budget:.0f} s); 'est.' = linear "
        "extrapolation from the previous size, not run.",
        "",
        (
            f"Memory warm-up: {args.prefault:.0f} bytes per vertex of memory are touched and freed just before "
            "each measurement (`--prefault`). This machine is a Firecracker VM whose balloon device hands free "
            "memory back to the host after a few seconds; touching a page the host has taken back costs about "
            "2.5 s per GiB (0.1 s per GiB for a backed page), so without the warm-up a time depends on what ran "
            "before it (up to 3x at 4M vertices). The warm-up applies to every row, peers included."
            if args.prefault > 0
            else "No memory warm-up (`--prefault 0`): on this VM, the first touch of memory the host has taken back "
            "costs about 2.5 s per GiB, and times at 4M vertices depend on what ran before."
        ),
        "",
    ]

    def find(label, key):
        for row in bench.rows.get(label, []):
            if row["key"] == key:
                return row
        return None

    def t(label, key):
        row = find(label, key)
        return median(row) if row else None

    def ratio(a, b):
        return a / b if a is not None and b not in (None, 0) else None

    # targets
    sizes = [m[0] for m in bench.meshes]
    one_m = "1M" if "1M" in sizes else None
    four_m = "4M" if "4M" in sizes else None
    db = bench.default_backend
    dm = bench.default_method

    def cpu_of(label, key):
        row = find(label, key)
        return statistics.median(row["cpu"]) if row and row.get("cpu") else None

    def compare(what, mine, theirs, name, other, ok):
        """``(ratio text, verdict)`` of ``mine / theirs`` seconds, both shown."""
        r = ratio(mine, theirs)
        shown = f"{name} ÷ {other} = {fmt_ratio(r)}"
        if r is not None:
            shown += f" ({fmt_s(mine)} s ÷ {fmt_s(theirs)} s {what})"
        return shown, met(None if r is None else ok(r))

    lines += [
        "## Targets (issue 31)",
        "",
        "One run; ratios at 1M vertices, wall time and CPU time (on this shared machine, the CPU seconds "
        "are the steadier figure). trueform: `principal_curvatures(k=2, directions=True)`; VTK: "
        "`vtkCurvatures` mean and Gaussian; libigl: `principal_curvature`.",
        "",
        "| target | measured | |",
        "|---|---|---|",
    ]
    if one_m:
        limit, need = 1 / TARGETS["vs_trueform"], TARGETS["vs_trueform_ring"]
        # (method, target, peer key, peer name, ratio = peer / method (else method / peer), test of the ratio)
        checks = [
            (
                dm,
                f"{dm} (default, full output) <= {limit:g}x trueform",
                TRUEFORM,
                "trueform",
                False,
                lambda r: r <= limit,
            ),
            (dm, f"{dm} faster than VTK", "vtk", "VTK", True, lambda r: r > TARGETS["vs_vtk"]),
            (
                dm,
                f"{dm} >= {TARGETS['vs_libigl']:g}x faster than libigl",
                "libigl",
                "libigl",
                True,
                lambda r: r >= TARGETS["vs_libigl"],
            ),
        ]
        checks += [
            (
                method,
                f"{method} (topology built in the call) >= {need:g}x faster than trueform",
                TRUEFORM,
                "trueform",
                True,
                lambda r: r >= need,
            )
            for method in ("normal_cycle", "matgeom")
        ]
        for method, text, peer, peer_name, theirs_first, ok in checks:
            key = f"meshcurv/{method}/{db}"
            for what, of in (("wall", t), ("CPU", cpu_of)):
                mine, theirs = of(one_m, key), of(one_m, peer)
                if theirs_first:
                    shown, verdict = compare(what, theirs, mine, peer_name, method, ok)
                else:
                    shown, verdict = compare(what, mine, theirs, method, peer_name, ok)
                lines.append(f"| {text}, {what} s | {shown} | {verdict} |")
    if one_m and four_m:
        n1, n4 = (next(m[2] for m in bench.meshes if m[0] == label) for label in (one_m, four_m))
        run_there = [
            row["key"].split("/")[1]
            for row in bench.rows[four_m]
            if row["key"].startswith("meshcurv/") and row["key"].count("/") == 2
        ]
        for method in dict.fromkeys((dm, "normal_cycle", "matgeom", *run_there)):
            key = f"meshcurv/{method}/{db}"
            if find(four_m, key) is None:
                continue
            for what, of in (("wall", t), ("CPU", cpu_of)):
                r = ratio(of(four_m, key), of(one_m, key))
                lines.append(
                    f"| linear growth: {method} t(4M) / t(1M) <= {TARGETS['growth']:g} "
                    f"({n4 / n1:.2f}x the vertices), {what} s | {fmt_ratio(r)} | "
                    f"{met(None if r is None else r <= TARGETS['growth'])} |"
                )
    row = find(four_m, f"meshcurv/{dm}/{db}") if four_m else None
    if row and "peak_rss" in row:
        n = next(m[2] for m in bench.meshes if m[0] == four_m)
        lines.append(
            f"| {dm}: peak RSS per vertex at 4M <= {TARGETS['bytes_4m']} B | {row['peak_rss'] / n:.0f} "
            f"B/vertex ({row['peak_rss'] / GIB:.2f} GiB, the whole process) | "
            f"{met(row['peak_rss'] / n <= TARGETS['bytes_4m'])} |"
        )
    lines.append("| no accuracy row worse | not measured here: `benchmarks/accuracy.md` before and after | — |")
    comp = bench.compile
    if comp and "cold" in comp and dm in comp["cold"]:
        cold, warm = comp["cold"][dm], comp["warm"][dm]
        cpu = cold[2] - warm[3] if len(cold) > 2 else None
        lines.append(
            f"| first use: {dm}'s kernels compile in <= {TARGETS['compile_cpu']:g} s CPU (cold cache) | "
            + (
                f"{cpu:.1f} s CPU, {cold[0] - warm[1]:.1f} s wall (first call in a fresh process, "
                "cold cache, less a warm call)"
                if cpu is not None
                else "no CPU figure"
            )
            + f" | {met(None if cpu is None else cpu <= TARGETS['compile_cpu'])} |"
        )
    cli = (getattr(bench, "cli", None) or {}).get("spot.obj")
    if cli and "runs" in cli:
        s = statistics.median(cli["runs"])
        lines.append(
            f"| a fresh process, warm cache, computes spot.obj in <= {TARGETS['spot']:g} s | "
            f"`meshcurv compute spot.obj`: {s:.2f} s (median of {len(cli['runs'])} processes) | "
            f"{met(s <= TARGETS['spot'])} |"
        )
    lines += ["", "Earlier targets (issues 4 and 15):", "", "| target | measured | |", "|---|---|---|"]
    if four_m:
        for key in dict.fromkeys(
            (
                f"meshcurv/{dm}/{db}",
                f"meshcurv/normal_cycle/{db}",
                f"meshcurv/matgeom/{db}",
                f"meshcurv/{dm}/numpy",
                "meshcurv/normal_cycle/numpy",
                "meshcurv/matgeom/numpy",
            )
        ):
            row = find(four_m, key)
            if row and "peak_rss" in row:
                n = next(m[2] for m in bench.meshes if m[0] == four_m)
                lines.append(
                    f"| {label_of(key)}: peak RSS at 4M < 6 GiB | {row['peak_rss'] / GIB:.2f} GiB "
                    f"({row['peak_rss'] / n:.0f} B/vertex) | {met(row['peak_rss'] < TARGETS['rss_4m'])} |"
                )
    for label in args.radius_sizes.split(","):
        ring = t(label, f"meshcurv/normal_cycle/{db}")
        for method in radius_methods():
            tr = t(label, f"meshcurv/{method}/{db}")
            r = ratio(tr, ring)
            if label in sizes:
                lines.append(
                    f"| {method} (default radius) within 3x of normal_cycle at {label} | {fmt_ratio(r)} | "
                    f"{met(None if r is None else r <= TARGETS['radius_vs_ring'])} |"
                )
    imp = bench.import_time["median"]
    lines.append(
        f"| `import meshcurv` < 0.3 s | {imp:.3f} s (median of {len(bench.import_time['runs'])}) | "
        f"{met(imp < TARGETS['import'])} |"
    )
    if comp and "cold" in comp:
        lines.append(
            f"| compile step cached across processes | {comp['cache_files']} files in NUMBA_CACHE_DIR; "
            f"see below | {met(comp['cache_files'] > 0)} |"
        )
    lines.append("")

    # per mesh
    for label, name, n, n_faces in bench.meshes:
        lb = t(label, "lower_bound")
        ref = t(label, bench.default_key)
        igl_t, vtk_t, tf_t = t(label, "libigl"), t(label, "vtk"), t(label, TRUEFORM)
        tf_row = find(label, TRUEFORM)
        tf_cpu = statistics.median(tf_row["cpu"]) if tf_row and tf_row.get("cpu") else None
        load = (getattr(bench, "mesh_load", None) or {}).get(label)
        lines += [f"## {label}: {name}, {n:,} vertices, {n_faces:,} faces", ""]
        if load and len(load) == 2:
            lines += [
                f"Load average (1 min) of the machine: {load[0][0]:.1f} when this mesh began, {load[1][0]:.1f} "
                f"when it ended ({bench.info['cores']} cores; the benchmark itself adds 1 to 2).",
                "",
            ]
        lines += [
            "| implementation | median s | CPU s | runs | fresh s | peak RSS MiB | bytes/vertex | ÷ lower | "
            "÷ default | libigl ÷ | VTK ÷ | trueform ÷ | CPU: trueform ÷ |",
            "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|",
        ]
        for row in bench.rows[label]:
            key = row["key"]
            if "skipped" in row or "error" in row:
                what = row.get("skipped") or "error: " + row["error"]
                lines.append(f"| {row['label']} | {what} | | | | | | | | | | | |")
                continue
            tm = median(row)
            cpu = statistics.median(row["cpu"]) if row.get("cpu") else None
            peak = row.get("peak_rss")
            is_mc = key.startswith("meshcurv/")
            cells = [
                row["label"] + (" (child process)" if row.get("where") == "child" else ""),
                fmt_s(tm),
                fmt_s(cpu),
                str(len(row["times"])),
                fmt_s(row.get("first_fresh")),
                f"{peak / MIB:.0f}" if peak else "—",
                f"{peak / n:.0f}" if peak else "—",
                fmt_ratio(ratio(tm, lb)) if key != "lower_bound" else "1x",
                fmt_ratio(ratio(tm, ref)),
                fmt_ratio(ratio(igl_t, tm)) if is_mc else "",
                fmt_ratio(ratio(vtk_t, tm)) if is_mc else "",
                fmt_ratio(ratio(tf_t, tm)) if is_mc else "",
                fmt_ratio(ratio(tf_cpu, cpu)) if is_mc else "",
            ]
            lines.append("| " + " | ".join(cells) + " |")
        lines.append("")

    # growth
    if one_m and four_m:
        lines += [
            "## Linear growth: t(4M) / t(1M)",
            "",
            "| implementation | 1M s | 4M s | ratio |",
            "|---|--:|--:|--:|",
        ]
        for row in bench.rows[one_m]:
            key = row["key"]
            a, b = t(one_m, key), t(four_m, key)
            lines.append(f"| {row['label']} | {fmt_s(a)} | {fmt_s(b)} | {fmt_ratio(ratio(b, a))} |")
        lines.append("(4M / 1M vertices = 4.0)")
        lines.append("")

    # radius
    if bench.radius:
        lines += [
            "## Radius-based methods: time as the radius grows",
            "",
            f"Default backend ({db}); radius in mean edge lengths `h`. The default radius is 2.5 h for "
            "quadric and normal_cycle_ball, and for icc follows the measured noise: 1 h on these clean "
            "icospheres (its normals are fitted over 3 r). "
            "`÷ 1-ring` = time / normal_cycle time on the same mesh.",
            "",
            "| mesh | method | r = 1 | r = 2 | default r | r = 4 | default ÷ 1-ring |",
            "|---|---|--:|--:|--:|--:|--:|",
        ]
        for label in [m[0] for m in bench.meshes]:
            ring = t(label, f"meshcurv/normal_cycle/{db}")
            for method in radius_methods():
                if (label, method, RADIUS_FACTORS[0]) not in bench.radius:
                    continue
                cells = []
                for factor in (1.0, 2.0, None, 4.0):
                    row = (
                        find(label, f"meshcurv/{method}/{db}")
                        if factor is None
                        else bench.radius[(label, method, factor)]
                    )
                    if row is None or "skipped" in row or "error" in row:
                        cells.append(row.get("skipped", row.get("error", "—")) if row else "—")
                    else:
                        cells.append(fmt_s(median(row)))
                lines.append(
                    f"| {label} | {method} | " + " | ".join(cells) + " | "
                    f"{fmt_ratio(ratio(t(label, f'meshcurv/{method}/{db}'), ring))} |"
                )
        lines.append("")

    # import and compile
    imp = bench.import_time
    lines += [
        "## Import and compile",
        "",
        f"`import meshcurv` in a fresh interpreter: median {imp['median']:.3f} s over {len(imp['runs'])} "
        f"runs ({', '.join(f'{x:.3f}' for x in imp['runs'])}); numba imported by `import meshcurv`: "
        f"{'yes' if imp['numba_loaded'] else 'no'}. Heaviest imports (`python -X importtime`, cumulative): "
        + ", ".join(f"{name} {s:.3f} s" for name, s in imp["heavy"])
        + ".",
        "",
    ]
    if comp and "cold" in comp:
        cold, warm = comp["cold"], comp["warm"]
        lines += [
            "numba compile cost: each method's first and second call on a 10k-vertex icosphere in a "
            "fresh process with `MESHCURV_BACKEND=numba` and `NUMBA_CACHE_DIR` an empty temporary "
            "directory (cold), then in a second fresh process on the cache the first one wrote (warm). "
            "`compile` = cold first call − warm second call.",
            "",
            "| method | cold first call s | warm-cache first call s | warm call s | compile s |",
            "|---|--:|--:|--:|--:|",
        ]
        total_cold = total_warm_first = total_warm = 0.0
        for method in cold:
            if method in ("import", "kernels_import"):
                continue
            c, w = cold[method], warm[method]
            total_cold += c[0]
            total_warm_first += w[0]
            total_warm += w[1]
            cost = c[0] - w[1]
            lines.append(
                f"| {method} | {c[0]:.2f} | {w[0]:.3f} | {w[1]:.3f} | "
                f"{f'{cost:.2f}' if cost > 0.05 else '~0 (no kernel of its own)'} |"
            )
        lines.append(
            f"| **all methods, one process** | {total_cold:.2f} | {total_warm_first:.3f} | "
            f"{total_warm:.3f} | {total_cold - total_warm:.2f} |"
        )
        lines += [
            "",
            f"Importing the kernels module (numba itself): {cold['kernels_import']:.2f} s cold, "
            f"{warm['kernels_import']:.2f} s warm. Cache files written: {comp['cache_files']}.",
            "",
        ]
    elif comp:
        lines += [f"numba compile measurement failed: {comp}", ""]
    if bench.warm:
        lines += [
            "Warm-up of this process (first call of each implementation on icosphere(8), "
            "642 vertices; numba kernels from the default cache): "
            + ", ".join(f"{label_of(k)} {s:.2f} s" for k, s in bench.warm.items() if s > 0.05)
            + ".",
            "",
        ]

    # the command line, fresh processes
    if getattr(bench, "cli", None):
        lines += [
            "## `meshcurv compute` in a fresh process",
            "",
            "`python -m meshcurv compute MESH` (default method, summary table printed), wall time of the "
            "whole process (interpreter start, imports, reading the OBJ, numba kernels loaded from the warm "
            "cache, the computation), each run a new process, after an untimed one. Every fresh process of "
            "this benchmark runs with Python's default bytecode cache (`PYTHONDONTWRITEBYTECODE` removed from "
            "its environment, which this machine's sessions set: with it, each process compiled meshcurv's "
            "modules from source again, 0.1-0.2 s that a user's installation spends once):",
            "",
            "| mesh | vertices | median s | runs |",
            "|---|--:|--:|---|",
        ]
        for name, res in bench.cli.items():
            if "error" in res:
                lines.append(f"| {name} | | error: {res['error']} | |")
            else:
                lines.append(
                    f"| {name} | {res['vertices']:,} | {statistics.median(res['runs']):.2f} | "
                    + ", ".join(f"{x:.2f}" for x in res["runs"])
                    + " |"
                )
        lines.append("")

    # profile
    if bench.profiles:
        lines += [f"## Where the time goes ({args.profile_size}, default backend)", ""]
        for method, (total, text) in bench.profiles.items():
            lines += [
                f"cProfile of one `{method}` call ({total}), top entries by own time:",
                "",
                "```",
                text,
                "```",
                "",
            ]
    return "\n".join(lines) + "\n"


#: Bench attributes that ``--json`` saves and ``--from-json`` restores (all that ``markdown`` reads).
SAVED = (
    "info",
    "meshes",
    "rows",
    "import_time",
    "compile",
    "found",
    "missing",
    "default_backend",
    "default_method",
    "default_key",
    "warm",
    "cli",
    "profiles",
    "command",
    "generated",
    "mesh_load",
)


def save_bench(bench, path: str) -> None:
    data = {name: getattr(bench, name, None) for name in SAVED}
    data["args"] = {k: v for k, v in vars(bench.args).items() if k != "from_json"}
    data["radius"] = [[list(key), row] for key, row in bench.radius.items()]
    with open(path, "w") as handle:
        json.dump(data, handle, indent=1, default=str)


def load_bench(path: str):
    """A finished Bench from a file written by ``save_bench``."""
    with open(path) as handle:
        data = json.load(handle)
    bench = Bench(argparse.Namespace(**data["args"]))
    for name in SAVED:
        setattr(bench, name, data.get(name))
    bench.radius = {tuple(key): row for key, row in data.get("radius", [])}
    bench.meshes = [tuple(m) for m in bench.meshes]
    for name in ("warm", "cli", "profiles", "found", "missing", "mesh_load"):
        setattr(bench, name, getattr(bench, name) or {})
    return bench


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--sizes",
        default="10k,100k,1M,4M",
        help="icosphere sizes (10k, 100k, 1M, 4M or e.g. 250k); default %(default)s",
    )
    parser.add_argument("--methods", default="", help="meshcurv methods to time, comma-separated (default: all)")
    parser.add_argument("--backends", default="", help="numpy, numba or both (default: all installed)")
    parser.add_argument(
        "--repeats",
        type=int,
        default=5,
        help="calls in a row per implementation and round (3 at most from 2M vertices)",
    )
    parser.add_argument(
        "--rounds",
        type=int,
        default=1,
        help="passes through all the implementations of a mesh, each timing --repeats calls: "
        "the median is over all of them, so that a slow spell of the machine falls on "
        "one call of several implementations rather than on all the calls of one "
        "(default: %(default)s)",
    )
    parser.add_argument("--output", default=OUTPUT, help="markdown file to write (default: %(default)s)")
    parser.add_argument(
        "--children",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="time meshcurv in child processes too, as the peers, their first call not counted "
        "(default: yes; --no-children: in this process)",
    )
    parser.add_argument(
        "--peers", action=argparse.BooleanOptionalAction, default=True, help="time the installed peers (default: yes)"
    )
    parser.add_argument(
        "--igea", action=argparse.BooleanOptionalAction, default=True, help=f"also igea.obj when present ({IGEA})"
    )
    parser.add_argument(
        "--memory",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="peak RSS of each implementation in a fresh process (default: yes)",
    )
    parser.add_argument(
        "--compile",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="measure the numba compile cost with an empty cache (default: yes)",
    )
    parser.add_argument(
        "--budget",
        type=float,
        default=300.0,
        help="seconds per call above which (extrapolated) an implementation is not run",
    )
    parser.add_argument(
        "--long", type=float, default=10.0, help="a first call longer than this many seconds is not repeated"
    )
    parser.add_argument("--trimesh-budget", type=float, default=120.0, help="seconds before trimesh is stopped")
    parser.add_argument("--trimesh-max", type=int, default=200_000, help="trimesh only up to this many vertices")
    parser.add_argument("--radius-sizes", default="100k,1M", help="sizes of the radius sweep")
    parser.add_argument(
        "--profile",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="cProfile one normal_cycle and matgeom call (default: yes)",
    )
    parser.add_argument("--profile-size", default="1M", help="mesh of the profile (default: %(default)s)")
    parser.add_argument("--profile-top", type=int, default=15)
    parser.add_argument(
        "--prefault",
        type=float,
        default=2000.0,
        help="bytes per vertex of memory touched just before each measurement (0: none); "
        "see prefault() (default: %(default)s)",
    )
    parser.add_argument(
        "--cli",
        action=argparse.BooleanOptionalAction,
        default=True,
        help="time `meshcurv compute` on spot.obj and igea.obj in fresh processes (default: yes)",
    )
    parser.add_argument("--json", help="also write the raw measurements to this JSON file")
    parser.add_argument(
        "--from-json",
        metavar="JSON",
        help="write the tables of a run saved with --json (its options and figures), measuring nothing",
    )
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--impl", help=argparse.SUPPRESS)
    parser.add_argument("--mesh-dir", help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        return worker(args)
    warnings.simplefilter("ignore")
    if args.from_json:  # the tables again from a saved run, nothing measured
        bench = load_bench(args.from_json)
    else:
        bench = Bench(args)
        bench.command = " ".join(["python benchmarks/speed.py"] + sys.argv[1:])
        bench.run()
        bench.generated = datetime.datetime.now().strftime("%Y-%m-%d %H:%M")
    text = markdown(bench)
    with open(args.output, "w") as handle:
        handle.write(text)
    if args.json and not args.from_json:
        save_bench(bench, args.json)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
