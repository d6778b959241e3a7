"""icc on the flat faces of a voxelised flat ellipsoid: which truth, and are the valid vertices trustworthy?

``shapes.voxel_ellipsoid((8, 8, 2), seed=2)`` (the fuzzer's ``voxel_flat_ellipsoid``) under the default ``icc``.
The flat faces are the vertices whose exact largest ``|k|`` (at the closest point of the analytic ellipsoid) is
below ``--flat`` of the shape's largest (the rim's). For each variant the table gives the flat vertices valid,
those off by more than half of their own ``|k|`` and by more than half of the shape's largest (the fuzzer's bar),
the median H against the exact median, and the median error in units of the vertex's own ``|k|``. Variants: the
default; the same radii with the exact normals interpolated (the corrected measures alone); given radii.
The last lines give the angle of the fitted normals to the exact ones on the flat faces and the share of those
whose normal-fit ball reaches the other side of the part (points whose exact normal faces away).

    python benchmarks/flat_voxel_truth.py [--flat 0.1]
"""

from __future__ import annotations

import argparse
import warnings

import numpy as np

import meshcurv
from meshcurv import jets, shapes
from meshcurv.estimators import icc
from meshcurv.topology import MeshTopology


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--flat", type=float, default=0.1, help="flat: own |k| below this share of the largest")
    options = parser.parse_args(argv)
    mesh = shapes.voxel_ellipsoid((8.0, 8.0, 2.0), seed=2)
    vertices, faces = np.asarray(mesh.vertices, float), np.asarray(mesh.faces)
    exact_h = np.asarray(mesh.mean)
    own = np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))
    largest = float(own.max())
    flat = own < options.flat * largest

    def run(**kwargs):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            return meshcurv.principal_curvatures(vertices, faces, method="icc", **kwargs)

    print(
        f"flat vertices: {int(flat.sum())} of {len(vertices)}; own |k| {own[flat].min():.3f}-{own[flat].max():.3f}, "
        f"largest |k| {largest:.3f}; sqrt(voxel x radius of curvature) on the flat faces: median "
        f"{np.median(np.sqrt(1.0 / own[flat])):.2f} voxels\n"
    )
    print("| variant | flat valid | off own | off largest | H median (exact) | error / own k median, p95 | radius |")
    print("|---|--:|--:|--:|--:|--:|--:|")

    def row(name, result):
        side = np.sign(np.einsum("ij,ij->i", result.normals, mesh.normals))
        error = np.abs(result.mean - side * exact_h)
        ok = result.valid & flat
        own_error = error[ok] / own[ok]
        print(
            f"| {name} | {int(ok.sum())} | {int((own_error > 0.5).sum())} | {int((error[ok] / largest > 0.5).sum())} "
            f"| {np.median(result.mean[ok]):.3f} ({np.median(exact_h[ok]):.3f}) | {np.median(own_error):.2f}, "
            f"{np.percentile(own_error, 95):.2f} | {np.median(result.radius[ok]):.2f} |"
        )

    default = run()
    row("default", default)
    fitted = icc.fitted_normals
    try:  # the same radii, the exact normals (at the vertices with a normal of their own)
        icc.fitted_normals = lambda *args, **kwargs: np.where(  # type: ignore[assignment]
            np.isfinite(args[1]).all(axis=1)[:, None], mesh.normals, args[1]
        )
        row("default radii, exact normals", run())
    finally:
        icc.fitted_normals = fitted
    for radius in (2.0, 3.0, 4.0, 5.7):
        row(f"radius {radius:g}", run(radius=radius))

    angle = np.degrees(np.arccos(np.clip(np.abs(np.einsum("ij,ij->i", default.normals, mesh.normals)), 0, 1)))
    print(
        f"\nfitted normals on the flat faces: {np.median(angle[flat]):.1f} degrees off the exact (median), "
        f"{np.percentile(angle[flat], 95):.1f} (95th percentile)"
    )
    topology = MeshTopology.from_faces(faces, n_vertices=len(vertices))
    details: dict = {}
    start = -np.asarray(mesh.normals)  # (any unit frame: only the share of the points facing away is read)
    jets._fit_jets(
        vertices,
        start,
        3.0 * np.asarray(default.radius),
        degree=3,
        iterations=1,
        adjacency=topology.neighbour_lists,
        facing=mesh.normals,
        details=details,
    )
    print(
        f"normal-fit balls (3 r) on the flat faces holding points of the other side: {np.mean(details['away'][flat] > 0):.0%}"
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
