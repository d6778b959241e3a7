"""The two backends as one estimator (issue 29, item 10), measured case by case on thin, open, noisy, voxel,
cracked and real meshes, for every mesh method and both point-cloud methods.

Each backend runs in its own child process (``MESHCURV_BACKEND=numpy`` against the default, numba), writes its
results to one ``.npz`` per case, and the parent compares them: are the valid masks (and reasons) equal, and
how far apart are ``k_min``, ``k_max``, ``H``, ``K`` and the normals, relative to the largest ``|k|`` over the
vertices valid on the compiled side (``K`` relative to its square)? Issue 29 asks for 1e-6.

Cases: each mesh at the default radius and at given radii (1.5, 3 and 6 mean edge lengths for the methods that
take one), float64 and float32 vertices (float32 at the default radius only: the library computes in float64,
so the two inputs differ only in the rounding of the vertices), and each mesh's vertices as a point cloud.
The families are split in two halves: ``tuned`` (the ones measured while the code was changed) and ``held``
(other sizes, seeds, poses and spacings, measured only at the end).

Run from the repository's root (the real meshes are read from ``../shared/meshes``)::

    python benchmarks/backend_parity_P71.py [--part tuned|held|all] [--only SUBSTRING] [--out DIR]

Prints one row per case (valid masks that differ, the largest relative difference and the field where it is)
and the worst cases.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
import traceback
import warnings
from pathlib import Path

import numpy as np

REAL_FOLDER = Path("../shared/meshes")
GIVEN_RADII = (1.5, 3.0, 6.0)
RTOL = 1e-6

#: Meshes whose given radii are multiples of their grid's spacing (not of the mean edge length): the radius then
#: equals the distance of whole rows of vertices, up to round-off (a comparison with the radius at a tie).
UNITS = {
    "grid_tenths": 0.1,
    "grid_tenths_bent": 0.1,
    "grid_fifths_offset": 0.2,
    "ties_grid_tenths": 0.1,
    "ties_voxel_sphere": 1.0,
    "ties_voxel_torus_halves": 0.5,
}

#: The radii of the part ``ties`` (in :data:`UNITS`): distances between the vertices of a square grid, and of a voxel
#: surface's half-voxel lattice (1, sqrt 2, 1.5, 2, sqrt 5 and 3 units apart).
TIE_RADII = (1.0, float(np.sqrt(2.0)), 1.5, 2.0, float(np.sqrt(5.0)), 3.0)


def _cut(vertices, faces, keep_face):
    """The faces where ``keep_face`` holds, and only the vertices they use (re-indexed)."""
    faces = faces[keep_face]
    used = np.unique(faces)
    index = np.full(vertices.shape[0], -1)
    index[used] = np.arange(used.size)
    return vertices[used], index[faces]


def _grid_patch(n, function, jitter=0.0, seed=0, scale=1.0, offset=(0.0, 0.0, 0.0)):
    """A ``(n + 1) x (n + 1)`` grid over ``[-scale, scale]^2`` lifted to ``z = function(x, y)`` and moved by
    ``offset``: an open patch."""
    side = np.linspace(-scale, scale, n + 1)
    x, y = np.meshgrid(side, side, indexing="ij")
    if jitter:
        rng = np.random.default_rng(seed)
        x = x + jitter * (side[1] - side[0]) * rng.uniform(-1, 1, x.shape) * (np.abs(x) < scale)
        y = y + jitter * (side[1] - side[0]) * rng.uniform(-1, 1, y.shape) * (np.abs(y) < scale)
    vertices = np.column_stack([x.ravel(), y.ravel(), function(x, y).ravel()]) + np.asarray(offset)
    corner = (np.arange(n)[:, None] * (n + 1) + np.arange(n)[None, :]).ravel()
    faces = np.vstack(
        [
            np.column_stack([corner, corner + n + 1, corner + n + 2]),
            np.column_stack([corner, corner + n + 2, corner + 1]),
        ]
    )
    return vertices, faces


def _sphere_patch(mesh, height):
    """The faces of a sphere above ``z = height``: a cap with a boundary."""
    centroids = mesh.vertices[mesh.faces].mean(axis=1)
    return _cut(mesh.vertices, mesh.faces, centroids[:, 2] > height)


def _cracked(vertices, faces, axis=0):
    """The faces beyond the plane ``axis = 0`` given their own copies of their vertices: a crack (a seam of
    coincident vertices) across the mesh."""
    side = vertices[faces][:, :, axis].mean(axis=1) > 0
    copied = np.unique(faces[side])
    index = np.arange(vertices.shape[0])
    index[copied] = vertices.shape[0] + np.arange(copied.size)
    faces = faces.copy()
    faces[side] = index[faces[side]]
    return np.vstack([vertices, vertices[copied]]), faces


def _cut_above(vertices, faces, fraction=0.7, axis=2):
    """The faces whose centroids lie below ``fraction`` of the mesh's extent along ``axis``: an open mesh."""
    low, high = vertices[:, axis].min(), vertices[:, axis].max()
    return _cut(vertices, faces, vertices[faces][:, :, axis].mean(axis=1) < low + fraction * (high - low))


