"""Voxel surfaces with holes and rims: icc's valid vertices off the exact H (issue 29).

``python benchmarks/holed_voxel.py [--method icc] [--seeds 3] [--shares 0,0.1,0.3,0.5,0.6]``

Marching-cubes spheres (radius 4 to 12 voxels, and 8 voxels in 2 x 1 x 1, 1 x 2 x 1, 3 x 1 x 1 and 1 x 1 x 2
voxels) and tori (``shapes.voxel_torus``)
with a share of their faces removed at random, and the same surfaces cut across an axis (a rim, no hole). The
exact mean curvature is that of the closest point of the analytic surface, with the sign of its outward normal
against the returned one (an open mesh is oriented patch by patch). A valid vertex is off where
``|H - H_exact|`` exceeds half of the exact largest ``|k|`` (the bar of ``benchmarks/fuzz_api.py`` and
``benchmarks/holed_meshes.py``). Rows: mesh, faces kept, valid vertices, those off, the vertices in a kept face
left invalid, and the median / 95th percentile / largest error over the valid vertices, in units of ``|k|``.
"""

import argparse
import warnings

import numpy as np

from meshcurv import principal_curvatures, shapes


def _errors(mesh, result) -> np.ndarray:
    side = np.sign(np.einsum("ij,ij->i", result.normals, mesh.normals))
    return np.abs(result.mean - side * mesh.mean) / np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))


def _row(name: str, label: str, mesh, faces_list, method: str, where=None) -> str:
    valid = off = invalid = 0
    errors = []
    for faces in faces_list:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # boundary and bow-tie vertices are counted in a warning
            result = principal_curvatures(mesh.vertices, faces, method=method)
        used = np.zeros(len(mesh.vertices), dtype=bool)
        used[faces.ravel()] = True
        chosen = result.valid if where is None else result.valid & where(faces)
        error = _errors(mesh, result)[chosen]
        valid += int(chosen.sum())
        off += int((error > 0.5).sum())
        invalid += int((used & ~result.valid).sum())
        errors.append(error)
    error = np.concatenate(errors)
    figures = f"{np.median(error):.2f} / {np.percentile(error, 95):.2f} / {error.max():.2f}" if error.size else "-"
    return f"| {name} | {label} | {valid} | {off} | {invalid} | {figures} |"


def _boundary_vertices(n: int):
    def where(faces: np.ndarray) -> np.ndarray:
        edges = np.sort(np.concatenate([faces[:, [0, 1]], faces[:, [1, 2]], faces[:, [2, 0]]]), axis=1)
        unique, counts = np.unique(edges, axis=0, return_counts=True)
        out = np.zeros(n, dtype=bool)
        out[unique[counts == 1].ravel()] = True
        return out

    return where


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--method", default="icc")
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--shares", default="0,0.1,0.3,0.5,0.6", help="shares of the faces removed")
    options = parser.parse_args()
    meshes = [
        ("voxel_sphere(4)", shapes.voxel_sphere(radius=4.0)),
        ("voxel_sphere(8)", shapes.voxel_sphere(radius=8.0)),
        ("voxel_sphere(12)", shapes.voxel_sphere(radius=12.0)),
        ("voxel_sphere(8), 2 x 1 x 1 voxels", shapes.voxel_sphere(radius=8.0, spacing=(2.0, 1.0, 1.0))),
        ("voxel_sphere(8), 1 x 2 x 1 voxels", shapes.voxel_sphere(radius=8.0, spacing=(1.0, 2.0, 1.0))),
        ("voxel_sphere(8), 3 x 1 x 1 voxels", shapes.voxel_sphere(radius=8.0, spacing=(3.0, 1.0, 1.0))),
        ("voxel_sphere(8), 1 x 1 x 2 voxels", shapes.voxel_sphere(radius=8.0, spacing=(1.0, 1.0, 2.0))),
        ("voxel_torus(8, 3)", shapes.voxel_torus(8.0, 3.0)),
        ("voxel_torus(12, 4)", shapes.voxel_torus(12.0, 4.0)),
    ]
    print("| mesh | faces | valid | off | invalid | error median / p95 / max |")
    print("|---|---|--:|--:|--:|---|")
    for name, mesh in meshes:
        for share in (float(x) for x in options.shares.split(",")):
            seeds = range(options.seeds if share > 0 else 1)
            faces_list = [mesh.faces[np.random.default_rng(seed).random(len(mesh.faces)) >= share] for seed in seeds]
            label = f"{share:.0%} removed, seeds 0-{len(seeds) - 1}" if share > 0 else "intact"
            print(_row(name, label, mesh, faces_list, options.method), flush=True)
        middles = mesh.vertices[mesh.faces].mean(axis=1)
        for axis in (0, 2):
            kept = mesh.faces[middles[:, axis] < np.median(middles[:, axis]) + 0.3]
            where = _boundary_vertices(len(mesh.vertices))
            print(_row(name, f"cut across axis {axis}: rim vertices", mesh, [kept], options.method, where), flush=True)


if __name__ == "__main__":
    main()
