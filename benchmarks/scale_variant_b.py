"""Variant B of the per-vertex scale for icc (issue 30): normals fitted once, the whole ladder in one walk.

Run from the repository root (needs scikit-image and scipy; the variant A data
come from ``benchmarks/scale_prototype.py --compute``, cached in
``/tmp/meshcurv_scale_cache``)::

    python benchmarks/scale_variant_b.py --compute    # variant B on every mesh, cached in <cache>/variant_b
    python benchmarks/scale_variant_b.py --timing     # the stage timings, 2 repeats on 6 meshes
    python benchmarks/scale_variant_b.py --grid       # variant B's rule constants, scored on the tuning meshes
    python benchmarks/scale_variant_b.py --anchored   # the recommended ladder (from r0): computed, cached, table
    python benchmarks/scale_variant_b.py --anchored-timing   # its stage timings, 3 repeats on 6 meshes
    python benchmarks/scale_variant_b.py              # the tables of benchmarks/scale.md, "Variant B"

Variant A (``scale_prototype.py``) runs icc in full at every rung ``r_j`` of
the ladder: normals fitted over ``3 r_j`` for every rung. Variant B, per mesh:

1. ``r0``: today's default radius (``principal_curvatures(v, f).parameters["radius"]``);
   the normals fitted **once**, over ``3 r0`` (:func:`meshcurv.estimators.icc.fitted_normals`).
2. The face measures of those normals summed over every rung of the ladder in
   **one walk** (:func:`meshcurv.neighborhoods.ball_face_sums_nested`); H and K
   of each rung from the sums (``H = mu_1 / (2 mu_0)``, ``K = mu_2 / mu_0``).
3. The rung of each vertex by the colleague's rule (``scale_prototype.RULE``,
   :func:`scale_prototype.select_stable`). **B1**: the chosen rung's values (fixed
   normals), with the directions from the chosen rung's sums.
4. **B2**: a final pass at the chosen per-vertex radius ``r_v``: normals fitted
   over ``3 r_v`` per vertex, the sums at ``r_v`` per vertex.

Ladders (:data:`LADDERS`): ratio ``sqrt 2`` or ``2^(1/4)`` from ``0.7 h_5``, up
to 8, 12 or 32 median edges (and the area cap of ``scale_prototype.ladder``).
The finest ladder (``2^(1/4)``, 32 h) holds every other one's rungs, so its
values serve them all; each ladder's own walk is timed.

The recommended setting (:data:`RECOMMENDED`) is B1 on the ladder ``r0 sqrt(2)^j``
up to 12 h (:func:`anchored_ladder`): the first rung is today's default radius.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

import meshcurv  # noqa: E402
import scale_families  # noqa: E402
import scale_prototype as proto  # noqa: E402
from meshcurv._prepared import PreparedMesh  # noqa: E402
from meshcurv._tensors import principal_from_mean_gaussian  # noqa: E402
from meshcurv.estimators import icc  # noqa: E402
from meshcurv.geometry import median_edge_length, vertex_edge_lengths  # noqa: E402
from meshcurv.measures import curvatures_from_measures, face_measures  # noqa: E402
from meshcurv.neighborhoods import ball_face_sums, ball_face_sums_nested  # noqa: E402

CACHE = os.path.join(proto.CACHE, "variant_b")

#: name -> (ratio, top in median edge lengths) of the ladders compared.
LADDERS = {
    "q2-32": (2**0.5, 32.0),
    "q2-12": (2**0.5, 12.0),
    "q2-8": (2**0.5, 8.0),
    "q4-32": (2**0.25, 32.0),
    "q4-12": (2**0.25, 12.0),
}

#: The normals of the ladder walk: ``r0`` (the brief's variant B: fitted over 3 r0, today's default radius) or
#: ``low`` (fitted over 3 x 0.75 h_v per vertex: the ladder's first usable rung), and the ladders run with each.
NORMAL_MODES = {"r0": tuple(LADDERS), "low": ("q2-32", "q2-12", "q4-12")}

#: The ladder whose rungs hold every other one's.
FINEST = "q4-32"

#: The meshes of the stage timings (3 repeats, the minimum kept): one per kind.
TIMING_MESHES = [
    "icosphere(32) [level 2]",
    "torus(R=3, r=1) + noise 0.3h [level 2]",
    "voxel_torus(R=12, r=4, voxel 0.5x0.5x0.5)",
    "smoothed sphere(20), sigma 1",
    "smoothed torus(25, 10), sigma 1",
    "varying ellipsoid(3, 2, 1) (25250 points, density 100:1)",
]


def _quiet(call, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return call(*args, **kwargs)


class Mesh:
    """The per-mesh data every stage reads (topology, first normals, usable faces, rings)."""

    def __init__(self, vertices, faces):
        self.vertices, self.faces = vertices, faces
        self.topology = meshcurv.MeshTopology.from_faces(faces, vertices.shape[0])
        prepared = PreparedMesh.as_given(vertices, self.topology)
        self.normals = prepared.vertex_normals
        _, self.valid = prepared.start(boundary=True)
        self.kept = ~prepared.degenerate
        self.referenced = self.topology.referenced_vertices
        self.adjacency = self.topology.neighbour_lists
        self.local = vertex_edge_lengths(vertices, self.topology.edges)
        self.h = median_edge_length(vertices, self.topology.edges)

    def fitted(self, radius):
        """Normals fitted over ``radius`` (a float, or (V,) one per vertex)."""
        return icc.fitted_normals(
            self.vertices, self.normals, self.valid, radius, neighbours=self.referenced, adjacency=self.adjacency
        )

    def measures(self, normals):
        finite = np.isfinite(normals).all(axis=1)
        kept = self.kept if finite.all() else self.kept & finite[self.faces].all(axis=1)
        return face_measures(self.vertices, self.faces, normals), None if kept.all() else kept


def default_call(mesh):
    """Today's default icc call: ``(seconds, result)``."""
    t0 = time.perf_counter()
    result = _quiet(meshcurv.principal_curvatures, mesh.vertices, mesh.topology)
    return time.perf_counter() - t0, result


