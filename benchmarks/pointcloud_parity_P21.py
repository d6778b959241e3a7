"""The two point-cloud backends on many drawn clouds: how far apart are their estimates (issue 29, class 10)?

Each case draws a cloud (thin, open, noisy, voxel, or the vertices of a symmetric mesh; with or without a copy
beside it or near-duplicate copies of its points), computes
``point_cloud_curvatures`` with the numba backend and with the NumPy one
(``meshcurv._backend.use_backend``), and reports the largest difference of
``k_min``, ``k_max``, ``H``, ``K`` (relative to the largest |k| of the NumPy
result; ``K`` to its square), of the normals, and the count of points whose
``valid`` or ``invalid_reason`` differ. Done when every relative difference is
below 1e-6 and no decision differs.

Usage::

    python benchmarks/pointcloud_parity_P21.py --seeds 0-39            # tuning seeds
    python benchmarks/pointcloud_parity_P21.py --seeds 1000-1039       # held-out seeds
    python benchmarks/pointcloud_parity_P21.py --seeds 0-199 --family symmetric   # one family
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))

from pointcloud import noisy, sample  # noqa: E402

FAMILIES = ("thin", "open", "noisy", "voxel", "symmetric")
COPIES = ("none", "beside", "near_duplicates", "rotated")


def _rotation(rng) -> np.ndarray:
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    return q * np.sign(np.diag(r))


def _thin(rng):
    from meshcurv import shapes

    kind = rng.integers(4)
    if kind == 0:
        subdivisions = int(rng.integers(8, 27))
        return f"ellipsoid(3,3,0.15) sub {subdivisions}", shapes.ellipsoid((3.0, 3.0, 0.15), subdivisions).vertices
    if kind == 1:
        n_major = int(rng.integers(60, 140))
        minor = float(rng.uniform(0.08, 0.2))
        mesh = shapes.torus(major_radius=3.0, minor_radius=minor, n_major=n_major, n_minor=int(rng.integers(8, 16)))
        return f"thin torus r {minor:.3f} n {n_major}", mesh.vertices
    if kind == 2:
        n = int(rng.integers(2000, 6000))
        thickness = float(rng.uniform(0.05, 0.3))
        return f"random ellipsoid(3,3,{thickness:.2f}) n {n}", shapes.random_ellipsoid(
            (3.0, 3.0, thickness), n, seed=int(rng.integers(1 << 30))
        ).vertices
    n = int(rng.integers(2000, 6000))
    return f"flat_ellipsoid sample n {n}", sample("flat_ellipsoid", n, seed=int(rng.integers(1 << 30)))[0]


def _open(rng):
    from meshcurv import shapes

    kind = rng.integers(3)
    if kind == 0:
        subdivisions = int(rng.integers(8, 24))
        irregular = bool(rng.integers(2))
        mesh = shapes.hemisphere(subdivisions, irregular=irregular, seed=int(rng.integers(1000)))
        return f"hemisphere sub {subdivisions} irregular {irregular}", mesh.vertices
    if kind == 1:
        surface = str(rng.choice(["sphere", "ellipsoid", "torus", "cylinder"]))
        n = int(rng.integers(2000, 6000))
        points = sample(surface, n, seed=int(rng.integers(1 << 30)))[0]
        cut = float(rng.uniform(0.3, 0.8))
        low, high = points[:, 0].min(), points[:, 0].max()
        return f"{surface} patch {cut:.2f} n {n}", points[points[:, 0] < low + cut * (high - low)]
    n = int(rng.integers(2000, 6000))
    return f"saddle n {n}", sample("saddle", n, uniform=bool(rng.integers(2)), seed=int(rng.integers(1 << 30)))[0]


def _noisy(rng):
    surface = str(rng.choice(["sphere", "ellipsoid", "torus", "flat_ellipsoid", "thin_torus", "saddle"]))
    n = int(rng.integers(2000, 6000))
    level = float(rng.choice([0.05, 0.1, 0.2, 0.3]))
    points, normals, *_, area = sample(surface, n, seed=int(rng.integers(1 << 30)))
    return f"{surface} n {n} noise {level}", noisy(points, normals, area, level, seed=int(rng.integers(1 << 30)))


def _voxel(rng):
    from meshcurv import shapes

    kind = rng.integers(3)
    seed = int(rng.integers(1000))
    if kind == 0:
        radius = float(rng.uniform(5, 14))
        return f"voxel_sphere {radius:.1f}", shapes.voxel_sphere(radius, seed=seed).vertices
    if kind == 1:
        axes = tuple(float(a) for a in np.round(rng.uniform([6, 5, 1.5], [14, 12, 6]), 1))
        return f"voxel_ellipsoid {axes}", shapes.voxel_ellipsoid(axes, seed=seed).vertices
    major, minor = float(rng.uniform(8, 14)), float(rng.uniform(2, 5))
    return f"voxel_torus {major:.1f} {minor:.1f}", shapes.voxel_torus(major, minor, seed=seed).vertices


def _symmetric(rng):
    """The vertices of a symmetric mesh (thin or not, whole or cut): their neighbourhoods tie by the thousand, and
    a decision taken on numbers equal to round-off falls on both sides of a tie."""
    from meshcurv import shapes

    kind = rng.integers(3)
    if kind == 0:
        axes = (3.0, float(rng.choice([2.0, 3.0])), float(rng.choice([0.1, 0.15, 0.3, 1.0])))
        subdivisions = int(rng.integers(10, 27))
        label, vertices = f"ellipsoid{axes} sub {subdivisions}", shapes.ellipsoid(axes, subdivisions).vertices
    elif kind == 1:
        minor = float(rng.choice([0.1, 0.15, 0.5]))
        n_major, n_minor = int(rng.integers(60, 160)), int(rng.integers(8, 24))
        mesh = shapes.torus(major_radius=3.0, minor_radius=minor, n_major=n_major, n_minor=n_minor)
        label, vertices = f"torus r {minor} {n_major}x{n_minor}", mesh.vertices
    else:
        subdivisions = int(rng.integers(10, 30))
        label, vertices = f"icosphere sub {subdivisions}", shapes.icosphere(subdivisions).vertices
    vertices = np.asarray(vertices, dtype=float)
    if rng.integers(2):
        low, high = vertices[:, 0].min(), vertices[:, 0].max()
        cut = float(rng.choice([0.5, 0.6]))
        label, vertices = f"{label} cut {cut}", vertices[vertices[:, 0] < low + cut * (high - low)]
    return label, vertices


def draw(seed: int) -> tuple[str, np.ndarray]:
    """``(label, points)``: the cloud of ``seed``."""
    rng = np.random.default_rng(seed)
    family = FAMILIES[seed % len(FAMILIES)]
    label, points = {"thin": _thin, "open": _open, "noisy": _noisy, "voxel": _voxel, "symmetric": _symmetric}[family](
        rng
    )
    points = np.asarray(points, dtype=float)
    copies = COPIES[(seed // len(FAMILIES)) % len(COPIES)]
    if copies == "beside":
        points = np.concatenate([points, points + np.ptp(points, axis=0)])
    elif copies == "near_duplicates":
        times = int(rng.integers(2, 4))
        scale = np.abs(points).max()
        points = np.concatenate([points + 1e-12 * scale * rng.normal(size=points.shape) for _ in range(times)])
    elif copies == "rotated":
        points = points @ _rotation(rng).T + rng.normal(size=3)
    return f"{family}: {label}, copies {copies}", points


def compare(compiled, reference) -> dict:
    """The differences of two results (see the module's docstring)."""
    scale = np.abs(np.concatenate([reference.k_min, reference.k_max]))
    scale = float(np.nanmax(scale)) if np.isfinite(scale).any() else 1.0
    scale = scale or 1.0
    both = compiled.valid & reference.valid
    out = {}
    for field, unit in (("k_min", scale), ("k_max", scale), ("mean", scale), ("gaussian", scale * scale)):
        a, b = getattr(compiled, field)[both], getattr(reference, field)[both]
        out[field] = float(np.max(np.abs(a - b), initial=0.0)) / unit
    usable = np.isfinite(compiled.normals).all(axis=1) & np.isfinite(reference.normals).all(axis=1)
    out["normals"] = float(np.max(np.abs(compiled.normals[usable] - reference.normals[usable]), initial=0.0))
    out["normals_nan"] = int((np.isnan(compiled.normals).any(axis=1) != np.isnan(reference.normals).any(axis=1)).sum())
    out["valid"] = int((compiled.valid != reference.valid).sum())
    out["reason"] = int((compiled.invalid_reason != reference.invalid_reason).sum())
    return out


def run_case(seed: int, method: str, radius_spacings: float | None) -> tuple[str, int, dict, float]:
    from scipy.spatial import cKDTree

    from meshcurv._backend import use_backend
    from meshcurv.pointcloud import point_cloud_curvatures

    label, points = draw(seed)
    radius = None
    if radius_spacings is not None:
        distances, _ = cKDTree(points).query(points, k=2)
        radius = radius_spacings * float(np.median(distances[:, 1][distances[:, 1] > 0]))
    results = {}
    start = time.process_time()
    for backend in ("numba", "numpy"):
        with use_backend(backend), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            results[backend] = point_cloud_curvatures(points, method=method, radius=radius)
    return label, points.shape[0], compare(results["numba"], results["numpy"]), time.process_time() - start


def parse_seeds(text: str) -> list[int]:
    seeds: list[int] = []
    for part in text.split(","):
        if "-" in part:
            low, high = part.split("-")
            seeds.extend(range(int(low), int(high) + 1))
        else:
            seeds.append(int(part))
    return seeds


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", default="0-31", help="seeds, e.g. 0-31 or 3,7,1000-1010")
    parser.add_argument("--methods", nargs="+", default=["corrected_measures", "jets"])
    parser.add_argument("--family", choices=FAMILIES, default=None, help="only the seeds of this family")
    parser.add_argument("--radius", type=float, default=None, help="a given radius in median spacings (else default)")
    args = parser.parse_args(argv)
    worst = {}
    failing = 0
    print("| seed | cloud | points | method | k_min | k_max | H | K | normals | valid | reason | CPU s |")
    print("|---|---|---|---|---|---|---|---|---|---|---|---|")
    for seed in parse_seeds(args.seeds):
        if args.family is not None and FAMILIES[seed % len(FAMILIES)] != args.family:
            continue
        for method in args.methods:
            label, n, found, cpu = run_case(seed, method, args.radius)
            for key, value in found.items():
                worst[key] = max(worst.get(key, 0), value)
            bad = any(found[f] > 1e-6 for f in ("k_min", "k_max", "mean", "gaussian", "normals")) or any(
                found[f] for f in ("valid", "reason", "normals_nan")
            )
            failing += bad
            print(
                f"| {seed} | {label} | {n} | {method} | {found['k_min']:.1e} | {found['k_max']:.1e} | "
                f"{found['mean']:.1e} | {found['gaussian']:.1e} | {found['normals']:.1e} | {found['valid']} | "
                f"{found['reason']} | {cpu:.1f} |" + (" **differ**" if bad else ""),
                flush=True,
            )
    print(f"\ncases that differ: {failing}; worst: " + ", ".join(f"{k} {v:.2g}" for k, v in worst.items()))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
