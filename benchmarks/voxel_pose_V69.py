"""How much icc's numbers move under rigid motions on voxel surfaces (V69, issue 29).

For each case, the call on the mesh as given and on ``--poses`` rigid motions of it (a random rotation and a shift
of up to one size; with ``--quarter``, quarter turns about the axes instead: the grid read along x, y and z): over
the vertices valid in both, ``|dk| / max|k|`` (k_min and k_max, the larger) at the same vertex, its median and
largest, the normals' largest angle, the vertices valid in one pose only, and the default radius's relative move
(its median over the vertices); the largest over the poses; the CPU seconds of the call on the given pose. A case
is ``name`` or ``name:key=value;key=value`` (``radius=6``, ``radius=adaptive``) or ``name:multiscale=2,4,6``.

    python benchmarks/voxel_pose_V69.py --cases vtorus vsphere vell_aniso "vtorus:radius=6" --poses 3
"""

from __future__ import annotations

import argparse
import os
import time
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes

CASES = {
    "vtorus": lambda: shapes.voxel_torus(10, 4),
    "vsphere": lambda: shapes.voxel_sphere(12),
    "vell_aniso": lambda: shapes.voxel_ellipsoid((9.0, 6.0, 4.0), spacing=(1.0, 0.8, 0.6)),
    "vsphere_aniso": lambda: shapes.voxel_sphere(6, spacing=(0.5, 0.2, 0.2)),
    "vtorus_big": lambda: shapes.voxel_torus(24, 9),
    "vell_big": lambda: shapes.voxel_ellipsoid((20.0, 14.0, 9.0), spacing=(1.0, 0.8, 0.6)),
}


def _rotation(rng: np.random.Generator) -> np.ndarray:
    q = rng.normal(size=4)
    q /= np.linalg.norm(q)
    w, x, y, z = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


QUARTERS = [
    np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]]),
    np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]]),
    np.array([[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]),
]


def _options(spec: str) -> tuple[str, dict, list | None]:
    name, _, text = spec.partition(":")
    options: dict = {}
    radii = None
    for item in filter(None, text.split(";")):
        key, _, value = item.partition("=")
        if key == "multiscale":
            radii = [float(x) for x in value.split(",")]
        else:
            options[key] = value if value == "adaptive" else float(value)
    return name, options, radii


def _call(vertices, faces, options, radii):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.process_time()
        if radii is None:
            results = [meshcurv.principal_curvatures(vertices, faces, method="icc", **options)]
        else:
            results = meshcurv.multiscale_curvatures(vertices, faces, radii, method="icc", **options)
        return results, time.process_time() - start


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--cases", nargs="+", default=["vtorus", "vsphere", "vell_aniso"])
    parser.add_argument("--poses", type=int, default=3)
    parser.add_argument("--quarter", action="store_true", help="quarter turns about the axes, not random ones")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--backend", default="numba", choices=["numba", "numpy"])
    args = parser.parse_args()
    from meshcurv._backend import use_backend

    print(f"meshcurv from {os.path.dirname(meshcurv.__file__)}, backend {args.backend}", flush=True)
    with use_backend(args.backend):
        for spec in args.cases:
            name, options, radii = _options(spec)
            mesh = CASES[name]()
            vertices, faces = np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces)
            bases, cpu = _call(vertices, faces, options, radii)
            size = float(np.linalg.norm(np.ptp(vertices, axis=0)))
            rng = np.random.default_rng(args.seed)
            rows = []
            for pose in range(args.poses):
                turn = QUARTERS[pose % 3] if args.quarter else _rotation(rng)
                shift = rng.uniform(-1, 1, 3) * size
                moved, _ = _call(vertices @ turn.T + shift, faces, options, radii)
                for base, other in zip(bases, moved):
                    scale = float(np.nanmax(np.abs(np.r_[base.k_min[base.valid], base.k_max[base.valid]])))
                    both = base.valid & other.valid
                    dk = np.maximum(np.abs(base.k_min - other.k_min), np.abs(base.k_max - other.k_max))[both] / scale
                    cos = np.abs(np.einsum("ij,ij->i", base.normals @ turn.T, other.normals)[both])
                    angle = np.degrees(np.arccos(np.clip(cos, -1, 1)))
                    apart = int((base.valid != other.valid).sum())
                    moved_radius = abs(np.median(other.radius) / np.median(base.radius) - 1)
                    rows.append((np.median(dk), dk.max(), angle.max(), apart, moved_radius))
            rows = np.array(rows)
            print(
                f"{spec:26s} V {vertices.shape[0]:6d} cpu {cpu:6.2f} s  |dk|/max|k| median {rows[:, 0].max():.1e} "
                f"max {rows[:, 1].max():.1e}  normals max {rows[:, 2].max():.1e} deg  valid apart "
                f"{int(rows[:, 3].max())}  radius moved {rows[:, 4].max():.1e}",
                flush=True,
            )


if __name__ == "__main__":
    main()
