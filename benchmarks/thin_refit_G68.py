"""icc's default on thin analytic parts with a noisy patch, two source trees compared (issue 31's connected refit).

``radius._patch_radii`` fits the noise again near a noisy patch, refusing a ball that holds the other side of the
surface (a part thinner than the ball). The question of stop 68: does the refit on the surface-connected balls
(one fits path, no Euclidean grid fits to compile) still refuse where the Euclidean refit does? Each case is a thin
ellipsoid (or a thin torus) with 30% of its vertices (a cap along a random axis) moved along their normals by
Gaussian noise of 0.1, 0.2 or 0.3 mean edge lengths, or 30% of its faces detached by 0.05 edge lengths; every
result is saved, then the two trees' results are compared with the exact curvatures (the error of H over the
largest exact |k| at the vertex, over the valid vertices; ``off``: above 0.5).

Run from the repository root, each tree a ``src`` directory (``git archive <commit> src | tar -x -C <dir>``)::

    PYTHONPATH=<old>/src python benchmarks/thin_refit_G68.py run old <folder>
    PYTHONPATH=<new>/src python benchmarks/thin_refit_G68.py run new <folder>
    python benchmarks/thin_refit_G68.py compare <folder> old new
"""

from __future__ import annotations

import glob
import os
import sys
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes
from noisy_patches_icc import holey, patch  # the noisy patches' draws

BASES = {
    "e15s16": lambda: shapes.ellipsoid((3.0, 3.0, 0.15), 16),
    "e15s24": lambda: shapes.ellipsoid((3.0, 3.0, 0.15), 24),
    "e15s32": lambda: shapes.ellipsoid((3.0, 3.0, 0.15), 32),
    "e30s24": lambda: shapes.ellipsoid((3.0, 3.0, 0.3), 24),
    "e10s24": lambda: shapes.ellipsoid((3.0, 2.0, 0.1), 24),
    "t15": lambda: shapes.torus(3.0, 0.15, 192, 12),
}


def _cases():
    for base in BASES:
        for seed in range(3):
            for amplitude in (0.1, 0.2, 0.3):
                yield base, "cap", (amplitude, seed, 0.3)
            yield base, "detach", (0.3, 0.05, seed)


def run(tag: str, folder: str) -> None:
    os.makedirs(folder, exist_ok=True)
    for base, kind, args in _cases():
        mesh = BASES[base]()
        if kind == "cap":  # a cap of 30% of the vertices, noise of `amplitude` edge lengths along the normals
            amplitude, seed, _ = args
            vertices, faces, source, _ = patch(mesh, seed, amplitude)
        else:  # a `share` of the faces detached by `offset` edge lengths
            share, offset, seed = args
            vertices, faces, source, _ = holey(mesh, seed, share, offset)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = meshcurv.principal_curvatures(vertices, faces)
        name = f"{base}_{kind}_{'_'.join(map(str, args))}"
        arrays = {key: getattr(result, key) for key in ("k_min", "k_max", "valid", "radius")}
        np.savez(os.path.join(folder, f"{tag}_{name}.npz"), source=source, **arrays)
        print(name, flush=True)


def _moved(a, b, key):
    """Rows that differ beyond round-off (two runs of one tree differ by up to 3e-10 of k: threads' sums)."""
    return ~(np.isclose(a[key], b[key], rtol=1e-8, atol=0.0) | (np.isnan(a[key]) & np.isnan(b[key])))


def compare(folder: str, old: str, new: str) -> None:
    print("| case | vertices | moved | radius moved | H error at the moved, median old/new | off old/new |")
    print("|---|---|---|---|---|---|")
    totals = [0, 0, 0, 0]
    for path in sorted(glob.glob(os.path.join(folder, f"{old}_*.npz"))):
        name = os.path.basename(path)[len(old) + 1 : -4]
        a, b = np.load(path), np.load(os.path.join(folder, f"{new}_{name}.npz"))
        mesh = BASES[name.split("_")[0]]()
        source = a["source"]
        largest = np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))[source]
        errors = [
            np.where(r["valid"], np.abs((r["k_min"] + r["k_max"]) / 2 - mesh.mean[source]) / largest, np.nan)
            for r in (a, b)
        ]
        off = [int(np.nansum(e > 0.5)) for e in errors]
        moved = _moved(a, b, "k_min") | _moved(a, b, "k_max")
        totals = [totals[0] + 1, totals[1] + int(moved.any()), totals[2] + off[0], totals[3] + off[1]]
        if moved.any():
            median = [np.nanmedian(e[moved]) for e in errors]
            radius = int(_moved(a, b, "radius").sum())
            print(
                f"| {name} | {len(source)} | {int(moved.sum())} | {radius} | {median[0]:.3f} / {median[1]:.3f} "
                f"| {off[0]} / {off[1]} |"
            )
    print(f"\n{totals[0]} cases, {totals[1]} moved; valid vertices off by > 0.5: {totals[2]} -> {totals[3]}")


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "run":
        run(sys.argv[2], sys.argv[3])
    elif len(sys.argv) == 5 and sys.argv[1] == "compare":
        compare(*sys.argv[2:])
    else:
        sys.exit(__doc__)
