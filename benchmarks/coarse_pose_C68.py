"""How much icc's numbers move under rigid motions, where its normals are fitted on the coarse level (C68, issue 29).

For each case, the call on the mesh as given and on ``--poses`` rigid motions of it (a random rotation and a
shift of up to one size): over the vertices valid in both, ``|dk| / max|k|`` (k_min and k_max, the larger) and
the normals' angle, their median / p90 / max over vertices, then over poses the largest; and the CPU seconds of
the call on the given pose.

    python benchmarks/coarse_pose_C68.py --cases ogre690 spot8 ico_noise vsphere vtorus --poses 3
"""

from __future__ import annotations

import argparse
import os
import time
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes

MESHES = os.environ.get("MESHCURV_MESHES", os.path.join(os.path.dirname(__file__), "..", "..", "shared", "meshes"))


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


def _edge(vertices, faces) -> float:
    e = np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]])
    return float(np.median(np.linalg.norm(vertices[e[:, 0]] - vertices[e[:, 1]], axis=1)))


def _case(name: str):
    """(vertices, faces, keyword arguments of the call)."""
    if name.startswith("ogre") or name.startswith("spot"):
        mesh = meshcurv.read_mesh(os.path.join(MESHES, ("ogre" if name.startswith("ogre") else "spot") + ".obj"))
        vertices, faces = np.asarray(mesh[0], dtype=float), np.asarray(mesh[1])
        if name == "ogre690":
            return vertices, faces, {"radius": np.asarray(0.5967), "orient": "outward"}
        if name.endswith("default"):
            return vertices, faces, {}
        edges = float(name[4:])
        return vertices, faces, {"radius": edges * _edge(vertices, faces)}
    if name == "ico_noise":
        mesh = shapes.with_normal_noise(shapes.icosphere(40), 0.2, seed=1)
        return mesh.vertices, mesh.faces, {}
    if name == "ico_noise8":
        mesh = shapes.with_normal_noise(shapes.icosphere(40), 0.2, seed=1)
        return mesh.vertices, mesh.faces, {"radius": 8 * _edge(mesh.vertices, mesh.faces)}
    if name == "vsphere":
        mesh = shapes.voxel_sphere(12)
        return mesh.vertices, mesh.faces, {}
    if name == "vtorus":
        mesh = shapes.voxel_torus(10, 4)
        return mesh.vertices, mesh.faces, {}
    if name == "vsphere_aniso":
        mesh = shapes.voxel_sphere(6, spacing=(0.5, 0.2, 0.2))
        return mesh.vertices, mesh.faces, {}
    raise SystemExit(f"unknown case {name}")


def _call(vertices, faces, options):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        start = time.process_time()
        result = meshcurv.principal_curvatures(vertices, faces, method="icc", **options)
        return result, time.process_time() - start


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--cases", nargs="+", default=["ogre690"])
    parser.add_argument("--poses", type=int, default=3)
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args()
    print(f"meshcurv from {os.path.dirname(meshcurv.__file__)}")
    for name in args.cases:
        vertices, faces, options = _case(name)
        base, cpu = _call(vertices, faces, options)
        size = float(np.linalg.norm(vertices.max(axis=0) - vertices.min(axis=0)))
        scale = float(np.nanmax(np.abs(np.r_[base.k_min[base.valid], base.k_max[base.valid]])))
        rng = np.random.default_rng(args.seed)
        rows = []
        for _ in range(args.poses):
            turn = _rotation(rng)
            shift = rng.uniform(-1, 1, 3) * size
            moved, _ = _call(vertices @ turn.T + shift, faces, options)
            both = base.valid & moved.valid
            dk = np.maximum(np.abs(base.k_min - moved.k_min), np.abs(base.k_max - moved.k_max))[both] / scale
            cos = np.abs(np.einsum("ij,ij->i", base.normals @ turn.T, moved.normals)[both])
            angle = np.degrees(np.arccos(np.clip(cos, -1, 1)))
            rows.append(
                (
                    np.median(dk),
                    np.percentile(dk, 90),
                    dk.max(),
                    np.percentile(angle, 90),
                    angle.max(),
                    int((base.valid != moved.valid).sum()),
                )
            )
        rows = np.array(rows)
        print(
            f"{name:14s} V {vertices.shape[0]:6d} cpu {cpu:6.2f} s  |dk|/max|k| median {rows[:, 0].max():.2e} "
            f"p90 {rows[:, 1].max():.2e} max {rows[:, 2].max():.2e}  normals p90 {rows[:, 3].max():.2e} "
            f"max {rows[:, 4].max():.2e} deg  valid apart {int(rows[:, 5].max())}",
            flush=True,
        )


if __name__ == "__main__":
    main()
