"""Prototype of a per-vertex scale for icc (issue 30): a ladder of radii and a per-vertex selection rule.

Run from the repository root (needs scikit-image and scipy)::

    python benchmarks/scale_prototype.py --compute              # icc on every ladder rung, cached in --cache
    python benchmarks/scale_prototype.py                        # the tables of benchmarks/scale.md (from the cache)
    python benchmarks/scale_prototype.py --families smoothed varying --compute

For each mesh of ``benchmarks/scale_families.py``, icc runs at its default and
at a ladder of global radii ``r_j = h q^j`` (``h`` the median edge length,
``q = sqrt 2``; :func:`ladder`); picking, per vertex, the row of the run at
``r_j`` is what a per-vertex radius ``r_j`` would give, up to the normals (fitted
over ``3 r_j`` for every vertex of the ball in the global run). A per-vertex
noise estimate (:func:`vertex_noise`: the distance of each vertex to a degree-2
jet fitted around it, as :func:`meshcurv.radius.noise_level` measures it,
averaged over a 2-ring) sets the standard deviation of the estimates at each
rung (:func:`sigma_model`) and the selection rule (:func:`select`, an
intersection-of-confidence-intervals / Lepski rule) picks the rung.

Errors as in ``benchmarks/accuracy.py``: ``|estimate - exact| / s``, ``s`` the
largest exact principal curvature magnitude at the vertex (``s^2`` for K);
median and 95th percentile over the vertices (all valid in every run here).
For the voxel families the table also gives the metric of
``benchmarks/accuracy_voxel.md`` (``|H - H_exact| / |H_exact|``), against which
its targets are set.
"""

from __future__ import annotations

import argparse
import os
import re
import sys
import time
import warnings

import numpy as np
from scipy import sparse

HERE = os.path.dirname(os.path.abspath(__file__))
if HERE not in sys.path:
    sys.path.insert(0, HERE)

import meshcurv  # noqa: E402
import scale_families  # noqa: E402
from meshcurv._prepared import PreparedMesh  # noqa: E402
from meshcurv.geometry import median_edge_length, vertex_edge_lengths  # noqa: E402
from meshcurv.jets import fit_jets  # noqa: E402
from meshcurv.measures import curvatures_from_measures, face_measures  # noqa: E402

CACHE = "/tmp/meshcurv_scale_cache"

#: Ladder ratio and its extent: from LADDER_LOW times the 5th percentile of the local edge lengths to
#: LADDER_HIGH median edge lengths, and never a normal-fit ball (3 r) above half the surface's area.
LADDER_RATIO = float(np.sqrt(2.0))
LADDER_LOW = 0.7
LADDER_HIGH = 32.0

#: The noise fits: degree-2 jets over balls of this many local edge lengths (as radius_rules.NOISE_FIT_RADIUS).
NOISE_FIT_EDGES = 2.0


# -- computing ---------------------------------------------------------------------------


def ladder(vertices, faces, topology, *, ratio=LADDER_RATIO, high=LADDER_HIGH):
    """The radii ``h_5 LADDER_LOW q^j`` up to ``min(high h, sqrt(area / (18 pi)))`` (``q``: ``ratio``)."""
    local = vertex_edge_lengths(vertices, topology.edges)
    h = median_edge_length(vertices, topology.edges)
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
    top = min(high * h, np.sqrt(area / (18 * np.pi)))
    low = LADDER_LOW * np.percentile(local[np.isfinite(local)], 5)
    # the small slack keeps the rungs of a finer ratio that coincide with a coarser one's (2^(2/4) = 2^(1/2))
    count = int(np.floor(np.log(top / low) / np.log(ratio) + 1e-9)) + 1
    return low * ratio ** np.arange(count)


def ring_matrix(indptr, indices):
    """The (V, V) sparse matrix of the 1-ring of every vertex, itself included."""
    n = indptr.size - 1
    return (sparse.csr_matrix((np.ones(indices.size), indices, indptr), shape=(n, n)) + sparse.identity(n)).tocsr()


