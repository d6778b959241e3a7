"""Pictures of meshes coloured by a per-vertex field (matplotlib, an optional extra)."""

from __future__ import annotations

import numpy as np

from .errors import MissingDependencyError

__all__ = ["plot_field"]


def _pyplot():
    try:
        import matplotlib

        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt
    except ImportError:
        raise MissingDependencyError(
            "pictures need matplotlib: pip install 'meshcurv[plot]'"
        ) from None
    return plt


def plot_field(vertices, faces, values, *, ax=None, title: str | None = None, label: str = "",
               percentiles: tuple[float, float] = (2.0, 98.0), view: tuple[float, float] = (30.0, -60.0),
               cmap: str | None = None):
    """Draw a triangle mesh coloured by a per-vertex field, with a colour bar.

    Each face takes the mean of its vertex values (matGeom's
    ``drawMesh(v, f, 'VertexColor', c)`` interpolates; at these resolutions the
    two look alike). Signed fields get a diverging colour map centred on zero;
    the limits are robust (the given percentiles of the finite values, stated on
    the colour bar), values beyond them are clipped to the end colours, and NaN
    faces are grey.

    Parameters
    ----------
    vertices : (V, 3) array
    faces : (F, 3) int array
    values : (V,) array
    ax : matplotlib 3D axes, optional
        Drawn into when given; otherwise a new figure is made.
    title, label : str
        Axes title and colour-bar label.
    percentiles : (float, float), default: (2, 98)
        Colour limits as percentiles of the finite values.
    view : (elevation, azimuth), default: (30, -60)
    cmap : str, optional
        Default ``'RdBu_r'`` centred on zero when the values change sign,
        ``'viridis'`` otherwise.

    Returns
    -------
    matplotlib.figure.Figure
    """
    plt = _pyplot()
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    vertices = np.asarray(vertices, dtype=float)
    faces = np.asarray(faces)
    values = np.asarray(values, dtype=float)
    finite = values[np.isfinite(values)]
    low, high = np.percentile(finite, percentiles) if finite.size else (0.0, 1.0)
    signed = low < 0 < high
    if signed:
        bound = max(abs(low), abs(high))
        low, high = -bound, bound
    if high <= low:
        high = low + 1.0
    colormap = plt.get_cmap(cmap or ("RdBu_r" if signed else "viridis")).with_extremes(bad="0.7")
    face_values = values[faces].mean(axis=1)
    norm = plt.Normalize(low, high)
    colours = colormap(norm(np.ma.masked_invalid(face_values)))
    # light the faces a little so that the shape reads
    normals = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), np.finfo(float).tiny)
    elev, azim = np.radians(view)
    light = np.array([np.cos(elev) * np.cos(azim), np.cos(elev) * np.sin(azim), np.sin(elev)])
    shade = 0.65 + 0.35 * np.abs(normals @ light)
    colours[:, :3] *= shade[:, None]

    if ax is None:
        fig = plt.figure(figsize=(7, 5.5), dpi=110)
        ax = fig.add_subplot(projection="3d")
    else:
        fig = ax.figure
    ax.add_collection3d(Poly3DCollection(vertices[faces], facecolors=colours, edgecolors="none"))
    lo, hi = vertices.min(axis=0), vertices.max(axis=0)
    span = np.maximum(hi - lo, 1e-3 * (hi - lo).max())
    ax.set_xlim(lo[0], lo[0] + span[0])
    ax.set_ylim(lo[1], lo[1] + span[1])
    ax.set_zlim(lo[2], lo[2] + span[2])
    ax.set_box_aspect(span, zoom=1.25)
    ax.view_init(*view)
    ax.set_axis_off()
    mappable = plt.cm.ScalarMappable(norm=norm, cmap=colormap)
    bar = fig.colorbar(mappable, ax=ax, shrink=0.7, pad=0.02)
    bar.set_label(f"{label}\ncolour limits: percentiles {percentiles[0]:g} to {percentiles[1]:g}")
    if title:
        ax.set_title(title)
    return fig
