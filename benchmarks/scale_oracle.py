"""What any choice of icc's per-vertex scale can still win on voxel surfaces (issue 30, round 5).

    python benchmarks/scale_oracle.py                              # smoothed spheres and tori, R >= 10 voxels
    python benchmarks/scale_oracle.py --families smoothed failing  # every smoothed row, the failing voxel rows
    python benchmarks/scale_oracle.py --measure 1,1.41,2 --normal 0.71,1,1.41 --output /tmp/grid.json
    python benchmarks/scale_oracle.py --lattice                    # the blurred masks' own level sets
    python benchmarks/scale_oracle.py --dump /tmp/voxel.npz --families voxel --measure 0.71,1,1.41,2
    python benchmarks/scale_oracle.py --rules /tmp/voxel.npz       # per-vertex rules along those factors

``--families`` of the dumps: those of ``scale_families.py`` (``voxel``, ``elongated``, ``smoothed``,
``failing``, ...). Tables and their reading: ``smoothed_isosurfaces.md``, round 5.

Runs icc's default call with each vertex's measure radius and normal-fit radius
(:func:`meshcurv.radius.voxel_vertex_radii`) multiplied by the factors ``f`` (``--measure``) and ``q``
(``--normal``), and, at each measure factor, the same ball sums with the analytic surface's normals at the
vertices in place of the fitted ones. Each mesh's figures:

- ``fitted``: the median ``|H - H_exact| / max|k|`` of the call at ``(f, q)``;
- ``exact normals``: the same sums at ``f r_v`` with the analytic normals: the error left by the ball itself
  (its bias, the lattice's ripple in the positions) once the normals are right;
- ``blur shift``: on the smoothed rows the median of ``|H_blur - H|`` (the shift of the 0.5 level set of a
  blurred mask, ``smoothed_isosurfaces.py``), the error of an estimator that measured the blurred surface
  exactly.

The best ``(f, q)`` of each mesh is an oracle: chosen with the exact curvatures, per mesh. If even that misses a
target, no rule that scales today's per-vertex radii by a factor can meet it (a rule that also varies the factor
from vertex to vertex is bounded by the per-vertex oracle, printed too: the factor of least error at each vertex,
which picks lucky noise and is therefore optimistic). Needs scikit-image.
"""

from __future__ import annotations

import argparse
import json
import os
import sys
import time
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import meshcurv  # noqa: E402
import meshcurv.radius as radius_rules  # noqa: E402
import scale_families  # noqa: E402
from meshcurv import shapes  # noqa: E402
from meshcurv.measures import curvatures_from_measures, face_measures  # noqa: E402
from meshcurv.neighborhoods import ball_face_sums  # noqa: E402
from meshcurv.topology import MeshTopology  # noqa: E402
from smoothed_isosurfaces import blurred_mean, exact_normals  # noqa: E402

ORIGINAL = radius_rules.voxel_vertex_radii


def _scaled_rule(measure: float, normal: float):
    def rule(*args, **kwargs):
        radii, normal_radii = ORIGINAL(*args, **kwargs)
        return measure * radii, normal * normal_radii

    return rule


def _settings(families):
    """``(case, kind, size, sigma, normals)``: the smoothed rows (sigma None elsewhere), analytic outward normals."""
    if "smoothed" in families or "smoothed-target" in families:
        settings = [(k, s, sg) for k, s, sigmas in scale_families.SMOOTHED for sg in sigmas]
        for case, (kind, size, sigma) in zip(scale_families.smoothed_cases(), settings, strict=True):
            if "smoothed" in families or (kind in ("sphere", "torus") and min(size) >= 10):
                yield case, kind, size, sigma, exact_normals(kind, size, case.vertices)
    if "failing" in families:
        for case, (kind, arguments, spacing, seed) in zip(
            scale_families.failing_cases(), scale_families.FAILING, strict=True
        ):
            build = shapes.voxel_torus if kind == "torus" else shapes.voxel_ellipsoid
            mesh = build(*arguments, spacing, seed=seed)  # its analytic normals (outward), as accuracy.py --voxel
            yield case, kind, None, None, np.asarray(mesh.normals, dtype=np.float64)