def ring_mean(ring, values, rings=2):
    """Mean of the finite ``values`` over the ``rings``-ring of every vertex (``ring``: :func:`ring_matrix`)."""
    finite = np.isfinite(values)
    total, count = np.where(finite, values, 0.0), finite.astype(float)
    for _ in range(rings):
        total, count = ring @ total, ring @ count
    with np.errstate(invalid="ignore", divide="ignore"):
        return total / count


def annotate(case, cache=CACHE):
    """The cheap per-vertex data of ``case`` (noise estimates, 1-ring lists) into ``cache/<name>.noise.npz``."""
    path = os.path.join(cache, _slug(case.name) + ".noise.npz")
    if os.path.exists(path):
        return path
    v, f = case.vertices, case.faces
    topology = meshcurv.MeshTopology.from_faces(f, v.shape[0])
    local = vertex_edge_lengths(v, topology.edges)
    indptr, indices = topology.neighbour_lists
    ring = ring_matrix(indptr, indices)
    noise = {}
    for edges in (2.0, 3.0, 4.0):
        d = vertex_noise(v, topology, local, fit_edges=edges)
        noise[f"noise{edges:g}"] = d
        noise[f"noise{edges:g}_ring"] = ring_mean(ring, d**2) ** 0.5
    os.makedirs(cache, exist_ok=True)
    np.savez_compressed(path, indptr=np.asarray(indptr), indices=np.asarray(indices), **noise)
    return path


def vertex_noise(vertices, topology, local, *, fit_edges=NOISE_FIT_EDGES):
    """(V,) distance of each vertex to a degree-2 jet fitted over ``fit_edges`` local edge lengths.

    The vertices are grouped by powers of two of their local edge length, as in
    :func:`meshcurv.radius.noise_level`; the distance is absolute (length units).
    """
    prepared = PreparedMesh.as_given(vertices, topology)
    normals, (_, valid) = prepared.vertex_normals, prepared.start(boundary=True)
    centres = np.flatnonzero(valid & (local > 0))
    scale = local[centres]
    level = np.round(np.log2(scale / np.median(scale))).astype(np.int64)
    out = np.full(vertices.shape[0], np.nan)
    for k in np.unique(level):
        members = centres[level == k]
        radius = fit_edges * local[members].mean()
        coefficients, _, _ = fit_jets(
            vertices,
            normals,
            radius,
            degree=2,
            centres=members,
            compact=True,
            neighbours=topology.referenced_vertices,
            adjacency=topology.neighbour_lists,
        )
        out[members] = np.abs(coefficients[:, 0]) * radius
    return out


def _slug(name):
    return re.sub(r"[^A-Za-z0-9]+", "_", name).strip("_")


def compute(case, cache=CACHE):
    """icc at the default and on every ladder rung, and the noise estimates, into ``cache/<name>.npz``."""
    path = os.path.join(cache, _slug(case.name) + ".npz")
    if os.path.exists(path):
        return path
    v, f = case.vertices, case.faces
    topology = meshcurv.MeshTopology.from_faces(f, v.shape[0])
    local = vertex_edge_lengths(v, topology.edges)
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        default = meshcurv.principal_curvatures(v, topology)
    t_default = time.perf_counter() - t0
    radii = ladder(v, f, topology)
    fields = np.full((4, radii.size, v.shape[0]), np.nan)
    seconds = np.zeros(radii.size)
    for j, r in enumerate(radii):
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            res = meshcurv.principal_curvatures(v, topology, radius=float(r))
        seconds[j] = time.perf_counter() - t0
        fields[:, j] = res.k_min, res.k_max, res.mean, res.gaussian
    default_radius = default.parameters.get("radius")
    os.makedirs(cache, exist_ok=True)
    np.savez_compressed(
        path,
        name=case.name,
        family=case.family,
        group=case.group,
        tuning=case.tuning,
        k_min=case.k_min,
        k_max=case.k_max,
        radii=radii,
        fields=fields,
        seconds=seconds,
        default=np.stack([default.k_min, default.k_max, default.mean, default.gaussian]),
        default_radius=np.atleast_1d(np.asarray(default_radius, dtype=float)),
        t_default=t_default,
        local=local,
        spacing=np.asarray(case.spacing if case.spacing is not None else (np.nan,) * 3, dtype=float),
        **{f"part_{k}": m for k, m in case.parts.items()},
    )
    print(
        f"{case.name}: {v.shape[0]} vertices, {radii.size} rungs {radii[0]:.3g}..{radii[-1]:.3g}, "
        f"{seconds.sum() + t_default:.1f} s",
        file=sys.stderr,
    )
    return path


