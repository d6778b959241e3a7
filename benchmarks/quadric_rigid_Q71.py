"""Invariance of ``quadric`` at a given radius on meshes with sharp creases (issue 29, fuzz 804/313).

Each case computes ``principal_curvatures(v, f, method="quadric", radius=r)`` and again on the mesh
under one relation, and compares the two as ``benchmarks/fuzz_api.py`` does: the same valid mask,
``k_min`` and ``k_max`` within 1e-6 of the largest ``|k|`` of the valid vertices.

- ``rigid``: a random rotation and a shift of up to 10 sizes;
- ``permute``: the vertices re-indexed;
- ``scale``: the mesh and the radius scaled by ``s`` (curvatures / s);
- ``backend``: the same call on the NumPy path (the first on numba).

Radii are multiples of the median edge length, given as float64 or float32 (as the fuzzer's
``--radius-forms``). Families: ``tuned`` (fandisk, boxes and a capped cylinder with sharp edges: the
ones the fix was tuned on) and ``held`` (other real meshes, other radii and rotations)::

    python benchmarks/quadric_rigid_Q71.py --family tuned --poses 3
    python benchmarks/quadric_rigid_Q71.py --family held --poses 2

The real meshes are read from ``../shared/meshes`` (as the fuzzer's ``REAL_FOLDER``).
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import warnings

import numpy as np

import meshcurv

REAL_FOLDER = os.path.join("..", "shared", "meshes")


def box(size=(2.0, 1.0, 0.5), n: int = 12) -> tuple[np.ndarray, np.ndarray]:
    """A closed box of grid faces (``n`` cells along its longest side), split quads, outward: 12 sharp edges."""
    size = np.asarray(size, float)
    cells = np.maximum(1, np.round(n * size / size.max())).astype(int)
    points: list = []
    faces: list = []
    for axis in range(3):
        a, b = [k for k in range(3) if k != axis]
        for side in (-1.0, 1.0):
            u = np.linspace(-size[a] / 2, size[a] / 2, cells[a] + 1)
            w = np.linspace(-size[b] / 2, size[b] / 2, cells[b] + 1)
            uu, ww = np.meshgrid(u, w, indexing="ij")
            grid = np.zeros((uu.size, 3))
            grid[:, a], grid[:, b], grid[:, axis] = uu.ravel(), ww.ravel(), side * size[axis] / 2
            base = sum(len(p) for p in points)
            idx = base + np.arange(uu.size).reshape(uu.shape)
            q = np.stack([idx[:-1, :-1], idx[1:, :-1], idx[1:, 1:], idx[:-1, 1:]], axis=-1).reshape(-1, 4)
            tri = np.concatenate([q[:, [0, 1, 2]], q[:, [0, 2, 3]]])
            normal = np.zeros(3)
            normal[axis] = side
            e1 = grid[tri[0, 1] - base] - grid[tri[0, 0] - base]
            e2 = grid[tri[0, 2] - base] - grid[tri[0, 0] - base]
            if np.dot(np.cross(e1, e2), normal) < 0:
                tri = tri[:, ::-1]
            points.append(grid)
            faces.append(tri)
    return _welded(np.concatenate(points), np.concatenate(faces))


def capped_cylinder(radius: float = 1.0, height: float = 2.0, n_around: int = 32, n_along: int = 8):
    """A closed cylinder with flat caps (rings of a fan), outward: two sharp circular edges."""
    angles = np.linspace(0, 2 * np.pi, n_around, endpoint=False)
    ring = np.stack([radius * np.cos(angles), radius * np.sin(angles)], axis=1)
    points = [np.column_stack([ring, np.full(n_around, z)]) for z in np.linspace(-height / 2, height / 2, n_along + 1)]
    faces = []
    for k in range(n_along):
        a = k * n_around + np.arange(n_around)
        b = (k + 1) * n_around + np.r_[np.arange(1, n_around), 0]
        a1 = k * n_around + np.r_[np.arange(1, n_around), 0]
        c = (k + 1) * n_around + np.arange(n_around)
        faces += [np.stack([a, a1, b], 1), np.stack([a, b, c], 1)]
    n_rings = max(2, int(round(radius / (2 * np.pi * radius / n_around))))
    for z, sign, rim in ((-height / 2, -1, 0), (height / 2, 1, n_along * n_around)):
        previous = rim + np.arange(n_around)
        for level in range(n_rings - 1, 0, -1):
            base = sum(len(p) for p in points)
            points.append(np.column_stack([ring * level / n_rings, np.full(n_around, z)]))
            here = base + np.arange(n_around)
            nxt = np.r_[np.arange(1, n_around), 0]
            t1 = np.stack([previous, previous[nxt], here], 1)
            t2 = np.stack([here, previous[nxt], here[nxt]], 1)
            faces += [t1 if sign > 0 else t1[:, ::-1], t2 if sign > 0 else t2[:, ::-1]]
            previous = here
        centre = sum(len(p) for p in points)
        points.append(np.array([[0.0, 0.0, z]]))
        nxt = np.r_[np.arange(1, n_around), 0]
        t = np.stack([previous, previous[nxt], np.full(n_around, centre)], 1)
        faces.append(t if sign > 0 else t[:, ::-1])
    return np.concatenate(points), np.concatenate(faces)


def _welded(points, faces):
    keys = np.round(points, 9)
    unique, inverse = np.unique(keys, axis=0, return_inverse=True)
    return unique, inverse.ravel()[faces]


def _outward(points, faces):
    a, b, c = (points[faces[:, k]] for k in range(3))
    volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum()
    return faces if volume > 0 else faces[:, ::-1]


def _real(name):
    here = os.path.dirname(os.path.abspath(__file__))
    mesh = meshcurv.read_mesh(os.path.join(here, "..", REAL_FOLDER, name + ".obj"))
    return np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)


FAMILIES = {
    "tuned": {
        "meshes": ["fandisk", "box", "flat_box", "capped_cylinder"],
        "edges": [1.5, 2.0, 3.0, 4.0],
        "seed": 1,
    },
    "held": {
        "meshes": ["rocker-arm", "spot", "fine_box", "wide_cylinder"],
        "edges": [1.3, 2.5, 3.5],
        "seed": 2,
    },
}


def mesh(name):
    if name == "box":
        v, f = box((2.0, 1.0, 0.5), 12)
    elif name == "flat_box":
        v, f = box((3.0, 2.0, 0.2), 30)
    elif name == "fine_box":
        v, f = box((1.0, 1.0, 1.0), 20)
    elif name == "capped_cylinder":
        v, f = capped_cylinder(1.0, 2.0, 32, 8)
    elif name == "wide_cylinder":
        v, f = capped_cylinder(2.0, 0.7, 48, 4)
    else:
        return _real(name)
    return v, _outward(v, f)


def rotation(rng):
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else q[:, [1, 0, 2]]


def compare(a, b, extent, factor=1.0):
    """(valid changes, the largest relative difference of k_min and k_max) as the fuzzer reads them (``extent``: the
    mesh's, whose 1e-6 / extent is the smallest curvature compared to: a flat patch's k ~ 1e-17 is round-off)."""
    changed = int((a.valid != b.valid).sum())
    both = a.valid & b.valid
    size = max(np.abs(a.k_min[both]).max(initial=0), np.abs(a.k_max[both]).max(initial=0), 1e-6 / extent)
    err = max(
        float(np.max(np.abs(a.k_min[both] - b.k_min[both] * factor), initial=0)),
        float(np.max(np.abs(a.k_max[both] - b.k_max[both] * factor), initial=0)),
    )
    return changed, err / size


def numpy_result(v, f, radius):
    """The NumPy path's result, in a child process (the backend is read once per process)."""
    import pickle
    import tempfile

    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "case.pkl")
        with open(path, "wb") as handle:
            pickle.dump((v, f, radius), handle)
        code = (
            "import pickle, sys, warnings, meshcurv; warnings.simplefilter('ignore'); "
            "v, f, r = pickle.load(open(sys.argv[1], 'rb')); "
            "res = meshcurv.principal_curvatures(v, f, method='quadric', radius=r); "
            "pickle.dump((res.valid, res.k_min, res.k_max), open(sys.argv[1], 'wb'))"
        )
        env = {**os.environ, "MESHCURV_BACKEND": "numpy"}
        subprocess.run([sys.executable, "-c", code, path], check=True, env=env)
        with open(path, "rb") as handle:
            valid, k_min, k_max = pickle.load(handle)

    class Result:
        pass

    out = Result()
    out.valid, out.k_min, out.k_max = valid, k_min, k_max
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--family", choices=sorted(FAMILIES), default="tuned")
    parser.add_argument("--poses", type=int, default=2, help="rigid motions per mesh and radius")
    parser.add_argument("--relations", default="rigid,permute,scale,backend")
    parser.add_argument("--meshes", default=None, help="comma-separated subset of the family's meshes")
    args = parser.parse_args(argv)
    family = FAMILIES[args.family]
    relations = args.relations.split(",")
    rng = np.random.default_rng(family["seed"])
    names = args.meshes.split(",") if args.meshes else family["meshes"]
    print("| mesh | radius (edges, form) | relation | valid | valid changed | largest difference / max abs k |")
    print("|---|---|---|---|---|---|")
    broken = 0
    for name in names:
        v, f = mesh(name)
        edge = float(np.median(np.linalg.norm(v[f[:, 0]] - v[f[:, 1]], axis=1)))
        extent = float(np.ptp(v))
        for edges in family["edges"]:
            for form in ("float64", "float32"):
                radius = edges * edge
                radius = np.float32(radius) if form == "float32" else float(radius)
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    base = meshcurv.principal_curvatures(v, f, method="quadric", radius=radius)
                    cases = []
                    for relation in relations:
                        for _ in range(args.poses if relation == "rigid" else 1):
                            if relation == "rigid":
                                shift = rng.uniform(-10, 10, size=3) * float(np.ptp(v))
                                other = meshcurv.principal_curvatures(
                                    v @ rotation(rng).T + shift, f, method="quadric", radius=radius
                                )
                                cases.append((relation, *compare(base, other, extent)))
                            elif relation == "permute":
                                perm = rng.permutation(len(v))
                                inverse = np.argsort(perm)
                                other = meshcurv.principal_curvatures(
                                    v[perm], inverse[f], method="quadric", radius=radius
                                )
                                cases.append((relation, *compare(base, _taken(other, inverse), extent)))
                            elif relation == "scale":
                                s = float(rng.choice([2.0**-20, 1e3, 3.7]))
                                other = meshcurv.principal_curvatures(v * s, f, method="quadric", radius=radius * s)
                                cases.append((f"scale {s:g}", *compare(base, other, extent, s)))
                            elif relation == "backend":
                                cases.append((relation, *compare(base, numpy_result(v, f, radius), extent)))
                for relation, changed, err in cases:
                    bad = changed > 0 or not err < 1e-6
                    broken += bad
                    print(
                        f"| {name} | {edges:g} {form} | {relation} | {int(base.valid.sum())} | {changed} | "
                        f"{err:.2g}{' **broken**' if bad else ''} |",
                        flush=True,
                    )
    print(f"\nbroken: {broken}")
    return 0


def _taken(result, rows):
    class Result:
        pass

    out = Result()
    out.valid, out.k_min, out.k_max = result.valid[rows], result.k_min[rows], result.k_max[rows]
    return out


if __name__ == "__main__":
    sys.exit(main())