def _median(values) -> float:
    return float(np.nanmedian(values))


def run(families, measures, normals_factors):
    warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
    rows = []
    for case, kind, size, sigma, truth_normals in _settings(families):
        scale = np.maximum(np.abs(case.k_min), np.abs(case.k_max))
        exact = case.mean
        blurred = blurred_mean(kind, size, sigma, case.vertices, case.k_min, case.k_max) if sigma else None
        exact_measures = face_measures(case.vertices, case.faces, truth_normals)
        row = {"mesh": case.name, "vertices": int(case.vertices.shape[0]), "grid": []}
        if blurred is not None:
            row["blur shift"] = _median(np.abs(blurred - exact) / scale)
        errors_v = []
        ladder = []  # (k_min, k_max) at each measure factor, today's normals (q = 1)
        for f in measures:
            for q in normals_factors:
                radius_rules.voxel_vertex_radii = _scaled_rule(f, q)
                try:
                    start = time.process_time()
                    result = meshcurv.principal_curvatures(case.vertices, case.faces)
                    cpu = time.process_time() - start
                finally:
                    radius_rules.voxel_vertex_radii = ORIGINAL
                cosine = np.abs(np.sum(result.normals * truth_normals, axis=1))
                angle = np.degrees(np.arccos(np.clip(cosine, 0, 1)))
                entry = {
                    "f": f,
                    "q": q,
                    "cpu": cpu,
                    "radius": float(np.median(result.radius)),
                    "H": _median(np.abs(result.mean - exact) / scale),
                    "H of |H|": _median(np.abs(result.mean - exact) / np.abs(exact)),  # accuracy_voxel.md's metric
                    "k_min": _median(np.abs(result.k_min - case.k_min) / scale),
                    "k_max": _median(np.abs(result.k_max - case.k_max) / scale),
                    "angle": float(np.median(angle)),
                }
                if blurred is not None:
                    entry["H blurred"] = _median(np.abs(result.mean - blurred) / scale)
                if q == 1.0 or len(normals_factors) == 1:
                    sums = ball_face_sums(case.vertices, case.faces, result.radius, exact_measures, connected=True)
                    k_min, k_max, *_ = curvatures_from_measures(sums, truth_normals)
                    entry["exact normals H"] = _median(np.abs(0.5 * (k_min + k_max) - exact) / scale)
                    if blurred is not None:
                        entry["exact normals H blurred"] = _median(np.abs(0.5 * (k_min + k_max) - blurred) / scale)
                row["grid"].append(entry)
                if q == 1.0:
                    ladder.append((result.k_min, result.k_max))
                errors_v.append(np.abs(result.mean - exact) / scale)
        row["per-vertex oracle H"] = _median(np.nanmin(np.stack(errors_v), axis=0))
        if len(ladder) > 1:  # the ladder's least-change rule (radius.stable_scales) over the measure factors
            k_min = np.stack([pair[0] for pair in ladder])
            k_max = np.stack([pair[1] for pair in ladder])
            lists = MeshTopology.from_faces(case.faces, case.vertices.shape[0]).neighbour_lists
            rung = radius_rules.stable_scales(k_min, k_max, lists)
            chosen = 0.5 * (k_min + k_max)[rung, np.arange(rung.size)]
            row["ladder H"] = _median(np.abs(chosen - exact) / scale)
            row["ladder rungs"] = np.bincount(rung, minlength=len(ladder)).tolist()
        rows.append(row)
        _print_row(row)
    return rows