def load(path):
    out = {}
    for name in (path, path[:-4] + ".noise.npz"):
        with np.load(name, allow_pickle=False) as data:
            out.update({k: data[k] for k in data.files if not k.startswith("noise") or name != path})
    for key in ("name", "family", "group"):
        out[key] = str(out[key])
    out["tuning"] = bool(out["tuning"])
    out["parts"] = {k[5:]: out.pop(k) for k in list(out) if k.startswith("part_")}
    return out


# -- selecting -----------------------------------------------------------------------------

#: The recommended rule (tuned on the tuning families only; see benchmarks/scale.md): the rung where H, k1
#: and k2 change least along the ladder, the change averaged over the 2-ring and pooled half with the
#: mesh median; the upper rung of that pair, or the first rung when the change is smallest there.
RULE = {
    "kind": "stable",
    "quantities": ("H", "k1", "k2"),
    "rings": 2,
    "pool": 0.5,
    "take": 1,
    "first_low": True,
    "min_edges": 0.75,
    "cap": 0.0,
}

#: The Lepski / ICI rule with the jet-residual noise model, at its best tuning-family constants (it fails).
ICI_RULE = {
    "kind": "ici",
    "noise": "noise2_ring",
    "c": 4.0,
    "beta": 1.0,
    "floor": 0.0,
    "quantities": ("H",),
    "cap": 0.0,
    "min_edges": 0.75,
}


def sigma_model(data, rule):
    """(J, V) standard deviation of H at each rung: ``(s_v + floor h_v) / r^2 (h_v / r)^beta``."""
    h = data["local"]
    s = np.nan_to_num(data[rule["noise"]]) + rule["floor"] * h
    r = data["radii"][:, None]
    return s[None, :] / r**2 * (h[None, :] / r) ** rule["beta"]


def select(data, rule):
    """(V,) rung index per vertex by ``rule["kind"]``: ``ici`` (:func:`select_ici`) or ``stable`` (:func:`select_stable`)."""
    return (select_stable if rule.get("kind") == "stable" else select_ici)(data, rule)


def _quantities(data, rule):
    k_min, k_max, mean, _ = data["fields"]
    values = {"H": mean, "k1": k_min, "k2": k_max}
    return [values[q] for q in rule["quantities"]]