def ladder_sums(mesh, normals, radii):
    """(2, J, V) k_min, k_max of every rung with fixed ``normals``, and the (J, V, 9) sums (one walk)."""
    values, usable = mesh.measures(normals)
    summed = ball_face_sums_nested(mesh.vertices, mesh.faces, radii, values, usable=usable)
    area = summed[..., 0]
    with np.errstate(invalid="ignore", divide="ignore"):
        mean, gaussian = summed[..., 1] / (2 * area), summed[..., 2] / area
    k_min, k_max = principal_from_mean_gaussian(mean, gaussian)
    bad = ~(area > 0) | ~np.isfinite(normals).all(axis=1)[None, :]
    k_min[bad], k_max[bad] = np.nan, np.nan
    return np.stack([k_min, k_max]), summed


def selection_data(mesh, radii, k):
    """The ``data`` dict :func:`scale_prototype.select_stable` reads."""
    k_min, k_max = k
    indptr, indices = mesh.adjacency
    return {
        "fields": np.stack([k_min, k_max, (k_min + k_max) / 2, k_min * k_max]),
        "radii": radii,
        "local": mesh.local,
        "indptr": np.asarray(indptr),
        "indices": np.asarray(indices),
    }


def pick(summed, normals, chosen):
    """B1's k_min, k_max and directions: the sums of the chosen rung at each vertex, one call."""
    rows = summed[chosen, np.arange(chosen.size)]
    return curvatures_from_measures(rows, normals)


def final_pass(mesh, radius):
    """B2: normals over ``3 radius`` (V,) and the sums at ``radius`` per vertex: ``k_min, k_max, seconds``."""
    t0 = time.perf_counter()
    normals = mesh.fitted(icc.NORMAL_RADIUS_RATIO * radius)
    t1 = time.perf_counter()
    values, usable = mesh.measures(normals)
    summed = ball_face_sums(mesh.vertices, mesh.faces, radius, values, usable=usable, connected=True)
    k_min, k_max, _, _ = curvatures_from_measures(summed, normals)
    t2 = time.perf_counter()
    return k_min, k_max, (t1 - t0, t2 - t1)


def ladders(mesh):
    return {
        name: proto.ladder(mesh.vertices, mesh.faces, mesh.topology, ratio=q, high=top)
        for name, (q, top) in LADDERS.items()
    }


def rungs_of(finest, radii):
    """Indices of ``radii`` among the ``finest`` ladder's rungs."""
    index = np.array([np.argmin(np.abs(finest - r)) for r in radii])
    assert np.allclose(finest[index], radii, rtol=1e-9), (finest, radii)
    return index


def ladder_normal_radius(mesh, mode, r0):
    """The normal-fit radius of the ladder walk (:data:`NORMAL_MODES`)."""
    if mode == "r0":
        return icc.NORMAL_RADIUS_RATIO * r0
    return icc.NORMAL_RADIUS_RATIO * proto.RULE["min_edges"] * mesh.local