def field_geometry(mask: np.ndarray, sigma: float, points: np.ndarray, chunk: int = 256):
    """The unit outward normals and mean curvature of the blurred mask's level set through ``points``.

    ``points`` are in voxel index coordinates. The field is the Gaussian blur of ``mask`` as
    ``scipy.ndimage.gaussian_filter`` computes it on the lattice (a sampled kernel normalised to sum 1,
    truncated at 4 sigma), extended between the lattice points by the same kernel taken as a continuous
    function, normalised along each axis: ``f(x) = sum_j m_j prod_a w(x_a - j_a)``, ``w(t) = g(t) / sum_k g(t - k)``,
    ``g(t) = exp(-t^2 / (2 sigma^2))``, which equals the filtered mask at every voxel and is 1 inside a full
    mask. Its level set is the smooth surface marching cubes samples: its normal
    ``n = -grad f / |grad f|`` and mean curvature ``div(n) / 2`` at each point are what a perfect
    estimator on the mesh could recover (the blur shift and the digitisation of the binary mask included).
    """
    reach = int(4.0 * sigma + 0.5)
    offsets = np.arange(-reach, reach + 1)
    z = float(np.sum(np.exp(-(offsets**2) / (2 * sigma**2))))
    gradient = np.zeros((points.shape[0], 3))
    hessian = np.zeros((points.shape[0], 3, 3))
    dims = np.array(mask.shape)
    for start in range(0, points.shape[0], chunk):
        p = points[start : start + chunk]
        base = np.floor(p).astype(np.int64)
        cells = base[:, None, :] + offsets[None, :, None]  # (n, m, 3): the lattice lines near each point
        t = p[:, None, :] - cells  # (n, m, 3)
        g = np.exp(-(t**2) / (2 * sigma**2)) / z
        dg = -t / sigma**2 * g
        ddg = (t**2 / sigma**4 - 1 / sigma**2) * g
        # normalised per axis by the kernel's sum over the lattice lines, S(t) = sum_k g(t - k), so that a full
        # mask is 1 everywhere (a sampled Gaussian of sigma 0.5 is no partition of unity: S varies by 3% along
        # a voxel, a ripple of the lattice's period that twice differentiated would swamp the curvature); S is
        # the same at every lattice point, so the field still equals the filtered mask there
        total, dtotal, ddtotal = (
            g.sum(axis=1, keepdims=True),
            dg.sum(axis=1, keepdims=True),
            ddg.sum(axis=1, keepdims=True),
        )
        g, dg, ddg = (
            g / total,
            (dg * total - g * dtotal) / total**2,
            (ddg * total**2 - g * ddtotal * total - 2 * dg * dtotal * total + 2 * g * dtotal**2) / total**3,
        )
        inside = (cells >= 0) & (cells < dims)
        g, dg, ddg = (np.where(inside, a, 0.0) for a in (g, dg, ddg))
        idx = np.clip(cells, 0, dims - 1)
        block = mask[idx[:, :, 0][:, :, None, None], idx[:, :, 1][:, None, :, None], idx[:, :, 2][:, None, None, :]]
        factors = (g, dg, ddg)

        def tri(a, b, c, block=block, factors=factors):
            return np.einsum("nijk,ni,nj,nk->n", block, factors[a][:, :, 0], factors[b][:, :, 1], factors[c][:, :, 2])

        gradient[start : start + chunk] = np.stack([tri(1, 0, 0), tri(0, 1, 0), tri(0, 0, 1)], axis=1)
        for a in range(3):
            for b in range(a, 3):
                order = [0, 0, 0]
                order[a] += 1
                order[b] += 1
                value = tri(*order)
                hessian[start : start + chunk, a, b] = value
                hessian[start : start + chunk, b, a] = value
    length = np.linalg.norm(gradient, axis=1)
    normals = -gradient / length[:, None]
    # div(grad f / |grad f|) = (tr(Hf) - n^T Hf n) / |grad f|, and n = -grad f / |grad f| (outward): a sphere's
    # tangential second derivatives are f' / R < 0, so H = -(tr(Hf) - n^T Hf n) / (2 |grad f|) = 1 / R
    trace = np.trace(hessian, axis1=1, axis2=2)
    along = np.einsum("ni,nij,nj->n", normals, hessian, normals)
    return normals, -0.5 * (trace - along) / length


def _given_normals_mean(case, radii, normals):
    """(V,) icc's mean curvature at ``radii`` with the given vertex ``normals`` in place of the fitted ones."""
    sums = ball_face_sums(
        case.vertices, case.faces, radii, face_measures(case.vertices, case.faces, normals), connected=True
    )
    k_min, k_max, *_ = curvatures_from_measures(sums, normals)
    return 0.5 * (k_min + k_max)


