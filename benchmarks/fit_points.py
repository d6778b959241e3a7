"""Points per normal fit of icc's default call, and how many fits take the second iteration (issue 30).

Records the arguments of every degree-3 jet fit of one default call (``jets._fit_jets``, which the normal fits
on the vertices, the sampled fits on a coarse level and the pilot's fits all reach), then refits them with one
iteration to count the fits whose first slope ``c10^2 + c01^2`` is at least ``settled`` (those the second
iteration runs for). Prints, per fit call, the centres, the radius (in median edge lengths of the mesh), the
points of non-zero weight per ball (5th, 50th and 95th percentiles) and the share taking the second iteration.

    python benchmarks/fit_points.py --meshes ico100k noise0.1 noise0.3 voxel6 voxel10
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

import meshcurv
from meshcurv import jets, shapes
from meshcurv.estimators import icc


def _mesh(name: str):
    if name.startswith("ico"):
        m = shapes.icosphere({"ico100k": 100, "ico1M": 316}[name])
        return m.vertices, m.faces
    if name.startswith("noise"):  # as benchmarks/accuracy.py: uniform displacement along the normal, in mean edges
        m = shapes.icosphere(40)
        v, f = m.vertices, m.faces
        h = float(np.mean(np.linalg.norm(v[f[:, 0]] - v[f[:, 1]], axis=1)))
        amplitude = float(name[len("noise") :]) * h
        shift = np.random.default_rng(0).uniform(-amplitude, amplitude, (len(v), 1))
        return v + v / np.linalg.norm(v, axis=1, keepdims=True) * shift, f
    radius, spacing = {"voxel6": (6.0, (0.5, 0.2, 0.2)), "voxel10": (10.0, (0.25, 0.1, 0.1))}[name]
    m = shapes.voxel_sphere(radius, spacing=spacing)
    return m.vertices, m.faces


def _fits(vertices, faces) -> list[tuple]:
    """The degree-3 fits of one default call: (points, normals, radius, options) each (``icc._fit_jet_normals``,
    the fits over the vertices, and ``jets._fit_jets``, the sampled and the pilot's fits; a call of the first
    that reaches the second, on the NumPy backend, is recorded once)."""
    calls = []
    inside = []
    originals = (jets._fit_jets, icc._fit_jet_normals)

    def recording(original):
        def record(points, normals, radius, **options):
            if options.get("degree") == icc.NORMAL_DEGREE and not inside:
                calls.append((points, normals, radius, dict(options)))
            inside.append(True)
            try:
                return original(points, normals, radius, **options)
            finally:
                inside.pop()

        return record

    jets._fit_jets, icc._fit_jet_normals = (recording(original) for original in originals)
    try:
        _default_call(vertices, faces)
    finally:
        jets._fit_jets, icc._fit_jet_normals = originals
    return calls


def _default_call(vertices, faces) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the voxel surfaces' warnings: not what is measured
        meshcurv.principal_curvatures(vertices, faces)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--meshes", nargs="+", default=["ico100k", "noise0.1", "noise0.3", "voxel6"])
    args = parser.parse_args(argv)
    print("| mesh | V | fit call | centres | radius / edge | points per fit (5%, 50%, 95%) | 2nd iteration |")
    print("|---|--:|---|--:|--:|---|--:|")
    for name in args.meshes:
        vertices, faces = _mesh(name)
        edge = float(np.median(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)))
        for k, (points, normals, radius, options) in enumerate(_fits(vertices, faces)):
            options = {**options, "iterations": 1, "compact": options.get("centres") is not None}
            settled = options.pop("settled", 0.0)
            coefficients, _, counts = jets._fit_jets(points, normals, radius, **options)
            slope = coefficients[:, 1] ** 2 + coefficients[:, 2] ** 2
            second = np.count_nonzero(slope >= settled)
            low, mid, high = np.percentile(counts, [5, 50, 95])
            print(
                f"| {name} | {vertices.shape[0]:,} | {k} | {counts.size:,} | {np.median(radius) / edge:.1f} | "
                f"{low:.0f}, {mid:.0f}, {high:.0f} | {second:,} ({second / max(counts.size, 1):.0%}) |"
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
