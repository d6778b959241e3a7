"""The methods without a voxel scale on intact voxel surfaces: valid vertices off the exact H (issue 29).

``python benchmarks/voxel_ring_methods.py [--methods normal_cycle rusinkiewicz ...]``

Marching-cubes spheres, an ellipsoid and a torus (``meshcurv.shapes.voxel_*``, isotropic and 4 x 1 x 1 voxels),
each method at its defaults (``normal_cycle`` also at the smoothing steps it names on a voxel surface,
``normal_cycle.voxel_steps_needed``; ``quadric`` also at a radius of the sphere's own radius). Exact values at each
vertex's closest point of the analytic surface, H signed by the returned normal against the exact outward one.
Rows: mesh, method (options), share of the vertices valid, median ``|H - H_exact| / |H_exact|`` over the valid
ones, and the share of the valid ones off by more than half of the exact largest ``|k|`` (the bar of
``benchmarks/fuzz_api.py``: a wrong number marked valid).
"""

import argparse
import warnings

import numpy as np

from meshcurv import principal_curvatures, shapes
from meshcurv._prepared import prepare_mesh
from meshcurv.estimators.normal_cycle import voxel_steps_needed

MESHES = [
    ("voxel_sphere(8)", lambda: shapes.voxel_sphere(8.0), 8.0),
    ("voxel_sphere(10)", lambda: shapes.voxel_sphere(10.0), 10.0),
    ("voxel_sphere(4), voxel 0.1", lambda: shapes.voxel_sphere(4.0, spacing=(0.1, 0.1, 0.1)), 4.0),
    ("voxel_sphere(20), 4 x 1 x 1 voxels", lambda: shapes.voxel_sphere(20.0, spacing=(4.0, 1.0, 1.0)), 20.0),
    ("voxel_ellipsoid((10, 7, 5))", lambda: shapes.voxel_ellipsoid((10.0, 7.0, 5.0)), None),
    ("voxel_torus(12, 4), voxel 0.5", lambda: shapes.voxel_torus(12.0, 4.0, spacing=(0.5, 0.5, 0.5)), None),
]


def _row(name: str, mesh, method: str, options: dict) -> str:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the voxel surface's warning: what this table measures
        result = principal_curvatures(mesh.vertices, mesh.faces, method=method, **options)
    side = np.sign(np.einsum("ij,ij->i", result.normals, mesh.normals))
    error = np.abs(side * result.mean - mesh.mean)
    valid = result.valid
    relative = error[valid] / np.abs(mesh.mean[valid])
    off = error[valid] / np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))[valid] > 0.5
    label = method + (" (" + ", ".join(f"{k}={v:g}" for k, v in options.items()) + ")" if options else "")
    median = f"{np.median(relative):.1%}" if valid.any() else "-"
    share = f"{off.mean():.1%}" if valid.any() else "-"
    return f"| {name} | {label} | {valid.mean():.0%} | {median} | {share} |"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--methods",
        nargs="+",
        default=["normal_cycle", "rusinkiewicz", "meyer", "quadric", "normal_cycle_ball", "icc"],
    )
    options = parser.parse_args()
    print("| mesh | method | valid | median H error | valid and off by > \\|k\\| / 2 |")
    print("|---|---|--:|--:|--:|")
    for name, make, sphere_radius in MESHES:
        mesh = make()
        for method in options.methods:
            runs = [{}]
            if method == "normal_cycle":
                prepared = prepare_mesh(mesh.vertices, mesh.faces, orient="outward", weld=True)
                steps = voxel_steps_needed(prepared, np.zeros(prepared.vertices.shape[0], dtype=bool))
                runs.append({"smoothing_steps": steps})
            if method == "quadric" and sphere_radius is not None:
                runs.append({"radius": sphere_radius})
            for run in runs:
                print(_row(name, mesh, method, run), flush=True)


if __name__ == "__main__":
    main()
