"""icc's default on the flat faces of thin voxelised parts: tuning and held-out shapes (issue 29/30).

For each flat voxel ellipsoid (marching cubes, ``shapes.voxel_ellipsoid``) the table gives its flat vertices
(exact largest ``|k|`` at the closest point of the analytic surface below ``--flat`` of the shape's largest), those
valid, those off by more than half of their own ``|k|`` (H against the exact H), the median of that error in units
of their own ``|k|``, the median angle of the returned normals to the exact ones on the flat faces, the median H
error over all valid vertices relative to the exact H, and the CPU time of the call (the best of two). The tuning
shapes are those the constants of ``icc._thin_part_normals`` (I20) and ``jets._thin_part_normals`` (J21) were chosen
on; the others were not looked at before (J21's held-out rows: the flat axis along image axis 0, and meshes turned
by a rigid rotation: the exact normals turned with them).
Compare two trees by running it with ``PYTHONPATH=<tree>/src``.

    python benchmarks/flat_voxel_normals.py [--flat 0.1]
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes

#: (label, semi-axes, spacing, seed, tuned on[, rotation: degrees about the axis (1, 2, 3)])
SHAPES = [
    ("(8, 8, 2)", (8.0, 8.0, 2.0), (1.0, 1.0, 1.0), 2, True),
    ("(10, 10, 3)", (10.0, 10.0, 3.0), (1.0, 1.0, 1.0), 1, True),
    ("(8, 8, 2) seed 5", (8.0, 8.0, 2.0), (1.0, 1.0, 1.0), 5, False),
    ("(12, 6, 2)", (12.0, 6.0, 2.0), (1.0, 1.0, 1.0), 0, False),
    ("(10, 10, 2.5) seed 3", (10.0, 10.0, 2.5), (1.0, 1.0, 1.0), 3, False),
    ("(16, 16, 4)", (16.0, 16.0, 4.0), (1.0, 1.0, 1.0), 4, False),
    ("(8, 8, 2), voxel 1 x 1 x 0.5", (8.0, 8.0, 2.0), (1.0, 1.0, 0.5), 6, False),
    ("(8, 2, 8), voxel 0.5 x 1 x 1", (8.0, 2.0, 8.0), (0.5, 1.0, 1.0), 7, False),
    ("(20, 20, 5), voxel 2 x 2 x 1", (20.0, 20.0, 5.0), (2.0, 2.0, 1.0), 8, False),
    ("(16, 16, 4) seed 0", (16.0, 16.0, 4.0), (1.0, 1.0, 1.0), 0, False),
    ("(20, 20, 5) seed 0", (20.0, 20.0, 5.0), (1.0, 1.0, 1.0), 0, False),
    ("(2.5, 10, 10) seed 9", (2.5, 10.0, 10.0), (1.0, 1.0, 1.0), 9, False),
    ("(9, 3, 9), voxel 1 x 0.5 x 1, seed 10", (9.0, 3.0, 9.0), (1.0, 0.5, 1.0), 10, False),
    ("(10, 10, 2.5) seed 3, turned 37 degrees", (10.0, 10.0, 2.5), (1.0, 1.0, 1.0), 3, False, 37.0),
    ("(16, 16, 4) seed 11, turned 71 degrees", (16.0, 16.0, 4.0), (1.0, 1.0, 1.0), 11, False, 71.0),
]


def _turned(points: np.ndarray, degrees: float) -> np.ndarray:
    """``points`` (N, 3) turned by ``degrees`` about the axis (1, 2, 3) (Rodrigues' formula)."""
    axis = np.array([1.0, 2.0, 3.0]) / np.sqrt(14.0)
    angle = np.radians(degrees)
    cross = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    rotation = np.eye(3) + np.sin(angle) * cross + (1.0 - np.cos(angle)) * cross @ cross
    return points @ rotation.T


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flat", type=float, default=0.1, help="flat: own |k| below this share of the largest")
    options = parser.parse_args(argv)
    print(
        "| shape | tuned | vertices | flat | flat valid | off own | error / own k median | normal angle median | H error (all) | CPU s |"
    )
    print("|---|---|--:|--:|--:|--:|--:|--:|--:|--:|")
    for label, semi_axes, spacing, seed, tuned, *turn in SHAPES:
        mesh = shapes.voxel_ellipsoid(semi_axes, spacing, seed=seed)
        vertices, exact_normals = mesh.vertices, mesh.normals
        if turn:
            vertices, exact_normals = _turned(vertices, turn[0]), _turned(exact_normals, turn[0])
        own = np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))
        flat = own < options.flat * own.max()
        times = []
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # the voxel surface's notes
            for _ in range(2):
                start = time.process_time()
                result = meshcurv.principal_curvatures(vertices, mesh.faces, method="icc")
                times.append(time.process_time() - start)
        side = np.sign(np.einsum("ij,ij->i", result.normals, exact_normals))  # marching cubes winds inwards
        error = np.abs(result.mean - side * mesh.mean)
        ok = result.valid & flat
        own_error = error[ok] / own[ok]
        cosine = np.abs(np.einsum("ij,ij->i", result.normals, exact_normals))
        angle = np.degrees(np.arccos(np.clip(cosine, 0.0, 1.0)))
        relative = error[result.valid] / np.abs(mesh.mean[result.valid])
        print(
            f"| {label} | {'yes' if tuned else 'held out'} | {len(mesh.vertices)} | {int(flat.sum())} | {int(ok.sum())} "
            f"| {int((own_error > 0.5).sum())} | {np.median(own_error):.2f} | {np.median(angle[ok]):.1f} "
            f"| {100 * np.median(relative):.1f}% | {min(times):.2f} |"
        )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
