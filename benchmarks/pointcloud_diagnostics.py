"""Point-cloud diagnostics that must not tell the user something false (issue 29): the figures of
``benchmarks/pointcloud_diagnostics.md``.

Usage::

    python benchmarks/pointcloud_diagnostics.py --noise    # noise level, radius, valid points per family
    python benchmarks/pointcloud_diagnostics.py --voxels   # voxel surfaces (anisotropic voxels) read as clouds
    python benchmarks/pointcloud_diagnostics.py --staircase  # voxel surfaces of 6-40 voxels: tuned, held out
    python benchmarks/pointcloud_diagnostics.py --facets --seed 1  # given radii on random voxel surfaces (7: held out)
    python benchmarks/pointcloud_diagnostics.py --flat --seed 11  # flat voxel ellipsoids (17: held out)
    python benchmarks/pointcloud_diagnostics.py --facets --seed 31 --off-grid "noise 0.1"  # moved off the grid
    python benchmarks/pointcloud_diagnostics.py --lattice --seed 5  # the grid read on and off it, and on none

``--noise`` prints, per cloud and method, the noise level (``parameters["noise"]``), the default radius, the valid
points, a hash of the results and whether the call noted an unmeasured noise level: run it on two trees and compare
the rows. The clouds: random unit spheres (800, 2,562, 10,000 points) under uniform noise of 0-3 spacings along the
normal; plates 2 x 1 x 0.04 (4,000 points) clean and under noise, with estimated and exact normals; the benchmark's
surfaces (``benchmarks/pointcloud.py``: 5,000 points, noise 0-1 mean spacings).

``--voxels`` prints, per marching-cubes surface (spheres, tori, ellipsoids in isotropic and anisotropic voxels) and
method, the share of points valid, the median relative error of H of the valid points, the points off (valid, with a
radius of curvature of 4 spacings or more, as ``benchmarks/fuzz_api.py`` judges, H off by more than half the largest
|k|) and the valid points whose normal is inward. ``--staircase``: the same over voxel surfaces of radii 6-40
voxels, every point counted, on the shapes the staircase's constants were tuned on, then on held-out ones.

``--facets``: voxel spheres, ellipsoids and tori of 6-40 voxels drawn at random (``--seed``: 1 the draw the facet and
staircase constants were set on, 7 a held-out draw) in six voxel shapes, as ``benchmarks/fuzz_api.py``'s voxel
clouds; jets at the default radius and at 0.55-1.3 times it, corrected_measures at the default and 0.6 times the
jets' default; per method and radius over all surfaces: points, share valid, points off (valid, H off by more than
half of the point's own largest exact |k|), median and 95th percentile of that error, CPU seconds. ``--flat``: the
same over 12 flat voxel ellipsoids (axes a, 0.7-1 a, 0.2-0.4 a; a 20-32 voxels), corrected_measures and jets at their
defaults, at 0.55 and 0.85 times the jets' default. ``--off-grid``: the same surfaces moved off their grid (every
point by 0.001 voxel, Gaussian noise of 0.05 or 0.1 voxel along each axis, or a random rotation; the exact normals
turned with them). ``--lattice``: whether the call reads a grid, and its steps over the half voxels, on voxel
ellipsoids in each voxel shape on and off their grid, on the surfaces of ``benchmarks/pointcloud.py`` (clean and
noisy, 2,000-80,000 points) and on the vertices of ``../shared/meshes`` (when present).
"""

from __future__ import annotations

import argparse
import hashlib
import sys
import time
import warnings
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

from meshcurv import point_cloud_curvatures, read_mesh, shapes

sys.path.insert(0, str(Path(__file__).parent))
import pointcloud as benchmark  # noqa: E402  (benchmarks/pointcloud.py: the surfaces and their noise)


def cloud_spacing(points: np.ndarray) -> float:
    """The clouds' median spacing: the distance to the 8th neighbour times sqrt(pi / 8)."""
    return float(np.median(cKDTree(points).query(points, k=9)[0][:, 8]) * np.sqrt(np.pi / 8))


def noisy_sphere(n: int, noise: float, seed: int = 1) -> np.ndarray:
    points = shapes.random_sphere(n, seed=seed).vertices
    moved = np.random.default_rng(seed).uniform(-noise, noise, (n, 1)) * cloud_spacing(points)
    return points * (1 + moved)


