"""Normals from volume integrals and smoother kernels on smoothed isosurfaces (issue 30, helper V26).

``python benchmarks/smoothed_normals_V26.py`` (tuning tori and held-out smoothed meshes), ``--voxel`` (the binary
voxel meshes of ``accuracy.py --voxel``), ``--clean`` (the clean and noisy meshes of ``accuracy.py --quick``).
Needs scikit-image and numba. Results in ``benchmarks/smoothed_normals_V26.md``.

Every candidate replaces the default's vertex normals in icc's sums at the default's own per-vertex radii
(``result.radius``; ``face_measures``, ``ball_face_sums(connected=True)``, ``curvatures_from_measures``, as the
"exact normals" column of ``smoothed_isosurfaces.md``), so the rows differ by the normals alone. Cells: median
``|estimate - exact| / max|k|`` of H, k_min, k_max in %, and the median angle of the normals to the analytic ones
in degrees.

Candidates (``rho`` = ``q`` times the default's normal-fit radius ``icc.NORMAL_RADIUS_RATIO * r_v``):

- ``ii p``: the integral invariant of the interior's centroid. For a closed surface bounding ``D`` and a radial
  kernel ``w`` vanishing at ``rho``, ``int_D w(|x - p|) (x - p) dV = oint W(|x - p|) n dA`` with
  ``W(r) = -int_r^rho s w(s) ds`` (divergence theorem on ``grad W = w (x - p)``; ``W`` is continuous and 0
  outside the ball, so no term on the sphere). So the centroid of ``D`` in the ball (``w = 1``) is the
  area-weighted mean of the face normals with weight ``rho^2 - r^2``, and the smooth kernel
  ``w = (1 - r^2 / rho^2)^(p - 1)`` gives the weight ``(1 - r^2 / rho^2)^p``: a volume integral, evaluated
  exactly (to the faces' flatness) on the mesh, with no voxel grid. ``p = 1`` is Pottmann et al.'s ball.
- ``ii p q xS``: the same at ``rho`` and ``rho / S`` combined to cancel the bias that grows as ``rho^2``
  (Richardson: ``(S^2 N(rho / S) - N(rho)) / (S^2 - 1)`` of the weight-normalised sums).
- ``cov p``: the covariance integral invariant (Pottmann et al. 2007): ``int_D w (x - p)(x - p)^T dV =
  sym(oint W (x - p) n^T dA) - I int_D W dV``; the isotropic term does not move the eigenvectors. About the
  centroid, ``M - m m^T / V`` with ``V`` the half-ball's weighted volume (first order); the normal is the
  eigenvector of the least eigenvalue, on the side of ``m``.
- ``... bA`` (last): ``rho`` bounded by ``A`` times the default's radius of curvature ``1 / max(|k_min|, |k_max|)``.
- ``jet deg q``: V23's prototype jets of degree ``deg`` (two fits, the second in the first's frame, every vertex,
  no coarse level, the kernel ``(1 - d^2 / rho^2)^2`` times the vertex areas).
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
import smoothed_isosurfaces  # noqa: E402
import smoothed_normals_V23  # noqa: E402
from meshcurv.estimators import icc  # noqa: E402
from meshcurv.measures import curvatures_from_measures, face_measures  # noqa: E402
from meshcurv.neighborhoods import ball_face_sums  # noqa: E402

CHUNK = 512


def _face_geometry(vertices, faces):
    corners = vertices[faces]
    centroids = corners.mean(axis=1)
    area_vectors = 0.5 * np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    return centroids, area_vectors


def _pairs(tree, points, radii):
    """(rows, cols) of the face centroids within each point's radius, chunked."""
    for start in range(0, points.shape[0], CHUNK):
        stop = min(start + CHUNK, points.shape[0])
        lists = tree.query_ball_point(points[start:stop], radii[start:stop], return_sorted=False)
        rows = np.repeat(np.arange(start, stop), [len(members) for members in lists])
        cols = np.concatenate([np.asarray(members, dtype=np.int64) for members in lists])
        yield rows, cols


