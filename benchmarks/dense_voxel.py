"""CPU per vertex of icc's default on dense voxel surfaces against a regular mesh (issue 30).

A marching-cubes sphere of radius 6 at the confocal spacing 0.5 x 0.2 x 0.2 (10,172 vertices: its
balls of about 2.5 units hold hundreds of vertices, the normal fits over three radii thousands),
a sphere of radius 3 at 0.25 x 0.1 x 0.1 (``--large``: radius 10, 113,072 vertices), and an icosphere of
100,002 vertices, in the same process.
Each figure is the median of ``--repeats`` calls after a warm-up (numba's compilation not counted):
CPU microseconds per vertex, the stage that costs most (from the ``progress`` callback), and the median
``|H - H_exact| / max|k|`` (issue 30's target: CPU per vertex within 3 times the icosphere's at <= 1%
median H error).

``--profile`` adds where the CPU time of one default call on the first mesh goes, by function
(``cProfile`` on CPU time; the pilot is the first pass of ``radius.voxel_surface_radius``, icc at 2
voxels over about half of the vertices, ``icc.voxel_pilot``). ``--shapes`` adds a dense torus and ellipsoid, whose
curvature varies within a ball (an estimate interpolated over half a radius blurred them: ``dense_voxel.md``).

    python benchmarks/dense_voxel.py --repeats 3 --profile
"""

from __future__ import annotations

import argparse
import cProfile
import pstats
import time
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes


def _timed(vertices, faces, repeats):
    """(median CPU s, {stage: median CPU s}, result) of the default call."""
    totals, stages_all = [], []
    result = None
    for _ in range(repeats + 1):
        marks = []

        def progress(stage, index, total):
            marks.append((stage, time.process_time()))

        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            start = time.process_time()
            result = meshcurv.principal_curvatures(vertices, faces, progress=progress)
            end = time.process_time()
        totals.append(end - start)
        stages = {}
        for (stage, at), (_, after) in zip(marks, marks[1:] + [("", end)]):
            stages[stage] = stages.get(stage, 0.0) + after - at
        stages_all.append(stages)
    totals, stages_all = totals[1:], stages_all[1:]  # the first call compiles
    names = stages_all[0].keys()
    return float(np.median(totals)), {k: float(np.median([s.get(k, 0.0) for s in stages_all])) for k in names}, result


#: The functions whose cumulative CPU time ``--profile`` lists (file suffix, function name, label).
PROFILED = (
    ("/radius.py", "_voxel_surface_radius", "voxel pilot and per-vertex radii (before the stages)"),
    ("/icc.py", "run", "  pilot: icc at 2 voxels"),
    ("/icc.py", "_pilot_normals", "    its normal fits (on a coarse level in anisotropic voxels)"),
    ("/icc.py", "_spread_normals", "    its normals spread from its centres to the other vertices"),
    ("/radius.py", "voxel_vertex_radii", "  per-vertex radii from the pilot"),
    ("/icc.py", "fitted_normals", "normal fits of the main pass"),
    ("/jets.py", "_fit_jet_normals", "  fits over every vertex (none on a dense surface)"),
    ("/icc.py", "_coarse_level", "  coarse levels (of the main fits; of the pilot's in anisotropic voxels)"),
    (
        "/jets.py",
        "_sampled_jet_normals",
        "  fits at one centre per cube, the others interpolated (jets.sampled_jet_normals)",
    ),
    ("/jets.py", "_fit_jets", "jet fits (the pilot's centres and the main pass's samples)"),
    ("_kernels/jets.py", "fit_jets_connected", "  their kernel (walks, weights, moments, solves)"),
    ("/meshcurv/neighborhoods.py", "_ball_face_sums", "sums over balls, face by face (the pilot's; sparse balls)"),
    ("_kernels/neighborhoods.py", "connected_face_sums", "  their kernel"),
    ("/icc.py", "_sampled_face_sums", "sums at a sample of the centres, the others interpolated (dense balls)"),
    ("_kernels/pilot.py", "interpolated_normals", "  interpolations (the sampled fits' normals, the sampled sums)"),
    ("/meshcurv/neighborhoods.py", "_coarse_face_sums", "sums over balls on clusters of faces (main pass)"),
    ("/meshcurv/neighborhoods.py", "_face_clusters", "  clusters of faces (balls of 800 faces or more)"),
    ("_kernels/neighborhoods.py", "coarse_face_sums", "  their kernel"),
    ("/meshcurv/neighborhoods.py", "check_ball_work", "pair estimates (all ball computations)"),
    ("/radius.py", "enclosing_ball", "smallest enclosing balls (the check of a given radius)"),
    ("/jets.py", "turned_cubes", "cube grids (pilot centres, coarse levels, samples)"),
    ("_kernels/neighborhoods.py", "vertex_face_lists", "faces around each vertex (each sum)"),
    ("thread.py", "_adjust_thread_count", "threads started by run_chunks (a new pool per kernel call)"),
)


