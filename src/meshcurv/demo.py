"""The demo: matGeom's torus (torusMesh), its curvatures, a picture.

matGeom's doc runs::

    [v, f] = torusMesh;
    f2 = triangulateFaces(f);
    [c1, c2] = meshCurvatures(v, f2);
    drawMesh(v, f2, 'VertexColor', c1 .* c2);
"""

from __future__ import annotations

import os
import pathlib

import numpy as np

from . import shapes
from .curvature import principal_curvatures
from .io._files import check_output
from .plotting import plot_field, save_figure

__all__ = ["run_demo"]


def run_demo(output: str | os.PathLike = "torus_gaussian.png", *, overwrite: bool = False) -> str:
    """Compute the curvatures of matGeom's default torus and draw its Gaussian curvature.

    The torus is :func:`meshcurv.shapes.torus` (R 30, r 10, 60 x 60), its
    curvatures those of :func:`meshcurv.principal_curvatures` with the
    default method, beside ``method='matgeom'``.

    Parameters
    ----------
    output : str or os.PathLike, default: 'torus_gaussian.png'
        The picture, a PNG whatever the extension, written atomically; its
        folder is created.
    overwrite : bool, default: False
        Replace an existing ``output``.

    Returns
    -------
    str
        A short summary, one line per field (``k_min``, ``k_max``, mean,
        Gaussian): the estimate's range, the exact range and the largest
        error, then matGeom's ranges and the picture's path.

    Raises
    ------
    MeshFileError
        ``output`` exists and ``overwrite`` is False, or is a directory
        (checked before the work).
    MissingDependencyError
        matplotlib is not installed (``pip install 'meshcurv[plot]'``).
    """
    output = pathlib.Path(output)
    output.parent.mkdir(parents=True, exist_ok=True)
    check_output(output, overwrite=overwrite)  # before the work, not after
    torus = shapes.torus()
    result = principal_curvatures(torus.vertices, torus.faces)
    compat = principal_curvatures(torus.vertices, torus.faces, method="matgeom")

    fig = plot_field(
        torus.vertices,
        torus.faces,
        result.gaussian,
        view=["iso", "top"],
        up="z",  # matGeom: z up
        label="Gaussian curvature K (1/length²)",
        title="matGeom's torusMesh (R 30, r 10): K = k_min · k_max",
    )
    save_figure(fig, output, overwrite=overwrite)

    rows = [
        ("k_min", result.k_min, torus.k_min),
        ("k_max", result.k_max, torus.k_max),
        ("mean H", result.mean, torus.mean),
        ("Gaussian K", result.gaussian, torus.gaussian),
    ]
    lines = [
        f"torus R=30 r=10, {torus.vertices.shape[0]} vertices, {torus.faces.shape[0]} triangles, method {result.method}",
        f"{'field':<11} {'min':>10} {'max':>10} {'exact min':>10} {'exact max':>10} {'max |error|':>12}",
    ]
    for name, estimate, exact in rows:
        lines.append(
            f"{name:<11} {estimate.min():>10.5f} {estimate.max():>10.5f} {exact.min():>10.5f} "
            f"{exact.max():>10.5f} {np.abs(estimate - exact).max():>12.2e}"
        )
    lines.append(
        f"matGeom's own numbers (method='matgeom', dimensionless): C1 in [{compat.k_min.min():.4f}, "
        f"{compat.k_min.max():.4f}], C2 in [{compat.k_max.min():.4f}, {compat.k_max.max():.4f}]"
    )
    lines.append(f"picture: {output}")
    return "\n".join(lines)