def compute(case, cache=CACHE, rule=None, final=True):
    """Variant B on one mesh, every ladder and normal mode (single timings), into ``cache/<name>.npz``."""
    rule = proto.RULE if rule is None else rule
    path = os.path.join(cache, proto._slug(case.name) + ".npz")
    if os.path.exists(path):
        return path
    mesh = Mesh(case.vertices, case.faces)
    t_default, default = default_call(mesh)
    r0 = float(default.parameters["radius"])
    radii = ladders(mesh)
    out = {
        "name": case.name,
        "r0": r0,
        "h": mesh.h,
        "t_default": t_default,
        "n": mesh.vertices.shape[0],
        "default": np.stack([default.k_min, default.k_max]),
    }
    for mode, configs in NORMAL_MODES.items():
        t0 = time.perf_counter()
        normals = mesh.fitted(ladder_normal_radius(mesh, mode, r0))
        out[f"{mode}_t_normals"] = time.perf_counter() - t0
        for name in configs:
            rr, key = radii[name], f"{mode} {name}"
            t0 = time.perf_counter()
            k, summed = ladder_sums(mesh, normals, rr)
            t1 = time.perf_counter()
            chosen = proto.select_stable(selection_data(mesh, rr, k), rule)
            b1 = pick(summed, normals, chosen)
            t2 = time.perf_counter()
            out[f"{name}_radii"], out[f"{key}_chosen"] = rr, chosen
            out[f"{key}_t_ladder"], out[f"{key}_t_select"] = t1 - t0, t2 - t1
            out[f"{key}_b1"] = np.stack(b1[:2])
            if name in (FINEST, "q2-32"):  # the rungs' values, for re-selecting under other rule constants
                out[f"{key}_k"] = k
            del summed
            if final:
                k_min, k_max, (t_fit, t_sum) = final_pass(mesh, rr[chosen])
                out[f"{key}_b2"] = np.stack([k_min, k_max])
                out[f"{key}_t_final_normals"], out[f"{key}_t_final_sums"] = t_fit, t_sum
    os.makedirs(cache, exist_ok=True)
    np.savez_compressed(path, **out)
    print(
        f"{case.name}: {mesh.vertices.shape[0]} vertices, default {t_default:.2f} s, "
        + ", ".join(
            f"{m} {n} {out[f'{m} {n}_t_ladder']:.2f}"
            f"+{out[f'{m} {n}_t_final_normals'] + out[f'{m} {n}_t_final_sums']:.2f} s"
            for m, c in NORMAL_MODES.items()
            for n in c
            if final
        ),
        file=sys.stderr,
    )
    return path


def anchored_ladder(mesh, r0, *, ratio=2**0.5, high=12.0):
    """The rungs ``r0 q^j`` up to ``min(high h, sqrt(area / (18 pi)))``: a ladder that starts at today's default."""
    top = proto.ladder(mesh.vertices, mesh.faces, mesh.topology, ratio=ratio, high=high)[-1]
    count = int(np.floor(np.log(max(top, r0) / r0) / np.log(ratio) + 1e-9)) + 1
    return r0 * ratio ** np.arange(max(count, 2))


def compute_anchored(case, cache=CACHE + "_anchored"):
    """B1 on the ladder from r0 (:func:`anchored_ladder`), normals over 3 r0: the rungs' values, cached."""
    path = os.path.join(cache, proto._slug(case.name) + ".npz")
    if os.path.exists(path):
        return path
    mesh = Mesh(case.vertices, case.faces)
    t_default, default = default_call(mesh)
    r0 = float(default.parameters["radius"])
    normals = mesh.fitted(icc.NORMAL_RADIUS_RATIO * r0)
    rr = anchored_ladder(mesh, r0)
    t0 = time.perf_counter()
    k, _ = ladder_sums(mesh, normals, rr)
    t_ladder = time.perf_counter() - t0
    os.makedirs(cache, exist_ok=True)
    np.savez_compressed(
        path,
        name=case.name,
        r0=r0,
        h=mesh.h,
        radii=rr,
        k=k,
        t_default=t_default,
        t_ladder=t_ladder,
        default=np.stack([default.k_min, default.k_max]),
    )
    print(
        f"{case.name}: anchored ladder of {rr.size} rungs, {t_ladder:.2f} s (default {t_default:.2f} s)",
        file=sys.stderr,
    )
    return path


