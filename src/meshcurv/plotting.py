"""Pictures of meshes coloured by a per-vertex field (matplotlib, an optional extra).

The mesh is rasterised here, with numpy, into an image per view (orthographic
camera, z-buffer, vertex values interpolated across each triangle as matGeom's
``drawMesh(v, f, 'VertexColor', c)`` does, Gouraud shading),
and matplotlib lays out the images, the colour bar and the direction strokes
(its own 3D axes sort whole polygons by depth, wrong where a non-convex
surface hides itself).
"""

from __future__ import annotations

import os
import sys
import textwrap

import numpy as np

from ._adapters import drawn_arrays
from ._validation import check_int_option
from .errors import InvalidMeshError, InvalidOptionError, optional_module
from .io._files import atomic_output, check_output

__all__ = ["plot_field", "save_figure", "choose_up", "VIEWS", "MAX_PIXELS", "MAX_DPI", "Z_UP_RATIO"]

#: The largest side of a view's image, in pixels: a panel of the figure is about 330 points wide, so
#: even a print at 1200 dpi (:data:`MAX_DPI`) needs fewer; 8192 x 8192 already takes gigabytes.
MAX_PIXELS = 8192

#: The highest resolution :func:`save_figure` writes (the figure is about 11 x 4 inches).
MAX_DPI = 1200

#: The memory a view takes while it is drawn: bytes per pixel (z-buffer, face and barycentric weights,
#: interpolated values, RGBA colours) and the rasteriser's chunks of pixel-face pairs (measured:
#: benchmarks/docstring_figures.md).
_BYTES_PER_PIXEL = 80
_BYTES_FIXED = 2**30

#: Named views as (elevation, azimuth) in degrees, matplotlib's convention:
#: the camera looks at the mesh from ``(cos e cos a, cos e sin a, sin e)``.
VIEWS = {
    "iso": (30.0, -60.0),
    "front": (0.0, -90.0),
    "back": (0.0, 90.0),
    "left": (0.0, 180.0),
    "right": (0.0, 0.0),
    "top": (90.0, -90.0),
    "bottom": (-90.0, -90.0),
    "iso-back": (30.0, 120.0),
}

_STROKE_COLOURS = ("black", "#7a7a7a")

#: Rotations that bring each "up" axis to z (the rows are the new x, y, z): with ``up="y"``
#: (the usual convention of OBJ and PLY files) "front" looks at the mesh from +z.
_UP = {
    "z": np.eye(3),
    "y": np.array([[1.0, 0, 0], [0, 0, -1], [0, 1, 0]]),
    "x": np.array([[0, -1.0, 0], [0, 0, -1], [1, 0, 0]]),
}


def _pyplot():
    """The matplotlib module (checked importable); meshcurv never imports pyplot nor changes the backend.

    Figures are :class:`matplotlib.figure.Figure` objects with an Agg canvas of their own, so the
    user's backend (and any open pyplot windows) are left as they are.
    """
    return optional_module("matplotlib", "pictures need matplotlib: pip install 'meshcurv[plot]'")


def choose_up(vertices) -> tuple[str, str]:
    """The axis drawn upwards when none is given, and why.

    Most OBJ and PLY files are made with y up (trimesh, Blender's OBJ export,
    the Stanford and Keenan Crane models); CAD, scanners and medical tools
    often write z up. A mesh is taken as z-up when it is more than
    :data:`Z_UP_RATIO` times as tall along z as along y, else y-up; x is
    never chosen.

    Parameters
    ----------
    vertices : array_like of shape (V, 3)
        V may be 0 (y up).

    Returns
    -------
    axis : {'y', 'z'}
        ``'z'`` when ``ptp(z) > Z_UP_RATIO * ptp(y)`` (a flat y extent with
        some z extent included).
    reason : str
        The ratio found, for a log line.

    Raises
    ------
    InvalidMeshError
        ``vertices`` not of shape (V, 3).
    """
    points = np.asarray(vertices, dtype=float)
    if points.ndim != 2 or points.shape[1] != 3:
        raise InvalidMeshError(f"`vertices` must have shape (V, 3); got {points.shape}")
    extent = np.ptp(points, axis=0) if points.size else np.zeros(3)
    ratio = extent[2] / extent[1] if extent[1] > 0 else np.inf if extent[2] > 0 else 1.0
    if ratio > Z_UP_RATIO:
        return "z", f"the mesh is {ratio:.2f} times as tall along z as along y"
    return "y", f"the mesh is {ratio:.2f} times as tall along z as along y (at most {Z_UP_RATIO:g}: y up)"


#: :func:`choose_up` takes z as the up axis beyond this ratio of the z extent to the y extent.
Z_UP_RATIO = 1.2


