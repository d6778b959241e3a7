"""Normal vector voting against the jets on lattice surfaces (issue 30): ``python benchmarks/normal_voting.py``.

    python benchmarks/normal_voting.py --families smoothed --factors 2 3 4 5 --jet-votes
    python benchmarks/normal_voting.py --families smoothed --factors 2 3 4 --jet-votes --kernels taper far
    python benchmarks/normal_voting.py --families voxel --factors 3 --jet-votes --kernels exp far --max-vertices 15000
    python benchmarks/normal_voting.py --families accuracy --factors 3 --jet-votes --kernels exp far --refit

Normal vector voting (Page, Sun, Koschan, Paik, Abidi 2002; step 1 of PyCurv's AVV, Salfer et al. 2020):
vertex ``v`` collects from every face ``f`` whose centroid ``c_f`` lies within ``g`` of it a vote, the face's
normal ``n_f`` turned along the circular arc that leaves ``c_f`` tangent to the face and passes through ``v``
(the reflection of ``n_f`` in the plane bisecting the chord ``c_f - x_v``):

    N_f = n_f - 2 (n_f . u) u,  u = (c_f - x_v) / |c_f - x_v|

weighted by ``A_f exp(-d / sigma)`` (``A_f`` the face's area, ``d`` the distance ``|c_f - x_v|``, Euclidean here
where PyCurv takes the geodesic one over its triangle graph: the same to second order on these balls;
``sigma = g / 3`` as PyCurv), and the normal is the eigenvector of the largest eigenvalue of
``sum_f w_f N_f N_f^T``, turned to the side of the vertex's mean face normal. On a sphere every vote is exact
(the arc is a great circle of the sphere), so only the lattice's ripple is left, averaged over the ball.

Rows: the normals' angle to the analytic ones (median and 95th percentile, degrees), and the median errors
``|estimate - exact| / max|k|`` of H, k_min and k_max of icc's measures summed at the default's own per-vertex
radii (``result.radius``) with those normals (the "exact normals" column of ``smoothed_isosurfaces.md``; H
against the blurred surface on the smoothed meshes, see ``smoothed_isosurfaces.py``). Normals compared:

- ``default``: the default call's own result (its jets, and its own sums: coarse on dense voxel surfaces);
- ``jets``: the default's fitted normals summed as the others (the same sums, so the rows compare normals);
- ``vote g``: voting with ``g = factor * r_v`` (``r_v`` the default's per-vertex measure radius);
- ``jets over 3 r_v, frame: ...`` (``--refit``): icc's jets (degree 3 over ``3 r_v``, every vertex, no coarse
  level) fitted from the frame of the mean face normal and from that of the voted normal at the largest factor;
- ``vote of jets g`` (``--jet-votes``): the same voting with the jets' vertex normals as the votes, cast from
  the vertices (vertex areas as weights);
- ``--kernels``: ``exp`` (Page's ``exp(-d / sigma)``), ``taper`` (``(1 - d^2 / g^2)^2``, the jets' kernel) and
  ``far`` (``exp`` without the votes nearer than ``g / 4``: a vote from a chord of length ``d`` is turned by
  about ``2 delta / d`` by a position error ``delta`` of the lattice's ripple);
- ``analytic``: the exact normals (what the scale alone gives).

On the binary voxel meshes (``accuracy.py --voxel``) the last column is ``accuracy_voxel.md``'s metric
(median ``|H - H_exact| / |H_exact|``). Needs scikit-image and scipy. The machine and load are printed.
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
from meshcurv.estimators import icc  # noqa: E402
from meshcurv.measures import curvatures_from_measures, face_measures  # noqa: E402
from meshcurv.neighborhoods import ball_face_sums  # noqa: E402
from meshcurv.topology import MeshTopology  # noqa: E402

#: The smoothed meshes run: spheres R 10, 20, tori (25, 10), (16, 6) (sigma 0.5, 1, 2) and the ellipsoid (a bias check).
SMOOTHED_WANTED = ("sphere(10)", "sphere(20)", "torus(25, 10)", "torus(16, 6)", "ellipsoid(24, 16, 10)")


def voted_normals(vertices, faces, radius, start, *, votes=None, vote_areas=None, kernel="exp", chunk=128):
    """(V, 3) unit normals by normal vector voting over balls of ``radius`` ((V,) array or float).

    ``votes`` (F, 3) unit vectors cast from the face centroids (default: the face normals) and
    ``vote_areas`` (F,) their weights' areas (default: face areas); with ``votes`` of shape (V, 3), the
    votes are cast from the vertices themselves. ``start`` (V, 3) picks the side. Euclidean balls.
    """
    n = vertices.shape[0]
    corners = vertices[faces]
    cross = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    if votes is None:
        area = 0.5 * np.linalg.norm(cross, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            votes = cross / (2 * area[:, None])
        sources = corners.mean(axis=1)
        vote_areas = area
    else:
        sources = vertices if votes.shape[0] == n else corners.mean(axis=1)
    good = np.isfinite(votes).all(axis=1) & (vote_areas > 0)
    sources, votes, vote_areas = sources[good], votes[good], vote_areas[good]
    tree = cKDTree(sources)
    radius = np.broadcast_to(np.asarray(radius, dtype=float), (n,))
    out = np.full((n, 3), np.nan)
    for begin in range(0, n, chunk):
        ids = np.arange(begin, min(begin + chunk, n))
        lists = tree.query_ball_point(vertices[ids], radius[ids], return_sorted=False)
        counts = np.fromiter((len(x) for x in lists), dtype=np.int64, count=ids.size)
        members = np.fromiter((j for x in lists for j in x), dtype=np.int64, count=int(counts.sum()))
        rows = np.repeat(np.arange(ids.size), counts)
        chord = sources[members] - vertices[ids[rows]]
        length = np.linalg.norm(chord, axis=1)
        with np.errstate(invalid="ignore", divide="ignore"):
            unit = np.where(length[:, None] > 0, chord / length[:, None], 0.0)
        vote = votes[members] - 2 * np.einsum("ij,ij->i", votes[members], unit)[:, None] * unit
        scaled = length / radius[ids[rows]]
        if kernel == "exp":  # Page et al., PyCurv: exp(-d / sigma), sigma = g / 3 (a cusp at d = 0)
            falloff = np.exp(-3.0 * scaled)
        elif kernel == "taper":  # the jets' kernel: (1 - d^2 / g^2)^2 (flat at d = 0)
            falloff = np.maximum(1 - scaled**2, 0) ** 2
        else:  # "far": the exp kernel without the votes nearer than g / 4 (their chords carry the ripple)
            falloff = np.where(scaled > 0.25, np.exp(-3.0 * scaled), 0.0)
        weight = vote_areas[members] * falloff
        tensor = np.zeros((ids.size, 3, 3))
        for a in range(3):
            for b in range(a, 3):
                tensor[:, a, b] = np.bincount(rows, weights=weight * vote[:, a] * vote[:, b], minlength=ids.size)
                tensor[:, b, a] = tensor[:, a, b]
        _, vectors = np.linalg.eigh(tensor)
        principal = vectors[:, :, 2]
        side = np.sign(np.einsum("ij,ij->i", principal, start[ids]))
        out[ids] = principal * np.where(side == 0, 1.0, side)[:, None]
    return out


def _analytic_cases(families):
    """Yield ``(name, family, vertices, faces, k_min, k_max, exact_normals, h_reference)``; faces outward."""
    import scale_families
    import smoothed_isosurfaces

    if "smoothed" in families:
        settings = [(kind, size, sigma) for kind, size, sigmas in scale_families.SMOOTHED for sigma in sigmas]
        for case, (kind, size, sigma) in zip(scale_families.smoothed_cases(), settings, strict=True):
            if not any(case.name.startswith(f"smoothed {w},") for w in SMOOTHED_WANTED):
                continue
            normals = smoothed_isosurfaces.exact_normals(kind, size, case.vertices)
            blurred = smoothed_isosurfaces.blurred_mean(kind, size, sigma, case.vertices, case.k_min, case.k_max)
            yield case.name, "smoothed", case.vertices, case.faces, case.k_min, case.k_max, normals, blurred
    if "voxel" in families:
        import accuracy

        for mesh, held_out in accuracy.voxel_meshes():
            vertices, faces = np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int64)
            normals = np.asarray(mesh.normals, dtype=float)
            corners = vertices[faces]
            if np.einsum("ij,ij->", corners[:, 0], np.cross(corners[:, 1], corners[:, 2])) < 0:
                faces = np.ascontiguousarray(faces[:, ::-1])
            label = mesh.name + (" (held out)" if held_out else "")
            yield label, "voxel", vertices, faces, mesh.k_min, mesh.k_max, normals, 0.5 * (mesh.k_min + mesh.k_max)
    if "accuracy" in families:
        import accuracy

        for surface, variant, level, mesh in accuracy.surfaces([1], ["sphere", "torus"]):
            if variant not in ("regular", "noise 0.1h", "noise 0.3h"):
                continue
            vertices, faces = np.asarray(mesh.vertices, dtype=float), np.asarray(mesh.faces, dtype=np.int64)
            label = f"{surface} {variant} [level {level}]"
            yield label, "accuracy", vertices, faces, mesh.k_min, mesh.k_max, np.asarray(mesh.normals), None


def _summed(vertices, faces, radius, normals):
    """``(H, k_min, k_max)`` of icc's measures with ``normals``, summed over the connected balls of ``radius``."""
    sums = ball_face_sums(vertices, faces, radius, face_measures(vertices, faces, normals), connected=True)
    k_min, k_max, *_ = curvatures_from_measures(sums, normals)
    return 0.5 * (k_min + k_max), k_min, k_max


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--families", nargs="+", default=["smoothed", "voxel", "accuracy"])
    parser.add_argument("--factors", nargs="+", type=float, default=[1.0, 2.0, 3.0])
    parser.add_argument("--refit", action="store_true", help="also the jets fitted in the voted frame")
    parser.add_argument("--jet-votes", action="store_true", help="also the voting of the jets' normals")
    parser.add_argument("--only", nargs="*", help="substrings of the mesh names to run")
    parser.add_argument("--max-vertices", type=int, help="skip larger meshes (the NumPy voting is slow on them)")
    parser.add_argument("--kernels", nargs="+", default=["exp"], help="exp (Page), taper, far (voted_normals)")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
    print(f"# {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load {os.getloadavg()[0]:.1f}")
    print(
        "| mesh | normals | angle, median (95%) | H | k_min | k_max | H / abs(H) (voxel metric) | CPU s |\n"
        "|---|---|--:|--:|--:|--:|--:|--:|"
    )
    for name, family, vertices, faces, k_min_x, k_max_x, exact, h_reference in _analytic_cases(args.families):
        if args.only and not any(s in name for s in args.only):
            continue
        if args.max_vertices and vertices.shape[0] > args.max_vertices:
            print(f"| {name} | skipped: {vertices.shape[0]:,} vertices | | | | | | |", flush=True)
            continue
        scale = np.maximum(np.abs(k_min_x), np.abs(k_max_x))
        h_exact = 0.5 * (k_min_x + k_max_x)
        h_ref = h_exact if h_reference is None else h_reference
        t0 = time.process_time()
        default = meshcurv.principal_curvatures(vertices, faces)
        cpu_default = time.process_time() - t0
        radius = np.asarray(default.radius, dtype=float)
        corners = vertices[faces]
        face_normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
        start = np.stack(
            [np.bincount(faces.ravel(), np.repeat(face_normals[:, i], 3), len(vertices)) for i in range(3)], 1
        )
        start /= np.linalg.norm(start, axis=1, keepdims=True)

        def row(label, normals, fields=None, cpu=float("nan")):
            if fields is None:
                fields = _summed(vertices, faces, radius, normals)
            mean, k_min, k_max = fields
            angle = np.degrees(np.arccos(np.clip(np.einsum("ij,ij->i", normals, exact), -1, 1)))

            def err(estimate, truth):
                return 100 * float(np.nanmedian(np.abs(estimate - truth) / scale))

            with np.errstate(divide="ignore", invalid="ignore"):
                relative = np.abs(mean - h_exact) / np.abs(h_exact)
            voxel = f"{100 * float(np.nanmedian(relative[np.isfinite(relative)])):.2f}%" if family == "voxel" else "-"
            print(
                f"| {name} | {label} | {np.nanmedian(angle):.2f} ({np.nanpercentile(angle, 95):.2f}) "
                f"| {err(mean, h_ref):.2f}% | {err(k_min, k_min_x):.2f}% | {err(k_max, k_max_x):.2f}% | {voxel} "
                f"| {cpu:.1f} |",
                flush=True,
            )

        row(
            f"default ({default.parameters.get('surface')}, r {np.median(radius):.3g})",
            default.normals,
            (default.mean, default.k_min, default.k_max),
            cpu_default,
        )
        row("jets", default.normals)
        voted = None
        areas = np.bincount(faces.ravel(), np.repeat(np.linalg.norm(face_normals, axis=1) / 6, 3), len(vertices))
        for kernel in args.kernels:
            tag = "" if kernel == "exp" else f", {kernel}"
            for factor in args.factors:
                t0 = time.process_time()
                voted = voted_normals(vertices, faces, factor * radius, start, kernel=kernel)
                row(f"vote g = {factor:g} r_v{tag}", voted, cpu=time.process_time() - t0)
            if args.jet_votes:
                for factor in args.factors:
                    t0 = time.process_time()
                    normals = voted_normals(
                        vertices, faces, factor * radius, start, votes=default.normals, vote_areas=areas, kernel=kernel
                    )
                    row(f"vote of jets g = {factor:g} r_v{tag}", normals, cpu=time.process_time() - t0)
        if args.refit and voted is not None:  # the same fits (all vertices, no coarse level) from two frames
            lists = MeshTopology.from_faces(faces, vertices.shape[0]).neighbour_lists
            every = np.ones(len(vertices), bool)
            for label, frame in (("mean face normal", start), (f"vote g = {args.factors[-1]:g} r_v", voted)):
                t0 = time.process_time()
                refit = icc.fitted_normals(vertices, frame, every, icc.NORMAL_RADIUS_RATIO * radius, adjacency=lists)
                row(f"jets over 3 r_v, frame: {label}", refit, cpu=time.process_time() - t0)
        row("analytic", exact)


if __name__ == "__main__":
    main()