def lattice_table():
    """Per smoothed row: the level set of the blurred mask against the analytic surface and the blur shift."""
    warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
    print(
        "| mesh | blur shift: H | input level set: H | its normals' angle to the analytic ones "
        "| fitted normals' angle: to the analytic / to the level set's | default: H "
        "| today's radii, the level set's normals: H | today's radii, analytic normals: H |"
    )
    print("|---|--:|--:|--:|--:|--:|--:|--:|")
    seed = 100
    rows = []
    cases = scale_families.smoothed_cases()
    for kind, size, sigmas in scale_families.SMOOTHED:
        inside, extent, _ = scale_families._solid(kind, size)
        for sigma in sigmas:
            seed += 1
            case = next(cases)
            axes, center = scale_families._grid(extent, (1.0, 1.0, 1.0), seed)
            mask = inside(*np.meshgrid(*axes, indexing="ij", sparse=True)).astype(float)
            field_normals, field_mean = field_geometry(mask, sigma, case.vertices + center)
            scale = np.maximum(np.abs(case.k_min), np.abs(case.k_max))
            analytic = exact_normals(kind, size, case.vertices)
            blurred = blurred_mean(kind, size, sigma, case.vertices, case.k_min, case.k_max)
            result = meshcurv.principal_curvatures(case.vertices, case.faces)
            # the same sums at the default's radii with the level set's normals: a perfect normal estimate of the
            # input surface (rather than of the analytic one)
            level_mean = _given_normals_mean(case, result.radius, field_normals)
            analytic_mean = _given_normals_mean(case, result.radius, analytic)

            def angle(a, b):
                return float(np.median(np.degrees(np.arccos(np.clip(np.abs(np.sum(a * b, axis=1)), 0, 1)))))

            row = {
                "mesh": case.name,
                "blur shift": None if blurred is None else _median(np.abs(blurred - case.mean) / scale),
                "level set H": _median(np.abs(field_mean - case.mean) / scale),
                "level set angle": angle(field_normals, analytic),
                "fitted angle": angle(result.normals, analytic),
                "fitted to level set": angle(result.normals, field_normals),
                "default H to level set": _median(np.abs(result.mean - field_mean) / scale),
                "default H": _median(np.abs(result.mean - case.mean) / scale),
                "level set normals H": _median(np.abs(level_mean - case.mean) / scale),
                "analytic normals H": _median(np.abs(analytic_mean - case.mean) / scale),
            }
            rows.append(row)
            shift = "-" if row["blur shift"] is None else _pct(row["blur shift"])
            print(
                f"| {case.name} | {shift} | {_pct(row['level set H'])} | {row['level set angle']:.2f} deg "
                f"| {row['fitted angle']:.2f} / {row['fitted to level set']:.2f} deg "
                f"| {_pct(row['default H'])} | {_pct(row['level set normals H'])} | {_pct(row['analytic normals H'])} |",
                flush=True,
            )
    return rows


def dump_ladder(families, measures, path):
    """The default call's H, k_min, k_max at each measure factor (normals as today) on ``families`` of
    ``scale_families.py``, with the exact values and the mesh's edge lists, to ``path`` (.npz): the data of the
    per-vertex rules compared in ``agreement_rules``."""
    warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
    arrays = {}
    names = []
    for index, case in enumerate(scale_families.cases(families)):
        stack = []
        for f in measures:
            radius_rules.voxel_vertex_radii = _scaled_rule(f, 1.0)
            try:
                result = meshcurv.principal_curvatures(case.vertices, case.faces)
            finally:
                radius_rules.voxel_vertex_radii = ORIGINAL
            stack.append(np.stack([result.k_min, result.k_max, result.radius]))
        indptr, indices = MeshTopology.from_faces(case.faces, case.vertices.shape[0]).neighbour_lists
        arrays[f"{index}_estimates"] = np.stack(stack)  # (J, 3, V)
        arrays[f"{index}_exact"] = np.stack([case.k_min, case.k_max])
        arrays[f"{index}_indptr"], arrays[f"{index}_indices"] = indptr, indices
        names.append(f"{case.family}|{case.name}|{int(case.tuning)}|{result.parameters.get('scale')}")
        print(names[-1], flush=True)
    np.savez_compressed(path, names=np.array(names), measures=np.array(measures), **arrays)