def _profile(vertices, faces, repeats):
    """Print the CPU seconds of :data:`PROFILED` in one default call (median over ``repeats`` calls)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        meshcurv.principal_curvatures(vertices, faces)  # compiled and cached first
        profiler = cProfile.Profile(timer=time.process_time)
        profiler.enable()
        for _ in range(repeats):
            meshcurv.principal_curvatures(vertices, faces)
        profiler.disable()
    stats = pstats.Stats(profiler).stats  # type: ignore[attr-defined]
    total = sum(row[3] for (_, _, name), row in stats.items() if name == "principal_curvatures")
    for suffix, function, label in PROFILED:
        seconds = sum(row[3] for (path, _, name), row in stats.items() if name == function and path.endswith(suffix))
        print(f"| {label} | {seconds / repeats:.3f} | {100 * seconds / max(total, 1e-12):.0f}% |")
    print(f"| the call | {total / repeats:.3f} | 100% |")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument(
        "--large",
        action="store_true",
        help="also a sphere R 10 at 0.25 x 0.1 x 0.1 (113,072 vertices; a minute a call before the coarse level)",
    )
    parser.add_argument("--profile", action="store_true", help="where one call's CPU time goes, by function")
    parser.add_argument(
        "--shapes",
        action="store_true",
        help="also a torus (3, 1) and an ellipsoid (4, 3, 2) at 0.1 x 0.04 x 0.04 (71,134 and 54,974 vertices): "
        "curvatures that vary within a ball, which an interpolation over the surface blurs",
    )
    args = parser.parse_args(argv)
    meshes = [
        ("voxel sphere R 6, 0.5 x 0.2 x 0.2", shapes.voxel_sphere(6.0, (0.5, 0.2, 0.2), seed=0), True),
        ("voxel sphere R 3, 0.25 x 0.1 x 0.1", shapes.voxel_sphere(3.0, (0.25, 0.1, 0.1), seed=2), True),
    ]
    if args.large:
        meshes.append(
            ("voxel sphere R 10, 0.25 x 0.1 x 0.1", shapes.voxel_sphere(10.0, (0.25, 0.1, 0.1), seed=1), True)
        )
    if args.shapes:
        meshes.append(
            ("voxel torus (3, 1), 0.1 x 0.04 x 0.04", shapes.voxel_torus(3.0, 1.0, (0.1, 0.04, 0.04), seed=0), True)
        )
        meshes.append(
            (
                "voxel ellipsoid (4, 3, 2), 0.1 x 0.04 x 0.04",
                shapes.voxel_ellipsoid((4.0, 3.0, 2.0), (0.1, 0.04, 0.04), seed=1),
                True,
            )
        )
    meshes.append(("icosphere 100,002", shapes.icosphere(subdivisions=100, radius=1.0), False))
    rows = []
    for name, mesh, inward in meshes:
        faces = mesh.faces[:, ::-1] if inward else mesh.faces
        cpu, stages, result = _timed(np.asarray(mesh.vertices, float), faces, args.repeats)
        exact = 0.5 * (mesh.k_min + mesh.k_max)
        scale = np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))
        error = float(np.median(np.abs(result.mean - exact)[result.valid] / scale[result.valid]))
        n = mesh.vertices.shape[0]
        top = max(stages, key=stages.get)
        rows.append((name, n, cpu, 1e6 * cpu / n, top, stages[top] / cpu, error, float(np.median(result.radius))))
        before = cpu - sum(stages.values())  # the voxel pilot and the checks run before the estimator's stages
        print(f"{name}: " + ", ".join(f"{k} {v:.2f} s" for k, v in {"before the stages": before, **stages}.items()))
    reference = rows[-1][3]
    print(
        "| mesh | vertices | CPU s | CPU us / vertex | x icosphere | costliest stage (share) | median H error | "
        "radius |"
    )
    print("|---|--:|--:|--:|--:|---|--:|--:|")
    for name, n, cpu, per, top, share, error, radius in rows:
        print(
            f"| {name} | {n:,} | {cpu:.2f} | {per:.1f} | {per / reference:.1f} | {top} ({100 * share:.0f}%) | "
            f"{100 * error:.2f}% | {radius:.3g} |"
        )
    if args.profile:
        name, mesh, _ = meshes[0]
        print(f"\n{name}, one default call: CPU s by function\n\n| function | CPU s | share |\n|---|--:|--:|")
        _profile(np.asarray(mesh.vertices, float), mesh.faces[:, ::-1], args.repeats)


if __name__ == "__main__":
    main()