def select_stable(data, rule):
    """(V,) the rung where the estimates change least along the ladder.

    ``D_j = sum_q |q_{j+1} - q_j|`` over the compared quantities, averaged over
    the ``rings``-ring of each vertex (``rule["rings"]``, 0: none) and over the
    whole mesh (or, with ``rule["pool_by"] = "class"``, over the vertices whose local edge
    length is in the same power of two) with weight ``rule["pool"]`` (0: per vertex only); among the rungs
    of at least ``min_edges`` local edge lengths, the lower end ``j`` of the pair
    with the smallest ``D_j`` (``rule["take"]`` = 1: the upper end ``j + 1``).
    """
    radii, h = data["radii"], data["local"]
    change = sum(np.abs(np.diff(q, axis=0)) for q in _quantities(data, rule))
    change = np.where(np.isfinite(change), change, np.inf)
    rings = rule.get("rings", 2)
    if rings:
        ring = ring_matrix(data["indptr"], data["indices"])
        change = np.stack([ring_mean(ring, row, rings) for row in change])
    pool = rule.get("pool", 0.0)
    if pool and rule.get("pool_by") == "class":  # the median over the vertices of the same resolution class
        classes = np.round(np.log2(h / np.median(h))).astype(np.int64)
        pooled = np.empty_like(change)
        for k in np.unique(classes):
            members = classes == k
            pooled[:, members] = np.nanmedian(change[:, members], axis=1, keepdims=True)
        change = (1 - pool) * change + pool * pooled
    elif pool:
        change = (1 - pool) * change + pool * np.nanmedian(change, axis=1, keepdims=True)
    usable = radii[:-1, None] >= rule["min_edges"] * h[None, :]
    if rule.get("floor_r0", 0) > 0:  # variant B: no rung below this many default radii (data["r0"])
        usable &= radii[:-1, None] >= rule["floor_r0"] * data["r0"] * (1 - 1e-9)
        usable[-1] |= ~usable.any(axis=0)
    if rule["cap"] > 0:
        k = np.maximum(np.abs(data["fields"][0]), np.abs(data["fields"][1]))[:-1]
        usable &= ~(radii[:-1, None] * k > rule["cap"]) | (np.cumsum(usable, axis=0) == 1)
    change = np.where(usable, change, np.inf)
    best = np.argmin(change, axis=0)
    take = np.full(best.size, rule.get("take", 0))
    if rule.get("first_low", False):  # the estimates agree best from the start: a clean surface, the smallest ball
        take[best == np.argmax(usable, axis=0)] = 0
    return np.minimum(best + take, radii.size - 1)


def select_ici(data, rule):
    """(V,) rung index per vertex: intersection of confidence intervals (Goldenshluger-Nemirovski / Lepski).

    Rungs below ``min_edges`` local edge lengths are skipped; from the first rung
    on, the intervals ``[q_j - c sigma_j, q_j + c sigma_j]`` (``q`` each of the
    compared quantities, sigma scaled by ``max(1, |k|)``-free units: k1, k2 use the
    sigma of H) are intersected rung by rung, and the last rung whose running
    intersection is not empty is kept. With ``cap`` > 0, rungs with
    ``r |k|_max > cap`` (the rung's own estimate) end the ladder too.
    """
    k_min, k_max, mean, _ = data["fields"]
    radii = data["radii"]
    h = data["local"]
    sigma = rule["c"] * sigma_model(data, rule)
    usable = radii[:, None] >= rule["min_edges"] * h[None, :]
    first = np.argmax(usable, axis=0)
    n = h.size
    alive = np.ones(n, dtype=bool)
    chosen = first.copy()
    lows = {q: np.full(n, -np.inf) for q in rule["quantities"]}
    highs = {q: np.full(n, np.inf) for q in rule["quantities"]}
    values = {"H": mean, "k1": k_min, "k2": k_max}
    for j in range(radii.size):
        active = usable[j] & alive
        ok = active.copy()
        for q in rule["quantities"]:
            x = values[q][j]
            lows[q] = np.where(active, np.maximum(lows[q], x - sigma[j]), lows[q])
            highs[q] = np.where(active, np.minimum(highs[q], x + sigma[j]), highs[q])
            ok &= (lows[q] <= highs[q]) & np.isfinite(x)
        if rule["cap"] > 0:
            ok &= radii[j] * np.maximum(np.abs(k_min[j]), np.abs(k_max[j])) <= rule["cap"]
        chosen = np.where(ok, j, chosen)
        alive &= ~active | ok
    return chosen


def picked(data, index):
    """(4, V) k_min, k_max, H, K of the rung ``index`` (V,) at each vertex."""
    return np.take_along_axis(data["fields"], index[None, None, :].repeat(4, axis=0), axis=1)[:, 0]