def _ring_mean(lists, rings, values):
    """(..., V) ``values`` averaged over each vertex and its neighbours within ``rings`` edges (NaN skipped)."""
    finite = np.isfinite(values)
    total, count = radius_rules._ring_sums(lists, rings, np.where(finite, values, 0.0).T, finite.astype(float).T)
    with np.errstate(invalid="ignore", divide="ignore"):
        return (total / count).T


def agreement_rungs(estimates, lists, threshold, rings=2):
    """(V,) the largest rung whose ring-averaged H, k_min, k_max stay within ``threshold`` times the local spread
    of the first rung's (their standard deviation over ``rings`` rings) of the first rung's, at every rung up to
    it: the ladder's agreement test (keep the largest ball that agrees with the smallest within its noise)."""
    k_min, k_max = estimates[:, 0], estimates[:, 1]
    fields = [0.5 * (k_min + k_max), k_min, k_max]
    ok = np.ones(k_min.shape, dtype=bool)
    for field in fields:
        mean = _ring_mean(lists, rings, field)
        spread = np.sqrt(np.maximum(_ring_mean(lists, rings, field[0] ** 2) - mean[0] ** 2, 0.0))
        ok &= np.abs(mean - mean[0]) <= threshold * spread
    ok = np.cumprod(ok, axis=0).astype(bool)  # agreement at every rung up to j
    return ok.shape[0] - 1 - np.argmax(ok[::-1], axis=0)


def agreement_table(paths, base_index=1, thresholds=(0.5, 1.0, 2.0), tubes=(0.5, 0.8)):
    """Per family: geometric means of the median H error of today (rung ``base_index``), each uniform factor, the
    least-change ladder and the agreement test from the base rung up, with the rows worse / better by a tenth."""
    for path in paths:
        data = np.load(path)
        names, measures = list(data["names"]), data["measures"]
        rules: dict[str, list] = {}
        for index in range(len(names)):
            estimates = data[f"{index}_estimates"][base_index:]  # from today's radius up
            exact = data[f"{index}_exact"]
            lists = (data[f"{index}_indptr"], data[f"{index}_indices"])
            scale = np.maximum(np.abs(exact[0]), np.abs(exact[1]))
            mean = 0.5 * (exact[0] + exact[1])

            def error(k_min, k_max, scale=scale, mean=mean, exact=exact):
                gauss = exact[0] * exact[1]
                return (
                    _median(np.abs(0.5 * (k_min + k_max) - mean) / scale),
                    _median(np.abs(k_min - exact[0]) / scale),
                    _median(np.abs(k_max - exact[1]) / scale),
                    _median(np.abs(k_min * k_max - gauss) / np.abs(gauss)),  # accuracy_voxel.md's K metric
                )

            for j, f in enumerate(measures):
                rules.setdefault(f"f {f:g}", []).append(error(*data[f"{index}_estimates"][j, :2]))
            every = np.arange(scale.size)
            rung = radius_rules.stable_scales(estimates[:, 0], estimates[:, 1], lists)
            rules.setdefault("least change", []).append(error(*estimates[rung, :2, every].T))
            rung = np.minimum(rung, 1)  # the same choice, the upper rung at most f 1.41
            rules.setdefault("least change, f <= 1.41", []).append(error(*estimates[rung, :2, every].T))
            for c in thresholds:
                rung = agreement_rungs(estimates, lists, c)
                rules.setdefault(f"agreement {c:g}", []).append(error(*estimates[rung, :2, every].T))
            # tube-like vertices (curved one way: t = 1 - 2 sqrt|K| / c, of today's estimates over 2 rings, as the
            # pilot's t_v of radius.voxel_vertex_radii) one rung up
            curvedness = _ring_mean(lists, 2, np.maximum(np.abs(estimates[0, 0]), np.abs(estimates[0, 1])))
            gauss = _ring_mean(lists, 2, np.abs(estimates[0, 0] * estimates[0, 1]))
            with np.errstate(invalid="ignore", divide="ignore"):
                tube = np.clip(1 - 2 * np.sqrt(gauss) / curvedness, 0, 1)
            for limit in tubes:
                rung = np.where(tube > limit, 1, 0)
                rules.setdefault(f"tube > {limit:g}", []).append(error(*estimates[rung, :2, every].T))
        today = np.array(rules[f"f {measures[base_index]:g}"])
        print(
            f"\n{path}: {len(names)} meshes; geometric mean of the median H / k_min / k_max error; rows (H) worse / better by a tenth"
        )
        for rule, values in rules.items():
            values = np.array(values)
            geo = np.exp(np.mean(np.log(np.maximum(values, 1e-6)), axis=0))
            worse = int(np.sum(values[:, 0] > 1.1 * today[:, 0]))
            better = int(np.sum(values[:, 0] < today[:, 0] / 1.1))
            worse_k = int(np.sum(values[:, 3] > 1.1 * today[:, 3]))
            print(
                f"  {rule:24s} {_pct(geo[0])} / {_pct(geo[1])} / {_pct(geo[2])}  ({worse} / {better});"
                f"  K of |K| {_pct(geo[3])} ({worse_k} worse)"
            )
        for index, name in enumerate(names):
            cells = " ".join(f"{rule}={100 * rules[rule][index][0]:.2f}" for rule in rules)
            print(f"    {name.split('|')[1]}: {cells}")


