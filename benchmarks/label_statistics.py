"""FreeSurfer's per-object statistics of label images against their exact values (issue 34).

Each case is one object voxelised analytically (a voxel is inside when its
centre is) with anisotropic voxels, its centre moved off the grid by a random
offset of up to half a voxel; the row of :func:`meshcurv.label_curvatures`
(default call) is set beside the value of the smooth surface:

- sphere of radius R: area 4 pi R^2, int H dA = 4 pi R, int K dA = 4 pi,
  BE = 8 pi, FI = 0, ICIp = 1, ICIn = 0, shape index 1, curvedness 1/R;
- torus of radii R > r (k1 = 1/r, k2 = cos t / (R + r cos t), dA = r (R + r cos t) dt dp):
  area 4 pi^2 R r, int H dA = 2 pi^2 R, int K dA = 0, ICIp = ICIn = 1, and
  BE, FI, the mean shape index and curvedness by quadrature over t;
- two tori fused side by side (genus 2): int K dA = -4 pi (Gauss-Bonnet), no other exact value.

``--repeats N`` draws N offsets per case and gives the worst relative error of
each column (absolute for the columns whose exact value is 0).

    python benchmarks/label_statistics.py                 # the table of docs/guide/label_statistics.md
    python benchmarks/label_statistics.py --repeats 10    # worst of 10 offsets per case
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from scipy import integrate

import meshcurv
from meshcurv.errors import MeshQualityWarning

COLUMNS = (
    "area",
    "mean_integral",
    "gaussian_integral",
    "bending_energy",
    "folding_index",
    "ici_positive",
    "ici_negative",
    "shape_index_mean",
    "curvedness_mean",
)


def voxelise(inside, extent, spacing, offset):
    """A uint8 image of the voxels whose centre is inside ``inside(z, y, x)`` (centred, moved by ``offset``)."""
    spacing = np.asarray(spacing, dtype=float)
    counts = np.ceil(np.asarray(extent, dtype=float) / spacing).astype(int) + 4
    axes = [np.arange(n) * s - (n - 1) * s / 2 - o for n, s, o in zip(counts, spacing, offset)]
    return inside(*np.meshgrid(*axes, indexing="ij")).astype(np.uint8)


def sphere_case(radius):
    truth = {
        "area": 4 * np.pi * radius**2,
        "mean_integral": 4 * np.pi * radius,
        "gaussian_integral": 4 * np.pi,
        "bending_energy": 8 * np.pi,
        "folding_index": 0.0,
        "ici_positive": 1.0,
        "ici_negative": 0.0,
        "shape_index_mean": 1.0,
        "curvedness_mean": 1 / radius,
    }
    return (lambda z, y, x: z**2 + y**2 + x**2 <= radius**2), [2 * radius] * 3, truth


def in_torus(z, y, x, major, minor):
    return (np.sqrt(x**2 + y**2) - major) ** 2 + z**2 <= minor**2


def torus_case(major, minor):
    def over_surface(f):  # int f dA over the torus
        value, _ = integrate.quad(lambda t: f(t) * minor * (major + minor * np.cos(t)), 0, 2 * np.pi, limit=200)
        return 2 * np.pi * value

    k1 = 1 / minor
    k2 = lambda t: np.cos(t) / (major + minor * np.cos(t))  # noqa: E731
    area = 4 * np.pi**2 * major * minor
    truth = {
        "area": area,
        "mean_integral": 2 * np.pi**2 * major,
        "gaussian_integral": 0.0,
        "bending_energy": over_surface(lambda t: k1**2 + k2(t) ** 2),
        "folding_index": over_surface(lambda t: k1 * (k1 - abs(k2(t)))) / (4 * np.pi),
        "ici_positive": 1.0,
        "ici_negative": 1.0,
        "shape_index_mean": over_surface(lambda t: (2 / np.pi) * np.arctan2(k1 + k2(t), k1 - k2(t))) / area,
        "curvedness_mean": over_surface(lambda t: np.sqrt((k1**2 + k2(t) ** 2) / 2)) / area,
    }
    return (
        (lambda z, y, x: in_torus(z, y, x, major, minor)),
        [2 * minor, 2 * (major + minor), 2 * (major + minor)],
        truth,
    )


def double_torus_case(major, minor):
    shift = major + 0.6 * minor

    def inside(z, y, x):
        return in_torus(z, y - shift, x, major, minor) | in_torus(z, y + shift, x, major, minor)

    truth = {"gaussian_integral": -4 * np.pi}
    return inside, [2 * minor, 2 * (shift + major + minor), 2 * (major + minor)], truth


CASES = (
    ("sphere R=6", sphere_case(6.0), (0.7, 0.5, 0.4)),
    ("sphere R=20", sphere_case(20.0), (2.0, 1.0, 1.0)),
    ("torus R=8 r=3.5", torus_case(8.0, 3.5), (0.7, 0.5, 0.4)),
    ("torus R=20 r=10", torus_case(20.0, 10.0), (2.0, 1.0, 1.0)),
    ("torus R=5 r=2", torus_case(5.0, 2.0), (0.7, 0.5, 0.4)),
    ("torus R=12 r=5", torus_case(12.0, 5.0), (2.0, 1.0, 1.0)),
    ("genus 2, R=6 r=2.8", double_torus_case(6.0, 2.8), (0.7, 0.5, 0.4)),
)


def measure(case, spacing, offset):
    inside, extent, _ = case
    image = voxelise(inside, extent, spacing, offset)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        table = meshcurv.label_curvatures(image, spacing=spacing)
    return table.iloc[0]


def error(measured, exact):
    return measured - exact if exact == 0 else measured / exact - 1


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=1, help="offsets per case (worst error reported)")
    parser.add_argument("--seed", type=int, default=0)
    args = parser.parse_args(argv)
    rng = np.random.default_rng(args.seed)
    print(
        "| object (voxels z x y x x) | column | exact | measured | error |"
        if args.repeats == 1
        else f"| object (voxels z x y x x) | column | exact | worst error over {args.repeats} offsets |"
    )
    print("|---|---|---|---|---|" if args.repeats == 1 else "|---|---|---|---|")
    for name, case, spacing in CASES:
        truth = case[2]
        started = time.perf_counter()
        rows = [measure(case, spacing, rng.uniform(-0.5, 0.5, 3) * np.asarray(spacing)) for _ in range(args.repeats)]
        seconds = (time.perf_counter() - started) / args.repeats
        label = f"{name} ({' x '.join(f'{s:g}' for s in spacing)}; {rows[0].n_vertices} vertices, {seconds:.1f} s)"
        for column in COLUMNS:
            exact = truth.get(column)
            if args.repeats == 1:
                measured = rows[0][column]
                text = (
                    ""
                    if exact is None
                    else (f"{error(measured, exact):+.4f}" if exact == 0 else f"{100 * error(measured, exact):+.2f}%")
                )
                print(f"| {label} | `{column}` | {'' if exact is None else f'{exact:.4g}'} | {measured:.4g} | {text} |")
            elif exact is not None:
                worst = max((error(row[column], exact) for row in rows), key=abs)
                text = f"{worst:+.4f}" if exact == 0 else f"{100 * worst:+.2f}%"
                print(f"| {label} | `{column}` | {exact:.4g} | {text} |")
            label = ""


if __name__ == "__main__":
    main()