def _mixed_winding(vertices, faces, seed):
    """Half of the faces (drawn at random) wound the other way."""
    flip = np.random.default_rng(seed).random(faces.shape[0]) < 0.5
    faces = faces.copy()
    faces[flip] = faces[flip][:, ::-1]
    return vertices, faces


def _soup(vertices, faces):
    """Every face with its own three vertices."""
    return vertices[faces].reshape(-1, 3), np.arange(3 * faces.shape[0]).reshape(-1, 3)


def _rotation(seed):
    q = np.random.default_rng(seed).normal(size=(3, 3))
    q, r = np.linalg.qr(q)
    return q * np.sign(np.diag(r))


def meshes(part: str) -> dict:
    """name -> ``(vertices, faces)`` of one half of the families."""
    from meshcurv import read_mesh, shapes

    def pair(mesh):
        return mesh.vertices, mesh.faces

    out = {}
    if part == "ties":
        out["ties_grid_tenths"] = _grid_patch(20, lambda x, y: 0.0 * x)
        out["ties_voxel_sphere"] = pair(shapes.voxel_sphere(5.0, seed=13))
        out["ties_voxel_torus_halves"] = pair(shapes.voxel_torus(3.0, 1.2, spacing=(0.5, 0.5, 0.5), seed=29))
    if part in ("tuned", "all"):
        out["thin_ellipsoid"] = pair(shapes.ellipsoid((3.0, 3.0, 0.15), subdivisions=12))
        out["thin_torus"] = pair(shapes.torus(2.0, 0.08, n_major=80, n_minor=10))
        out["hemisphere"] = pair(shapes.hemisphere(10))
        out["saddle"] = pair(shapes.saddle(1.0, 0.1))
        out["uv_patch"] = _grid_patch(16, lambda x, y: 0.4 * x**2 + 0.1 * y**2)
        out["grid_tenths"] = _grid_patch(20, lambda x, y: 0.0 * x)
        out["grid_tenths_bent"] = _grid_patch(20, lambda x, y: 0.05 * x**2)
        out["noisy_sphere_0.2"] = pair(shapes.with_normal_noise(shapes.icosphere(8), 0.2, seed=11))
        out["noisy_thin_ellipsoid_0.1"] = pair(
            shapes.with_normal_noise(shapes.ellipsoid((3.0, 3.0, 0.15), subdivisions=12), 0.1, seed=12)
        )
        out["voxel_sphere_iso"] = pair(shapes.voxel_sphere(5.0, seed=13))
        out["voxel_ellipsoid_aniso"] = pair(shapes.voxel_ellipsoid((7.0, 5.0, 3.0), spacing=(1.0, 0.8, 1.4), seed=14))
        out["cracked_sphere"] = _cracked(*pair(shapes.icosphere(8)))
        out["mixed_winding_sphere"] = _mixed_winding(*pair(shapes.icosphere(7)), seed=15)
        out["soup_hemisphere"] = _soup(*pair(shapes.hemisphere(6)))
        out["real_fandisk"] = _real("fandisk.obj", read_mesh)
    if part in ("held", "all"):
        turn = _rotation(21)
        flat = shapes.ellipsoid((3.0, 3.0, 0.15), subdivisions=15)
        out["thin_ellipsoid_turned"] = (flat.vertices @ turn.T + [0.3, -1.2, 2.0], flat.faces)
        out["thin_torus_jitter"] = pair(shapes.torus(2.0, 0.08, n_major=70, n_minor=9, jitter=0.2, seed=22))
        out["hemisphere_irregular"] = pair(shapes.hemisphere(9, irregular=True, seed=23))
        out["sphere_cap"] = _sphere_patch(shapes.icosphere(9), 0.3)
        out["saddle_jitter"] = pair(shapes.saddle(1.0, 0.08, jitter=0.3, seed=24))
        out["uv_patch_jitter"] = _grid_patch(14, lambda x, y: 0.3 * x * y - 0.2 * y**2, jitter=0.3, seed=25)
        out["grid_fifths_offset"] = _grid_patch(15, lambda x, y: 0.0 * x, scale=1.5, offset=(0.7, -2.1, 0.3))
        out["noisy_torus_0.3"] = pair(shapes.with_normal_noise(shapes.torus(2.0, 0.6, 40, 16), 0.3, seed=26))
        out["noisy_hemisphere_0.2"] = pair(
            shapes.with_normal_noise(shapes.hemisphere(10, irregular=True, seed=27), 0.2, seed=28)
        )
        out["voxel_torus_aniso"] = pair(shapes.voxel_torus(6.0, 2.5, spacing=(0.9, 1.0, 1.3), seed=29))
        out["voxel_thin_ellipsoid"] = pair(shapes.voxel_ellipsoid((8.0, 8.0, 1.6), seed=30))
        out["voxel_sphere_aniso_open"] = _cut_above(*pair(shapes.voxel_sphere(5.5, spacing=(0.8, 1.0, 1.2), seed=31)))
        out["cracked_torus"] = _cracked(*pair(shapes.torus(2.0, 0.7, 36, 14)), axis=1)
        out["real_spot"] = _real("spot.obj", read_mesh)
    return out