def _pct(x) -> str:
    return f"{100 * x:.2f}%"


def _print_row(row):
    grid = row["grid"]
    today = next((e for e in grid if e["f"] == 1.0 and e["q"] == 1.0), grid[0])
    best = min(grid, key=lambda e: e["H"])
    exact = [e for e in grid if "exact normals H" in e]
    best_exact = min(exact, key=lambda e: e["exact normals H"])
    print(
        f"| {row['mesh']} | {_pct(today['H'])} ({today['angle']:.2f} deg) "
        f"| {_pct(best['H'])} at f {best['f']:g}, q {best['q']:g} ({best['angle']:.2f} deg; "
        f"k_min {_pct(best['k_min'])}, k_max {_pct(best['k_max'])}) "
        f"| {_pct(today.get('exact normals H', float('nan')))} "
        f"| {_pct(best_exact['exact normals H'])} at f {best_exact['f']:g} "
        f"| {_pct(row.get('blur shift', float('nan')))} | {_pct(row['per-vertex oracle H'])} "
        f"| {_pct(row.get('ladder H', float('nan')))} {row.get('ladder rungs', '')} |",
        flush=True,
    )


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--families", nargs="+", default=["smoothed-target"], help="smoothed-target, smoothed, failing")
    parser.add_argument("--measure", default="0.71,1,1.41,2", help="factors of the measure radii")
    parser.add_argument("--normal", default="0.71,1,1.41", help="factors of the normal-fit radii")
    parser.add_argument("--lattice", action="store_true", help="the blurred masks' level sets (smoothed rows)")
    parser.add_argument("--dump", metavar="PATH.npz", help="save the estimates at each --measure factor")
    parser.add_argument("--rules", nargs="+", metavar="PATH.npz", help="compare per-vertex rules on --dump files")
    parser.add_argument("--output")
    args = parser.parse_args(argv)
    if args.rules:
        agreement_table(args.rules)
        return
    if args.dump:
        dump_ladder(args.families, [float(x) for x in args.measure.split(",")], args.dump)
        return
    if args.lattice:
        rows = lattice_table()
        if args.output:
            with open(args.output, "w") as handle:
                json.dump(rows, handle, indent=1)
        return
    measures = [float(x) for x in args.measure.split(",")]
    normals_factors = [float(x) for x in args.normal.split(",")]
    print(
        "| mesh | today: H (normal angle) | best (f, q) of the grid: H | exact normals, today's radii: H "
        "| exact normals, best f: H | blur shift | per-vertex oracle: H | least-change ladder over f: H (rungs) |"
    )
    print("|---|--:|--:|--:|--:|--:|--:|--:|")
    rows = run(args.families, measures, normals_factors)
    if args.output:
        with open(args.output, "w") as handle:
            json.dump(rows, handle, indent=1)


if __name__ == "__main__":
    main()
