"""Every field of ``point_cloud_curvatures`` on a set of clouds, saved to compare two trees to the bit.

Issue 31 (point-cloud speed): a speed change must leave the results equal. Run
this script on each tree (``PYTHONPATH=<tree>/src``) with its own ``--out``,
then ``--compare A.npz B.npz``: each field (k, directions, normals, ``valid``,
``invalid_reason``) identical to the bit, or its largest difference.

Usage::

    python benchmarks/pointcloud_equal_P19.py --out before.npz [--backend numpy] [--large]
    python benchmarks/pointcloud_equal_P19.py --compare before.npz after.npz
"""

from __future__ import annotations

import argparse
import sys
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

from pointcloud import noisy, sample  # noqa: E402

FIELDS = ("k_min", "k_max", "dir_min", "dir_max", "normals", "valid", "invalid_reason")


def clouds(large: bool):
    """``name -> (points, normals or None)``: the clouds of the comparison."""
    out = {}
    torus = sample("torus", 100_000)
    out["torus_100k"] = (torus[0], None)
    points, normals, *_, area = sample("ellipsoid", 20_000)
    out["ellipsoid_noise_0.2"] = (noisy(points, normals, area, 0.2), None)
    out["saddle_nonuniform"] = (sample("saddle", 20_000, uniform=False)[0], None)
    points, normals = sample("sphere", 8_000)[:2]
    signs = np.where(np.random.default_rng(3).random(points.shape[0]) < 0.3, -1.0, 1.0)
    out["sphere_given_mixed"] = (points, normals * signs[:, None])
    sphere = sample("sphere", 6_000)[0]
    out["two_spheres_0.03"] = (np.concatenate([sphere, sphere * 1.0 + [2.03, 0.0, 0.0]]), None)
    rng = np.random.default_rng(5)
    plane = np.column_stack([rng.random(8_000), rng.random(8_000), np.zeros(8_000)])
    line = np.column_stack([np.linspace(0, 1, 300), np.full(300, 1.5), np.zeros(300)])
    out["plane_scan_line"] = (np.concatenate([plane, line]), None)
    x, y = np.meshgrid(np.linspace(-1, 1, 120), np.linspace(-1, 1, 120))
    out["lattice_dome"] = (
        np.column_stack([x.ravel(), y.ravel(), np.sqrt(4.0 - x.ravel() ** 2 - y.ravel() ** 2)]),
        None,
    )
    out["flat_ellipsoid_noise_0.1"] = (
        noisy(*sample("flat_ellipsoid", 20_000)[:2], sample("flat_ellipsoid", 20_000)[5], 0.1),
        None,
    )
    if large:
        out["torus_1M"] = (sample("torus", 1_000_000)[0], None)
    return out


def compute(out: str, backend: str, large: bool) -> None:
    from meshcurv._backend import use_backend
    from meshcurv.pointcloud import POINT_CLOUD_METHODS, point_cloud_curvatures

    arrays = {}
    with use_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for name, (points, normals) in clouds(large).items():
            for method in POINT_CLOUD_METHODS:
                result = point_cloud_curvatures(points, normals=normals, method=method)
                for field in FIELDS:
                    arrays[f"{name}/{method}/{field}"] = np.asarray(getattr(result, field))
                print(name, method, f"valid {np.mean(result.valid):.4f}", flush=True)
    np.savez_compressed(out, **arrays)


def compare(a: str, b: str) -> int:
    first, second = np.load(a), np.load(b)
    differ = 0
    for key in sorted(set(first.files) | set(second.files)):
        if key not in first.files or key not in second.files:
            print(key, "missing on one side")
            differ += 1
            continue
        x, y = first[key], second[key]
        if x.shape == y.shape and np.array_equal(x, y, equal_nan=x.dtype.kind == "f"):
            continue
        differ += 1
        largest = np.nanmax(np.abs(x - y)) if x.dtype.kind == "f" and x.shape == y.shape else "-"
        print(key, "differs; largest difference", largest)
    print(f"{len(first.files)} fields, {differ} differ")
    return 1 if differ else 0


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out")
    parser.add_argument("--backend", default="numba", choices=("numba", "numpy"))
    parser.add_argument("--large", action="store_true", help="a 1M-point torus too")
    parser.add_argument("--compare", nargs=2)
    args = parser.parse_args(argv)
    if args.compare:
        return compare(*args.compare)
    compute(args.out, args.backend, args.large)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
