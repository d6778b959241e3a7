"""Where the smoothed tori's H error comes from, and normal fits tried against it (issue 30, helper V23).

``python benchmarks/smoothed_normals_V23.py`` (the split: a few seconds) and ``--prototype`` (the normal fits
tried: about 15 minutes on one core). Needs scikit-image; ``--prototype`` needs numba. Results in
``benchmarks/smoothed_normals_V23.md``.

The split: the default call on the smoothed tori of ``scale_families`` (marching cubes at 0.5 of a binary mask
blurred by a Gaussian of sigma voxels, the grid offset drawn by ``seed``) and on the same meshes with every
vertex moved to its closest point of the analytic torus (the lattice's sampling kept, its positions exact). The
median of ``|H - H_exact| / max|k|`` and the median angle of the result's normals to the analytic ones.

The prototype: the normals the default fits (``icc.fitted_normals``) replaced by jets of degree ``deg`` fitted
over every vertex (no coarse level) within ``q`` times the default's normal-fit radius, each point weighted by
``(1 - d^2 / rho^2)^2`` times its area and, after the first fit, by ``(1 - alpha s^2)^2`` with ``s = 2 |z| / d``
(``z`` its height over the first fit's tangent plane, ``d`` its distance): about the sine of the tilt of the
surface's normal at the point on a surface of constant curvature, so that the ball is cut short where the
surface turns fast (the tube of a torus) and kept long where it is flat (along the ring). Everything else, the
radii and the sums, is the default's.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import meshcurv  # noqa: E402
import scale_families  # noqa: E402
import smoothed_isosurfaces  # noqa: E402
from meshcurv.estimators import icc  # noqa: E402

TUNING = [("torus", (25.0, 10.0), 1.0), ("torus", (20.0, 8.0), 1.0)]
TUNING_SEEDS = (7, 11)
HELD_OUT = [
    ("torus", (30.0, 12.0), 1.0),
    ("torus", (16.0, 6.0), 1.0),
    ("torus", (25.0, 10.0), 0.5),
    ("torus", (25.0, 10.0), 1.5),
    ("sphere", (10.0,), 1.0),
    ("sphere", (20.0,), 0.5),
    ("ellipsoid", (24.0, 16.0, 10.0), 1.0),
]
VARIANTS = [
    {},
    {"deg": 3, "q": 1.0, "alpha": 0.0},
    {"deg": 4, "q": 1.0, "alpha": 0.0},
    {"deg": 5, "q": 1.0, "alpha": 0.0},
    {"deg": 3, "q": 0.8, "alpha": 0.0},
    {"deg": 3, "q": 1.0, "alpha": 1.0},
    {"deg": 3, "q": 1.2, "alpha": 1.0},
    {"deg": 3, "q": 1.5, "alpha": 1.0},
    {"deg": 3, "q": 2.0, "alpha": 1.0},
    {"deg": 3, "q": 1.5, "alpha": 2.0},
]
HELD_OUT_VARIANTS = [{}, {"deg": 3, "q": 1.0, "alpha": 0.0}, {"deg": 3, "q": 1.2, "alpha": 1.0}]


def _torus_frame(points, major):
    rho = np.hypot(points[:, 1], points[:, 2])
    radial = np.zeros_like(points)
    radial[:, 1:] = points[:, 1:] / rho[:, None]
    tube = points - major * radial
    return tube / np.linalg.norm(tube, axis=1, keepdims=True), radial


def _mesh(kind, size, sigma, seed, *, projected=False):
    inside, extent, exact = scale_families._solid(kind, size)
    vertices, faces = scale_families._smoothed_mesh(inside, extent, sigma, seed)
    if projected:  # the closest points of the analytic torus
        normals, radial = _torus_frame(vertices, size[0])
        vertices = size[0] * radial + size[1] * normals
    k_min, k_max = exact(vertices)
    return vertices, faces, k_min, k_max


def _errors(kind, size, vertices, faces, k_min, k_max):
    """(H, k_min, k_max errors in % of max|k|, normal angle in degrees or NaN), medians."""
    result = meshcurv.principal_curvatures(vertices, faces)
    scale = np.maximum(np.abs(k_min), np.abs(k_max))
    errors = [
        100 * np.nanmedian(np.abs(estimate - exact) / scale)
        for estimate, exact in ((result.mean, (k_min + k_max) / 2), (result.k_min, k_min), (result.k_max, k_max))
    ]
    angle = np.nan
    if kind == "torus":
        normals, _ = _torus_frame(vertices, size[0])
        angle = np.degrees(np.nanmedian(np.arccos(np.clip(np.einsum("ij,ij->i", result.normals, normals), -1, 1))))
    return (*errors, angle)


def split() -> None:
    print("| torus, sigma, seed | H error | normal angle | projected: H error | projected: normal angle |")
    print("|---|--:|--:|--:|--:|")
    for kind, size, sigma in TUNING:
        for seed in TUNING_SEEDS:
            cells = []
            for projected in (False, True):
                h, _, _, angle = _errors(kind, size, *_mesh(kind, size, sigma, seed, projected=projected))
                cells += [f"{h:.2f}%", f"{angle:.2f} deg"]
            print(f"| {size}, {sigma:g}, {seed} | " + " | ".join(cells) + " |")


def blur_split() -> None:
    """The tori of ``scale_families.SMOOTHED`` (their seeds): H error against the analytic torus and against the
    blurred level set (``smoothed_isosurfaces.blurred_mean``, first order in sigma^2), signed, per side."""
    print("| mesh | side | against the torus: error / signed | against the blurred surface: error / signed |")
    print("|---|---|--:|--:|")
    settings = [(kind, size, sigma) for kind, size, sigmas in scale_families.SMOOTHED for sigma in sigmas]
    for case, (kind, size, sigma) in zip(scale_families.smoothed_cases(), settings, strict=True):
        if kind != "torus":
            continue
        result = meshcurv.principal_curvatures(case.vertices, case.faces)
        scale = np.maximum(np.abs(case.k_min), np.abs(case.k_max))
        blurred = smoothed_isosurfaces.blurred_mean(kind, size, sigma, case.vertices, case.k_min, case.k_max)
        gaussian = case.k_min * case.k_max
        for side, rows in (
            ("all", np.ones_like(gaussian, dtype=bool)),
            ("outer", gaussian > 0),
            ("inner", gaussian < 0),
        ):
            cells = []
            for exact in (case.mean, blurred):
                signed = ((result.mean - exact) / scale)[rows]
                cells.append(f"{100 * np.nanmedian(np.abs(signed)):.2f}% / {100 * np.nanmedian(signed):.2f}%")
            print(f"| {case.name} | {side} | " + " | ".join(cells) + " |")


def _prototype_fits():
    import numba
    from scipy.spatial import cKDTree

    @numba.njit(cache=False)
    def fit_all(points, areas, start, centres, radii, indptr, indices, exponents, alpha):
        terms = exponents.shape[0]
        out = np.full((centres.shape[0], 3), np.nan)
        for c in range(centres.shape[0]):
            v = centres[c]
            n = start[v] / np.sqrt(start[v] @ start[v])
            for step in range(2):
                helper = np.array([1.0, 0.0, 0.0]) if abs(n[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
                t1 = helper - (helper @ n) * n
                t1 /= np.sqrt(t1 @ t1)
                t2 = np.cross(n, t1)
                moments = np.zeros((terms, terms))
                right = np.zeros(terms)
                row = np.zeros(terms)
                for j in indices[indptr[c] : indptr[c + 1]]:
                    d = (points[j] - points[v]) / radii[c]
                    x, y, z = d @ t1, d @ t2, d @ n
                    q = x * x + y * y + z * z
                    w = 1.0 - q
                    if w <= 0:
                        continue
                    w = w * w * areas[j]
                    if step > 0 and alpha > 0 and q > 0:  # the tilt weight, in the first fit's frame
                        f = 1.0 - alpha * 4 * z * z / q
                        if f <= 0:
                            continue
                        w *= f * f
                    for k in range(terms):
                        row[k] = x ** exponents[k, 0] * y ** exponents[k, 1]
                    for k in range(terms):
                        right[k] += w * row[k] * z
                        for m in range(terms):
                            moments[k, m] += w * row[k] * row[m]
                solution = np.linalg.solve(moments, right)
                tilted = n - solution[1] * t1 - solution[2] * t2
                n = tilted / np.sqrt(tilted @ tilted)
            out[c] = n
        return out

    def fit(points, areas, start, centres, radii, degree, alpha):
        lists = cKDTree(points).query_ball_point(points[centres], radii, return_sorted=False)
        indptr = np.concatenate([[0], np.cumsum([len(members) for members in lists])]).astype(np.int64)
        indices = np.concatenate([np.asarray(members, dtype=np.int64) for members in lists])
        exponents = np.array([(i, t - i) for t in range(degree + 1) for i in range(t, -1, -1)], dtype=np.int64)
        return fit_all(points, areas, start, centres, radii, indptr, indices, exponents, alpha)

    return fit


def prototype() -> None:
    fit = _prototype_fits()
    original = icc.fitted_normals
    variant: dict = {}

    def replaced(vertices, normals, valid, radius, **options):
        fitted = original(vertices, normals, valid, radius, **options)
        if not variant:
            return fitted
        areas = options.get("areas")
        areas = np.ones(vertices.shape[0]) if areas is None else areas
        centres = np.flatnonzero(valid)
        radii = np.broadcast_to(np.asarray(radius, dtype=float), (vertices.shape[0],))[centres] * variant["q"]
        start = np.where(np.isfinite(fitted), fitted, normals)
        fitted = fitted.copy()
        fitted[centres] = fit(
            vertices, areas, start, centres, np.ascontiguousarray(radii), variant["deg"], variant["alpha"]
        )
        return fitted

    icc.fitted_normals = replaced
    try:
        meshes = [
            (f"{size}, sigma {sigma:g}, seed {seed}", kind, size, _mesh(kind, size, sigma, seed))
            for kind, size, sigma in TUNING
            for seed in TUNING_SEEDS
        ]
        print("Tuning (cells: H error / normal angle):\n")
        print("| normals | " + " | ".join(name for name, *_ in meshes) + " | mean H | CPU s |")
        print("|---|" + "--:|" * (len(meshes) + 2))
        for settings in VARIANTS:
            variant.clear()
            variant.update(settings)
            start = time.process_time()
            rows = [_errors(kind, size, *mesh) for _, kind, size, mesh in meshes]
            cells = [f"{h:.2f}% / {angle:.2f}" for h, _, _, angle in rows]
            mean = np.mean([row[0] for row in rows])
            print(
                f"| {settings or 'default'} | "
                + " | ".join(cells)
                + f" | {mean:.3f}% | {time.process_time() - start:.0f} |"
            )
        held = [
            (f"{kind}{size}, sigma {sigma:g}", kind, size, _mesh(kind, size, sigma, 7))
            for kind, size, sigma in HELD_OUT
        ]
        print("\nHeld out (seed 7; cells: H / k_min / k_max errors, % of max|k|):\n")
        print("| normals | " + " | ".join(name for name, *_ in held) + " |")
        print("|---|" + "--:|" * len(held))
        for settings in HELD_OUT_VARIANTS:
            variant.clear()
            variant.update(settings)
            rows = [_errors(kind, size, *mesh) for _, kind, size, mesh in held]
            print(
                f"| {settings or 'default'} | "
                + " | ".join(f"{h:.2f} / {a:.2f} / {b:.2f}" for h, a, b, _ in rows)
                + " |"
            )
    finally:
        icc.fitted_normals = original


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--prototype", action="store_true", help="the normal fits tried (about 15 minutes)")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
    if args.prototype:
        prototype()
    else:
        split()
        print()
        blur_split()
    return 0


if __name__ == "__main__":
    sys.exit(main())