def errors(data, fields, mask=None):
    """Median and 95th percentile of |error| / max|k| of k_min, k_max, H (and K / max|k|^2); voxel metric of H."""
    k_min, k_max = data["k_min"], data["k_max"]
    scale = np.maximum(np.abs(k_min), np.abs(k_max))
    exact = {"k1": k_min, "k2": k_max, "H": (k_min + k_max) / 2, "K": k_min * k_max}
    out = {}
    keep = np.ones(scale.size, dtype=bool) if mask is None else mask
    for i, key in enumerate(("k1", "k2", "H", "K")):
        e = np.abs(fields[i] - exact[key]) / (scale**2 if key == "K" else scale)
        e = e[keep & np.isfinite(e)]
        out[key] = (np.median(e), np.percentile(e, 95)) if e.size else (np.nan, np.nan)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.abs(fields[2] - exact["H"]) / np.abs(exact["H"])
        relk = np.abs(fields[3] - exact["K"]) / np.abs(exact["K"])
    rel, relk = rel[keep & np.isfinite(rel)], relk[keep & np.isfinite(relk)]
    out["Hrel"] = np.median(rel) if rel.size else np.nan
    out["Krel"] = np.median(relk) if relk.size else np.nan
    out["bad25"] = np.mean(np.abs(fields[2] - exact["H"])[keep] > 0.25 * scale[keep])
    return out


def oracle(data, mask=None):
    """The rung with the lowest median H error over the mesh (or ``mask``): the best single global radius."""
    scores = [errors(data, data["fields"][:, j], mask)["H"][0] for j in range(data["radii"].size)]
    return int(np.nanargmin(scores))


# -- reporting -----------------------------------------------------------------------------


def _labels():
    """name -> (family, tuning) from the builders (a mesh in two families keeps the first, tuning, one)."""
    out = {}
    for case in scale_families.cases(["voxel", "failing"]):
        out.setdefault(case.name, (case.family, case.tuning))
    return out


def _pct(x):
    return "-" if not np.isfinite(x) else f"{100 * x:.2g}%" if x < 0.1 else f"{100 * x:.0f}%"


def _cell(e, key="H"):
    return f"{_pct(e[key][0])} ({_pct(e[key][1])})"


def _geo(values):
    values = np.asarray(values, dtype=float)
    return float(np.exp(np.mean(np.log(np.maximum(values, 1e-6)))))


def runs(data):
    """``(name, errors, radius / h)`` of the default, the global oracle, the rule and the ICI rule."""
    h = np.median(data["local"])
    j = oracle(data)
    rule, ici = select(data, RULE), select(data, ICI_RULE)
    return {
        "default": (errors(data, data["default"]), data["default_radius"] / h),
        "oracle": (errors(data, data["fields"][:, j]), np.array([data["radii"][j] / h])),
        "rule": (errors(data, picked(data, rule)), data["radii"][rule] / h),
        "ici": (errors(data, picked(data, ici)), data["radii"][ici] / h),
    }


def _radius(r):
    return (
        f"{r[0]:.1f}" if r.size == 1 else f"{np.median(r):.1f} [{np.percentile(r, 10):.1f}-{np.percentile(r, 90):.1f}]"
    )


FAMILY_TITLES = {
    "accuracy": "Tuning: clean, irregular and noisy meshes of accuracy.py",
    "voxel": "Tuning: binary marching cubes of accuracy.py --voxel",
    "smoothed": "Held out: smoothed isosurfaces (blurred masks, voxel 1)",
    "varying": "Held out: 10:1 change of resolution (one component)",
    "elongated": "Held out: elongated ellipsoids and thin tori, anisotropic voxels",
    "failing": "Held out (3 of 5) : the 5 failing rows of accuracy_voxel.md",
}