def plate(n: int, axes, seed: int, noise: float) -> tuple[np.ndarray, np.ndarray]:
    """``n`` samples of the ellipsoid ``axes`` uniform by area, moved along the exact normal by uniform noise of
    ``noise`` spacings; and the exact normals."""
    rng = np.random.default_rng(seed)
    axes = np.asarray(axes, dtype=float)
    u = rng.normal(size=(8 * n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    weight = np.linalg.norm(u / axes, axis=1)
    points = u[rng.random(u.shape[0]) < weight / weight.max()][:n] * axes
    exact = points / axes**2
    exact /= np.linalg.norm(exact, axis=1, keepdims=True)
    return points + rng.uniform(-noise, noise, size=(n, 1)) * cloud_spacing(points) * exact, exact


def noise_clouds():
    """name -> a function returning ``(points, normals or None)``."""
    clouds = {}
    for n in (800, 2562, 10000):
        for level in (0, 0.2, 0.5, 1, 1.5, 2, 3):
            clouds[f"sphere {n} noise {level}"] = lambda n=n, level=level: (noisy_sphere(n, level), None)
    for seed in (0, 1):
        for level in (0, 0.1, 0.3, 1.0):
            for given in (False, True):
                name = f"plate 2x1x0.04 seed {seed} noise {level} {'given' if given else 'estimated'}"
                clouds[name] = lambda s=seed, level=level, g=given: (lambda made: (made[0], made[1] if g else None))(
                    plate(4000, (1.0, 0.5, 0.02), s, level)
                )
    for surface in ("ellipsoid", "torus", "cylinder", "saddle", "flat_ellipsoid", "thin_torus"):
        for level in (0, 0.1, 0.2, 0.5, 1.0):

            def make(surface=surface, level=level):
                x, normals, *_, area = benchmark.sample(surface, 5000)
                return benchmark.noisy(x, normals, area, level), None

            clouds[f"{surface} 5000 noise {level}"] = make
    return clouds


def run_noise() -> None:
    print("| cloud | method | noise | radius | valid | results | note |")
    print("|---|---|---|---|---|---|---|")
    for name, make in noise_clouds().items():
        points, normals = make()
        for method in ("corrected_measures", "jets"):
            with warnings.catch_warnings(record=True) as caught:
                warnings.simplefilter("always")
                r = point_cloud_curvatures(points, normals=normals, method=method)
            fields = np.concatenate([r.k_min, r.k_max, r.normals.ravel()])
            digest = hashlib.sha1(fields.tobytes() + r.valid.tobytes()).hexdigest()[:10]
            note = any("noise level was not measured" in str(w.message) for w in caught)
            p = r.parameters
            print(
                f"| {name} | {method} | {p['noise']:.4f} | {p['radius']:.4f} | {r.valid.sum()} | {digest} | {note} |",
                flush=True,
            )


VOXEL_SURFACES = {
    "ellipsoid (16, 12, 10), 0.7 x 1 x 1.3, seed 3": lambda: shapes.voxel_ellipsoid(
        (16.0, 12.0, 10.0), spacing=(0.7, 1.0, 1.3), seed=3
    ),
    "ellipsoid (16, 12, 10), 1 x 1 x 1, seed 3": lambda: shapes.voxel_ellipsoid((16.0, 12.0, 10.0), seed=3),
    "ellipsoid (8, 6, 5), 0.7 x 1 x 1.3, seed 3": lambda: shapes.voxel_ellipsoid(
        (8.0, 6.0, 5.0), spacing=(0.7, 1.0, 1.3), seed=3
    ),
    "ellipsoid (10, 7, 5), 1 x 1 x 2, seed 4": lambda: shapes.voxel_ellipsoid(
        (10.0, 7.0, 5.0), spacing=(1.0, 1.0, 2.0), seed=4
    ),
    "sphere 3, 0.5 x 0.2 x 0.2, seed 1": lambda: shapes.voxel_sphere(3.0, spacing=(0.5, 0.2, 0.2), seed=1),
    "sphere 12, 2 x 0.5 x 0.5, seed 1": lambda: shapes.voxel_sphere(12.0, spacing=(2.0, 0.5, 0.5), seed=1),
    "sphere 6, 1 x 1 x 1, seed 1": lambda: shapes.voxel_sphere(6.0, seed=1),
    "torus (3, 1.2), 0.5 x 0.2 x 0.2, seed 2": lambda: shapes.voxel_torus(3.0, 1.2, spacing=(0.5, 0.2, 0.2), seed=2),
    "torus (16, 6), 2 x 0.5 x 0.5, seed 2": lambda: shapes.voxel_torus(16.0, 6.0, spacing=(2.0, 0.5, 0.5), seed=2),
    "torus (12, 4), 1 x 1 x 1, seed 0": lambda: shapes.voxel_torus(12.0, 4.0, seed=0),
    # held out (no constant looked at): other proportions and voxels
    "sphere 10, 0.7 x 1 x 1.3, seed 2": lambda: shapes.voxel_sphere(10.0, spacing=(0.7, 1.0, 1.3), seed=2),
    "torus (14, 6), 1 x 0.7 x 1.2, seed 5": lambda: shapes.voxel_torus(14.0, 6.0, spacing=(1.0, 0.7, 1.2), seed=5),
    "ellipsoid (12, 9, 7), 1.2 x 1 x 0.8, seed 6": lambda: shapes.voxel_ellipsoid(
        (12.0, 9.0, 7.0), spacing=(1.2, 1.0, 0.8), seed=6
    ),
}

#: ``--staircase``: the jets' staircase bias (``LATTICE_AGREEMENT``, ``TREAD_SHARE``), radii 6-40 voxels.
STAIRCASE_TUNED = {
    "ellipsoid (16, 12, 10), 1 x 1 x 1, seed 3": lambda: shapes.voxel_ellipsoid((16.0, 12.0, 10.0), seed=3),
    "ellipsoid (16, 12, 10), 0.7 x 1 x 1.3, seed 3": lambda: shapes.voxel_ellipsoid(
        (16.0, 12.0, 10.0), spacing=(0.7, 1.0, 1.3), seed=3
    ),
    "sphere 6, 1 x 1 x 1, seed 1": lambda: shapes.voxel_sphere(6.0, seed=1),
    "sphere 20, 1 x 1 x 2.5, seed 1": lambda: shapes.voxel_sphere(20.0, spacing=(1.0, 1.0, 2.5), seed=1),
    "torus (12, 4), 1 x 1 x 1, seed 0": lambda: shapes.voxel_torus(12.0, 4.0, seed=0),
    "ellipsoid (24, 16, 10), 1 x 1 x 1, seed 1": lambda: shapes.voxel_ellipsoid((24.0, 16.0, 10.0), seed=1),
    "torus (16, 6), 2 x 0.5 x 0.5, seed 2": lambda: shapes.voxel_torus(16.0, 6.0, spacing=(2.0, 0.5, 0.5), seed=2),
    "ellipsoid (20, 14, 9), 1 x 1 x 1, seed 7": lambda: shapes.voxel_ellipsoid((20.0, 14.0, 9.0), seed=7),
    "ellipsoid (30, 20, 31.25), 1 x 1 x 2.5, seed 8": lambda: shapes.voxel_ellipsoid(
        (30.0, 20.0, 31.25), spacing=(1.0, 1.0, 2.5), seed=8
    ),
    "sphere 14, 1 x 1 x 1, seed 9": lambda: shapes.voxel_sphere(14.0, seed=9),
    "sphere 35, 1 x 1 x 1, seed 9": lambda: shapes.voxel_sphere(35.0, seed=9),
    "torus (18, 7), 1 x 1 x 2.5, seed 5": lambda: shapes.voxel_torus(18.0, 7.0, spacing=(1.0, 1.0, 2.5), seed=5),
    "ellipsoid (12, 9, 7), 1.2 x 1 x 0.8, seed 6": lambda: shapes.voxel_ellipsoid(
        (12.0, 9.0, 7.0), spacing=(1.2, 1.0, 0.8), seed=6
    ),
    "sphere 40, 1 x 1 x 1, seed 4": lambda: shapes.voxel_sphere(40.0, seed=4),
    "ellipsoid (36, 28, 20), 1 x 1 x 1, seed 2": lambda: shapes.voxel_ellipsoid((36.0, 28.0, 20.0), seed=2),
    "torus (28, 10), 1 x 1 x 1, seed 3": lambda: shapes.voxel_torus(28.0, 10.0, seed=3),
    "sphere 9, 1 x 1 x 1, seed 5": lambda: shapes.voxel_sphere(9.0, seed=5),
}

#: ... and held out (no constant looked at): other radii, axes and voxels.
STAIRCASE_HELD_OUT = {
    "sphere 30, 1 x 1 x 1, seed 11": lambda: shapes.voxel_sphere(30.0, seed=11),
    "sphere 38, 1 x 1 x 1, seed 12": lambda: shapes.voxel_sphere(38.0, seed=12),
    "ellipsoid (40, 25, 18), 1 x 1 x 1, seed 13": lambda: shapes.voxel_ellipsoid((40.0, 25.0, 18.0), seed=13),
    "ellipsoid (28, 22, 14), 1 x 1 x 1, seed 14": lambda: shapes.voxel_ellipsoid((28.0, 22.0, 14.0), seed=14),
    "ellipsoid (22, 17, 12), 0.8 x 1 x 1.2, seed 15": lambda: shapes.voxel_ellipsoid(
        (22.0, 17.0, 12.0), spacing=(0.8, 1.0, 1.2), seed=15
    ),
    "torus (24, 9), 1 x 1 x 1, seed 16": lambda: shapes.voxel_torus(24.0, 9.0, seed=16),
    "sphere 7.5, 1 x 1 x 1, seed 17": lambda: shapes.voxel_sphere(7.5, seed=17),
}


def run_voxels(surfaces=None, *, every: bool = False) -> None:
    """The table of ``--voxels`` over ``surfaces`` (name -> a function returning a ``VoxelMesh``; default
    :data:`VOXEL_SURFACES`); ``every``: the points off counted over every point, not only the resolved ones."""
    print("| surface | points | method | valid | median H error | points off | valid inward | CPU s |")
    print("|---|---|---|---|---|---|---|---|")
    for name, make in (VOXEL_SURFACES if surfaces is None else surfaces).items():
        mesh = make()
        points = mesh.vertices
        largest = np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))
        resolved = every | (largest * cloud_spacing(points) <= 0.25)
        for method in ("corrected_measures", "jets"):
            start = time.process_time()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = point_cloud_curvatures(points, method=method)
            seconds = time.process_time() - start
            valid = r.valid
            off = int((valid & resolved & (np.abs(r.mean - mesh.mean) > 0.5 * largest)).sum())
            error = np.median(np.abs(r.mean[valid] / mesh.mean[valid] - 1)) if valid.any() else np.nan
            inward = int((valid & (np.einsum("ij,ij->i", r.normals, mesh.normals) < 0)).sum())
            print(
                f"| {name} | {points.shape[0]} | {method} | {valid.mean():.3f} | {error:.4f} | {off} | {inward} "
                f"| {seconds:.1f} |",
                flush=True,
            )


