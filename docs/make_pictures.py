"""The pictures of the user guide (docs/guide), made with meshcurv itself: ``make pictures``.

Each picture is computed here from meshcurv's own shapes, the meshes of ``tests/data`` and the tables of
``benchmarks/``, and drawn with :func:`meshcurv.plotting.plot_field` (meshes) or matplotlib (charts).
The other pictures of ``docs/`` come from the command line: ``torus_gaussian.png`` is what ``make demo``
draws, ``spot_mean.png`` is ``meshcurv plot spot.obj --field mean --directions max --view left``, and
``torus_points_gaussian.png`` is ``meshcurv plot`` on 30,000 points sampled on a torus.

Run from the repository's root: ``python docs/make_pictures.py [NAME ...]`` (all by default).
"""

from __future__ import annotations

import pathlib
import sys
import warnings

import numpy as np

import meshcurv
from meshcurv.plotting import plot_field, save_figure

DOCS = pathlib.Path(__file__).resolve().parent
ROOT = DOCS.parent


def _figure(width, height):
    from matplotlib.figure import Figure

    return Figure(figsize=(width, height), dpi=120, layout="constrained")


def _quiet(function, *args, **kwargs):
    """Call ``function`` with its one warning per call kept out of the output (the pictures show defects)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return function(*args, **kwargs)


def dirty_sphere():
    """meshes.md: a sphere with a hole, 200 faces wound the wrong way and a fin; invalid vertices grey."""
    sphere = meshcurv.shapes.icosphere(12)
    vertices, faces = sphere.vertices, sphere.faces.copy()
    centres = vertices[faces].mean(axis=1)
    faces = faces[np.linalg.norm(centres - [0.6, -0.6, 0.53], axis=1) > 0.3]  # a hole, in front of the camera
    faces[:200] = faces[:200, ::-1]  # flipped: turned back by orient="auto"
    top = faces[np.argmax(vertices[faces].mean(axis=1)[:, 2])]
    vertices = np.vstack([vertices, [[0.0, 0.0, 1.4]]])  # a fin: a third face on an edge at the top
    faces = np.vstack([faces, [[top[0], top[1], len(vertices) - 1]]])
    result = _quiet(meshcurv.principal_curvatures, vertices, faces)
    return plot_field(
        vertices,
        faces,
        result.mean,
        view=["iso", "top"],
        up="z",
        limits=(0.8, 1.2),
        label="mean curvature H (exact 1)",
        title=f"a unit sphere with a hole, flipped faces and a fin: {int((~result.valid).sum())} "
        "vertices without an estimate (grey)",
    )


def voxel_ellipsoid():
    """label_images.md: the marching-cubes mesh of a voxelised ellipsoid, the default call's mean curvature."""
    mesh = meshcurv.shapes.voxel_ellipsoid((12.0, 8.0, 6.0), spacing=(1.0, 0.5, 0.5))
    result = _quiet(meshcurv.principal_curvatures, mesh.vertices, mesh.faces)
    return plot_field(
        mesh.vertices,
        mesh.faces,
        result.mean,
        view=["iso", "top"],
        up="z",
        label="mean curvature H (1/voxel)",
        title="marching cubes of a 12 x 8 x 6 ellipsoid, voxels 1 x 0.5 x 0.5: the default call",
    )


def gaussian_shares():
    """integrals.md: each vertex's share of the total Gaussian curvature of spot (it sums to 4 pi)."""
    data = np.load(ROOT / "tests" / "data" / "matgeom" / "spot.npz")
    vertices, faces = data["vertices"], data["faces"]
    result = meshcurv.principal_curvatures(vertices, faces)
    shares = result.vertex_integrals("gaussian")
    total = result.integral("gaussian") / np.pi
    return plot_field(
        vertices,
        faces,
        shares,
        view=["left", "right"],
        up="y",
        label="share of int K dA per vertex",
        title=f"spot.obj: the shares of the total Gaussian curvature sum to {total:.4f} pi",
    )