def integral_normals(vertices, faces, start, rho, power, *, covariance=False):
    """(V, 3) unit normals from the interior's weighted centroid (or covariance) in a ball of ``rho`` per vertex.

    Faces facing away from ``start`` (another sheet) are left out. Returns also the weight-normalised mean of the
    face normals (for the Richardson combination).
    """
    from scipy.spatial import cKDTree

    centroids, area_vectors = _face_geometry(vertices, faces)
    if np.einsum("ij,ij->", area_vectors, start[faces].sum(axis=1)) < 0:  # faces wound inward (marching cubes)
        area_vectors = -area_vectors
    tree = cKDTree(centroids)
    n = vertices.shape[0]
    moment = np.zeros((n, 3))
    total = np.zeros(n)
    second = np.zeros((n, 3, 3)) if covariance else None
    for rows, cols in _pairs(tree, vertices, rho):
        offsets = centroids[cols] - vertices[rows]
        t = np.einsum("ij,ij->i", offsets, offsets) / rho[rows] ** 2
        weight = np.maximum(1.0 - t, 0.0) ** power
        weight = np.where(np.einsum("ij,ij->i", area_vectors[cols], start[rows]) > 0, weight, 0.0)
        weighted = weight[:, None] * area_vectors[cols]
        for axis in range(3):
            moment[:, axis] += np.bincount(rows, weights=weighted[:, axis], minlength=n)
        total += np.bincount(rows, weights=weight * np.linalg.norm(area_vectors[cols], axis=1), minlength=n)
        if covariance:
            for a in range(3):
                for b in range(3):
                    second[:, a, b] += np.bincount(rows, weights=offsets[:, a] * weighted[:, b], minlength=n)
    mean = moment / total[:, None]
    if not covariance:
        return mean / np.linalg.norm(mean, axis=1, keepdims=True), mean
    # the weighted volume of a half ball for w = (1 - r^2 / rho^2)^(p - 1): 2 pi rho^3 B(3/2, p) / 2
    from scipy.special import beta

    # W = -(rho^2 / (2 p)) (1 - t)^p for w = (1 - t)^(p - 1); the moments above used (1 - t)^p, so scale them
    scale = rho**2 / (2 * power)
    m = -scale[:, None] * moment
    sym = -scale[:, None, None] * 0.5 * (second + second.transpose(0, 2, 1))
    volume = np.pi * rho**3 * beta(1.5, power)  # half of 4 pi rho^3 int_0^1 s^2 (1 - s^2)^(p-1) ds
    centred = sym - np.einsum("ni,nj->nij", m, m) / volume[:, None, None]
    _, vectors = np.linalg.eigh(centred)
    normals = vectors[:, :, 0]
    normals = np.where(np.einsum("ij,ij->i", normals, mean)[:, None] < 0, -normals, normals)
    return normals, mean


def _jet_fitter():
    """V23's prototype fits (two degree-``deg`` jets, kernel ``(1 - d^2 / rho^2)^2`` times the vertex areas)."""
    fit = smoothed_normals_V23._prototype_fits()

    def fitted(vertices, faces, start, rho, degree):
        _, area_vectors = _face_geometry(vertices, faces)
        areas = np.zeros(vertices.shape[0])
        np.add.at(areas, faces.ravel(), np.repeat(np.linalg.norm(area_vectors, axis=1) / 3, 3))
        centres = np.arange(vertices.shape[0])
        return fit(vertices, areas, start, centres, np.ascontiguousarray(rho), int(degree), 0.0)

    return fitted


def candidate_normals(name, vertices, faces, default, fitter):
    """(V, 3) the normals of candidate ``name`` ('default', 'exact' handled by the caller)."""
    kind, power, q, *rest = name.split()
    power = float(power)
    rho = float(q) * icc.NORMAL_RADIUS_RATIO * np.asarray(default.radius, dtype=float)
    start = default.normals
    if rest and rest[-1].startswith("b"):  # "bA": rho bounded by A / max(|k_min|, |k_max|) of the default's estimate
        bound = float(rest.pop()[1:]) / np.maximum(np.abs(default.k_min), np.abs(default.k_max))
        rho = np.where(np.isfinite(bound), np.minimum(rho, bound), rho)
    if kind == "jet":  # "jet deg q": V23's fits of degree deg
        return fitter(vertices, faces, start, rho, power)
    if kind == "ii":
        normals, mean = integral_normals(vertices, faces, start, rho, power)
        if rest:  # "xS": Richardson over rho and rho / S
            ratio = float(rest[0][1:])
            _, inner = integral_normals(vertices, faces, start, rho / ratio, power)
            combined = (ratio**2 * inner - mean) / (ratio**2 - 1)
            return combined / np.linalg.norm(combined, axis=1, keepdims=True)
        return normals
    if kind == "cov":
        return integral_normals(vertices, faces, start, rho, power, covariance=True)[0]
    raise ValueError(name)


def _errors(vertices, faces, k_min, k_max, radius, normals, exact):
    sums = ball_face_sums(vertices, faces, radius, face_measures(vertices, faces, normals), connected=True)
    est_min, est_max, *_ = curvatures_from_measures(sums, normals)
    scale = np.maximum(np.abs(k_min), np.abs(k_max))
    cells = [
        100 * np.nanmedian(np.abs(estimate - truth) / scale)
        for estimate, truth in (
            (0.5 * (est_min + est_max), 0.5 * (k_min + k_max)),
            (est_min, k_min),
            (est_max, k_max),
        )
    ]
    angle = np.degrees(np.nanmedian(np.arccos(np.clip(np.abs(np.einsum("ij,ij->i", normals, exact)), -1, 1))))
    return (*cells, angle)


