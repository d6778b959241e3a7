"""Meshes full of holes: each method's valid vertices off the sphere's H, by how much of a fan a vertex keeps.

``python benchmarks/holed_meshes.py [--share 0.5] [--seeds 3] [--methods icc,normal_cycle_ball,...]``

A sphere (an icosphere, a uv sphere, the vertices of a voxel sphere) with a share of its faces removed at random:
every vertex keeps a part of its fan, its corner angles summing to less than 2 pi. The exact mean curvature is
``1 / R`` with the sign of the vertex normal the method returns (an open mesh keeps its winding: marching cubes
winds inward). A valid vertex is off where ``|H - H_exact| > 0.5 / R`` (the fuzzer's bar,
``benchmarks/fuzz_api.py``). Rows: mesh, method, and for each range of the angle sum at the vertex (radians) the
valid vertices and those off, over the seeds. Found while checking issue 29's detached faces with cracks wider
than the weld (``fuzz_api.py --wide-cracks``).
"""

import argparse
import warnings

import numpy as np

from meshcurv import principal_curvatures, shapes

BINS = (0.0, 1.0, 2.0, np.pi, 5.0, 2 * np.pi + 1e-9)


def angle_sums(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(V,) the sum of the corner angles of ``faces`` at each vertex."""
    corners = vertices[faces]
    total = np.zeros(vertices.shape[0])
    for k in range(3):
        a = corners[:, (k + 1) % 3] - corners[:, k]
        b = corners[:, (k + 2) % 3] - corners[:, k]
        angle = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))
        total += np.bincount(faces[:, k], weights=angle, minlength=vertices.shape[0])
    return total


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--share", type=float, default=0.5, help="share of the faces removed")
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--methods", default="icc,normal_cycle_ball,quadric,rusinkiewicz")
    options = parser.parse_args()
    meshes = [("icosphere(8)", shapes.icosphere(subdivisions=8)), ("uv_sphere()", shapes.uv_sphere())]
    try:
        meshes.append(("voxel_sphere(4)", shapes.voxel_sphere(radius=4.0)))
    except ImportError:  # marching cubes needs scikit-image
        pass
    labels = [f"[{lo:.2g}, {hi:.2g})" for lo, hi in zip(BINS[:-1], BINS[1:])]
    print("| mesh | method | " + " | ".join(f"angle sum {label}: valid / off" for label in labels) + " |")
    print("|---|---|" + "--:|" * len(labels))
    for name, mesh in meshes:
        vertices = np.asarray(mesh.vertices, dtype=float)
        faces = np.asarray(mesh.faces)
        centre = vertices.mean(axis=0)
        radius = float(np.median(np.linalg.norm(vertices - centre, axis=1)))
        for method in options.methods.split(","):
            valid_counts = np.zeros(len(labels), dtype=int)
            off_counts = np.zeros(len(labels), dtype=int)
            for seed in range(options.seeds):
                kept = faces[np.random.default_rng(seed).random(len(faces)) >= options.share]
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    result = principal_curvatures(vertices, kept, method=method)
                side = np.sign(np.einsum("ij,ij->i", result.normals, vertices - centre))
                off = result.valid & (np.abs(result.mean - side / radius) > 0.5 / radius)
                where = np.digitize(angle_sums(vertices, kept), BINS) - 1
                for b in range(len(labels)):
                    valid_counts[b] += int((result.valid & (where == b)).sum())
                    off_counts[b] += int((off & (where == b)).sum())
            cells = " | ".join(f"{v} / {o}" for v, o in zip(valid_counts, off_counts))
            print(f"| {name} | {method} | {cells} |", flush=True)


if __name__ == "__main__":
    main()
