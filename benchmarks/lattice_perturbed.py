"""The voxel reading of meshes off their exact grid: how far off it holds, where smooth meshes would pass.

``python benchmarks/lattice_perturbed.py`` prints four tables (``benchmarks/lattice_perturbed.md``):

1. voxel meshes whose every coordinate got Gaussian noise of ``sigma`` voxels: read as voxel surfaces or not;
2. smooth meshes (``meshcurv.shapes`` and the real meshes of ``../shared/meshes`` when present): the share of their
   vertices with two coordinates within ``s`` of the planes of the grid the periodic reading finds, for several
   ``s`` (:data:`meshcurv.lattice.VOXEL_SNAP` is 0.05; a mesh is read as voxel from a share of 0.95), and the least
   share of one axis' coordinates on the planes (:data:`meshcurv.lattice.VOXEL_AXIS_SHARE`);
3. voxel meshes moved rigidly (translations, rotations about a tilted axis): read or not;
4. the CPU time of :func:`meshcurv.lattice.voxel_grid` on smooth meshes, exact reading only and with the periodic one.
"""

from __future__ import annotations

import argparse
import os
import pathlib
import time

import numpy as np

from meshcurv import shapes
from meshcurv.lattice import LATTICE_PROBE, _nearest_planes, _periodic_planes, voxel_grid

SNAPS = (0.02, 0.05, 0.1, 0.2, 0.3, 0.4, 0.45)
SIGMAS = (0.0, 1e-6, 1e-4, 1e-3, 3e-3, 5e-3, 1e-2, 2e-2)
ANGLES = (1e-6, 1e-5, 1e-4, 3e-4, 1e-3, 1e-2)


def median_edge(vertices, faces):
    return float(np.median(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)))


def voxel_meshes():
    return {
        "voxel_sphere(r=4)": shapes.voxel_sphere(radius=4.0),
        "voxel_sphere(r=10)": shapes.voxel_sphere(radius=10.0),
        "voxel_sphere(r=10, 1x0.5x0.7)": shapes.voxel_sphere(radius=10.0, spacing=(1.0, 0.5, 0.7)),
        "voxel_ellipsoid((12, 9, 6), seed=1)": shapes.voxel_ellipsoid((12.0, 9.0, 6.0), seed=1),
        "voxel_torus()": shapes.voxel_torus(),
    }


def smooth_meshes(folder: pathlib.Path):
    meshes = {
        "icosphere(3)": shapes.icosphere(3),
        "icosphere(8)": shapes.icosphere(8),
        "icosphere(16)": shapes.icosphere(16),
        "random_sphere()": shapes.random_sphere(),
        "random_ellipsoid()": shapes.random_ellipsoid(),
        "torus()": shapes.torus(),
        "uv_sphere()": shapes.uv_sphere(),
        "saddle()": shapes.saddle(),
        "saddle(1.0, 0.1)": shapes.saddle(1.0, 0.1),
        "cylinder()": shapes.cylinder(),
        "hemisphere(irregular=True)": shapes.hemisphere(irregular=True),
        "ellipsoid()": shapes.ellipsoid(),
    }
    out = {name: (mesh.vertices, mesh.faces) for name, mesh in meshes.items()}
    # a height field on a grid whose few heights (a sine of x alone) are periodic along z
    grid = shapes.saddle()
    x, y = grid.vertices[:, 0], grid.vertices[:, 1]
    out["saddle() with z = 0.5 sin(3 x)"] = (np.c_[x, y, 0.5 * np.sin(3.0 * x)], grid.faces)
    if folder.is_dir():
        from meshcurv.io import read_mesh

        for path in sorted(folder.glob("*.obj")):
            mesh = read_mesh(path)
            out[path.name] = (np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces))
    return out