def _as_views(view) -> list[tuple[str, tuple[float, float]]]:
    """``view`` as a list of (title, (elevation, azimuth))."""
    single = isinstance(view, str) or (len(view) == 2 and all(isinstance(v, (int, float, np.number)) for v in view))
    views = []
    for item in [view] if single else list(view):
        if isinstance(item, str):
            if item not in VIEWS:
                raise InvalidOptionError(
                    f"unknown view {item!r}; choose one of {', '.join(VIEWS)} or give (elevation, azimuth) in degrees"
                )
            views.append((item, VIEWS[item]))
        else:
            angles = np.asarray(item, dtype=float)
            if angles.shape != (2,) or not np.isfinite(angles).all():
                raise InvalidOptionError(f"a view is a name or (elevation, azimuth) in degrees; got {item!r}")
            views.append((f"elevation {angles[0]:g}°, azimuth {angles[1]:g}°", (angles[0], angles[1])))
    if not views:
        raise InvalidOptionError("`view` is empty; give at least one view")
    return views


def _camera(elevation: float, azimuth: float) -> np.ndarray:
    """Rows: screen right, screen up, towards the eye (orthonormal)."""
    e, a = np.radians([elevation, azimuth])
    eye = np.array([np.cos(e) * np.cos(a), np.cos(e) * np.sin(a), np.sin(e)])
    right = np.array([-np.sin(a), np.cos(a), 0.0])
    up = np.cross(eye, right)
    return np.stack([right, up, eye])


def _vertex_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    cross = np.cross(vertices[faces[:, 1]] - vertices[faces[:, 0]], vertices[faces[:, 2]] - vertices[faces[:, 0]])
    normals = np.stack(
        [np.bincount(faces.ravel(), np.repeat(cross[:, k], 3), minlength=len(vertices)) for k in range(3)], axis=1
    )
    return normals / np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), np.finfo(float).tiny)