def _real(name, read_mesh):
    mesh = read_mesh(REAL_FOLDER / name)
    return np.asarray(mesh[0] if isinstance(mesh, tuple) else mesh.vertices), np.asarray(
        mesh[1] if isinstance(mesh, tuple) else mesh.faces
    )


#: Options other than the radius, on some tuned meshes: (mesh, method, keyword arguments).
OPTIONS = {
    "tuned": [
        ("hemisphere", "icc", {"radius": "adaptive"}),
        ("voxel_sphere_iso", "icc", {"radius": "adaptive"}),
        ("noisy_sphere_0.2", "icc", {"radius": "adaptive"}),
        ("mixed_winding_sphere", "icc", {}),
        ("mixed_winding_sphere", "quadric", {}),
        ("mixed_winding_sphere", "normal_cycle", {"orient": "consistent"}),
        ("mixed_winding_sphere", "rusinkiewicz", {"orient": "keep"}),
        ("cracked_sphere", "icc", {"weld": False}),
        ("cracked_sphere", "quadric", {"weld": False}),
        ("cracked_sphere", "normal_cycle_ball", {"weld": False}),
        ("soup_hemisphere", "icc", {"weld": False}),
        ("soup_hemisphere", "normal_cycle", {"weld": True}),
        ("noisy_sphere_0.2", "normal_cycle", {"smoothing_steps": 0}),
        ("noisy_sphere_0.2", "matgeom", {"smoothing_steps": 6}),
    ],
    "held": [
        ("sphere_cap", "icc", {"radius": "adaptive"}),
        ("voxel_torus_aniso", "icc", {"radius": "adaptive"}),
        ("cracked_torus", "icc", {"weld": False}),
        ("cracked_torus", "quadric", {"weld": False}),
        ("noisy_torus_0.3", "normal_cycle", {"smoothing_steps": 0}),
    ],
}


def cases(part: str, only: str | None):
    """(case name, mesh name, kind, method, radius in edges or None, dtype, options)."""
    import meshcurv
    from meshcurv.pointcloud import POINT_CLOUD_METHODS

    ball = {"icc", "quadric", "normal_cycle_ball"}
    out = []
    if part == "ties":
        for name in meshes(part):
            for method in (*sorted(ball), *(f"cloud-{m}" for m in POINT_CLOUD_METHODS)):
                kind, method = ("cloud", method[6:]) if method.startswith("cloud-") else ("mesh", method)
                for edges in TIE_RADII:
                    case = f"{name}|{'cloud-' if kind == 'cloud' else ''}{method}|{edges:.4f}|f64"
                    out.append((case, name, kind, method, edges, "float64", {}))
        return [case for case in out if not only or only in case[0]]
    for name in meshes(part):
        for method in meshcurv.METHODS:
            radii = (None, *GIVEN_RADII) if method in ball else (None,)
            for edges in radii:
                out.append((f"{name}|{method}|{edges or 'default'}|f64", name, "mesh", method, edges, "float64", {}))
            out.append((f"{name}|{method}|default|f32", name, "mesh", method, None, "float32", {}))
        for method in POINT_CLOUD_METHODS:
            for edges in (None, 3.0):
                case = f"{name}|cloud-{method}|{edges or 'default'}|f64"
                out.append((case, name, "cloud", method, edges, "float64", {}))
    for part_name in ("tuned", "held") if part == "all" else (part,):  # (not "ties")
        for name, method, options in OPTIONS[part_name]:
            kind, method = ("cloud", method[6:]) if method.startswith("cloud-") else ("mesh", method)
            label = ",".join(f"{key}={value}" for key, value in options.items()) or "orient"
            prefix = "cloud-" if kind == "cloud" else ""
            out.append((f"{name}|{prefix}{method}|{label}|f64", name, kind, method, None, "float64", options))
    if only:
        out = [case for case in out if only in case[0]]
    return out