#: ``--facets``: the voxel shapes of the random surfaces (those of ``benchmarks/fuzz_api.py`` and one finer).
FACET_SPACINGS = ((1.0, 1.0, 1.0), (0.7, 1.0, 1.3), (1.2, 1.0, 0.8), (1.0, 1.0, 2.5), (2.0, 1.0, 1.0), (0.5, 0.8, 1.0))

#: ... the method and the share of the jets' default radius of each call (None: the method's default).
FACET_CALLS = (
    ("jets", None),
    ("jets", 0.55),
    ("jets", 0.7),
    ("jets", 0.85),
    ("jets", 1.3),
    ("corrected_measures", None),
    ("corrected_measures", 0.6),
)


#: ``--flat``: the calls on the flat ellipsoids.
FLAT_CALLS = (("corrected_measures", None), ("jets", None), ("corrected_measures", 0.55), ("jets", 0.85))


#: ``--off-grid``: how each voxel surface leaves its grid (in voxels: a registration error, noise; a rotation).
OFF_GRID = {"moved": 1e-3, "noise 0.05": 0.05, "noise 0.1": 0.1, "rotated": None}


def _off_grid(mesh, spacing, how: str, rng):
    """``(points, normals)`` of the voxel surface ``mesh`` moved off its grid as :data:`OFF_GRID` ``how`` says."""
    points, normals = mesh.vertices, mesh.normals
    if how == "none":
        return points, normals
    if OFF_GRID[how] is None:
        turn, _ = np.linalg.qr(rng.normal(size=(3, 3)))
        return points @ turn.T, normals @ turn.T
    if how == "moved":  # every point by the same small distance in a random direction
        step = rng.normal(size=points.shape)
        step /= np.linalg.norm(step, axis=1, keepdims=True)
        return points + OFF_GRID[how] * np.mean(spacing) * step, normals
    return points + rng.normal(size=points.shape) * OFF_GRID[how] * np.asarray(spacing), normals