def anchored_report(cache=CACHE + "_anchored", rules=None):
    """Geometric means per family of B1 on the anchored ladder under ``rules`` (label -> rule)."""
    rules = rules or {
        "anchored q2-12, RULE": proto.RULE,
        "anchored q2-12, tuned pool 0.75": dict(RULE_B1, pool=0.75),
        "anchored q2-12, tuned pool 1": RULE_B1,
    }
    labels = proto._labels()
    per_family = {}
    for path in sorted(p for p in os.listdir(cache) if p.endswith(".npz")):
        with np.load(os.path.join(cache, path)) as z:
            b = {k: z[k] for k in z.files}
        a = proto.load(os.path.join(proto.CACHE, path))
        family = labels.get(a["name"], (a["family"], a["tuning"]))[0]
        d = proto.errors(a, _fields(b["default"]))
        data = {
            "fields": _fields(b["k"]),
            "radii": b["radii"],
            "local": a["local"],
            "indptr": a["indptr"],
            "indices": a["indices"],
            "r0": float(b["r0"]),
        }
        row = per_family.setdefault(family, {k: [] for k in ["default", *rules]})
        worse = per_family.setdefault(family + " worse", {k: 0 for k in rules})
        row["default"].append(d["H"][0])
        for label, rule in rules.items():
            e = proto.errors(a, proto.picked(data, proto.select_stable(data, rule)))
            row[label].append(e["H"][0])
            worse[label] += e["H"][0] > 1.1 * d["H"][0] + 2e-4
    lines = [
        "| run | " + " | ".join(f for f in per_family if not f.endswith("worse")) + " |",
        "|---|" + "---|" * (len(per_family) // 2),
    ]
    for key in ["default", *rules]:
        cells = []
        for family, row in per_family.items():
            if family.endswith("worse"):
                continue
            extra = "" if key == "default" else f" ({per_family[family + ' worse'][key]})"
            cells.append(proto._pct(proto._geo(row[key])) + extra)
        lines.append(f"| {key} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def anchored_cost(cache=CACHE + "_anchored", names=TIMING_MESHES):
    """(default + anchored ladder) / default per timing mesh, from the single timings of ``--anchored``."""
    lines = [
        "| mesh | V | rungs | default, us per vertex | ladder, us per vertex | (default + ladder) / default |",
        "|---|---|---|---|---|---|",
    ]
    ratios = []
    for path in sorted(os.listdir(cache)):
        with np.load(os.path.join(cache, path)) as z:
            name, n = str(z["name"]), z["default"].shape[1]
            ratio = (z["t_default"] + z["t_ladder"]) / z["t_default"]
            ratios.append(ratio)
            if name in names:
                lines.append(
                    f"| {name} | {n} | {z['radii'].size} | {1e6 * z['t_default'] / n:.0f} | "
                    f"{1e6 * z['t_ladder'] / n:.0f} | {ratio:.1f} |"
                )
    lines.append(
        f"| all {len(ratios)} meshes: median [10-90%, max] | | | | | {np.median(ratios):.1f} "
        f"[{np.percentile(ratios, 10):.1f}-{np.percentile(ratios, 90):.1f}, {np.max(ratios):.1f}] |"
    )
    return "\n".join(lines)


def anchored_timing(names=TIMING_MESHES, repeats=3):
    """Per-vertex microseconds of the recommended variant's stages (minimum of ``repeats`` interleaved runs)."""
    warm_up()
    lines = [
        "| mesh | V | rungs | default | normals 3 r0 (in default) | ladder sums | selection + pick | "
        "B1 total / default |",
        "|---|---|---|---|---|---|---|---|",
    ]
    wanted = set(names)
    for case in scale_families.cases():
        if case.name not in wanted:
            continue
        wanted.discard(case.name)
        mesh = Mesh(case.vertices, case.faces)
        n, best = mesh.vertices.shape[0], {}
        for _ in range(repeats):
            t, default = default_call(mesh)
            r0 = float(default.parameters["radius"])
            t0 = time.perf_counter()
            normals = mesh.fitted(icc.NORMAL_RADIUS_RATIO * r0)
            t1 = time.perf_counter()
            rr = anchored_ladder(mesh, r0)
            k, summed = ladder_sums(mesh, normals, rr)
            t2 = time.perf_counter()
            chosen = proto.select_stable(dict(selection_data(mesh, rr, k), r0=r0), proto.RULE)
            pick(summed, normals, chosen)
            t3 = time.perf_counter()
            for key, value in (("default", t), ("normals", t1 - t0), ("ladder", t2 - t1), ("select", t3 - t2)):
                best[key] = min(best.get(key, np.inf), value)
        total = best["default"] + best["ladder"] + best["select"]
        lines.append(
            f"| {case.name} | {n} | {rr.size} | "
            + " | ".join(f"{1e6 * best[k] / n:.0f}" for k in ("default", "normals", "ladder", "select"))
            + f" | {total / best['default']:.2f} |"
        )
        if not wanted:
            break
    return "\n".join(lines)


def warm_up():
    """Compile every kernel the stages call (numba), on a small mesh."""
    sphere = meshcurv.shapes.icosphere(subdivisions=4)
    mesh = Mesh(np.asarray(sphere.vertices, dtype=float), np.ascontiguousarray(sphere.faces, dtype=np.int64))
    _, default = default_call(mesh)
    r0 = float(default.parameters["radius"])
    normals = mesh.fitted(3 * r0)
    rr = ladders(mesh)[FINEST]
    k, summed = ladder_sums(mesh, normals, rr)
    chosen = proto.select_stable(selection_data(mesh, rr, k), proto.RULE)
    pick(summed, normals, chosen)
    final_pass(mesh, rr[chosen])


# -- timing ---------------------------------------------------------------------------------

TIMED = ("r0 q2-32", "r0 q2-12", "r0 q2-8", "r0 q4-12", "low q2-32")


def timing(names=TIMING_MESHES, repeats=2, configs=TIMED, rules=None):
    """Per-vertex microseconds of each stage on ``names``, the minimum of ``repeats`` interleaved runs.

    ``rules``: ``{"mode ladder": rule}`` where a configuration selects with other constants than ``RULE``.
    """
    warm_up()
    wanted = set(names)
    rows = []
    for case in scale_families.cases():
        if case.name not in wanted:
            continue
        wanted.discard(case.name)
        mesh = Mesh(case.vertices, case.faces)
        n = mesh.vertices.shape[0]
        best = {}

        def keep(key, seconds):
            best[key] = min(best.get(key, np.inf), seconds)

        radii = ladders(mesh)
        for _ in range(repeats):
            t, default = default_call(mesh)
            keep("default", t)
            r0 = float(default.parameters["radius"])
            normals = {}
            for mode in NORMAL_MODES:
                t0 = time.perf_counter()
                normals[mode] = mesh.fitted(ladder_normal_radius(mesh, mode, r0))
                keep(f"{mode} normals", time.perf_counter() - t0)
            for key in configs:
                mode, name = key.split()
                rr = radii[name]
                rule = (rules or {}).get(key, proto.RULE)
                t0 = time.perf_counter()
                k, summed = ladder_sums(mesh, normals[mode], rr)
                t1 = time.perf_counter()
                data = dict(selection_data(mesh, rr, k), r0=r0)
                chosen = proto.select_stable(data, rule)
                pick(summed, normals[mode], chosen)
                t2 = time.perf_counter()
                del summed
                _, _, (t_fit, t_sum) = final_pass(mesh, rr[chosen])
                keep(f"{key} ladder", t1 - t0)
                keep(f"{key} select", t2 - t1)
                keep(f"{key} final normals", t_fit)
                keep(f"{key} final sums", t_sum)
                best[f"{key} rungs"] = rr.size
                best[f"{key} r_v/h"] = float(np.median(rr[chosen]) / mesh.h)
        t0 = time.perf_counter()  # variant A: icc in full at every rung of its ladder (once: it is slow)
        for r in radii["q2-32"]:
            _quiet(meshcurv.principal_curvatures, mesh.vertices, mesh.topology, radius=float(r))
        best["A"] = time.perf_counter() - t0
        rows.append((case.name, n, r0 / mesh.h, best))
        print(f"timed {case.name}", file=sys.stderr)
        if not wanted:
            break
    return rows


def timing_report(rows, configs=TIMED):
    """Per-vertex microseconds of the stages, and each variant's total against today's default.

    B with ``r0`` normals: B1 = default (noise, normals over 3 r0, sums at r0) + ladder + selection; with
    ``low`` normals: B1 = the low normal fit + ladder + selection (no default call). B2 = B1 + final pass.
    """
    us = 1e6
    head = (
        "| mesh | V | r0/h | default | A (icc per rung, q2-32, 1 run) | normals 3 r0 (in default) | "
        "normals 2.25 h_v | "
        + " | ".join(f"{c}: rungs, ladder, select, final normals + sums, r_v/h" for c in configs)
        + " |"
    )
    lines = [head, "|---|---|---|---|---|---|---|" + "---|" * len(configs)]
    ratio_lines = [
        "| mesh | A / default | " + " | ".join(f"{c}: B1, B2" for c in configs) + " |",
        "|---|---|" + "---|" * len(configs),
    ]
    for name, n, r0h, b in rows:
        cells = [
            f"{b[c + ' rungs']}, {us * b[c + ' ladder'] / n:.0f}, {us * b[c + ' select'] / n:.0f}, "
            f"{us * b[c + ' final normals'] / n:.0f} + {us * b[c + ' final sums'] / n:.0f}, "
            f"{b[c + ' r_v/h']:.1f}"
            for c in configs
        ]
        lines.append(
            f"| {name} | {n} | {r0h:.1f} | {us * b['default'] / n:.0f} | {us * b['A'] / n:.0f} | "
            f"{us * b['r0 normals'] / n:.0f} | {us * b['low normals'] / n:.0f} | " + " | ".join(cells) + " |"
        )
        ratios = []
        for c in configs:
            start = b["default"] if c.startswith("r0") else b["low normals"]
            b1 = start + b[c + " ladder"] + b[c + " select"]
            b2 = b1 + b[c + " final normals"] + b[c + " final sums"]
            ratios.append(f"{b1 / b['default']:.1f}, {b2 / b['default']:.1f}")
        ratio_lines.append(f"| {name} | {b['A'] / b['default']:.1f} | " + " | ".join(ratios) + " |")
    return "\n".join(lines + ["", "Time against today's default (same run):", ""] + ratio_lines)


# -- accuracy ---------------------------------------------------------------------------------


def load_b(name, cache=CACHE):
    path = os.path.join(cache, proto._slug(name) + ".npz")
    if not os.path.exists(path):
        return None
    with np.load(path, allow_pickle=False) as data:
        return {k: data[k] for k in data.files}


def _fields(k):
    k_min, k_max = k
    return np.stack([k_min, k_max, (k_min + k_max) / 2, k_min * k_max])


def reselect(a, b, mode, name, rule):
    """B1's fields with another ``rule`` (from the cached rungs of the finest ladder): (4, V), chosen radii."""
    rr = b[f"{name}_radii"]
    source = next(
        c
        for c in ("q2-32", FINEST)
        if f"{mode} {c}_k" in b and np.all(np.isin(np.round(rr, 9), np.round(b[f"{c}_radii"], 9)))
    )
    k = b[f"{mode} {source}_k"][:, rungs_of(b[f"{source}_radii"], rr)]
    data = {
        "fields": _fields(k),
        "radii": rr,
        "local": a["local"],
        "indptr": a["indptr"],
        "indices": a["indices"],
        "r0": float(b["r0"]),
    }
    chosen = proto.select_stable(data, rule)
    return proto.picked(data, chosen), rr[chosen]


def proxy_b2(a, rr, chosen):
    """B2 read from variant A's rungs (icc at r_j with normals over 3 r_j; ``rr`` must be rungs of A's ladder)."""
    return proto.picked(a, rungs_of(a["radii"], rr)[chosen])


def score(errors, defaults):
    """The colleague's tuning score: mean of log(e / d) of the median H error (+0.1%) plus half that of the p95 (+0.3%)."""
    med = [np.log((e["H"][0] + 1e-3) / (d["H"][0] + 1e-3)) for e, d in zip(errors, defaults)]
    p95 = [np.log((e["H"][1] + 3e-3) / (d["H"][1] + 3e-3)) for e, d in zip(errors, defaults)]
    return float(np.mean(med) + 0.5 * np.mean(p95))


def grid(cache=CACHE, ladder_name="q2-32"):
    """Rule constants for variant B, scored on the tuning meshes (B1, and B2 through :func:`proxy_b2`)."""
    import itertools

    cases = cases_ab(cache)
    tuning = [(a, b) for a, b in cases.values() if a["tuning"]]
    held = [(a, b) for a, b in cases.values() if not a["tuning"]]
    defaults = {id(a): proto.errors(a, _fields(b["default"])) for a, b in cases.values()}
    lines = [
        "| normals | pool | take | rings | min_edges | floor r0 | B1 tuning score | B2 tuning score "
        "| B2 one rung lower, tuning | B1 held-out score | B2 held-out score | B2 one rung lower, held out |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    rows = []
    for mode, pool, take, rings, min_edges, floor in itertools.product(
        NORMAL_MODES, (0.0, 0.5, 0.75, 1.0), (0, 1), (0, 2), (0.75, 1.0), (0.0, 1.0)
    ):
        rule = dict(proto.RULE, pool=pool, take=take, rings=rings, min_edges=min_edges, floor_r0=floor)
        scores = []
        for group in (tuning, held):
            b1, b2, lower, d = [], [], [], []
            for a, b in group:
                if f"{mode} {ladder_name}_k" not in b:
                    continue
                rr = b[f"{ladder_name}_radii"]
                k = b[f"{mode} {ladder_name}_k"]
                data = {
                    "fields": _fields(k),
                    "radii": rr,
                    "local": a["local"],
                    "indptr": a["indptr"],
                    "indices": a["indices"],
                    "r0": float(b["r0"]),
                }
                chosen = proto.select_stable(data, rule)
                b1.append(proto.errors(a, proto.picked(data, chosen)))
                b2.append(proto.errors(a, proxy_b2(a, rr, chosen)))
                lower.append(proto.errors(a, proxy_b2(a, rr, np.maximum(chosen - 1, 0))))
                d.append(defaults[id(a)])
            scores += [score(b1, d), score(b2, d), score(lower, d)]
        rows.append(
            (
                scores[1],
                f"| {mode} | {pool:g} | {take} | {rings} | {min_edges:g} | {floor:g} | "
                + " | ".join(f"{x:.3f}" for x in scores)
                + " |",
            )
        )
        print(rows[-1][1], file=sys.stderr)
    reference = []
    for group in (tuning, held):
        errs = [proto.errors(a, proto.picked(a, proto.select(a, proto.RULE))) for a, _ in group]
        reference.append(score(errs, [defaults[id(a)] for a, _ in group]))
    lines.append(f"| variant A (its RULE, for reference) | | | | | | | {reference[0]:.3f} | | | {reference[1]:.3f} | |")
    return "\n".join(lines + [r for _, r in sorted(rows)])


def runs(a, b, rules=None):
    """Errors of today's default, the default at ce27127 (variant A's cache), variant A's rule, and B1 / B2 of
    every normal mode and ladder (and B1 under extra ``rules``: label -> (mode, ladder, rule))."""
    h = np.median(a["local"])
    chosen_a = proto.select(a, proto.RULE)
    out = {
        "default": (proto.errors(a, _fields(b["default"])), np.array([b["r0"] / h])),
        "default@ce27127": (proto.errors(a, a["default"]), a["default_radius"] / h),
        "A": (proto.errors(a, proto.picked(a, chosen_a)), a["radii"][chosen_a] / h),
    }
    for cap in (12.0, 8.0):  # variant A with its ladder capped lower: the rule among the rungs up to cap h
        m = int(np.sum(a["radii"] <= cap * float(b["h"]) * (1 + 1e-9)))
        capped = dict(a, fields=a["fields"][:, :m], radii=a["radii"][:m])
        chosen = proto.select(capped, proto.RULE)
        out[f"A <= {cap:g} h"] = (proto.errors(a, proto.picked(capped, chosen)), a["radii"][chosen] / h)
    for mode, configs in NORMAL_MODES.items():
        for c in configs:
            key = f"{mode} {c}"
            if f"{key}_b1" not in b:
                continue
            rr = b[f"{c}_radii"][b[f"{key}_chosen"]] / h
            out[f"B1 {key}"] = (proto.errors(a, _fields(b[f"{key}_b1"])), rr)
            if f"{key}_b2" in b:
                out[f"B2 {key}"] = (proto.errors(a, _fields(b[f"{key}_b2"])), rr)
    if "anchored" in b:
        fields, rr = anchored_fields(a, b)
        out[RECOMMENDED] = (proto.errors(a, fields), rr / h)
    for label, (mode, c, rule) in (rules or {}).items():
        fields, rr = reselect(a, b, mode, c, rule)
        out[label] = (proto.errors(a, fields), rr / h)
        if c.startswith("q2-"):  # B2 read from A's rungs (what the final pass computes, see proxy_b2)
            radii = b[f"{c}_radii"]
            chosen = rungs_of(radii, rr)
            out[label.replace("B1", "B2") + " (A's rungs)"] = (proto.errors(a, proxy_b2(a, radii, chosen)), rr / h)
    return out


#: Variant B's rule constants from the grid (``--grid``, tuning meshes only): no rung below r0, the change
#: pooled fully (one curve per mesh); the upper rung for B1, the lower for B2.
RULE_B1 = dict(proto.RULE, pool=1.0, take=1, rings=2, min_edges=0.75, floor_r0=1.0)
RULE_B2 = dict(proto.RULE, pool=1.0, take=0, rings=2, min_edges=0.75, floor_r0=1.0)
TUNED = {
    "B1 r0 q2-32 tuned": ("r0", "q2-32", RULE_B1),
    "B1 r0 q2-8 tuned": ("r0", "q2-8", RULE_B1),
    "B1 r0 q4-12 tuned": ("r0", "q4-12", RULE_B1),
    "B1 r0 q2-32 tuned for B2": ("r0", "q2-32", RULE_B2),
    "B1 r0 q2-8 tuned for B2": ("r0", "q2-8", RULE_B2),
    "B1 r0 q2-32 RULE": ("r0", "q2-32", proto.RULE),
    "B1 r0 q2-32 tuned, pool 0.75": ("r0", "q2-32", dict(RULE_B1, pool=0.75)),
    "B1 r0 q2-12 tuned, pool 0.75": ("r0", "q2-12", dict(RULE_B1, pool=0.75)),
    "B1 r0 q2-8 tuned, pool 0.75": ("r0", "q2-8", dict(RULE_B1, pool=0.75)),
    "B1 r0 q4-12 tuned, pool 0.75": ("r0", "q4-12", dict(RULE_B1, pool=0.75)),
}

#: The recommended setting (see benchmarks/scale.md, "Variant B"): B1 on the ladder r0 sqrt(2)^j up to 12 h
#: (:func:`anchored_ladder`), normals over 3 r0, the colleague's RULE unchanged.
RECOMMENDED = "B1 anchored q2-12"


def anchored_fields(a, b, rule=None):
    """(4, V) fields and (V,) radii of B1 on the anchored ladder (``b["anchored"]``) under ``rule`` (RULE)."""
    z = b["anchored"]
    data = {
        "fields": _fields(z["k"]),
        "radii": z["radii"],
        "local": a["local"],
        "indptr": a["indptr"],
        "indices": a["indices"],
        "r0": float(z["r0"]),
    }
    chosen = proto.select_stable(data, proto.RULE if rule is None else rule)
    return proto.picked(data, chosen), z["radii"][chosen]


def cases_ab(cache=CACHE):
    """name -> (variant A data, variant B data) for the meshes in both caches, families relabelled."""
    labels = proto._labels()
    out = {}
    for path in sorted(p for p in os.listdir(proto.CACHE) if p.endswith(".noise.npz")):
        a = proto.load(os.path.join(proto.CACHE, path.replace(".noise", "")))
        b = load_b(a["name"], cache)
        if b is None:
            continue
        a["family"], a["tuning"] = labels.get(a["name"], (a["family"], a["tuning"]))
        anchored = os.path.join(cache + "_anchored", proto._slug(a["name"]) + ".npz")
        if os.path.exists(anchored):
            with np.load(anchored) as z:
                b["anchored"] = {k: z[k] for k in z.files}
        out[a["name"]] = (a, b)
    return out


def all_keys(rules=None):
    keys = ["default", "default@ce27127", "A", "A <= 12 h", "A <= 8 h"]
    for mode, configs in NORMAL_MODES.items():
        keys += [f"{s} {mode} {c}" for c in configs for s in ("B1", "B2")]
    keys.append(RECOMMENDED)
    for label, (_, c, _) in (rules or {}).items():
        keys.append(label)
        if c.startswith("q2-"):
            keys.append(label.replace("B1", "B2") + " (A's rungs)")
    return keys


def report(cache=CACHE, rules=None, keys=None):
    """Summary (geometric means per family) and per-mesh tables of B against A and the default."""
    cases = cases_ab(cache)
    failing = [case.name for case in scale_families.failing_cases()]
    rules = TUNED if rules is None else rules
    keys = all_keys(rules) if keys is None else keys
    summary, tables = [], []
    for family, title in proto.FAMILY_TITLES.items():
        names = (
            [n for n in cases if n in failing]
            if family == "failing"
            else [n for n, (a, _) in cases.items() if a["family"] == family]
        )
        if not names:
            continue
        agg = {k: [] for k in keys}
        worse = {k: 0 for k in keys}
        rows = []
        for name in sorted(names, key=lambda n: (cases[n][0]["group"], n)):
            a, b = cases[name]
            out = runs(a, b, rules)
            d = out["default"][0]["H"][0]
            for k in keys:
                if k in out:
                    e = out[k][0]["H"][0]
                    agg[k].append(e)
                    worse[k] += e > 1.1 * d + 2e-4
            rows.append((name, a["local"].size, out))
        summary.append((title, len(names), agg, worse))
        tables.append((title, rows))
    lines = [
        "| run | "
        + " | ".join(f"{title.split(':')[0]}: {title.split(': ')[-1]} ({count})" for title, count, _, _ in summary)
        + " |",
        "|---|" + "---|" * len(summary),
    ]
    for k in keys:
        cells = [f"{proto._pct(proto._geo(agg[k]))} ({worse[k]})" if agg[k] else "-" for _, _, agg, worse in summary]
        lines.append(f"| {k} | " + " | ".join(cells) + " |")
    return "\n".join(lines), tables


def mesh_tables(tables, shown=("default", "A", "B1 r0 q2-32", "B2 r0 q2-32", "B2 low q2-32", RECOMMENDED)):
    lines = []
    for title, rows in tables:
        lines += [
            f"#### {title}",
            "",
            "| mesh | V | " + " | ".join(f"{k}: H (p95), r/h" for k in shown) + " | A k1 / k2 | recommended k1 / k2 |",
            "|---|---|" + "---|" * (len(shown) + 2),
        ]
        for name, n, out in rows:
            cells = [
                f"{proto._cell(out[k][0])}, {proto._radius(np.atleast_1d(out[k][1]))}" if k in out else "-"
                for k in shown
            ]
            kk = [
                " / ".join(proto._pct(out[k][0][q][0]) for q in ("k1", "k2")) if k in out else "-"
                for k in ("A", RECOMMENDED)
            ]
            lines.append(f"| {name} | {n} | " + " | ".join(cells + kk) + " |")
        lines.append("")
    return "\n".join(lines)


def target_report(cache=CACHE):
    """The accuracy_voxel.md metric on the voxel meshes, and the varying meshes' parts, for ``label``."""
    lines = [
        "| mesh | family | target H / K | default H / K | A H / K | recommended H / K |",
        "|---|---|---|---|---|---|",
    ]
    parts = [
        "| mesh | part | default H / >25% | A H / >25% | recommended H / >25% | recommended r/h |",
        "|---|---|---|---|---|---|",
    ]
    for a, b in cases_ab(cache).values():
        fields, rr = anchored_fields(a, b)
        chosen_a = proto.select(a, proto.RULE)
        runs_ = {"default": _fields(b["default"]), "A": proto.picked(a, chosen_a), "rec": fields}
        if a["name"].startswith("voxel_"):
            aspect = a["spacing"].max() / a["spacing"].min()
            cells = []
            for fields_ in runs_.values():
                e = proto.errors(a, fields_)
                cells.append(f"{proto._pct(e['Hrel'])} / {proto._pct(e['Krel'])}")
            lines.append(
                f"| {a['name']} | {a['family']} | {'3% / 6%' if aspect == 1 else '6% / 12%'} | "
                + " | ".join(cells)
                + " |"
            )
        for part, mask in a["parts"].items():
            cells = []
            for fields_ in runs_.values():
                e = proto.errors(a, fields_, mask)
                cells.append(f"{proto._pct(e['H'][0])} / {proto._pct(e['bad25'])}")
            parts.append(
                f"| {a['name']} | {part} | "
                + " | ".join(cells)
                + f" | {proto._radius(rr[mask] / np.median(a['local']))} |"
            )
    return "\n".join(lines[:2] + sorted(lines[2:])) + "\n\n" + "\n".join(parts)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--compute", action="store_true", help="variant B on every mesh (cached)")
    parser.add_argument("--families", nargs="*", default=None, help=f"subset of {list(scale_families.BUILDERS)}")
    parser.add_argument("--timing", action="store_true", help="the stage timings instead")
    parser.add_argument("--grid", action="store_true", help="the rule-constant grid for variant B instead")
    parser.add_argument("--anchored-timing", action="store_true", help="the recommended variant's stage timings")
    parser.add_argument(
        "--anchored", action="store_true", help="B1 on a ladder that starts at r0 (compute, cached, then its table)"
    )
    parser.add_argument("--cache", default=CACHE)
    args = parser.parse_args(argv)
    if args.compute:
        warm_up()
        for case in scale_families.cases(args.families):
            compute(case, args.cache)
        return
    if args.timing:
        print(timing_report(timing(rules={key: RULE_B1 for key in TIMED if key.startswith("r0")})))
        return
    if args.anchored_timing:
        print(anchored_timing())
        return
    if args.anchored:
        warm_up()
        for case in scale_families.cases(args.families):
            compute_anchored(case)
        print(anchored_report())
        print()
        print(anchored_cost())
        return
    if args.grid:
        print(grid(args.cache))
        return
    summary, tables = report(args.cache)
    print(summary)
    print()
    print(mesh_tables(tables))
    print(target_report(args.cache))


if __name__ == "__main__":
    main()