def worker(part: str, only: str | None, folder: Path) -> None:
    """Computes every case on this process's backend and writes ``folder / <case>.npz``."""
    import meshcurv
    from meshcurv.geometry import mean_edge_length
    from meshcurv.topology import MeshTopology

    all_meshes = meshes(part)
    warnings.simplefilter("ignore")
    for case, name, kind, method, edges, dtype, options in cases(part, only):
        vertices, faces = all_meshes[name]
        vertices = np.asarray(vertices, dtype=dtype)
        radius = None
        if edges is not None and name in UNITS:
            radius = edges * UNITS[name]
        elif edges is not None:
            h = mean_edge_length(np.asarray(vertices, float), MeshTopology.from_faces(faces, vertices.shape[0]).edges)
            radius = edges * h
        start = time.perf_counter()
        try:
            options = dict(options)
            if kind == "mesh":
                options.setdefault("radius", radius)
                result = meshcurv.principal_curvatures(vertices, faces, method=method, **options)
            else:
                result = meshcurv.point_cloud_curvatures(vertices, radius=radius, method=method)
            arrays = {
                field: np.asarray(getattr(result, field))
                for field in ("k_min", "k_max", "mean", "gaussian", "normals", "valid")
            }
            reasons = np.asarray(result.invalid_reason)
            arrays["invalid_reason"] = reasons.astype(str) if reasons.dtype.kind in "OUS" else reasons
            arrays["radius"] = np.float64(result.parameters.get("radius", np.nan) or np.nan)
            arrays["error"] = np.str_("")
        except Exception:  # noqa: BLE001 -- an error is a result to compare too
            arrays = {"error": np.str_(traceback.format_exc().strip().splitlines()[-1])}
        arrays["seconds"] = np.float64(time.perf_counter() - start)
        np.savez(folder / (case.replace("|", "__") + ".npz"), **arrays)