def run_facets(seed: int, *, flat: bool = False, how: str = "none") -> None:
    """The table of ``--facets`` for the draw ``seed``; ``flat``: the table of ``--flat`` (flat ellipsoids);
    ``how``: the surfaces moved off their grid (:data:`OFF_GRID`)."""
    rng = np.random.default_rng(seed)
    moves = np.random.default_rng(seed + 1000)
    totals: dict = {}
    for shape in ("flat", "flat") if flat else ("sphere", "ellipsoid", "torus"):
        for spacing in FACET_SPACINGS:
            voxel = float(np.mean(spacing))
            draw = int(rng.integers(1000))
            if shape == "flat":
                a = rng.uniform(20, 32)
                axes = np.array([a, a * rng.uniform(0.7, 1.0), a * rng.uniform(0.2, 0.4)]) * voxel
                mesh = shapes.voxel_ellipsoid(tuple(axes), spacing=spacing, seed=draw)
            elif shape == "sphere":
                mesh = shapes.voxel_sphere(float(rng.uniform(6, 40)) * voxel, spacing=spacing, seed=draw)
            elif shape == "ellipsoid":
                axes = np.sort(rng.uniform(6, 32, 3))[::-1] * voxel
                mesh = shapes.voxel_ellipsoid(tuple(axes), spacing=spacing, seed=draw)
            else:
                minor = float(rng.uniform(6, 12)) * voxel
                mesh = shapes.voxel_torus(minor * float(rng.uniform(2, 3)), minor, spacing=spacing, seed=draw)
            points, exact_normals = _off_grid(mesh, spacing, how, moves)
            if points.shape[0] > 40000:
                continue
            largest = np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                default = point_cloud_curvatures(points, method="jets").parameters["radius"]
                for method, share in FLAT_CALLS if flat else FACET_CALLS:
                    start = time.process_time()
                    radius = None if share is None else share * default
                    r = point_cloud_curvatures(points, method=method, radius=radius)
                    seconds = time.process_time() - start
                    side = np.sign(np.einsum("ij,ij->i", r.normals, exact_normals))
                    error = np.abs(r.mean - side * mesh.mean) / largest
                    total = totals.setdefault((method, share), [0, 0, 0, 0.0, []])
                    total[0] += points.shape[0]
                    total[1] += int(r.valid.sum())
                    total[2] += int((r.valid & (error > 0.5)).sum())
                    total[3] += seconds
                    total[4].append(error[r.valid])
    print("| method | radius | points | valid | points off | median error | 95th percentile | CPU s |")
    print("|---|---|---|---|---|---|---|---|")
    for (method, share), (n, valid, off, seconds, errors) in totals.items():
        errors = np.concatenate(errors)
        what = "default" if share is None else f"{share:g} x the jets' default"
        print(
            f"| {method} | {what} | {n} | {valid / n:.3f} | {off} | {np.median(errors):.3f} | "
            f"{np.percentile(errors, 95):.3f} | {seconds:.1f} |",
            flush=True,
        )


