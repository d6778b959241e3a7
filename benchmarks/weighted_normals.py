"""Weighted normal fits against the jets on lattice surfaces (issue 30): ``python benchmarks/weighted_normals.py``.

    python benchmarks/weighted_normals.py --families smoothed
    python benchmarks/weighted_normals.py --families accuracy voxel --max-vertices 15000

The hypothesis tested: the lattice's ripple on an isosurface of a smoothed mask leaks into the fitted normals
through the window of the fits, and a smoother window (or a weight by each vertex's area share) would bring
the normals near the analytic ones, and icc's H near its "exact normals" column
(``smoothed_isosurfaces.md``). Every normal here is a NumPy prototype, fitted at every vertex over the
Euclidean ball of radius ``g = factor * r_v`` (``r_v`` the default call's own per-vertex measure radius,
``result.radius``; the library's fits take the surface-connected piece of that ball, and on dense surfaces
clusters of vertices instead of the vertices):

- ``jet d, kernel, g``: a height function of degree ``d`` over the tangent plane, fitted by weighted least
  squares (two fits, the first in the frame of the area-weighted mean of the face normals, the second in
  that of the first fit, as :func:`meshcurv.jets.fit_jets`); the normal is ``(n - c10 t1 - c01 t2) /
  sqrt(1 + c10^2 + c01^2)``;
- ``pca, kernel, g``: the weighted plane fit (the eigenvector of the least eigenvalue of the weighted
  covariance of the points about their weighted mean);
- ``mean, kernel, g``: the weighted sum of the vertices' area vectors (the sum of a third of the area-weighted
  normals of their faces), normalised: the face normals weighted by area times the kernel;

kernels of ``x = d / g`` (``d`` the distance to the centre), 0 beyond ``g``: ``box`` (1), ``taper``
(``(1 - x^2)^2``, the library's jets' kernel today), ``taper4`` (``(1 - x^2)^4``), ``wendland``
(``(1 - x)^4 (4 x + 1)``, C2 at the rim) and ``gauss`` (``exp(-4.5 x^2)``, sigma ``g / 3``, cut at
``g``); ``+area``: each point's weight also multiplied by its vertex area (a third of its faces' areas).

Where a fitted normal turns more than 60 degrees from the mean face normal (or the fit fails) the mean face
normal is kept, as the library does. Rows: the normals' angle to the analytic ones (median and 95th
percentile, degrees), and the median errors ``|estimate - exact| / max|k|`` of H, k_min and k_max of icc's
measures summed at the default's per-vertex radii with those normals (``meshcurv.measures.face_measures``,
``meshcurv.neighborhoods.ball_face_sums`` over the connected balls: the "exact normals" column of
``smoothed_isosurfaces.md``; H against the blurred surface on the smoothed meshes). ``default`` is the default
call's own result; ``library jets`` the default's normals summed as the others. On the binary voxel meshes the
H column is ``accuracy_voxel.md``'s metric (median ``|H - H_exact| / |H_exact|``). Needs scikit-image and scipy.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import meshcurv  # noqa: E402
from meshcurv._tensors import tangent_basis  # noqa: E402
from meshcurv.measures import curvatures_from_measures, face_measures  # noqa: E402
from meshcurv.neighborhoods import ball_face_sums  # noqa: E402

#: The smoothed meshes run by default (issue 30's target: spheres and tori of radius >= 10 voxels).
SMOOTHED_WANTED = ("sphere(10)", "sphere(20)", "torus(25, 10)", "torus(16, 6)")

#: Kernels of ``x = d / g`` in [0, 1].
KERNELS = {
    "box": lambda x: np.ones_like(x),
    "taper": lambda x: (1 - x * x) ** 2,
    "taper4": lambda x: (1 - x * x) ** 4,
    "wendland": lambda x: (1 - x) ** 4 * (4 * x + 1),
    "gauss": lambda x: np.exp(-4.5 * x * x),
}

#: The variants of the default run: ``(kind, degree, kernel, factor, area)``.
VARIANTS = [
    ("jet", 3, "taper", 3.0, False),  # the library's fit (every vertex, Euclidean ball)
    ("jet", 3, "box", 3.0, False),
    ("jet", 3, "gauss", 3.0, False),
    ("jet", 3, "wendland", 3.0, False),
    ("jet", 3, "taper4", 3.0, False),
    ("jet", 3, "taper4", 4.0, False),
    ("jet", 3, "taper", 3.0, True),
    ("jet", 3, "taper4", 4.0, True),
    ("jet", 2, "taper", 3.0, False),
    ("jet", 2, "taper", 2.0, False),
    ("jet", 2, "taper4", 3.0, True),
    ("jet", 3, "gauss", 4.0, True),
    ("pca", 1, "taper", 2.0, True),
    ("pca", 1, "taper", 3.0, True),
    ("mean", 0, "taper", 1.0, True),
    ("mean", 0, "taper", 2.0, True),
    ("mean", 0, "taper4", 3.0, True),
]


def variant_label(kind, degree, kernel, factor, area):
    head = f"jet {degree}" if kind == "jet" else kind
    return f"{head}, {kernel}{'+area' if area else ''}, {factor:g} r_v"


def _exponents(degree):
    return [(i, total - i) for total in range(degree + 1) for i in range(total, -1, -1)]


def _grouped(values, starts):
    """Sums of the rows of ``values`` (P, ...) over the groups beginning at ``starts`` (sorted, non-empty)."""
    return np.add.reduceat(values, starts, axis=0)


def _jet_normal(offsets, rows, starts, weights, frame_normals, degree):
    """(C, 3) the normals of weighted jets of ``degree`` in the frames of ``frame_normals`` (C, 3)."""
    t1, t2 = tangent_basis(frame_normals)
    u = np.einsum("ij,ij->i", offsets, t1[rows])
    v = np.einsum("ij,ij->i", offsets, t2[rows])
    w = np.einsum("ij,ij->i", offsets, frame_normals[rows])
    basis = np.stack([u**i * v**k for i, k in _exponents(degree)], axis=1)
    weighted = basis * weights[:, None]
    matrix = _grouped(weighted[:, :, None] * basis[:, None, :], starts)
    right = _grouped(weighted * w[:, None], starts)
    m = basis.shape[1]
    scale = np.trace(matrix, axis1=1, axis2=2)[:, None, None] / m
    matrix = matrix + 1e-12 * scale * np.eye(m)
    with np.errstate(invalid="ignore", divide="ignore"):
        try:
            coefficients = np.linalg.solve(matrix, right[:, :, None])[:, :, 0]
        except np.linalg.LinAlgError:
            coefficients = np.einsum("cij,cj->ci", np.linalg.pinv(matrix), right)
    p, q = coefficients[:, 1:2], coefficients[:, 2:3]
    normal = frame_normals - p * t1 - q * t2
    return normal / np.linalg.norm(normal, axis=1, keepdims=True)


def _pca_normal(offsets, starts, weights, start):
    total = _grouped(weights, starts)
    mean = _grouped(offsets * weights[:, None], starts) / total[:, None]
    counts = np.diff(np.append(starts, offsets.shape[0]))
    centred = offsets - np.repeat(mean, counts, axis=0)
    covariance = _grouped(centred[:, :, None] * centred[:, None, :] * weights[:, None, None], starts)
    _, vectors = np.linalg.eigh(covariance)
    normal = vectors[:, :, 0]
    return normal * np.where(np.einsum("ij,ij->i", normal, start) < 0, -1.0, 1.0)[:, None]


def weighted_normals(vertices, faces, radius, variants, *, at=None, chunk_pairs=60000):
    """{variant: (V, 3) unit normals} for each variant (see the module's docstring); ``radius`` (V,) the ``r_v``.

    ``at``: the vertices fitted (default: all; the others keep the mean face normal)."""
    n = vertices.shape[0]
    corners = vertices[faces]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    area_vectors = np.stack([np.bincount(faces.ravel(), np.repeat(cross[:, i], 3), n) for i in range(3)], 1) / 6
    areas = np.bincount(faces.ravel(), np.repeat(np.linalg.norm(cross, axis=1), 3), n) / 6
    areas = areas / np.median(areas[areas > 0])
    start = area_vectors / np.linalg.norm(area_vectors, axis=1, keepdims=True)
    reach = max(v[3] for v in variants) * radius
    tree = cKDTree(vertices)
    out = {v: start.copy() for v in variants}
    at = np.arange(n) if at is None else np.asarray(at)
    typical = max(1, int(chunk_pairs / max(1.0, _mean_ball(tree, vertices, reach))))
    for begin in range(0, at.size, typical):
        ids = at[begin : begin + typical]
        lists = tree.query_ball_point(vertices[ids], reach[ids], return_sorted=True)
        counts = np.fromiter((len(x) for x in lists), dtype=np.int64, count=ids.size)
        members = np.fromiter((j for x in lists for j in x), dtype=np.int64, count=int(counts.sum()))
        rows = np.repeat(np.arange(ids.size), counts)
        starts = np.concatenate([[0], np.cumsum(counts)[:-1]])
        for variant in variants:
            kind, degree, kernel, factor, area = variant
            g = factor * radius[ids]
            offsets = (vertices[members] - vertices[ids[rows]]) / g[rows, None]
            x = np.linalg.norm(offsets, axis=1)
            weights = np.where(x < 1, KERNELS[kernel](np.minimum(x, 1.0)), 0.0)
            if area:
                weights = weights * areas[members]
            if kind == "jet":
                normal = _jet_normal(offsets, rows, starts, weights, start[ids], degree)
                normal = _jet_normal(offsets, rows, starts, weights, normal, degree)
            elif kind == "pca":
                normal = _pca_normal(offsets, starts, weights, start[ids])
            else:
                summed = _grouped(
                    area_vectors[members] * (weights / np.maximum(areas[members], 1e-300))[:, None], starts
                )
                summed = summed if area else _grouped(start[members] * weights[:, None], starts)
                normal = summed / np.linalg.norm(summed, axis=1, keepdims=True)
            with np.errstate(invalid="ignore"):
                bad = ~(np.einsum("ij,ij->i", normal, start[ids]) > 0.5)
            normal[bad] = start[ids][bad]
            out[variant][ids] = normal
    return out


def _mean_ball(tree, vertices, reach, sample=200):
    picks = np.linspace(0, vertices.shape[0] - 1, min(sample, vertices.shape[0])).astype(int)
    return float(np.mean([len(x) for x in tree.query_ball_point(vertices[picks], reach[picks])]))


def _cases(families):
    """Yield ``(name, family, vertices, faces, k_min, k_max, exact_normals, h_reference)``; faces outward."""
    import normal_voting

    yield from normal_voting._analytic_cases(families)


def _accuracy_cases(surfaces):
    import accuracy

    for surface, variant, level, mesh in accuracy.surfaces([1], surfaces):
        if variant not in ("regular", "irregular", "noise 0.1h", "noise 0.3h"):
            continue
        vertices, faces = np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int64)
        label = f"{surface} {variant} [level {level}]"
        yield label, "accuracy", vertices, faces, mesh.k_min, mesh.k_max, np.asarray(mesh.normals), None


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--families", nargs="+", default=["smoothed", "accuracy", "voxel"])
    parser.add_argument("--surfaces", nargs="+", default=["sphere", "torus", "ellipsoid"], help="accuracy surfaces")
    parser.add_argument("--only", nargs="*", help="substrings of the mesh names to run")
    parser.add_argument("--max-vertices", type=int, help="skip larger meshes")
    parser.add_argument("--variants", nargs="*", type=int, help="indices into VARIANTS (default: all)")
    parser.add_argument(
        "--sector", action="store_true", help="smoothed spheres and tori: measure one fundamental domain (sector)"
    )
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
    variants = VARIANTS if args.variants is None else [VARIANTS[i] for i in args.variants]
    print(f"# {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load {os.getloadavg()[0]:.1f}")
    print("| mesh | normals | angle, median (95%) | H | k_min | k_max |\n|---|---|--:|--:|--:|--:|")
    cases = []
    if "smoothed" in args.families:
        cases.append(c for c in _cases(["smoothed"]) if any(c[0].startswith(f"smoothed {w},") for w in SMOOTHED_WANTED))
    if "accuracy" in args.families:
        cases.append(_accuracy_cases(args.surfaces))
    if "voxel" in args.families:
        cases.append(_cases(["voxel"]))
    for group in cases:
        for name, family, vertices, faces, k_min_x, k_max_x, exact, h_reference in group:
            if args.only and not any(s in name for s in args.only):
                continue
            if args.max_vertices and vertices.shape[0] > args.max_vertices:
                print(f"| {name} | skipped: {vertices.shape[0]:,} vertices | | | | |", flush=True)
                continue
            _run_case(name, family, vertices, faces, k_min_x, k_max_x, exact, h_reference, variants, part=args.sector)


def sector(name, vertices):
    """(M,) the vertices of a fundamental domain of the cubic lattice's symmetries that map the surface to itself
    (a torus about x: the tube angles ``atan2(z, y)`` in [0, 45) degrees; a sphere: the octant x, y, z > 0), or
    None (all vertices). The marching-cubes grids are offset from the centre, so the symmetry is statistical."""
    if "torus(" in name and name.startswith("smoothed"):
        angle = np.arctan2(vertices[:, 2], vertices[:, 1]) % (2 * np.pi)
        return np.flatnonzero(angle < np.pi / 4)
    if "sphere(" in name and name.startswith("smoothed"):
        return np.flatnonzero((vertices > 0).all(axis=1))
    return None


def _run_case(name, family, vertices, faces, k_min_x, k_max_x, exact, h_reference, variants, *, part=False):
    n = vertices.shape[0]
    default = meshcurv.principal_curvatures(vertices, faces)
    radius = np.asarray(default.radius, dtype=float) * np.ones(n)
    centres = sector(name, vertices) if part else None
    at = None
    if centres is not None:  # the vertices of the faces that meet the centres' balls
        edge = float(np.max(np.linalg.norm(vertices[faces] - vertices[np.roll(faces, 1, axis=1)], axis=2)))
        lists = cKDTree(vertices).query_ball_point(vertices[centres], radius[centres] + 2 * edge)
        at = np.unique(np.fromiter((j for x in lists for j in x), dtype=np.int64))
    pick = slice(None) if centres is None else centres
    scale = np.maximum(np.abs(k_min_x), np.abs(k_max_x))[pick]
    h_exact = 0.5 * (k_min_x + k_max_x)[pick]
    h_ref = h_exact if h_reference is None else h_reference[pick]
    k_min_x, k_max_x = k_min_x[pick], k_max_x[pick]

    def row(label, normals, fields=None):
        if fields is None:
            measures = face_measures(vertices, faces, normals)
            sums = ball_face_sums(vertices, faces, radius, measures, connected=True, centres=centres)
            k_min, k_max, *_ = curvatures_from_measures(sums, normals[pick])
            fields = 0.5 * (k_min + k_max), k_min, k_max
        else:
            fields = tuple(f[pick] for f in fields)
        mean, k_min, k_max = fields
        angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", normals[pick], exact[pick]), -1, 1)))

        def err(estimate, truth):
            return 100 * float(np.nanmedian(np.abs(estimate - truth) / scale))

        if family == "voxel":
            with np.errstate(divide="ignore", invalid="ignore"):
                relative = np.abs(mean - h_exact) / np.abs(h_exact)
            h_cell = f"{100 * float(np.nanmedian(relative[np.isfinite(relative)])):.2f}%"
        else:
            h_cell = f"{err(mean, h_ref):.2f}%"
        print(
            f"| {name} | {label} | {np.nanmedian(angle):.2f} ({np.nanpercentile(angle, 95):.2f}) "
            f"| {h_cell} | {err(k_min, k_min_x):.2f}% | {err(k_max, k_max_x):.2f}% |",
            flush=True,
        )

    own = (default.mean, default.k_min, default.k_max)
    for label, fields in ((f"default ({default.parameters.get('surface')}, r {np.median(radius):.3g})", own),):
        row(label, default.normals, fields)  # the default call's own sums (coarse on dense surfaces)
    row("library jets", default.normals)
    t0 = time.process_time()
    fitted = weighted_normals(vertices, faces, radius, variants, at=at)
    cpu = time.process_time() - t0
    for variant in variants:
        row(variant_label(*variant), fitted[variant])
    row("analytic", exact)
    where = "" if centres is None else f", measured at {centres.size:,} (sector), fitted at {at.size:,}"
    print(f"<!-- {name}: {n:,} vertices{where}, fits {cpu:.0f} CPU s -->", flush=True)


if __name__ == "__main__":
    main()
