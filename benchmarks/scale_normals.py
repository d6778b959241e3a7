"""What limits icc's default on voxel surfaces: the scale or the normals (issue 30, round 3).

    python benchmarks/scale_normals.py                      # the failing voxel rows with the analytic normals
    python benchmarks/scale_normals.py --set VOXEL_NORMAL_RATIO=2 --families voxel smoothed --output /tmp/v.json
    python benchmarks/scale_normals.py --normal-ladder 0.71,1,1.41,2 --families voxel failing --output /tmp/l.json
    python benchmarks/scale_normals.py --smoothed-normals     # other normal fits on three smoothed isosurfaces
    python benchmarks/scale_normals.py --normal-variant mean:1 --families voxel --output /tmp/m.json

The first form runs the default call on the five voxel meshes of ``accuracy_voxel.md`` that miss their
target, then the same ball sums at the same per-vertex radii (``result.radius``) with the analytic surface's
normals in place of the fitted ones, and prints both median errors of ``|H|`` over ``|H_exact|`` (the metric of
``accuracy_voxel.md``) and the fitted normals' angle to the analytic ones. ``--set NAME=VALUE`` changes
constants of :mod:`meshcurv.radius` (``--normal-degree`` icc's ``NORMAL_DEGREE``) and runs ``scale_default.py`` on ``--families``; ``--normal-ladder``
replaces the voxel path's normal fits by fits over each ``q`` times the per-vertex normal radius, keeping at
each vertex the upper rung of the consecutive pair whose normals turn least (averaged over 2 rings).
``--smoothed-normals`` fits the normals of three smoothed isosurfaces in other ways (jets of degree 2, 3, 4 over
6-18 voxels, ring averages of the face normals, jets on Taubin-smoothed positions) and sums the measures at
r = 4 and 6 voxels: median normal angle, and errors of H (against the blurred surface), k_min, k_max.
``--normal-variant NAME`` replaces the voxel path's normal fits (round 4, :func:`normal_variant`): ``area``
(points weighed by their vertex areas), ``mean:A`` (the fitted normals averaged over balls of ``A r_v``),
``extrapolated:A`` (the same average of the neighbours' jets' normals at the vertex's position), ``taper:P``
(kernel ``(1 - d^2 / R^2)^P``; today ``P = 2``) and ``gauss:S`` (``exp(-d^2 / (2 S^2 R^2))`` within the ball), then
runs ``scale_default.py`` on ``--families``. Tables: ``benchmarks/scale_default.md`` (rounds 3 and 4). Needs
scikit-image.
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import meshcurv  # noqa: E402
import meshcurv.radius as radius_rules  # noqa: E402
from meshcurv import shapes  # noqa: E402
from meshcurv.estimators import icc  # noqa: E402
from meshcurv.measures import curvatures_from_measures, face_measures  # noqa: E402
from meshcurv.neighborhoods import ball_face_sums  # noqa: E402

#: The failing rows of accuracy_voxel.md: (kind, size, spacing, seed).
FAILING = [
    ("torus", (12.0, 4.0), (2.0, 0.5, 0.5), 12),
    ("torus", (12.0, 4.0), (0.5, 0.5, 0.5), 12),
    ("torus", (20.0, 5.0), (1.5, 0.5, 0.5), 5),
    ("ellipsoid", (5.0, 8.0, 12.0), (1.2, 0.4, 0.4), 5),
    ("ellipsoid", (12.0, 6.0, 4.0), (0.4, 0.4, 0.4), 5),
]


def exact_normals_table():
    warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
    print("| mesh | default: H error | analytic normals, same radii: H error | fitted normals' angle, median (90%) |")
    print("|---|--:|--:|--:|")
    for kind, size, spacing, seed in FAILING:
        build = shapes.voxel_torus if kind == "torus" else shapes.voxel_ellipsoid
        mesh = build(*size, spacing, seed=seed) if kind == "torus" else build(size, spacing, seed=seed)
        vertices, faces = np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces)
        result = meshcurv.principal_curvatures(vertices, faces)
        normals = np.asarray(mesh.normals, dtype=float)  # outward
        corners = vertices[faces]
        if np.einsum("ij,ij->", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])) < 0:
            faces = np.ascontiguousarray(faces[:, ::-1])  # marching cubes winds these inward
        sums = ball_face_sums(vertices, faces, result.radius, face_measures(vertices, faces, normals), connected=True)
        k_min, k_max, *_ = curvatures_from_measures(sums, normals)
        exact = np.abs(mesh.mean)

        def error(mean):
            return 100 * float(np.nanmedian(np.abs(np.abs(mean) - exact) / exact))

        angle = np.degrees(np.arccos(np.clip(np.abs(np.sum(result.normals * normals, axis=1)), 0, 1)))
        print(
            f"| {mesh.name} | {error(result.mean):.2f}% | {error(0.5 * (k_min + k_max)):.2f}% "
            f"| {np.median(angle):.2f} ({np.percentile(angle, 90):.2f}) degrees |"
        )


def _ring_mean(neighbour_lists, rings, vectors):
    (total,) = radius_rules._ring_sums(neighbour_lists, rings, vectors)
    return total / np.linalg.norm(total, axis=1, keepdims=True)


def _taubin(vertices, neighbour_lists, steps, shrink=0.5, inflate=-0.53):
    from scipy import sparse

    indptr, indices = neighbour_lists
    n = vertices.shape[0]
    ring = sparse.csr_matrix((np.ones(indices.size), indices, indptr), shape=(n, n))
    mean = sparse.diags(1.0 / np.maximum(np.diff(indptr), 1)) @ ring
    moved = vertices.copy()
    for _ in range(steps):
        moved = moved + shrink * (mean @ moved - moved)
        moved = moved + inflate * (mean @ moved - moved)
    return moved


def smoothed_normals_table():
    import scale_families
    import smoothed_isosurfaces
    from meshcurv.jets import fit_jet_normals
    from meshcurv.topology import MeshTopology

    warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
    wanted = {"smoothed sphere(10), sigma 0.5", "smoothed torus(25, 10), sigma 0.5", "smoothed torus(16, 6), sigma 1"}
    settings = [(kind, size, sigma) for kind, size, sigmas in scale_families.SMOOTHED for sigma in sigmas]
    print("| mesh | normals | angle, median (90%) | r = 4: H / k_min / k_max | r = 6: H / k_min / k_max |")
    print("|---|---|--:|--:|--:|")
    for case, (kind, size, sigma) in zip(scale_families.smoothed_cases(), settings, strict=True):
        if case.name not in wanted:
            continue
        vertices, faces = case.vertices, case.faces
        exact = smoothed_isosurfaces.exact_normals(kind, size, vertices)
        blurred = smoothed_isosurfaces.blurred_mean(kind, size, sigma, vertices, case.k_min, case.k_max)
        scale = np.maximum(np.abs(case.k_min), np.abs(case.k_max))
        lists = MeshTopology.from_faces(faces, vertices.shape[0]).neighbour_lists
        corners = vertices[faces]
        face_normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        start = np.stack(
            [np.bincount(faces.ravel(), np.repeat(face_normals[:, i], 3), vertices.shape[0]) for i in range(3)], 1
        )
        start /= np.linalg.norm(start, axis=1, keepdims=True)
        every = np.ones(vertices.shape[0], dtype=bool)
        candidates = {"analytic": exact, "face normals, 1 ring": start}
        candidates.update({f"face normals, {k} rings": _ring_mean(lists, k, start) for k in (2, 4, 8)})
        for degree, radii in ((3, (6, 9, 12, 15, 18)), (2, (6, 9, 12)), (4, (9, 12, 15))):
            for radius in radii:
                candidates[f"jets of degree {degree} over {radius}"] = fit_jet_normals(
                    vertices, start, float(radius), degree=degree, iterations=2, adjacency=lists
                )
        jets_12 = candidates["jets of degree 3 over 12"]
        candidates["jets of degree 3 over 12, 1 ring mean"] = _ring_mean(lists, 1, jets_12)
        for steps in (5, 20, 50):
            candidates[f"jets of degree 3 over 12 on Taubin x{steps}"] = icc.fitted_normals(
                _taubin(vertices, lists, steps), start, every, 12.0, adjacency=lists
            )
        for label, normals in candidates.items():
            angle = np.degrees(np.arccos(np.clip(np.sum(normals * exact, axis=1), -1, 1)))
            cells = []
            for radius in (4.0, 6.0):
                sums = ball_face_sums(vertices, faces, radius, face_measures(vertices, faces, normals), connected=True)
                k_min, k_max, *_ = curvatures_from_measures(sums, normals)
                errors = [
                    np.nanmedian(np.abs(estimate - truth) / scale)
                    for estimate, truth in ((0.5 * (k_min + k_max), blurred), (k_min, case.k_min), (k_max, case.k_max))
                ]
                cells.append(" / ".join(f"{100 * e:.2f}%" for e in errors))
            print(
                f"| {case.name} | {label} | {np.median(angle):.2f} ({np.percentile(angle, 90):.2f}) | {cells[0]} | {cells[1]} |",
                flush=True,
            )


def normal_ladder(factors):
    """Replace icc's per-vertex normal fits by the least-change choice along ``factors`` times their radii."""
    fit = icc.fitted_normals

    def chosen(vertices, normals, valid, radius, **options):
        if np.ndim(radius) == 0:  # the one-radius paths (the pilot, other meshes): unchanged
            return fit(vertices, normals, valid, radius, **options)
        options.pop("failed", None)
        rungs = np.stack([fit(vertices, normals, valid, np.asarray(radius) * q, **options) for q in factors])
        turn = np.arccos(np.clip(np.abs(np.einsum("jvk,jvk->jv", rungs[1:], rungs[:-1])), 0, 1))
        (total,) = radius_rules._ring_sums(options["adjacency"], 2, turn.T)
        (count,) = radius_rules._ring_sums(options["adjacency"], 2, np.ones((vertices.shape[0], 1)))
        best = np.argmin((total / count).T, axis=0)
        return rungs[best + 1, np.arange(vertices.shape[0])]

    icc.fitted_normals = chosen