def report(cache=CACHE):
    """The markdown tables of benchmarks/scale.md, from the cache."""
    labels = _labels()
    cases = {}
    for path in sorted(p for p in os.listdir(cache) if p.endswith(".noise.npz")):
        data = load(os.path.join(cache, path.replace(".noise", "")))
        family, tuning = labels.get(data["name"], (data["family"], data["tuning"]))
        data["family"], data["tuning"] = family, tuning
        cases[data["name"]] = data
    failing_names = [case.name for case in scale_families.failing_cases()]
    lines = []
    summary = []
    for family, title in FAMILY_TITLES.items():
        names = (
            [n for n in cases if n in failing_names]
            if family == "failing"
            else [n for n, d in cases.items() if d["family"] == family]
        )
        if not names:
            continue
        lines += [
            f"### {title}",
            "",
            "| mesh | V | default r/h | default H (p95) | oracle r/h | oracle H (p95) | rule r/h median [10-90%] "
            "| rule H (p95) | rule k1 / k2 / K | default k1 / k2 / K | ICI H (p95) |",
            "|---|---|---|---|---|---|---|---|---|---|---|",
        ]
        agg = {k: [] for k in ("default", "oracle", "rule", "ici")}
        worse = 0
        for name in sorted(names, key=lambda n: (cases[n]["group"], n)):
            d = cases[name]
            out = runs(d)
            for k in agg:
                agg[k].append(out[k][0]["H"][0])
            de, re_ = out["default"][0], out["rule"][0]
            worse += re_["H"][0] > 1.1 * de["H"][0] + 2e-4
            kk = " / ".join(_pct(re_[q][0]) for q in ("k1", "k2", "K"))
            dk = " / ".join(_pct(de[q][0]) for q in ("k1", "k2", "K"))
            lines.append(
                f"| {name} | {d['local'].size} | {_radius(out['default'][1])} | {_cell(de)} | "
                f"{_radius(out['oracle'][1])} | {_cell(out['oracle'][0])} | {_radius(out['rule'][1])} | "
                f"{_cell(re_)} | {kk} | {dk} | {_cell(out['ici'][0])} |"
            )
        lines.append("")
        summary.append(f"| {title} | {len(names)} | " + " | ".join(_pct(_geo(agg[k])) for k in agg) + f" | {worse} |")
    head = [
        "| family | meshes | default | oracle (one radius) | rule | ICI rule | rule worse than default by >10% |",
        "|---|---|---|---|---|---|---|",
    ]
    return "\n".join(
        ["Geometric mean over the meshes of the median |H error| / max|k|:", ""] + head + summary + [""] + lines
    )