def shares(vertices, spacing):
    """``(steps, on_grid (V, 3) of |off| / step)`` of the periodic reading, or None where an axis has no grid."""
    probe = vertices[:: max(1, vertices.shape[0] // LATTICE_PROBE)]
    steps, offs = [], []
    for k in range(3):
        planes = _periodic_planes(vertices[:, k], probe[:, k], spacing, full=False)
        if planes is None:
            return None
        step, offset, _ = planes
        steps.append(step)
        offs.append(np.abs(_nearest_planes(vertices[:, k], step, offset)[1]) / step)
    return np.array(steps), np.column_stack(offs)


def noise_table(rng):
    print("| voxel mesh | " + " | ".join(f"sigma {s:g}" for s in SIGMAS) + " |")
    print("|---|" + "---|" * len(SIGMAS))
    for name, mesh in voxel_meshes().items():
        cells = []
        for sigma in SIGMAS:
            moved = mesh.vertices + rng.normal(size=mesh.vertices.shape) * sigma * np.max(mesh.spacing)
            grid = voxel_grid(moved, mesh.faces)
            cells.append("no" if grid is None else f"{grid.fraction:.3f}")
        print(f"| {name} | " + " | ".join(cells) + " |")


def smooth_table(folder):
    print(
        "| smooth mesh | steps read / edge | "
        + " | ".join(f"s={s:g}" for s in SNAPS)
        + " | least axis share at 0.05 | read |"
    )
    print("|---|---|" + "---|" * len(SNAPS) + "---|---|")
    for name, (vertices, faces) in smooth_meshes(folder).items():
        used = vertices[np.unique(faces)]
        edge = median_edge(vertices, faces)
        found = shares(used, edge)
        if found is None:
            print(f"| {name} | not periodic along every axis | " + " | ".join("-" for _ in SNAPS) + " | - | no |")
            continue
        steps, off = found
        cells = [f"{float(((off <= s).sum(axis=1) >= 2).mean()):.3f}" for s in SNAPS]
        least = float((off <= 0.05).mean(axis=0).min())
        read = "no" if voxel_grid(vertices, faces) is None else "yes"
        print(
            f"| {name} | {', '.join(f'{x / edge:.2f}' for x in steps)} | "
            + " | ".join(cells)
            + f" | {least:.3f} | {read} |"
        )


def motion_table():
    print("| voxel mesh | moved 0.3 | moved 0.37 voxels | " + " | ".join(f"turned {a:g} rad" for a in ANGLES) + " |")
    print("|---|---|---|" + "---|" * len(ANGLES))
    axis = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    for name, mesh in voxel_meshes().items():
        cells = []
        for shift in (0.3, 0.37 * np.asarray(mesh.spacing)):
            grid = voxel_grid(mesh.vertices + shift, mesh.faces)
            cells.append("no" if grid is None else f"{grid.fraction:.3f}")
        centre = mesh.vertices.mean(axis=0)
        for angle in ANGLES:
            k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
            turn = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
            grid = voxel_grid((mesh.vertices - centre) @ turn.T + centre, mesh.faces)
            cells.append("no" if grid is None else f"{grid.fraction:.3f}")
        print(f"| {name} | " + " | ".join(cells) + " |")


def time_table(folder):
    print("| smooth mesh | vertices | exact reading (ms CPU) | with the periodic one (ms CPU) |")
    print("|---|--:|--:|--:|")
    for name, (vertices, faces) in smooth_meshes(folder).items():
        times = []
        for given in (None, faces):
            start = time.process_time()
            for _ in range(5):
                voxel_grid(vertices, given)
            times.append((time.process_time() - start) / 5 * 1e3)
        print(f"| {name} | {vertices.shape[0]:,} | {times[0]:.1f} | {times[1]:.1f} |")


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--meshes",
        default=os.environ.get("MESHCURV_SHARED_MESHES", "../shared/meshes"),
        help="folder of real .obj meshes (default: ../shared/meshes)",
    )
    args = parser.parse_args(argv)
    folder = pathlib.Path(args.meshes)
    noise_table(np.random.default_rng(0))
    print()
    smooth_table(folder)
    print()
    motion_table()
    print()
    time_table(folder)


if __name__ == "__main__":
    main()