def _jets_at_vertices(vertices, start, radius, *, neighbours, adjacency, areas, weighted):
    """``(coefficients, frame)`` of icc's normal fits at every vertex (as :func:`icc.fitted_normals`, coarse level included)."""
    from meshcurv.jets import NORMAL_MIN_SPREAD, fit_jets

    options = {
        "degree": icc.NORMAL_DEGREE,
        "iterations": icc.NORMAL_ITERATIONS,
        "settled": icc.NORMAL_SETTLED,
        "min_spread": NORMAL_MIN_SPREAD,
    }
    scaled = None if areas is None or not np.any(areas > 0) else areas / np.median(areas[areas > 0])
    coarse = None if scaled is None else icc._coarse_level(vertices, start, radius, scaled, neighbours, adjacency)
    if coarse is None:  # the vertices themselves, area-weighted only when ``weighted``
        points, rows = (vertices, start, neighbours, adjacency, scaled if weighted else None), {}
    else:  # the coarse level: vertices then cluster centroids, the rows of the vertices only
        points, rows = coarse, {"centres": np.arange(vertices.shape[0]), "compact": True}
    coefficients, frame, _ = fit_jets(
        points[0], points[1], radius, neighbours=points[2], adjacency=points[3], areas=points[4], **rows, **options
    )
    return coefficients, frame