class _Raster:
    """One view of a mesh rasterised with a z-buffer.

    Attributes ``face`` (-1 for background), ``weights`` (barycentric, (H, W, 3))
    and ``depth`` are per pixel; ``to_pixels`` maps points to the pixel grid.
    """

    def __init__(self, vertices, faces, camera, *, pixels: int, chunk: int = 2**22):
        screen = vertices @ camera.T
        self._frame(screen, pixels)
        points = self.to_pixels(screen)
        n_pixels = self.width * self.height
        self.depth = np.full(n_pixels, -np.inf)
        self.face = np.full(n_pixels, -1)
        self.weights = np.zeros((n_pixels, 3))

        corners = points[faces]  # (F, 3, 3): x, y in pixels, depth
        x, y = corners[:, :, 0], corners[:, :, 1]
        area = (x[:, 1] - x[:, 0]) * (y[:, 2] - y[:, 0]) - (x[:, 2] - x[:, 0]) * (y[:, 1] - y[:, 0])
        x_first = np.ceil(x.min(axis=1) - 0.5).astype(np.int64).clip(0, self.width)
        x_last = np.floor(x.max(axis=1) - 0.5).astype(np.int64).clip(-1, self.width - 1)
        y_first = np.ceil(y.min(axis=1) - 0.5).astype(np.int64).clip(0, self.height)
        y_last = np.floor(y.max(axis=1) - 0.5).astype(np.int64).clip(-1, self.height - 1)
        columns = np.maximum(x_last - x_first + 1, 0)
        counts = columns * np.maximum(y_last - y_first + 1, 0)
        drawn = np.flatnonzero((counts > 0) & (np.abs(area) > 1e-12))
        bounds = np.searchsorted(np.cumsum(counts[drawn]), np.arange(chunk, counts[drawn].sum() + chunk, chunk))
        for part in np.split(drawn, np.unique(bounds)[:-1] + 1):  # a few chunks bound the memory
            if part.size:
                self._draw(part, corners[part], area[part], x_first[part], y_first[part], columns[part], counts[part])
        self.face = self.face.reshape(self.height, self.width)
        self.weights = self.weights.reshape(self.height, self.width, 3)
        self.depth = self.depth.reshape(self.height, self.width)

    @classmethod
    def of_points(cls, points, camera, *, pixels: int, spacing: np.ndarray, chunk: int = 2**22) -> _Raster:
        """One view of a point cloud: each point a disc of its ``spacing``, the nearest one per pixel.

        ``face`` holds the index of the point seen at each pixel (weights ``(1, 0, 0)``), so that
        :meth:`interpolate` with the faces ``(i, i, i)`` reads the points' values.
        """
        raster = cls.__new__(cls)
        screen = points @ camera.T
        raster._frame(screen, pixels)
        scale = raster.scale
        pixel = raster.to_pixels(screen)
        n_pixels = raster.width * raster.height
        depth = np.full(n_pixels, -np.inf)
        face = np.full(n_pixels, -1)
        centre = np.floor(pixel[:, :2]).astype(np.int64)
        level = ((screen[:, 2] - raster.depth_low) * raster.depth_step).astype(np.int64).clip(0, 2**30 - 1)
        radii = np.clip(np.round(2 * spacing * scale) / 2, 0.5, MAX_DISC_PIXELS)  # half-pixel steps
        for radius in np.unique(radii):  # one disc of pixel offsets per radius class
            reach = int(np.ceil(radius))
            dx, dy = np.meshgrid(np.arange(-reach, reach + 1), np.arange(-reach, reach + 1))
            keep = dx**2 + dy**2 <= radius**2 + 0.25
            offsets = np.column_stack([dx[keep], dy[keep]])
            members = np.flatnonzero(radii == radius)
            step = max(1, chunk // len(offsets))
            for start in range(0, members.size, step):  # chunks bound the memory and the keys' 23 bits
                rows = members[start : start + step]
                x = (centre[rows, 0][:, None] + offsets[:, 0]).ravel()
                y = (centre[rows, 1][:, None] + offsets[:, 1]).ravel()
                owner = np.repeat(rows, len(offsets))
                inside = (x >= 0) & (x < raster.width) & (y >= 0) & (y < raster.height)
                x, y, owner = x[inside], y[inside], owner[inside]
                target = y * raster.width + x
                best = np.full(n_pixels, -1, dtype=np.int64)
                np.maximum.at(best, target, (level[owner] << 23) | np.arange(owner.size))
                winner = best[best >= 0] & (2**23 - 1)
                winner = winner[screen[owner[winner], 2] > depth[target[winner]]]
                depth[target[winner]] = screen[owner[winner], 2]
                face[target[winner]] = owner[winner]
        raster.depth = depth.reshape(raster.height, raster.width)
        raster.face = face.reshape(raster.height, raster.width)
        raster.weights = np.zeros((raster.height, raster.width, 3))
        raster.weights[..., 0] = 1.0
        return raster

    def _frame(self, screen: np.ndarray, pixels: int) -> None:
        """The image's size, scale and offset for ``screen`` points (right, up, depth), and the depth scale."""
        low, high = screen[:, :2].min(axis=0), screen[:, :2].max(axis=0)
        span = np.maximum(high - low, 1e-12 * max(float((high - low).max()), 1e-300))
        # no supersampling: the image has about twice the resolution of its panel in the figure,
        # and matplotlib's antialiased resampling smooths the edges when it is drawn
        scale = (pixels - 2) / span.max()  # one pixel of margin each side
        self.width, self.height = np.ceil(span * scale).astype(int) + 2
        self.offset = low - 1 / scale
        self.scale = scale
        right, top = self.offset + np.array([self.width, self.height]) / scale
        self.extent = (self.offset[0], right, self.offset[1], top)
        self.depth_low = screen[:, 2].min()
        self.depth_step = (2**30 - 1) / max(np.ptp(screen[:, 2]), 1e-300)

    def to_pixels(self, screen: np.ndarray) -> np.ndarray:
        """(n, 3) screen coordinates (right, up, depth) -> (n, 3) pixel x, pixel y, depth."""
        return np.column_stack([(screen[:, :2] - self.offset) * self.scale, screen[:, 2]])

    def _draw(self, faces, corners, area, x_first, y_first, columns, counts):
        # barycentric weights w1, w2 and depth are affine in the pixel centre (cx, cy): one row of
        # coefficients per face, repeated for each pixel of its bounding box (np.repeat streams;
        # a gather would not)
        x, y, z = corners[:, :, 0], corners[:, :, 1], corners[:, :, 2]
        p1, q1 = (y[:, 2] - y[:, 0]) / area, -(x[:, 2] - x[:, 0]) / area
        p2, q2 = -(y[:, 1] - y[:, 0]) / area, (x[:, 1] - x[:, 0]) / area
        r1, r2 = -(p1 * x[:, 0] + q1 * y[:, 0]), -(p2 * x[:, 0] + q2 * y[:, 0])
        dz1, dz2 = z[:, 1] - z[:, 0], z[:, 2] - z[:, 0]
        depth_plane = (p1 * dz1 + p2 * dz2, q1 * dz1 + q2 * dz2, z[:, 0] + r1 * dz1 + r2 * dz2)
        plane = np.column_stack([p1, q1, r1, p2, q2, r2, *depth_plane, x_first + 0.5, y_first + 0.5, faces])
        c = np.repeat(plane, counts, axis=0)
        local = np.arange(c.shape[0]) - np.repeat(np.cumsum(counts) - counts, counts)
        row, column = np.divmod(local, np.repeat(columns, counts))
        cx, cy = c[:, 9] + column, c[:, 10] + row
        w1 = c[:, 0] * cx + c[:, 1] * cy + c[:, 2]
        w2 = c[:, 3] * cx + c[:, 4] * cy + c[:, 5]
        inside = np.flatnonzero((w1 >= -1e-9) & (w2 >= -1e-9) & (w1 + w2 <= 1 + 1e-9))
        cx, cy, w1, w2, c = cx[inside], cy[inside], w1[inside], w2[inside], c[inside]
        pixel = (cy - 0.5).astype(np.int64) * self.width + (cx - 0.5).astype(np.int64)
        depth = c[:, 6] * cx + c[:, 7] * cy + c[:, 8]
        # nearest per pixel: the largest (quantised depth, candidate) key, by np.maximum.at
        level = ((depth - self.depth_low) * self.depth_step).astype(np.int64).clip(0, 2**30 - 1)
        best = np.full(self.depth.size, -1, dtype=np.int64)
        np.maximum.at(best, pixel, (level << 23) | np.arange(depth.size))
        winner = best[best >= 0] & (2**23 - 1)
        winner = winner[depth[winner] > self.depth[pixel[winner]]]
        target = pixel[winner]
        self.depth[target] = depth[winner]
        self.face[target] = c[winner, 11].astype(np.int64)
        self.weights[target] = np.column_stack([1 - w1[winner] - w2[winner], w1[winner], w2[winner]])

    def interpolate(self, faces: np.ndarray, vertex_values: np.ndarray) -> np.ndarray:
        """(H, W, ...) vertex values interpolated at each covered pixel (NaN elsewhere)."""
        covered = self.face >= 0
        shape = self.face.shape + vertex_values.shape[1:]
        out = np.full(shape, np.nan)
        corners = vertex_values[faces[self.face[covered]]]  # (n, 3, ...)
        weights = self.weights[covered].reshape((-1, 3) + (1,) * (vertex_values.ndim - 1))
        out[covered] = (weights * corners).sum(axis=1)
        return out


def _colour_limits(values, percentiles, limits=None):
    """``(low, high, signed)``: the fixed ``limits``, or the percentiles (symmetric about 0 when signed)."""
    if limits is not None:
        low, high = limits
        return low, high, low < 0 < high
    finite = values[np.isfinite(values)]
    low, high = np.percentile(finite, percentiles) if finite.size else (0.0, 1.0)
    signed = low < 0 < high
    if signed:
        bound = max(abs(low), abs(high))
        low, high = -bound, bound
    if high <= low:
        high = low + 1.0
    return float(low), float(high), signed


def check_percentiles(percentiles) -> tuple[float, float]:
    """``percentiles`` as ``(low, high)`` floats with ``0 <= low < high <= 100``, or an InvalidOptionError."""
    try:
        low, high = (float(value) for value in percentiles)
    except (TypeError, ValueError):
        raise InvalidOptionError(f"`percentiles` must be two numbers (low, high); got {percentiles!r}") from None
    if not 0 <= low < high <= 100:
        raise InvalidOptionError(f"`percentiles` must satisfy 0 <= low < high <= 100; got {percentiles!r}")
    return low, high


def _check_limits(limits):
    if limits is None:
        return None
    try:
        low, high = (float(x) for x in limits)
    except (TypeError, ValueError):
        raise InvalidOptionError(f"`limits` must be (low, high); got {limits!r}") from None
    if not (np.isfinite(low) and np.isfinite(high) and low < high):
        raise InvalidOptionError(f"`limits` must be finite with low < high; got {limits!r}")
    return low, high


def _colormap(matplotlib, cmap, signed: bool):
    name = cmap or ("RdBu_r" if signed else "viridis")
    if not isinstance(name, (str, matplotlib.colors.Colormap)):
        raise InvalidOptionError(f"`cmap` must be a name of matplotlib.colormaps or a Colormap; got {name!r}")
    try:
        colormap = matplotlib.colormaps[name] if isinstance(name, str) else name
    except KeyError:
        known = sorted(matplotlib.colormaps)
        raise InvalidOptionError(
            f"unknown colour map {name!r}; choose a name of matplotlib.colormaps "
            f"({len(known)} of them, e.g. viridis, cividis, magma, RdBu_r, coolwarm)"
        ) from None
    return colormap.with_extremes(bad="0.6")


def _auto_pixels(panel_pixels: float) -> int:
    """The image side of a view: twice its panel's side in the saved picture, within memory and 3000."""
    pixels = int(np.clip(round(2 * panel_pixels), 16, _AUTO_MAX_PIXELS))
    available = _available_memory()
    if available is not None:
        fits = int(np.sqrt(max(available - _BYTES_FIXED, 0) / _BYTES_PER_PIXEL))
        pixels = max(16, min(pixels, fits))
    return pixels


#: The largest image of a view when ``pixels`` is not given (1.7 GiB while drawn).
_AUTO_MAX_PIXELS = 3000

#: The figure's size: per view, and for the colour bar and margins, in inches.
_PANEL_INCHES = 3.3
_EXTRA_INCHES = 1.2
_HEIGHT_INCHES = 4.2


def _fitted_lines(text: str, bar_height_points: float, fontsize: float) -> list[str]:
    """``text`` in lines no longer than the colour bar (about 0.55 em a character)."""
    width = max(12, int(bar_height_points / (0.55 * fontsize)))
    return [line for paragraph in text.split("\n") for line in textwrap.wrap(paragraph, width)]


def plot_field(
    vertices,
    faces,
    values,
    *,
    ax=None,
    view=(30.0, -60.0),
    title: str | None = None,
    label: str = "",
    percentiles: tuple[float, float] = (2.0, 98.0),
    limits=None,
    cmap: str | None = None,
    directions=None,
    up: str | None = None,
    pixels: int | None = None,
    dpi: int = 100,
    normals=None,
):
    """Draw a triangle mesh (or a point cloud) coloured by a per-vertex field, with a colour bar.

    Vertex values are interpolated across each triangle (matGeom's
    ``drawMesh(v, f, 'VertexColor', c)``), so matGeom's demo is one call:
    ``plot_field(v, f, c1 * c2)``. Signed fields get a diverging colour map
    centred on zero; the limits are robust (the given percentiles of the
    finite values, stated on the colour bar) unless fixed by ``limits``,
    values beyond them take the end colours, and NaN is grey. The figure is
    a :class:`matplotlib.figure.Figure` with its own Agg canvas: pyplot is
    not imported and the backend is not changed.

    Parameters
    ----------
    vertices : array_like of shape (V, 3), or a mesh or point cloud object
        Or, with ``faces`` None, what :func:`meshcurv.principal_curvatures`
        takes alone (a trimesh ``Trimesh``, PyVista ``PolyData``, meshio
        ``Mesh`` or Open3D ``TriangleMesh``: its faces are drawn) or
        :func:`meshcurv.point_cloud_curvatures` (an object of points alone).
    faces : array_like of shape (F, 3) or (F, k), list of index lists, MeshTopology, or None
        0-based; polygons are fan-triangulated (with a ``TriangulationWarning``).
        None (or empty) with an array of vertices draws a point cloud: each
        point a disc of about its spacing (the median distance to its nearest
        neighbour), the nearest point per pixel.
    values : array_like of shape (V,)
    ax : matplotlib Axes, optional
        A 2D axes to draw one view into; by default a new figure is made, with
        one panel per view (3.3 x 4.2 inches each, and 1.2 inches for the
        colour bar).
    view : str, (elevation, azimuth), or a sequence of them, default: (30, -60)
        A name of :data:`VIEWS` (``'iso'``, ``'front'``, ``'back'``, ``'left'``,
        ``'right'``, ``'top'``, ``'bottom'``, ``'iso-back'``) or angles in
        degrees; a sequence draws several views side by side with one colour bar.
    title : str, optional
        Figure title.
    label : str
        Colour-bar label (wrapped to the bar's length).
    percentiles : (float, float), default: (2, 98)
        Colour limits as percentiles of the finite values (symmetric about 0
        when they have opposite signs).
    limits : (float, float), optional
        Fixed colour limits (low < high), instead of ``percentiles``: the same
        colours mean the same values across pictures.
    cmap : str or Colormap, optional
        A name of ``matplotlib.colormaps``. Default ``'RdBu_r'`` when the
        limits have opposite signs, ``'viridis'`` otherwise.
    directions : (V, 3) array or dict of str to (V, 3) arrays, optional
        Tangent directions drawn as short strokes at evenly spread visible
        vertices (a dict of at most two, e.g. ``{"k_max": r.dir_max, "k_min":
        r.dir_min}``, labelled in a legend). Directions are defined up to sign.
    up : {'z', 'y', 'x'}, optional
        The coordinate axis drawn upwards. Default: chosen from the mesh by
        :func:`choose_up` (z when the mesh is more than 1.2 times as tall
        along z as along y, else y, the convention of most OBJ and PLY
        files). With ``'y'``, ``'front'`` looks from +z.
    pixels : int, optional
        Size of the longer side of each view's image, from 16 to
        :data:`MAX_PIXELS` (8192), within the memory available (about 80
        bytes a pixel and 1 GiB while a view is drawn). Default: twice the
        panel's size in the saved picture (660 at 100 dpi), at most 3000.
    dpi : int, default: 100
        Dots per inch of the figure, 10 to :data:`MAX_DPI`, which
        :func:`save_figure` keeps: a picture of one view is ``4.5 * dpi``
        pixels wide, of ``n`` views ``(3.3 n + 1.2) * dpi``.
    normals : array_like of shape (V, 3), optional
        Unit normals for the shading (e.g. ``result.normals``). Default: the
        mesh's area-weighted vertex normals; a point cloud without them is
        drawn unshaded.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    InvalidOptionError
        ``values`` or ``directions`` without one row per vertex, more than two
        direction fields, an unknown view, colour map or ``up``, several
        views with ``ax``, ``pixels`` below 16, above :data:`MAX_PIXELS` or
        beyond the memory available, ``dpi`` out of range, ``limits`` not
        finite or not increasing.
    InvalidMeshError
        Unusable vertices or faces.
    MissingDependencyError
        matplotlib is not installed (``pip install 'meshcurv[plot]'``).

    Examples
    --------
    >>> import meshcurv
    >>> from meshcurv.plotting import plot_field
    >>> torus = meshcurv.shapes.torus()
    >>> r = meshcurv.principal_curvatures(torus.vertices, torus.faces)
    >>> fig = plot_field(torus.vertices, torus.faces, r.k_min * r.k_max, label="K", view=["iso", "top"])
    >>> len(fig.axes)          # two views and the colour bar
    3
    >>> [round(x) for x in fig.get_size_inches() * fig.dpi]   # pixels of the saved picture
    [780, 420]
    """
    matplotlib = _pyplot()
    from matplotlib.cm import ScalarMappable
    from matplotlib.colors import Normalize
    from matplotlib.lines import Line2D

    points, drawn = drawn_arrays(vertices, faces, stacklevel=3)
    cloud = drawn is None
    triangles = np.repeat(np.arange(points.shape[0])[:, None], 3, axis=1) if drawn is None else drawn
    for text, name in ((title, "title"), (label, "label")):
        if text is not None and not isinstance(text, str):
            raise InvalidOptionError(f"`{name}` must be a string; got {type(text).__name__}")
    try:
        values = np.asarray(values, dtype=float)
    except (TypeError, ValueError):
        raise InvalidOptionError(
            f"`values` must be numbers, one per vertex; got a {type(values).__name__} of others"
        ) from None
    if values.shape != (points.shape[0],):
        raise InvalidOptionError(f"`values` must have shape ({points.shape[0]},), one per vertex; got {values.shape}")
    strokes = _as_directions(directions, points.shape[0])
    views = _as_views(view)
    if ax is not None and len(views) > 1:
        raise InvalidOptionError(f"`ax` takes one view; got {len(views)} (leave `ax` out for several panels)")
    dpi = check_int_option(dpi, "dpi", minimum=10, maximum=MAX_DPI)
    if pixels is not None:
        pixels = _check_pixels(pixels)
    limits = _check_limits(limits)
    percentiles = check_percentiles(percentiles)
    if up is None:
        up, _ = choose_up(points)
    if up not in _UP:
        raise InvalidOptionError(f"`up` must be one of 'z', 'y', 'x'; got {up!r} (or None: chosen from the mesh)")
    rotation = _UP[up]
    if normals is not None:
        normals = np.asarray(normals, dtype=float)
        if normals.shape != points.shape:
            raise InvalidOptionError(f"`normals` must have shape {points.shape}, one per vertex; got {normals.shape}")
        normals = np.where(np.isfinite(normals), normals, 0.0) @ rotation.T
    points = points @ rotation.T
    strokes = {name: field @ rotation.T for name, field in strokes.items()}

    low, high, signed = _colour_limits(values, percentiles, limits)
    colormap = _colormap(matplotlib, cmap, signed)
    norm = Normalize(low, high)
    if normals is None:
        normals = _vertex_normals(points, triangles) if not cloud else None
    spacing = _point_spacing(points) if cloud else None
    center = (points.min(axis=0) + points.max(axis=0)) / 2

    if ax is None:
        from matplotlib.backends.backend_agg import FigureCanvasAgg
        from matplotlib.figure import Figure

        fig = Figure(
            figsize=(_PANEL_INCHES * len(views) + _EXTRA_INCHES, _HEIGHT_INCHES), dpi=dpi, layout="constrained"
        )
        FigureCanvasAgg(fig)
        axes = list(fig.subplots(1, len(views), squeeze=False)[0])
        panel_pixels = _PANEL_INCHES * dpi
    else:
        fig, axes = ax.figure, [ax]
        box = ax.get_position()
        width, height = fig.get_size_inches()
        panel_pixels = max(box.width * width, box.height * height) * fig.dpi
    if pixels is None:
        pixels = _auto_pixels(panel_pixels)
    centred = points - center
    for axis, (name, angles) in zip(axes, views):
        camera = _camera(*angles)
        _draw_view(
            axis, centred, triangles, values, normals, camera, colormap, norm, strokes, pixels=pixels, spacing=spacing
        )
        if len(views) > 1:
            axis.set_title(name, fontsize=9)
    mappable = ScalarMappable(norm=norm, cmap=colormap)
    bar = fig.colorbar(mappable, ax=axes, shrink=0.8, pad=0.02, aspect=30)
    how = f"percentiles {percentiles[0]:g}-{percentiles[1]:g}{', centred on 0' if signed else ''}"
    bar_points = 0.8 * (fig.get_size_inches()[1] - 0.9) * 72  # the bar's length, titles and margins aside
    limit_lines = (
        [f"colour limits {low:.3g} to {high:.3g} (fixed)"]
        if limits is not None
        else [f"colour limits {low:.3g} to {high:.3g}:", *_fitted_lines(how, bar_points, 8)]
    )
    lines = [*_fitted_lines(label, bar_points, 8), *limit_lines]
    bar.set_label("\n".join(lines), fontsize=8)
    bar.ax.tick_params(labelsize=8)
    if strokes:
        handles = [
            Line2D([], [], color=colour, lw=1.2, label=f"{name} direction")
            for (name, _), colour in zip(strokes.items(), _STROKE_COLOURS)
        ]
        if ax is None:
            fig.legend(handles=handles, loc="outside lower center", ncols=len(handles), fontsize=8, frameon=False)
        else:
            ax.legend(handles=handles, loc="lower left", fontsize=7, framealpha=0.8)
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


def _check_pixels(pixels) -> int:
    """``pixels`` as an int in [16, :data:`MAX_PIXELS`] whose image fits in the memory available."""
    pixels = check_int_option(pixels, "pixels", minimum=16, maximum=MAX_PIXELS)
    needed = pixels * pixels * _BYTES_PER_PIXEL + _BYTES_FIXED
    available = _available_memory()
    if available is not None and needed > available:
        raise InvalidOptionError(
            f"`pixels`={pixels} needs about {needed / 2**30:.1f} GiB for each view; "
            f"{available / 2**30:.1f} GiB of memory is available: give fewer pixels"
        )
    return pixels


def _available_memory() -> int | None:
    """The bytes of memory available (Linux: MemAvailable), or None where it cannot be known."""
    try:
        with open("/proc/meminfo") as meminfo:
            for line in meminfo:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    return None


def _as_directions(directions, n_vertices: int) -> dict[str, np.ndarray]:
    if directions is None:
        return {}
    fields = dict(directions) if isinstance(directions, dict) else {"principal": directions}
    if len(fields) > 2:
        raise InvalidOptionError(f"`directions` takes at most two fields; got {len(fields)}")
    out = {}
    for name, field in fields.items():
        array = np.asarray(field, dtype=float)
        if array.shape != (n_vertices, 3):
            raise InvalidOptionError(
                f"`directions` arrays must have shape ({n_vertices}, 3); got {array.shape} for {name!r}"
            )
        out[name] = array
    return out


def _point_spacing(points: np.ndarray) -> np.ndarray:
    """(N,) the disc radius of each point: the distance to its :data:`DISC_NEIGHBOUR` th nearest neighbour.

    Random samples leave holes between the nearest neighbours; the few next
    ones close them, where the cloud is dense as where it is sparse.
    """
    from scipy.spatial import cKDTree

    distances, _ = cKDTree(points).query(points, k=DISC_NEIGHBOUR + 1)
    radius = distances[:, -1]
    finite = radius[np.isfinite(radius) & (radius > 0)]
    return np.where(np.isfinite(radius), radius, np.median(finite) if finite.size else 0.0)


#: The disc of a point in a picture of a point cloud reaches its this-th nearest neighbour.
DISC_NEIGHBOUR = 5

#: The largest disc of a point, in pixels (a lone point far from the others stays a point).
MAX_DISC_PIXELS = 12.0


def _draw_view(axis, points, triangles, values, normals, camera, colormap, norm, strokes, *, pixels, spacing=None):
    from matplotlib.collections import LineCollection

    if spacing is None:
        raster = _Raster(points, triangles, camera, pixels=pixels)
    else:  # a point cloud: discs of about the spacing
        raster = _Raster.of_points(points, camera, pixels=pixels, spacing=spacing)
    covered = raster.face >= 0
    # Gouraud shading: the light is computed at the vertices and interpolated with the values
    light = camera[2] + 0.45 * camera[1] - 0.3 * camera[0]
    light /= np.linalg.norm(light)
    shade = np.abs(normals @ light) if normals is not None else np.ones(len(points))
    both = raster.interpolate(triangles, np.column_stack([values, shade]))
    colours = colormap(norm(np.ma.masked_invalid(both[..., 0])))
    colours[covered, :3] *= (0.45 + 0.55 * both[covered, 1])[:, None]
    colours[~covered] = 0.0
    axis.imshow(colours.clip(0, 1), origin="lower", extent=raster.extent, interpolation="antialiased")
    for field, colour in zip(strokes.values(), _STROKE_COLOURS):
        segments = _strokes(
            raster, points, field, camera, normals if normals is not None else np.tile(camera[2], (len(points), 1))
        )
        axis.add_collection(
            LineCollection(
                segments,  # type: ignore[arg-type]  # matplotlib's stubs want a sequence; an (N, 2, 2) array is documented
                colors=colour,
                linewidths=0.8,
                capstyle="round",
            )
        )
    axis.set_xlim(*raster.extent[:2])
    axis.set_ylim(*raster.extent[2:])
    axis.set_aspect("equal")
    axis.set_axis_off()


def _strokes(raster, points, directions, camera, normals, *, per_side: int = 30) -> np.ndarray:
    """(n, 2, 2) segments through evenly spread visible vertices along their projected directions."""
    pixel = raster.to_pixels(points @ camera.T)
    column = np.clip(pixel[:, 0].astype(int), 0, raster.width - 1)
    row = np.clip(pixel[:, 1].astype(int), 0, raster.height - 1)
    depth_range = np.ptp(raster.depth[np.isfinite(raster.depth)]) if np.isfinite(raster.depth).any() else 1.0
    visible = pixel[:, 2] >= raster.depth[row, column] - 2e-3 * max(depth_range, 1e-300)
    visible &= np.isfinite(directions).all(axis=1) & (normals @ camera[2] > 0.2)
    cell = max(raster.width, raster.height) / per_side
    candidates = np.flatnonzero(visible)
    cells = (pixel[candidates, 1] // cell) * (per_side + 1) + pixel[candidates, 0] // cell
    centre_distance = np.hypot(*(((pixel[candidates, :2] / cell) % 1) - 0.5).T)
    order = np.lexsort((centre_distance, cells))
    chosen = candidates[order[np.r_[True, cells[order][1:] != cells[order][:-1]]]]
    flat = directions[chosen] @ camera[:2].T  # foreshortened as seen
    half = 0.42 * cell / raster.scale * flat
    middle = points[chosen] @ camera[:2].T
    return np.stack([middle - half, middle + half], axis=1)


def save_figure(fig, path, *, overwrite: bool = False, dpi: int | None = None):
    """Save ``fig`` as a PNG atomically (temporary file, then rename) and close it.

    Parameters
    ----------
    fig : matplotlib.figure.Figure
    path : str or os.PathLike
    overwrite : bool, default: False
        Replace an existing file.
    dpi : int, optional
        Dots per inch, from 10 to :data:`MAX_DPI` (1200); the figure's own
        (``plot_field(..., dpi=)``) when not given, whatever matplotlib's
        ``savefig.dpi`` setting.

    Returns
    -------
    pathlib.Path

    Raises
    ------
    MeshFileError
        ``path`` exists (without ``overwrite``; also when another process
        wrote it while the figure was being saved), is a directory, or its
        folder does not exist.
    InvalidOptionError
        ``dpi`` outside 10 to :data:`MAX_DPI`.
    """
    _pyplot()
    dpi = fig.dpi if dpi is None else check_int_option(dpi, "dpi", minimum=10, maximum=MAX_DPI)
    path = check_output(os.fspath(path), overwrite=overwrite)
    try:
        with atomic_output(path, overwrite=overwrite) as temporary:  # no silent replacement of a file made meanwhile
            fig.savefig(temporary, format="png", dpi=dpi)
    finally:
        pyplot = sys.modules.get("matplotlib.pyplot")
        if pyplot is not None:  # a figure of the user's pyplot: closed there (ours are not pyplot's)
            pyplot.close(fig)
    return path
