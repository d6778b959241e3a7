"""Where one default call on a dense voxel surface spends its CPU time, function by function (issue 30, helper D31).

Inclusive CPU timers (``time.process_time``, every thread) wrapped around the functions of the voxel default's
two passes (the pilot, ``radius._voxel_surface_radius``, and icc's main pass, ``icc._curvatures``) and around every
compiled kernel the call reaches (``K:module.kernel``); each line is the path of calls that led to it, so a
function called by the pilot and by the main pass shows on two lines. Not ``cProfile``: its per-call cost
inflates the many small NumPy calls. The figures are the mean over ``--repeats`` calls after a warm-up call
(numba's compilation not counted); lines under 0.5 ms are left out::

    python benchmarks/profile_dense_D31.py --mesh R6 --repeats 5
"""

from __future__ import annotations

import argparse
import functools
import importlib
import os
import sys
import time
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes

#: (module, function, label) wrapped; a function imported by name elsewhere is wrapped there too.
TARGETS = (
    ("meshcurv.curvature", "_voxel_surface_radius", "PILOT (radius._voxel_surface_radius)"),
    ("meshcurv.radius", "_voxel_surface_grid", "grid reading"),
    ("meshcurv.radius", "voxel_vertex_radii", "voxel_vertex_radii"),
    ("meshcurv.radius", "_ring_max", "ring_max"),
    ("meshcurv.radius", "_ring_sums", "ring_sums"),
    ("meshcurv.estimators.icc", "_pilot_centres", "pilot centres"),
    ("meshcurv.estimators.icc", "_pilot_normals", "pilot normals"),
    ("meshcurv.estimators.icc", "_spread_normals", "spread normals"),
    ("meshcurv.estimators.icc", "_sampled_face_sums", "pilot sampled sums"),
    ("meshcurv.estimators.icc", "face_measures", "face measures"),
    ("meshcurv.estimators.icc", "_coarse_level", "coarse level"),
    ("meshcurv.estimators.icc", "_sampled_jet_normals", "sampled jet normals"),
    ("meshcurv.jets", "_fit_jets", "_fit_jets"),
    ("meshcurv.jets", "_cube_samples", "cube samples"),
    ("meshcurv.estimators.icc", "_cube_samples", "cube samples"),
    ("meshcurv.estimators.icc", "_ball_face_sums", "ball face sums"),
    ("meshcurv.estimators.icc", "_curvatures", "MAIN (icc._curvatures)"),
    ("meshcurv.estimators.icc", "fitted_normals", "fitted normals"),
    ("meshcurv.estimators.icc", "_coarse_face_sums", "coarse sums"),
    ("meshcurv.neighborhoods", "_face_clusters", "face clusters"),
    ("meshcurv.neighborhoods", "check_ball_work", "check_ball_work"),
    ("meshcurv.estimators.icc", "curvatures_from_measures", "curvatures from measures"),
    ("meshcurv.jets", "turned_cubes", "turned_cubes"),
    ("meshcurv.curvature", "_finished", "_finished"),
)

MESHES = {
    "R6": lambda: shapes.voxel_sphere(6.0, (0.5, 0.2, 0.2), seed=0),
    "R3": lambda: shapes.voxel_sphere(3.0, (0.25, 0.1, 0.1), seed=2),
    "R10": lambda: shapes.voxel_sphere(10.0, (0.25, 0.1, 0.1), seed=1),
}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", choices=sorted(MESHES), default="R6")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    totals: dict = {}
    stack: list = []

    def timed(function, label):
        @functools.wraps(function)
        def call(*given, **options):
            stack.append(label)
            key = " > ".join(stack)
            start = time.process_time()
            try:
                return function(*given, **options)
            finally:
                totals[key] = totals.get(key, 0.0) + time.process_time() - start
                stack.pop()

        return call

    mesh = MESHES[args.mesh]()
    vertices, faces = np.asarray(mesh.vertices, float), mesh.faces[:, ::-1]  # marching cubes winds inward
    warnings.simplefilter("ignore")
    meshcurv.principal_curvatures(vertices, faces)  # compiled and cached first
    for module_name, name, label in TARGETS:
        module = importlib.import_module(module_name)
        original = getattr(module, name)
        wrapped = timed(original, label)
        for other in list(sys.modules.values()):
            if getattr(other, "__name__", "").startswith("meshcurv") and getattr(other, name, None) is original:
                setattr(other, name, wrapped)
    from meshcurv import _backend

    kernels_of = _backend.numba_kernels

    class Timed:
        def __init__(self, module, name):
            self._module, self._name = module, name

        def __getattr__(self, attribute):
            value = getattr(self._module, attribute)
            if callable(value) and not isinstance(value, type):
                return timed(value, f"K:{self._name}.{attribute}")
            return value

    def timed_kernels(name):
        module = kernels_of(name)
        return None if module is None else Timed(module, name)

    for other in list(sys.modules.values()):
        if (
            getattr(other, "__name__", "").startswith("meshcurv")
            and getattr(other, "numba_kernels", None) is kernels_of
        ):
            other.numba_kernels = timed_kernels
    calls = []
    for _ in range(args.repeats):
        start = time.process_time()
        result = meshcurv.principal_curvatures(vertices, faces)
        calls.append(time.process_time() - start)
    exact = 0.5 * (mesh.k_min + mesh.k_max)
    scale = np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))
    error = float(np.median(np.abs(result.mean - exact)[result.valid] / scale[result.valid]))
    call = float(np.mean(calls))
    print(
        f"{args.mesh}, {vertices.shape[0]:,} vertices: calls of {', '.join(f'{c:.3f}' for c in calls)} CPU s, "
        f"median H error {100 * error:.2f}%, load {os.getloadavg()[0]:.1f}\n"
    )
    print("| path | CPU ms | share |\n|---|--:|--:|")
    for key in sorted(totals):
        if totals[key] / args.repeats > 5e-4:
            print(
                f"| {key} | {1e3 * totals[key] / args.repeats:.1f} | {100 * totals[key] / args.repeats / call:.0f}% |"
            )


if __name__ == "__main__":
    main()