def run(meshes, names, fitter, *, label="mesh") -> None:
    print(f"| normals | {' | '.join(name for name, *_ in meshes)} | mean H | CPU s |")
    print("|---|" + "--:|" * (len(meshes) + 2))
    prepared = []
    for _, kind, size, (vertices, faces, k_min, k_max) in meshes:
        default = meshcurv.principal_curvatures(vertices, faces)
        exact = smoothed_isosurfaces.exact_normals(kind, size, vertices)
        exact = np.where(np.einsum("ij,ij->i", exact, default.normals)[:, None] < 0, -exact, exact)
        prepared.append((vertices, faces, k_min, k_max, default, exact))
    for name in names:
        start = time.process_time()
        rows = []
        for vertices, faces, k_min, k_max, default, exact in prepared:
            if name == "exact":
                normals = exact
            elif name == "default":
                normals = default.normals
            else:
                normals = candidate_normals(name, vertices, faces, default, fitter)
            rows.append(_errors(vertices, faces, k_min, k_max, default.radius, normals, exact))
        cells = [f"{h:.2f} / {a:.2f} / {b:.2f} ({angle:.2f})" for h, a, b, angle in rows]
        mean = np.mean([row[0] for row in rows])
        print(f"| {name} | " + " | ".join(cells) + f" | {mean:.3f} | {time.process_time() - start:.0f} |", flush=True)


DEFAULT_NAMES = [
    "default",
    "exact",
    "jet 3 1",
    "ii 1 1",
    "ii 2 1",
    "ii 2 1.5",
    "ii 3 1.5",
    "ii 2 1.5 x2",
    "cov 2 1",
]


def run_voxel(names, fitter, *, max_vertices=10_000) -> None:
    """The binary voxel meshes of ``accuracy.py --voxel`` (up to ``max_vertices``), the default called on the faces
    as returned, the sums on them reversed (outward, as its normals): cells
    ``accuracy_voxel.md``'s median ``|H - H_exact| / |H_exact|``, then K's, in %."""
    import accuracy

    meshes = [(mesh, held) for mesh, held in accuracy.voxel_meshes() if mesh.vertices.shape[0] <= max_vertices]
    print("| normals | " + " | ".join(mesh.name + (" [held out]" if held else "") for mesh, held in meshes) + " |")
    print("|---|" + "--:|" * len(meshes))
    defaults = [meshcurv.principal_curvatures(mesh.vertices, mesh.faces) for mesh, _ in meshes]
    for name in names:
        cells = []
        for (mesh, _), default in zip(meshes, defaults, strict=True):
            # the faces reversed to outward, as the default's normals (the measures' areas take the winding)
            vertices, faces = mesh.vertices, np.ascontiguousarray(mesh.faces[:, ::-1])
            if name == "default":
                normals = default.normals
            else:
                normals = candidate_normals(name, vertices, faces, default, fitter)
            values = face_measures(vertices, faces, normals)
            sums = ball_face_sums(vertices, faces, default.radius, values, connected=True)
            k_min, k_max, *_ = curvatures_from_measures(sums, normals)
            mean = 0.5 * (k_min + k_max)
            errors = accuracy.voxel_errors(mesh, mean, k_min * k_max, np.isfinite(mean))
            cells.append(f"{100 * errors['H']:.2f} / {100 * errors['K']:.2f}")
        print(f"| {name} | " + " | ".join(cells) + " |", flush=True)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--names", nargs="+", default=DEFAULT_NAMES, help="candidates ('kind power q [x2]')")
    parser.add_argument("--held-out", action="store_true", help="V23's held-out smoothed meshes (seed 7)")
    parser.add_argument("--voxel", action="store_true", help="the binary voxel meshes of accuracy.py --voxel")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
    fitter = _jet_fitter()
    if args.voxel:
        run_voxel(args.names, fitter)
        return 0
    if args.held_out:
        meshes = [
            (f"{kind}{size}, sigma {sigma:g}", kind, size, smoothed_normals_V23._mesh(kind, size, sigma, 7))
            for kind, size, sigma in smoothed_normals_V23.HELD_OUT
        ]
    else:
        meshes = [
            (f"{size}, sigma {sigma:g}, seed {seed}", kind, size, smoothed_normals_V23._mesh(kind, size, sigma, seed))
            for kind, size, sigma in smoothed_normals_V23.TUNING
            for seed in smoothed_normals_V23.TUNING_SEEDS
        ]
    run(meshes, args.names, fitter)
    return 0


if __name__ == "__main__":
    sys.exit(main())