def _ball_average(
    vertices,
    normals,
    weights,
    radius,
    adjacency,
    coefficients=None,
    frame=None,
    fit_radius=None,
    shape=None,
    centroid=False,
):
    """(V, 3) unit normals averaged over each vertex's surface-connected ball of ``radius`` ((V,) array),
    each neighbour weighing ``weights[j] (1 - d^2 / r^2)^2``. With ``coefficients``, ``frame`` and
    ``fit_radius`` (the jets of the neighbours, coefficients in units of ``fit_radius``), each neighbour's
    normal is its jet's normal at the vertex's position (the slope of its quadric at the vertex's
    tangent coordinates) rather than at the neighbour; with ``shape`` (``k_min, k_max, dir_min, dir_max``
    of a first pass), each neighbour's normal moved to the vertex by its shape operator; with ``shape`` and
    ``centroid``, the plain average moved from the ball's weighted centroid to the vertex by the vertex's
    shape operator (``mean + S_v (x_v - c)``)."""
    from meshcurv.neighborhoods import connected_ball_pairs

    n = vertices.shape[0]
    order = np.argsort(radius, kind="stable")
    total = np.zeros((n, 3))
    spread, mass = np.zeros((n, 3)), np.zeros(n)
    usable = np.isfinite(normals).all(axis=1)
    for _chunk, centre, neighbour in connected_ball_pairs(vertices, order, radius[order], adjacency, usable):
        index = order[centre]
        offset = vertices[index] - vertices[neighbour]
        d2 = np.einsum("ij,ij->i", offset, offset) / radius[index] ** 2
        w = np.maximum(1 - d2, 0) ** 2 * weights[neighbour]
        if centroid:
            moved = normals[neighbour]
            for k in range(3):
                spread[:, k] += np.bincount(index, weights=w * offset[:, k], minlength=n)
            mass += np.bincount(index, weights=w, minlength=n)
        elif shape is not None:  # n_j + S_j (x_v - x_j), S_j from the first pass's curvatures and directions
            k_min, k_max, dir_min, dir_max = (a[neighbour] for a in shape)
            moved = (
                normals[neighbour]
                + (k_max * np.einsum("ij,ij->i", dir_max, offset))[:, None] * dir_max
                + (k_min * np.einsum("ij,ij->i", dir_min, offset))[:, None] * dir_min
            )
            moved /= np.linalg.norm(moved, axis=1, keepdims=True)
            moved[~np.isfinite(moved).all(axis=1)] = 0.0
        elif coefficients is None:
            moved = normals[neighbour]
        else:
            t1, t2, nn = (f[neighbour] for f in frame)
            c = coefficients[neighbour]
            u = np.einsum("ij,ij->i", offset, t1) / fit_radius[neighbour]
            v = np.einsum("ij,ij->i", offset, t2) / fit_radius[neighbour]
            p = c[:, 1] + 2 * c[:, 3] * u + c[:, 4] * v
            q = c[:, 2] + c[:, 4] * u + 2 * c[:, 5] * v
            moved = nn - p[:, None] * t1 - q[:, None] * t2
            moved /= np.linalg.norm(moved, axis=1, keepdims=True)
            bad = ~np.isfinite(moved).all(axis=1)
            moved[bad] = 0.0
        for k in range(3):
            total[:, k] += np.bincount(index, weights=w * moved[:, k], minlength=n)
    if centroid:  # x_v - c = spread / mass; the mean normal is that of the centroid: move it to the vertex
        k_min, k_max, dir_min, dir_max = shape
        with np.errstate(invalid="ignore", divide="ignore"):
            back = spread / mass[:, None]
            unit = total / np.linalg.norm(total, axis=1, keepdims=True)
        total = (
            unit
            + (k_max * np.einsum("ij,ij->i", dir_max, back))[:, None] * dir_max
            + (k_min * np.einsum("ij,ij->i", dir_min, back))[:, None] * dir_min
        )
    length = np.linalg.norm(total, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = total / length
    return np.where(np.isfinite(out).all(axis=1, keepdims=True), out, normals)


def _tapered_normals(vertices, start, radius, *, neighbours, adjacency, areas, kernel, iterations=2, robust=0):
    """(V, 3) normals of icc's degree-3 jets (coarse level and area weights as the default) with another kernel
    of ``d = |x_j - x_v| / R``: ``kernel(d2)`` in place of ``(1 - d2)^2``. NumPy; per-vertex ``radius``."""
    from meshcurv import jets
    from meshcurv._tensors import tangent_basis
    from meshcurv.neighborhoods import connected_ball_pairs

    n = vertices.shape[0]
    positive = areas[areas > 0]
    areas = areas / np.median(positive)
    coarse = icc._coarse_level(vertices, start, radius, areas, neighbours, adjacency)
    if coarse is None:
        points, point_normals, allowed, lists, point_areas = vertices, start, neighbours, adjacency, None
    else:
        points, point_normals, allowed, lists, point_areas = coarse
    degree = icc.NORMAL_DEGREE
    order = np.argsort(radius, kind="stable")
    out = np.full((n, 3), np.nan)
    for chunk, centre, neighbour in connected_ball_pairs(points, order, radius[order], lists, allowed):
        index = order[chunk]
        size = index.size
        rows = centre - chunk.start
        offsets = (points[neighbour] - points[index[rows]]) / radius[index[rows]][:, None]
        d2 = np.einsum("ij,ij->i", offsets, offsets)
        weights = np.where(d2 < 1, kernel(np.minimum(d2, 1)), 0.0)
        if point_areas is not None:
            weights = weights * point_areas[neighbour]
        count = np.bincount(rows, weights=(weights > 0).astype(float), minlength=size)
        local = [*tangent_basis(start[index]), start[index]]
        for step in range(iterations):
            matrix, right = jets._fit_chunk(offsets, rows, size, local, weights, degree)
            fitted = jets._solve(matrix, right, count, degree, jets.NORMAL_MIN_SPREAD)
            p, q = fitted[:, 1:2], fitted[:, 2:3]
            tilted = local[2] - p * local[0] - q * local[1]
            tilted /= np.linalg.norm(tilted, axis=1, keepdims=True)
            if step + 1 < iterations:
                keep = np.isfinite(tilted).all(axis=1, keepdims=True)
                new_normal = np.where(keep, tilted, local[2])
                local = [*tangent_basis(new_normal), new_normal]
        for _ in range(robust):  # refits in the last frame, each point weighed down by its residual (Cauchy)
            solution, ok, _ = jets._solve_block(matrix, right, degree, jets.NORMAL_MIN_SPREAD)
            u, v, w = (np.einsum("ij,ij->i", offsets, axis[rows]) for axis in local)
            terms = np.stack([u**i * v**k for i, k in jets._exponents(degree)], axis=1)
            residual = w - np.einsum("ij,ij->i", terms, solution[rows])
            spread = np.bincount(rows, weights=weights * residual**2, minlength=size) / np.maximum(
                np.bincount(rows, weights=weights, minlength=size), 1e-300
            )
            robust_weights = weights / (1.0 + residual**2 / np.maximum(spread[rows], 1e-30))
            matrix, right = jets._fit_chunk(offsets, rows, size, local, robust_weights, degree)
            fitted = jets._solve(matrix, right, count, degree, jets.NORMAL_MIN_SPREAD)
            p, q = fitted[:, 1:2], fitted[:, 2:3]
            refit = local[2] - p * local[0] - q * local[1]
            refit /= np.linalg.norm(refit, axis=1, keepdims=True)
            tilted = np.where((ok[:, None] & np.isfinite(refit).all(axis=1, keepdims=True)), refit, tilted)
        out[index] = tilted
    return out


def normal_variant(name):
    """Replace the voxel path's normal fits (per-vertex radii) by variant ``name`` (the one-radius paths unchanged).

    ``area``: the fits weigh each point by its vertex area (the voxel path's fine fits do not today);
    ``mean:A``: the fitted normals averaged over balls of ``A / 3`` times the normal-fit radius (``A r_v`` where
    that radius is ``3 r_v``), each neighbour weighing its vertex area times ``(1 - d^2 / rho^2)^2``;
    ``shape:A``: icc run twice, the second pass's normals the first's averaged over ``A r_v`` with each
    neighbour's normal moved to the vertex by its first-pass shape operator; ``centroid:A``: the same two
    passes, the plain area-weighted mean moved from the ball's centroid to the vertex by the vertex's shape operator;
    ``extrapolated:A``: the same average of the neighbours' jets' normals at the vertex's position (the
    slope of each neighbour's quadric there); ``taper:P`` and ``gauss:S``: the fits with the kernel
    ``(1 - d^2 / R^2)^P`` (today ``P = 2``) or ``exp(-d^2 / (2 S^2 R^2))`` within the ball; ``robust:N``: N refits
    with Cauchy weights on the residuals (iteratively reweighted; NumPy,
    :func:`_tapered_normals`); a suffix ``+area`` (``mean:1+area``) adds ``area``.
    """
    fit = icc.fitted_normals
    kind, _, rest = name.partition(":")
    weighted = kind == "area" or rest.endswith("+area")
    factor = float(rest.split("+")[0]) if rest and kind != "area" else 0.0

    def chosen(vertices, normals, valid, radius, **options):
        if np.ndim(radius) == 0:
            return fit(vertices, normals, valid, radius, **options)
        failed = options.pop("failed", None)
        options["weighted"] = options.get("weighted") or weighted
        fitted = fit(vertices, normals, valid, radius, failed=failed, **options)
        if kind == "area":
            return fitted
        if kind in ("taper", "gauss", "robust"):
            if kind in ("taper", "robust"):

                def kernel(d2):
                    return (1 - d2) ** (factor if kind == "taper" else 2)
            else:

                def kernel(d2):
                    return np.exp(-0.5 * d2 / factor**2)

            start = np.where(valid[:, None], normals, [0.0, 0.0, 1.0])
            found = _tapered_normals(
                vertices,
                start,
                np.asarray(radius, dtype=float),
                neighbours=options.get("neighbours"),
                adjacency=options["adjacency"],
                areas=options["areas"],
                kernel=kernel,
                robust=int(factor) if kind == "robust" else 0,
            )
            with np.errstate(invalid="ignore"):
                usable = valid & (np.einsum("ij,ij->i", found, start) > icc.NORMAL_AGREEMENT)
            return np.where(usable[:, None], found, normals)
        areas, adjacency = options["areas"], options["adjacency"]
        rho = np.asarray(radius) * (factor / icc.NORMAL_RADIUS_RATIO)
        if kind == "mean":
            return _ball_average(vertices, fitted, areas, rho, adjacency)
        start = np.where(valid[:, None], normals, [0.0, 0.0, 1.0])
        coefficients, frame = _jets_at_vertices(
            vertices,
            start,
            np.asarray(radius, dtype=float),
            neighbours=options.get("neighbours"),
            adjacency=adjacency,
            areas=areas,
            weighted=options["weighted"],
        )
        return _ball_average(vertices, fitted, areas, rho, adjacency, coefficients, frame, np.asarray(radius, float))

    if kind in ("shape", "centroid"):
        icc._curvatures = _two_pass(icc._curvatures, factor, centroid=kind == "centroid")
        return
    icc.fitted_normals = chosen


def _two_pass(first, factor, centroid=False):
    """icc's ``_curvatures`` on per-vertex radii run twice: the second pass's normals are the first's averaged
    over balls of ``factor r_v``, each neighbour's normal moved to the vertex by its first-pass shape operator."""
    from meshcurv.measures import curvatures_from_measures, face_measures
    from meshcurv.neighborhoods import ball_face_sums

    def run(vertices, faces, degenerate, normals, valid, radius, stages=None, **options):
        out = first(vertices, faces, degenerate, normals, valid, radius, stages, **options)
        if np.ndim(radius) == 0:
            return out
        k_min, k_max, dir_min, dir_max, fitted, valid_out = out
        shape = tuple(
            np.where(valid_out[:, None], a, np.nan) if a.ndim == 2 else np.where(valid_out, a, np.nan)
            for a in (k_min, k_max, dir_min, dir_max)
        )
        moved = _ball_average(
            vertices,
            fitted,
            options["areas"],
            np.asarray(radius) * factor,
            options["adjacency"],
            shape=shape,
            centroid=centroid,
        )
        moved = np.where(valid_out[:, None], moved, fitted)
        summed = ball_face_sums(
            vertices,
            faces,
            radius,
            face_measures(vertices, faces, moved),
            usable=icc._usable_faces(faces, degenerate, moved),
            connected=True,
        )
        k_min, k_max, dir_min, dir_max = curvatures_from_measures(summed, moved)
        return k_min, k_max, dir_min, dir_max, moved, valid_out & np.isfinite(k_min)

    return run


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--set", nargs="*", default=[], metavar="NAME=VALUE")
    parser.add_argument("--normal-ladder", metavar="Q1,Q2,...")
    parser.add_argument("--smoothed-normals", action="store_true")
    parser.add_argument("--normal-variant", metavar="NAME", help="area, mean:A, extrapolated:A (normal_variant)")
    parser.add_argument("--normal-degree", type=int, help="icc.NORMAL_DEGREE (the jets of the normal fits)")
    parser.add_argument("--families", nargs="+")
    parser.add_argument("--output")
    args = parser.parse_args(argv)
    if args.smoothed_normals:
        smoothed_normals_table()
        return
    if not (args.set or args.normal_ladder or args.normal_degree or args.normal_variant):
        exact_normals_table()
        return
    for setting in args.set:
        name, value = setting.split("=")
        if not hasattr(radius_rules, name):
            raise SystemExit(f"meshcurv.radius has no constant {name}")
        setattr(radius_rules, name, float(value))
    if args.normal_degree:
        icc.NORMAL_DEGREE = args.normal_degree
    if args.normal_variant:
        normal_variant(args.normal_variant)
    if args.normal_ladder:
        normal_ladder([float(q) for q in args.normal_ladder.split(",")])
    import scale_default

    scale_default.main(
        ["--families", *(args.families or ["voxel"])] + (["--output", args.output] if args.output else [])
    )


if __name__ == "__main__":
    main()