def compare(a, b) -> dict:
    """The figures of one case: ``a`` compiled, ``b`` NumPy."""
    if str(a["error"]) or str(b["error"]):
        same = str(a["error"]) == str(b["error"])
        return {
            "valid": 0 if same else -1,
            "rel": 0.0 if same else np.inf,
            "field": f"error {a['error']} | {b['error']}",
        }
    valid_a, valid_b = a["valid"], b["valid"]
    differ = int((valid_a != valid_b).sum())
    reasons = (
        int((a["invalid_reason"] != b["invalid_reason"]).sum())
        if a["invalid_reason"].shape == b["invalid_reason"].shape
        else -1
    )
    both = valid_a & valid_b
    scale = float(np.abs(np.concatenate([a["k_min"][valid_a], a["k_max"][valid_a]])).max(initial=0.0)) or 1.0
    worst, field, where = 0.0, "", -1
    for name in ("k_min", "k_max", "mean", "gaussian", "normals"):
        unit = scale * scale if name == "gaussian" else (1.0 if name == "normals" else scale)
        x, y = a[name][both], b[name][both]
        if name == "normals" and x.size:
            # an unoriented normal (matgeom) is the same up to sign
            y = y * np.where(np.einsum("ij,ij->i", x, y) < 0, -1.0, 1.0)[:, None]
        difference = np.abs(x - y) / unit
        # NaN on both sides agrees; NaN on one side only is the largest difference
        difference = np.where(np.isnan(x) & np.isnan(y), 0.0, np.where(np.isnan(difference), np.inf, difference))
        if difference.ndim == 2:
            difference = difference.max(axis=1, initial=0.0)
        if difference.size and difference.max() > worst:
            worst, field = float(difference.max()), name
            where = int(np.flatnonzero(both)[np.argmax(difference)])
    radius = (float(a["radius"]), float(b["radius"]))
    radius_rel = abs(radius[0] - radius[1]) / abs(radius[0]) if np.isfinite(radius[0]) and radius[0] else 0.0
    return {
        "valid": differ,
        "reasons": reasons,
        "rel": worst,
        "field": f"{field}@{where}" if field else "",
        "radius_rel": radius_rel,
        "n": int(valid_a.size),
        "n_valid": int(valid_a.sum()),
        "seconds": (float(a["seconds"]), float(b["seconds"])),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--part", choices=("tuned", "held", "all", "ties"), default="tuned")
    parser.add_argument("--only", default=None, help="only the cases whose name holds this text")
    parser.add_argument("--out", default=None, help="folder of the per-case results (a temporary one by default)")
    parser.add_argument("--worker", default=None, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.worker:
        worker(args.part, args.only, Path(args.worker))
        return 0
    root = Path(args.out or tempfile.mkdtemp(prefix="parity_"))
    folders = {}
    for backend in ("numba", "numpy"):
        folders[backend] = root / backend
        folders[backend].mkdir(parents=True, exist_ok=True)
        environment = dict(os.environ)
        if backend == "numpy":
            environment["MESHCURV_BACKEND"] = "numpy"
        else:
            environment.pop("MESHCURV_BACKEND", None)
        command = [sys.executable, __file__, "--part", args.part, "--worker", str(folders[backend])]
        if args.only:
            command += ["--only", args.only]
        subprocess.run(command, env=environment, check=True)
    rows = []
    for case, *_ in cases(args.part, args.only):
        file = case.replace("|", "__") + ".npz"
        with np.load(folders["numba"] / file) as a, np.load(folders["numpy"] / file) as b:
            rows.append((case, compare(dict(a), dict(b))))
    print(f"{'case':58s} {'n':>6s} {'valid':>6s} {'vdiff':>5s} {'rdiff':>5s} {'max rel':>9s} {'radius':>8s}  field")
    for case, row in rows:
        if "n" not in row:
            print(f"{case:58s} {'':>6s} {'':>6s} {row['valid']:5d} {'':>5s} {row['rel']:9.1e} {'':>8s}  {row['field']}")
            continue
        print(
            f"{case:58s} {row['n']:6d} {row['n_valid']:6d} {row['valid']:5d} {row['reasons']:5d} {row['rel']:9.1e} "
            f"{row['radius_rel']:8.1e}  {row['field']}"
        )
    bad = [(case, row) for case, row in rows if row["valid"] or row["rel"] > RTOL or row.get("radius_rel", 0) > 1e-9]
    print(f"\n{len(bad)} of {len(rows)} cases part (valid masks differ, or a value beyond {RTOL:g} of max |k|):")
    for case, row in sorted(bad, key=lambda item: -item[1]["rel"] if np.isfinite(item[1]["rel"]) else -1e300):
        print(f"  {case}: valid differ {row['valid']}, max rel {row['rel']:.2e} ({row['field']})")
    total = {backend: sum(row.get("seconds", (0, 0))[i] for _, row in rows) for i, backend in enumerate(folders)}
    print(f"\nseconds: numba {total['numba']:.1f}, numpy {total['numpy']:.1f}; results in {root}")
    _dtype_table(folders["numba"], [case for case, *_ in cases(args.part, args.only)])
    return 0


def _dtype_table(folder: Path, names: list) -> None:
    """float32 against float64 vertices on the compiled backend, at the default radius: the cases whose valid
    masks differ or whose values part by more than 1e-4 of max |k| (float32's rounding of the vertices is some
    6e-8 of their size: a larger difference is a decision that the rounding flips)."""
    print("\nfloat32 against float64 vertices (compiled backend, default radius): valid differ, max rel")
    parted = 0
    for name in names:
        if not name.endswith("|default|f32"):
            continue
        other = name[: -len("f32")] + "f64"
        with (
            np.load(folder / (other.replace("|", "__") + ".npz")) as a,
            np.load(folder / (name.replace("|", "__") + ".npz")) as b,
        ):
            row = compare(dict(a), dict(b))
        if row["valid"] or row["rel"] > 1e-4:
            parted += 1
            print(f"  {name[: -len('|default|f32')]}: valid differ {row['valid']}, max rel {row['rel']:.1e}")
    print(f"  {parted} case(s)")


if __name__ == "__main__":
    raise SystemExit(main())