def run_lattice(seed: int) -> None:
    """The table of ``--lattice``: the grid :func:`meshcurv._pointcloud_normals.read_lattice` reads (as the call does:
    the median spacing, each point's 10 nearest) on voxel surfaces on and off their grid, and on clouds on none."""
    from meshcurv._pointcloud_normals import read_lattice

    def read(points):
        distances, indices = cKDTree(points).query(points, k=11)
        start = time.process_time()
        lattice = read_lattice(points, float(np.median(distances[:, 1])), neighbours=indices[:, 1:])
        return lattice, time.process_time() - start

    rng = np.random.default_rng(seed)
    print("| cloud | how | points | grid read | steps / half voxel | CPU s |")
    print("|---|---|---|---|---|---|")
    for spacing in FACET_SPACINGS:
        voxel = float(np.mean(spacing))
        axes = np.sort(rng.uniform(6, 32, 3))[::-1] * voxel
        mesh = shapes.voxel_ellipsoid(tuple(axes), spacing=spacing, seed=int(rng.integers(1000)))
        for how in ("none", *OFF_GRID):
            turn = np.eye(3)
            points, _ = _off_grid(mesh, spacing, how, rng)
            if OFF_GRID.get(how, 0.0) is None:  # the turn, from the points (a rigid motion about the origin)
                turn = np.linalg.lstsq(mesh.vertices, points, rcond=None)[0].T
            lattice, seconds = read(points)
            if lattice.steps.all():
                frame = np.eye(3) if lattice.frame is None else lattice.frame
                axis = np.abs(frame @ turn).argmax(axis=1)
                ratio = " ".join(f"{r:.4f}" for r in lattice.steps / (np.array(spacing)[axis] / 2))
            else:
                ratio = "-"
            print(
                f"| voxel ellipsoid {np.round(axes, 1).tolist()}, voxels {spacing} | {how} | {points.shape[0]} | "
                f"{'yes' if lattice.steps.all() else 'no'}{' (turned)' if lattice.frame is not None else ''} | "
                f"{ratio} | {seconds:.3f} |",
                flush=True,
            )
    found = 0
    slowest = 0.0
    clouds = 0
    for surface in benchmark.SURFACES:
        for uniform in (True, False):
            for n in (2_000, 20_000, 80_000):
                for level in (0.0, 0.05, 0.3):
                    points, normals, *_, area = benchmark.sample(surface, n, uniform=uniform, seed=seed)
                    if level:
                        points = benchmark.noisy(points, normals, area, level, seed=seed + 1)
                    lattice, seconds = read(points)
                    found += bool(lattice.steps.any())
                    slowest = max(slowest, seconds)
                    clouds += 1
    print(
        f"| benchmarks/pointcloud.py's surfaces | noise 0, 0.05, 0.3 spacings | {clouds} clouds | {found} | - | "
        f"{slowest:.3f} (slowest) |"
    )
    root = Path(__file__).resolve().parents[2] / "shared" / "meshes"
    for path in sorted(root.glob("*.obj")):
        vertices = np.unique(np.asarray(read_mesh(path).vertices, dtype=float), axis=0)
        lattice, seconds = read(vertices)
        print(
            f"| {path.name}'s vertices | - | {vertices.shape[0]} | {'yes' if lattice.steps.any() else 'no'} | - | "
            f"{seconds:.3f} |"
        )


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--noise", action="store_true", help="noise level, radius and valid points per family")
    parser.add_argument("--voxels", action="store_true", help="voxel surfaces read as clouds")
    parser.add_argument("--staircase", action="store_true", help="voxel surfaces, radii 6-40 voxels: tuned, held out")
    parser.add_argument("--facets", action="store_true", help="given radii on random voxel surfaces")
    parser.add_argument("--flat", action="store_true", help="flat voxel ellipsoids (c / a 0.2-0.4)")
    parser.add_argument("--lattice", action="store_true", help="the grid read on voxel surfaces on and off it")
    parser.add_argument("--seed", type=int, default=1, help="--facets, --flat: the draw (1 tuned, 7 held out)")
    parser.add_argument(
        "--off-grid",
        choices=["none", *OFF_GRID],
        default="none",
        help="--facets, --flat: surfaces moved off their grid",
    )
    args = parser.parse_args(argv)
    if args.noise:
        run_noise()
    if args.voxels:
        run_voxels()
    if args.staircase:
        run_voxels(STAIRCASE_TUNED, every=True)
        run_voxels(STAIRCASE_HELD_OUT, every=True)
    if args.facets:
        run_facets(args.seed, how=args.off_grid)
    if args.flat:
        run_facets(args.seed, flat=True, how=args.off_grid)
    if args.lattice:
        run_lattice(args.seed)


if __name__ == "__main__":
    main()