def batch_summary():
    """batch.md: what a summary row says, per mesh: area-weighted median of H against the exact 1/R."""
    fig = _figure(6.4, 3.6)
    axis = fig.add_subplot()
    for subdivisions, marker in ((3, "o"), (5, "s"), (8, "^")):
        radii = np.array([0.5, 1.0, 2.0, 4.0])
        medians = []
        for radius in radii:
            sphere = meshcurv.shapes.icosphere(subdivisions, radius=radius)
            result = meshcurv.principal_curvatures(sphere.vertices, sphere.faces)
            weights = result.vertex_areas
            order = np.argsort(result.mean)
            cumulative = np.cumsum(weights[order]) / weights.sum()
            medians.append(result.mean[order][np.searchsorted(cumulative, 0.5)])
        axis.plot(1 / radii, medians, marker, label=f"icosphere({subdivisions}): {len(sphere.vertices)} vertices")
    axis.plot([0, 2.2], [0, 2.2], "k-", lw=0.8, label="exact")
    axis.set_xlabel("1 / R (exact mean curvature)")
    axis.set_ylabel("mean_area_median")
    axis.set_title("the summary of 12 spheres: each row's area-weighted median of H")
    axis.legend(fontsize=8)
    return fig


def speed():
    """speed.md: seconds per call at 1M vertices, from the last run of benchmarks/speed.md."""
    names = ["icc (default)", "normal_cycle", "matgeom", "libigl", "MeshLab quadric", "VTK (H, K)", "trueform"]
    seconds = [4.31, 1.34, 1.8, 30.6, 8.47, 1.35, 1.8]  # CPU s, benchmarks/speed.md at 2d31b96
    fig = _figure(6.4, 3.4)
    axis = fig.add_subplot()
    colours = ["tab:blue"] * 3 + ["tab:grey"] * 4
    axis.barh(names[::-1], seconds[::-1], color=colours[::-1])
    axis.set_xscale("log")
    axis.set_xlim(0.3, 60)
    axis.set_xlabel("CPU seconds (log scale), icosphere of 1M vertices, one run")
    axis.set_title("meshcurv (blue) and the peers (grey): benchmarks/speed.md")
    for y, value in enumerate(seconds[::-1]):
        axis.text(value * 1.05, y, f"{value:g} s", va="center", fontsize=8)
    return fig


def matgeom_refinement():
    """matgeom.md: matGeom's numbers shrink with the edge length; normal_cycle's stay at 1/r."""
    counts, matgeom, normal_cycle = [], [], []
    for subdivisions in (2, 4, 8, 16, 32):
        sphere = meshcurv.shapes.icosphere(subdivisions)
        compat = meshcurv.principal_curvatures(sphere.vertices, sphere.faces, method="matgeom")
        ours = meshcurv.principal_curvatures(sphere.vertices, sphere.faces, method="normal_cycle")
        counts.append(len(sphere.vertices))
        matgeom.append(np.median(compat.k_max))
        normal_cycle.append(np.median(ours.k_max))
    fig = _figure(6.4, 3.6)
    axis = fig.add_subplot()
    axis.loglog(counts, normal_cycle, "o-", label='method="normal_cycle" (1/length)')
    axis.loglog(counts, matgeom, "s-", label='method="matgeom" (matGeom\'s C2, dimensionless)')
    axis.axhline(1.0, color="k", lw=0.8, label="exact: 1/r = 1")
    axis.set_xlabel("vertices of the unit icosphere")
    axis.set_ylabel("median k_max")
    axis.set_title("matGeom's numbers shrink as the mesh is refined")
    axis.legend(fontsize=8)
    return fig


PICTURES = {
    "dirty_sphere_mean.png": dirty_sphere,
    "voxel_ellipsoid_mean.png": voxel_ellipsoid,
    "spot_gaussian_shares.png": gaussian_shares,
    "batch_summary.png": batch_summary,
    "speed.png": speed,
    "matgeom_refinement.png": matgeom_refinement,
}


def main(names=()):
    for name in names or PICTURES:
        fig = PICTURES[name]()
        save_figure(fig, DOCS / name, overwrite=True)
        sys.stdout.write(f"wrote docs/{name}\n")


if __name__ == "__main__":
    main(sys.argv[1:])
