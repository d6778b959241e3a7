"""Figures for the foundation (issue 2): matGeom parity, sphere and saddle errors, igea timings.

Run from the repository root: ``python benchmarks/foundation.py``. The parity
table uses the reference files in tests/data/matgeom (the deviation of each
output from the real matGeom's, outside the README's ambiguity masks); the
timings and the ogre check need ../shared/meshes and are skipped without it.
"""

import glob
import os
import pathlib
import time
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes
from meshcurv._backend import use_backend

ROOT = pathlib.Path(__file__).resolve().parents[1]
SHARED = ROOT.parent / "shared" / "meshes"
warnings.simplefilter("ignore")
print("| case | C1,C2,H max dev / scale | K max dev / scale^2 | U1,U2,N worst 1-|dot| (outside masks) |")
for f in sorted(glob.glob(str(ROOT / "tests" / "data" / "matgeom" / "*.npz"))):
    z = np.load(f)
    r = meshcurv.principal_curvatures(
        z["vertices"], z["faces"], method="matgeom", smoothing_steps=int(z["smoothing_steps"])
    )
    C1, C2, U1, U2, H, K, N = r.as_matgeom()
    scale = max(np.abs(z["C1"]).max(), np.abs(z["C2"]).max())
    dc = max(np.abs(C1 - z["C1"]).max(), np.abs(C2 - z["C2"]).max(), np.abs(H - z["H"]).max()) / scale
    dk = np.abs(K - z["K"]).max() / scale**2
    umb = np.abs(z["C2"] - z["C1"]) <= 1e-8 * scale
    from meshcurv.estimators.matgeom import matgeom_tensors
    from meshcurv.estimators._eigen import sorted_by_magnitude

    top = meshcurv.MeshTopology._build(meshcurv.triangulate_faces(z["faces"]), z["vertices"].shape[0])
    t, *_ = matgeom_tensors(np.asarray(z["vertices"], float), top, int(z["smoothing_steps"]))
    vals, _ = sorted_by_magnitude(t)
    flat = np.abs(vals[:, 1]) - np.abs(vals[:, 0]) <= 1e-8 * scale

    def vd(a, b, m):
        d = 1 - np.abs(np.sum(a * b, 1))
        return d[~m].max() if (~m).any() else 0

    v = max(vd(U1, z["U1"], umb), vd(U2, z["U2"], umb | flat), vd(N, z["N"], flat))
    print(f"| {os.path.basename(f)[:-4]} | {dc:.1e} | {dk:.1e} | {v:.1e} |")
for radius in (1.0, 1000.0):
    s = shapes.icosphere(16, radius=radius)
    r = meshcurv.principal_curvatures(s.vertices, s.faces, method="normal_cycle")
    for name in ("k_min", "k_max", "mean"):
        e = np.abs(getattr(r, name) * radius - 1)
        print(f"sphere r={radius:g} {name}: median {np.median(e) * 100:.3f}% worst {e.max() * 100:.3f}%")
sd = shapes.saddle(1.0, 0.025)
r = meshcurv.principal_curvatures(sd.vertices, sd.faces, method="normal_cycle")
c = np.argmin(np.linalg.norm(sd.vertices[:, :2], axis=1))
print(
    f"saddle centre k_min {r.k_min[c]:.4f} ({abs(r.k_min[c] + 2) / 2 * 100:.2f}%), k_max {r.k_max[c]:.4f} ({abs(r.k_max[c] - 2) / 2 * 100:.2f}%), normal {np.round(r.normals[c], 12)}"
)
if not SHARED.is_dir():
    raise SystemExit(f"no {SHARED}: igea and ogre figures skipped")
v, f = meshcurv.read_mesh(SHARED / "igea.obj")
for backend in ("numba", "numpy"):
    with use_backend(backend):
        for m in ("normal_cycle", "matgeom"):
            meshcurv.principal_curvatures(v, f, method=m)
            ts = []
            for _ in range(5):
                t = time.perf_counter()
                meshcurv.principal_curvatures(v, f, method=m)
                ts.append(time.perf_counter() - t)
            print(f"igea {backend} {m}: median {np.median(ts):.3f} s (min {min(ts):.3f})")
v, f = meshcurv.read_mesh(SHARED / "ogre.obj")
for m in ("normal_cycle", "matgeom", "meyer", "rusinkiewicz"):
    with warnings.catch_warnings(record=True) as w:
        warnings.simplefilter("always")
        r = meshcurv.principal_curvatures(v, f, method=m)
    ok = all(np.isfinite(x[r.valid]).all() for x in (r.k_min, r.k_max, r.mean, r.gaussian))
    print(
        f"ogre {m}: valid {int(r.valid.sum())}/{r.n_vertices}, finite at every valid vertex: {ok}, warnings {len(w)}: {str(w[0].message)[:160] if w else ''}"
    )
