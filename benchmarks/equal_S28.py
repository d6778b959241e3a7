"""Whether two versions of meshcurv give the same curvatures: every field of the calls, saved and compared
(issue 31, helper S28: a change of speed that must not move any number).

Computes ``principal_curvatures`` (default method unless ``--method``) on analytic families (clean, noisy,
irregular, voxel, holed, multi-radius calls) and on the real meshes of ``../shared/meshes`` when present, and
saves every result field to an ``.npz`` (``--save``), or compares them with a saved file (``--compare``): the
number of fields bit-equal and the largest relative difference of the others. Old and new code in turns
(``PYTHONPATH=<snapshot>/src`` for the old)::

    PYTHONPATH=/tmp/old/src python benchmarks/equal_S28.py --save /tmp/old.npz
    python benchmarks/equal_S28.py --compare /tmp/old.npz
"""

from __future__ import annotations

import argparse
import os
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes

FIELDS = ("k_min", "k_max", "mean", "gaussian", "dir_min", "dir_max", "normals", "valid", "radius")
SHARED = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "meshes")


def _cases(quick: bool):
    yield "icosphere(40)", shapes.icosphere(40), {}
    yield "torus", shapes.torus(), {}
    yield "ellipsoid", shapes.ellipsoid(), {}
    yield "saddle jitter", shapes.saddle(jitter=0.2, seed=1), {}
    yield "random_sphere", shapes.random_sphere(5000, seed=2), {}
    yield "hemisphere irregular", shapes.hemisphere(24, irregular=True, seed=3), {}
    yield "noisy torus", shapes.with_normal_noise(shapes.torus(), 0.05, seed=4), {}
    yield "voxel_sphere", shapes.voxel_sphere(8.0, (0.5, 0.5, 0.5), seed=5), {}
    yield "torus radius 0.3", shapes.torus(), {"radius": 0.3}
    yield "ellipsoid multiscale", shapes.ellipsoid(), {"radii": (0.15, 0.3, 0.6)}
    if quick:
        return
    for name in ("spot", "fandisk", "igea", "ogre", "rocker-arm", "nefertiti"):
        path = os.path.join(SHARED, f"{name}.obj")
        if os.path.exists(path):
            yield name, meshcurv.io.read_mesh(path), {}


def _arrays(method: str, quick: bool) -> dict:
    out = {}
    for name, mesh, options in _cases(quick):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if "radii" in options:  # the nested fits of one walk (estimate_multiscale)
                results = meshcurv.multiscale_curvatures(mesh.vertices, mesh.faces, options["radii"], method=method)
            else:
                results = [meshcurv.principal_curvatures(mesh.vertices, mesh.faces, method=method, **options)]
        for r, result in enumerate(results):
            for field in FIELDS:
                value = getattr(result, field, None)
                if value is not None:
                    out[f"{name}/{r}/{field}"] = np.asarray(value)
    return out


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--method", default="icc")
    parser.add_argument("--quick", action="store_true", help="the analytic families only")
    parser.add_argument("--save")
    parser.add_argument("--compare")
    options = parser.parse_args(argv)
    arrays = _arrays(options.method, options.quick)
    if options.save:
        np.savez(options.save, **arrays)
    if options.compare:
        old = np.load(options.compare)
        same = 0
        for key, new in arrays.items():
            if key not in old:
                print(f"{key}: missing in the saved file")
                continue
            if np.array_equal(old[key], new, equal_nan=True):
                same += 1
                continue
            a, b = np.asarray(old[key], float), np.asarray(new, float)
            with np.errstate(invalid="ignore", divide="ignore"):
                scale = np.nanmax(np.abs(a)) if np.isfinite(a).any() else 1.0
                relative = np.nanmax(np.abs(a - b)) / scale
            print(f"{key}: differs, largest difference {relative:.3g} of the largest value")
        print(f"{same} of {len(arrays)} fields bit-equal")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
