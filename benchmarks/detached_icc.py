"""icc's default radius beside detached faces and cracks (issue 29): one row per draw.

A share ``a`` of the faces of a large closed surface each given its own three corners, moved ``b`` mean edge lengths
in random 3D directions (``noisy_patches_icc.holey``; the weld joins the corners within its crack tolerance). Each
detached corner is compared with the exact curvatures of the vertex it came from. ``off``: valid vertices whose H is
off by more than half the largest exact |k| there; ``neg``: valid vertices whose H has the other sign than the exact
one (where |H| exact is more than a tenth of the largest |k|); ``max``/``p95``/``med``: the error over the largest
|k|; ``r/h``, ``r95/h``: the median and 95th percentile of ``result.radius`` in mean edge lengths; ``cpu``: seconds.

    python benchmarks/detached_icc.py lead 0,1,2,3,4,5     # icosphere(40), a = 0.5, b = 0.054, both windings
    python benchmarks/detached_icc.py lead 10,11,12,13,14,15
    python benchmarks/detached_icc.py shapes 10,11,12,13    # held out: a in 0.3-0.5, b in 0.03-0.1
"""

import sys
import time
import warnings
from types import SimpleNamespace

import numpy as np

import meshcurv
from meshcurv import shapes
from noisy_patches_icc import holey

SHAPES = {
    "ellipsoid24": lambda: shapes.ellipsoid((3.0, 2.0, 1.0), 24),
    "ellipsoid32": lambda: shapes.ellipsoid((3.0, 2.0, 1.0), 32),
    "torus": lambda: shapes.torus(3.0, 1.0, 192, 64),
    "uv_sphere": lambda: shapes.uv_sphere(96, 48),
}


def run(name, mesh, seed, share, offset, reverse=False):
    faces = mesh.faces[:, ::-1] if reverse else mesh.faces
    v, f, source, edge = holey(SimpleNamespace(vertices=mesh.vertices, faces=faces), seed, share, offset)
    start = time.process_time()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        r = meshcurv.principal_curvatures(v, f)
    cpu = time.process_time() - start
    mean = (r.k_min + r.k_max) / 2
    exact = mesh.mean[source]
    scale = np.max(np.abs(np.stack([mesh.k_min, mesh.k_max])), axis=0)[source]
    ok = r.valid
    rel = np.abs(mean - exact)[ok] / scale[ok]
    signed = np.abs(exact[ok]) > 0.1 * scale[ok]
    neg = int(np.sum(signed & (np.sign(mean[ok]) != np.sign(exact[ok]))))
    off = int(np.sum(rel > 0.5))
    print(
        f"{name:11s} rev={int(reverse)} seed={seed:3d} a={share:.2f} b={offset:.3f} valid={ok.sum():6d} off={off:4d} "
        f"neg={neg:3d} max={rel.max():.3f} p95={np.percentile(rel, 95):.4f} med={np.median(rel):.4f} "
        f"r/h={np.median(r.radius[ok]) / edge:.2f} r95/h={np.percentile(r.radius[ok], 95) / edge:.2f} cpu={cpu:.1f}",
        flush=True,
    )
    return off


if __name__ == "__main__":
    kind, seeds = sys.argv[1], [int(s) for s in sys.argv[2].split(",")]
    total = 0
    if kind == "lead":
        sphere = shapes.icosphere(40)
        for seed in seeds:
            for reverse in (False, True):
                total += run("icosphere40", sphere, seed, 0.5, 0.054, reverse)
    else:
        rng = np.random.default_rng(seeds[0] * 7919 + 1)
        for seed in seeds:
            for name, make in SHAPES.items():
                total += run(name, make(), seed, rng.uniform(0.3, 0.5), rng.uniform(0.03, 0.1))
    print("total off", total)