def voxel_report(cache=CACHE):
    """The accuracy_voxel.md metric (median |H - H_exact| / |H_exact|, same for K) on the voxel meshes."""
    lines = [
        "| mesh | family | target H / K | default H / K | rule H / K | oracle H / K |",
        "|---|---|---|---|---|---|",
    ]
    for path in sorted(p for p in os.listdir(cache) if p.endswith(".noise.npz")):
        d = load(os.path.join(cache, path.replace(".noise", "")))
        if not d["name"].startswith("voxel_"):
            continue
        spacing = d["spacing"]
        aspect = spacing.max() / spacing.min()
        target = "3% / 6%" if aspect == 1 else "6% / 12%"
        out = runs(d)
        cells = [f"{_pct(out[k][0]['Hrel'])} / {_pct(out[k][0]['Krel'])}" for k in ("default", "rule", "oracle")]
        lines.append(f"| {d['name']} | {d['family']} | {target} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def varying_report(cache=CACHE):
    """Fine and coarse parts of the varying-resolution meshes: median H error and share off by > 25%."""
    lines = [
        "| mesh | part | V | default H / >25% | oracle H / >25% | rule H / >25% | rule r/h (of the median edge) |",
        "|---|---|---|---|---|---|---|",
    ]
    for path in sorted(p for p in os.listdir(cache) if p.endswith(".noise.npz")):
        d = load(os.path.join(cache, path.replace(".noise", "")))
        if d["family"] != "varying":
            continue
        h = np.median(d["local"])
        rule = select(d, RULE)
        for part, mask in d["parts"].items():
            j = oracle(d, mask)
            cells = []
            for fields in (d["default"], d["fields"][:, j], picked(d, rule)):
                e = errors(d, fields, mask)
                cells.append(f"{_pct(e['H'][0])} / {_pct(e['bad25'])}")
            lines.append(
                f"| {d['name']} | {part} | {int(mask.sum())} | "
                + " | ".join(cells)
                + f" | {_radius(d['radii'][rule[mask]] / h)} |"
            )
    return "\n".join(lines)


def shrinkage_report(cache=CACHE):
    """Smoothed spheres: how far the level set shrank, and the H error that alone explains."""
    lines = [
        "| mesh | mean vertex radius / R | H error from the shrinkage alone | rule H error | oracle H error |",
        "|---|---|---|---|---|",
    ]
    for case in scale_families.smoothed_cases():
        if "sphere" not in case.name:
            continue
        radius = 1 / case.k_max[0]
        measured = np.linalg.norm(case.vertices, axis=1).mean()
        d = load(os.path.join(cache, _slug(case.name) + ".npz"))
        out = runs(d)
        lines.append(
            f"| {case.name} | {measured / radius:.4f} | {_pct(abs(radius / measured - 1))} | "
            f"{_pct(out['rule'][0]['H'][0])} | {_pct(out['oracle'][0]['H'][0])} |"
        )
    return "\n".join(lines)


#: (mesh name, measure radius in median edge lengths) of the normal-radius study: each near its oracle radius.
NORMAL_STUDY = [
    ("smoothed sphere(20), sigma 1", 8.0),
    ("smoothed torus(25, 10), sigma 1", 5.6),
    ("icosphere(32) + noise 0.3h [level 2]", 9.7),
    ("ellipsoid(3.0, 2.0, 1.0) + noise 0.1h [level 2]", 3.0),
    ("voxel_torus(R=12, r=4, voxel 0.5x0.5x0.5)", 4.5),
    ("torus(R=3, r=1) [level 1]", 1.0),
]


def normal_study(ratios=(1.0, 1.5, 2.0, 3.0)):
    """Median H error and time of icc at one radius with the normals fitted over ``ratio`` times it."""
    from meshcurv.estimators import icc

    wanted = dict(NORMAL_STUDY)
    lines = [
        "| mesh | r / h | " + " | ".join(f"normals over {q:g} r: H (p95), s" for q in ratios) + " |",
        "|---|---|" + "---|" * len(ratios),
    ]
    for case in scale_families.cases(["accuracy", "smoothed", "voxel"]):
        if case.name not in wanted:
            continue
        v, f = case.vertices, case.faces
        topology = meshcurv.MeshTopology.from_faces(f, v.shape[0])
        radius = wanted.pop(case.name) * median_edge_length(v, topology.edges)
        prepared = PreparedMesh.as_given(v, topology)
        normals = prepared.vertex_normals
        _, valid = prepared.start(boundary=True)
        adjacency = topology.neighbour_lists
        cells = []
        for ratio in ratios:
            t0 = time.perf_counter()
            fitted = icc.fitted_normals(
                v, normals, valid, ratio * radius, neighbours=topology.referenced_vertices, adjacency=adjacency
            )
            per_face = face_measures(v, f, fitted)
            summed = meshcurv.neighborhoods.ball_face_sums(v, f, radius, per_face, connected=True)
            k_min, k_max, _, _ = curvatures_from_measures(summed, fitted)
            seconds = time.perf_counter() - t0
            e = errors(
                {"k_min": case.k_min, "k_max": case.k_max}, np.stack([k_min, k_max, (k_min + k_max) / 2, k_min * k_max])
            )
            cells.append(f"{_cell(e)}, {seconds:.2f}")
        lines.append(
            f"| {case.name} | {radius / median_edge_length(v, topology.edges):.1f} | " + " | ".join(cells) + " |"
        )
        if not wanted:
            break
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--compute", action="store_true", help="run icc on the ladders (cached)")
    parser.add_argument("--families", nargs="*", default=None, help=f"subset of {list(scale_families.BUILDERS)}")
    parser.add_argument("--cache", default=CACHE)
    parser.add_argument("--normals", action="store_true", help="the normal-fit radius study instead")
    args = parser.parse_args(argv)
    if args.compute:
        for case in scale_families.cases(args.families):
            compute(case, args.cache)
            annotate(case, args.cache)
        return
    if args.normals:
        print(normal_study())
        return
    print(report(args.cache))
    print("\n### Voxel meshes, the metric of accuracy_voxel.md\n")
    print(voxel_report(args.cache))
    print("\n### Varying resolution: fine and coarse parts\n")
    print(varying_report(args.cache))
    print("\n### Smoothed spheres: shrinkage of the level set\n")
    print(shrinkage_report(args.cache))


if __name__ == "__main__":
    main()
