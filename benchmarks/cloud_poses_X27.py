"""Real meshes' vertices as point clouds under rigid motions and scalings: the same valid points and reasons, k within
1e-6 of the largest |k| (issue 29, fuzz_api 540/33's class).

``python benchmarks/cloud_poses_X27.py [--meshes spot,ogre] [--relations ...] [--method corrected_measures]``:
one line per mesh and relation with the points whose validity or reason changed and the largest k difference.
The meshes are read from ``../shared/meshes`` (beside the repository); the relations are those of
``benchmarks/fuzz_api.py``'s cloud cases (a shift of 1024 or -2^20 sizes, a rotation with a shift of up to ten
sizes, a scale by a power of two or by 1e-8, 0.037, 1e30).
"""

from __future__ import annotations

import argparse
import os
import time
import warnings

import numpy as np

import meshcurv
from meshcurv import pointcloud

HERE = os.path.dirname(os.path.abspath(__file__))
MESHES = os.path.join(HERE, "..", "..", "shared", "meshes")
RELATIONS = (
    "translate:1024",
    "translate:-1048576",
    "rigid:7",
    "rigid:1234",
    "scale:1048576",
    "scale:1e-08",
    "scale:0.037",
)


def _rotation(seed: int) -> np.ndarray:
    """A random proper rotation of the stream ``seed`` (as fuzz_api's)."""
    q, r = np.linalg.qr(np.random.default_rng(seed).normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else q[:, [1, 0, 2]]


def moved(points: np.ndarray, relation: str) -> tuple[np.ndarray, float]:
    """``(points moved, factor of k)`` for ``relation`` ``kind:value``."""
    kind, value = relation.split(":")
    size = max(float(np.ptp(points)), 1.0)
    if kind == "translate":
        return points + float(value) * size, 1.0
    if kind == "scale":
        return points * float(value), float(value)
    seed = int(value)
    return points @ _rotation(seed).T + np.random.default_rng(seed).uniform(-10.0, 10.0, size=3) * size, 1.0


def compare(a, b, factor: float) -> tuple[int, int, float]:
    """``(validity changes, reason changes, largest k difference over the largest |k|)`` of ``b`` against ``a``."""
    flips = int((a.valid != b.valid).sum())
    reasons = int((a.invalid_reason != b.invalid_reason).sum())
    both = a.valid & b.valid
    largest = max(
        float(np.abs(a.k_min[a.valid]).max(initial=0)), float(np.abs(a.k_max[a.valid]).max(initial=0)), 1e-300
    )
    error = max(
        float(np.abs(a.k_min[both] - b.k_min[both] * factor).max(initial=0)),
        float(np.abs(a.k_max[both] - b.k_max[both] * factor).max(initial=0)),
    )
    return flips, reasons, error / largest


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", default="spot,fandisk,rocker-arm,nefertiti,ogre,igea")
    parser.add_argument("--relations", default=",".join(RELATIONS))
    parser.add_argument("--method", default=None)
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore")
    options = {} if args.method is None else {"method": args.method}
    for name in args.meshes.split(","):
        points = np.asarray(meshcurv.read_mesh(os.path.join(MESHES, f"{name}.obj"))[0], dtype=np.float64)
        start = time.process_time()
        base = pointcloud.point_cloud_curvatures(points, **options)
        print(
            f"{name}: {len(points)} points, {int(base.valid.sum())} valid ({time.process_time() - start:.1f} CPU s)",
            flush=True,
        )
        for relation in args.relations.split(","):
            other, factor = moved(points, relation)
            flips, reasons, error = compare(base, pointcloud.point_cloud_curvatures(other, **options), factor)
            print(f"  {relation}: validity {flips}, reasons {reasons}, k {error:.2g}", flush=True)


if __name__ == "__main__":
    main()
