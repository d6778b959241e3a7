"""icc's default radius on meshes with a noisy patch (issue 29): one row per draw.

Two kinds of draws on four closed surfaces (icosphere(24), uv_sphere(64, 32), ellipsoid (3, 2, 1) at 16
subdivisions, torus (3, 1) 96 x 32): ``detach``, a share ``a`` (20-50%) of the faces each given its own three
corners moved ``b`` (0.03-0.1) mean edge lengths in random 3D directions; ``patch``, the vertices of a cap (30% of
them along a random axis) moved along their normal by Gaussian noise of ``a`` (0.05-0.3) mean edge lengths. Each
detached corner is compared with the exact curvatures of the vertex it came from. ``off``: valid vertices whose H
is off by more than half the largest exact |k| there; ``max``/``p95``/``med``: that error over the largest |k|;
``r/h``, ``r95/h``: the median and 95th percentile of ``result.radius`` in mean edge lengths.

    python benchmarks/noisy_patches_icc.py 0,1,2          # the tuning draws
    python benchmarks/noisy_patches_icc.py 10,11,12,13    # held out
"""

import sys
import warnings
import numpy as np
import meshcurv
from meshcurv import shapes


def holey(mesh, seed, share, offset):
    v, f = mesh.vertices, mesh.faces
    rng = np.random.default_rng(seed)
    edge = float(np.mean(np.linalg.norm(v[f[:, 0]] - v[f[:, 1]], axis=1)))
    picked = rng.random(len(f)) < share
    corners = v[f[picked]].reshape(-1, 3)
    src = f[picked].reshape(-1)
    d = rng.normal(size=corners.shape)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    moved = f.copy()
    moved[picked] = len(v) + np.arange(corners.shape[0]).reshape(-1, 3)
    source = np.concatenate([np.arange(len(v)), src])
    return np.concatenate([v, corners + d * offset * edge]), moved, source, edge


def patch(mesh, seed, amplitude):
    v, f = mesh.vertices, mesh.faces
    rng = np.random.default_rng(seed)
    edge = float(np.mean(np.linalg.norm(v[f[:, 0]] - v[f[:, 1]], axis=1)))
    axis = rng.normal(size=3)
    axis /= np.linalg.norm(axis)
    c = v.mean(axis=0)
    x = (v - c) @ axis
    inside = x > np.percentile(x, 70)
    noisy = v + inside[:, None] * mesh.normals * rng.normal(size=(len(v), 1)) * amplitude * edge
    return noisy, f, np.arange(len(v)), edge


SHAPES = {
    "icosphere": lambda: shapes.icosphere(24),
    "uv_sphere": lambda: shapes.uv_sphere(64, 32),
    "ellipsoid": lambda: shapes.ellipsoid((3.0, 2.0, 1.0), 16),
    "torus": lambda: shapes.torus(3.0, 1.0, 96, 32),
}


def run(name, kind, seed, a, b, method="icc"):
    mesh = SHAPES[name]()
    if kind == "detach":
        v, f, source, edge = holey(mesh, seed, a, b)
    else:
        v, f, source, edge = patch(mesh, seed, a)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = meshcurv.principal_curvatures(v, f, method=method)
    H = (r.k_min + r.k_max) / 2
    exact = mesh.mean[source]
    scale = np.max(np.abs(np.stack([mesh.k_min, mesh.k_max])), axis=0)[source]
    ok = r.valid
    err = np.abs(H - exact)[ok]
    off = (err > 0.5 * scale[ok]).sum()
    rel = err / scale[ok]
    print(
        f"{name:10s} {kind:6s} seed={seed:3d} a={a:.2f} b={b:.3f} valid={ok.sum():6d} off={off:4d} "
        f"max={rel.max():.3f} p95={np.percentile(rel, 95):.4f} med={np.median(rel):.4f} "
        f"r/h={np.median(r.radius[ok]) / edge:.2f} r95/h={np.percentile(r.radius[ok], 95) / edge:.2f}",
        flush=True,
    )
    return off


if __name__ == "__main__":
    seeds = [int(s) for s in sys.argv[1].split(",")]
    names = sys.argv[2].split(",") if len(sys.argv) > 2 else list(SHAPES)
    rng = np.random.default_rng(seeds[0] * 7919)
    total = 0
    for seed in seeds:
        for name in names:
            share, offset = rng.uniform(0.2, 0.5), rng.uniform(0.03, 0.1)
            total += run(name, "detach", seed, share, offset)
        for name in names:
            total += run(name, "patch", seed, rng.uniform(0.05, 0.3), 0.0)
    print("total off", total)
