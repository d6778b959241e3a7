"""What limits icc's default on voxel surfaces: the scale or the normals (issue 30, round 3).

    python benchmarks/scale_normals.py                      # the failing voxel rows with the analytic normals
    python benchmarks/scale_normals.py --set VOXEL_NORMAL_RATIO=2 --families voxel smoothed --output /tmp/v.json
    python benchmarks/scale_normals.py --normal-ladder 0.71,1,1.41,2 --families voxel failing --output /tmp/l.json
    python benchmarks/scale_normals.py --smoothed-normals     # other normal fits on three smoothed isosurfaces

The first form runs the default call on the five voxel meshes of ``accuracy_voxel.md`` that miss their
target, then the same ball sums at the same per-vertex radii (``result.radius``) with the analytic surface's
normals in place of the fitted ones, and prints both median errors of ``|H|`` over ``|H_exact|`` (the metric of
``accuracy_voxel.md``) and the fitted normals' angle to the analytic ones. ``--set NAME=VALUE`` changes
constants of :mod:`meshcurv.radius` (``--normal-degree`` icc's ``NORMAL_DEGREE``) and runs ``scale_default.py`` on ``--families``; ``--normal-ladder``
replaces the voxel path's normal fits by fits over each ``q`` times the per-vertex normal radius, keeping at
each vertex the upper rung of the consecutive pair whose normals turn least (averaged over 2 rings).
``--smoothed-normals`` fits the normals of three smoothed isosurfaces in other ways (jets of degree 2, 3, 4 over
6-18 voxels, ring averages of the face normals, jets on Taubin-smoothed positions) and sums the measures at
r = 4 and 6 voxels: median normal angle, and errors of H (against the blurred surface), k_min, k_max. Tables:
``benchmarks/scale_default.md`` (round 3). Needs scikit-image.
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


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--set", nargs="*", default=[], metavar="NAME=VALUE")
    parser.add_argument("--normal-ladder", metavar="Q1,Q2,...")
    parser.add_argument("--smoothed-normals", action="store_true")
    parser.add_argument("--normal-degree", type=int, help="icc.NORMAL_DEGREE (the jets of the normal fits)")
    parser.add_argument("--families", nargs="+")
    parser.add_argument("--output")
    args = parser.parse_args(argv)
    if args.smoothed_normals:
        smoothed_normals_table()
        return
    if not (args.set or args.normal_ladder or args.normal_degree):
        exact_normals_table()
        return
    for setting in args.set:
        name, value = setting.split("=")
        if not hasattr(radius_rules, name):
            raise SystemExit(f"meshcurv.radius has no constant {name}")
        setattr(radius_rules, name, float(value))
    if args.normal_degree:
        icc.NORMAL_DEGREE = args.normal_degree
    if args.normal_ladder:
        normal_ladder([float(q) for q in args.normal_ladder.split(",")])
    import scale_default

    scale_default.main(
        ["--families", *(args.families or ["voxel"])] + (["--output", args.output] if args.output else [])
    )


if __name__ == "__main__":
    main()
