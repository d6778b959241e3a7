"""An interactive 3D view of the curvatures in one self-contained HTML file (WebGL2, no network).

:func:`write_html` writes a page that opens from disk in any current browser,
offline: the script (``_viewer.js`` beside this module, plain WebGL2) and the
data are inside the page; nothing is fetched (the page's Content-Security-Policy
forbids it). In the page: left drag rotates, right (or shift) drag pans, the
wheel zooms, a double click resets the view; a menu picks the field (k_min,
k_max, mean, gaussian, shape_index, curvedness), two boxes set the colour
limits, another menu draws the principal directions, and the value under the
cursor is shown. Given the results of several radii (:func:`meshcurv.multiscale_curvatures`),
a menu picks the scale; the colour limits stay when the scale changes, so that the
scales compare.

Per vertex the page stores the position (float32, relative to the bounding
box's centre, recorded as ``offset``), ``k_min`` and ``k_max`` (float32; the
other fields are computed from them in the page) and the reason a vertex has
no value (uint8); the triangles as deflated uint32 differences of consecutive
indices (a point cloud: int8 normals instead); principal directions for a
spatially even subsample of at most ``max_directions`` vertices; all base64.
The curvatures, reasons and directions of the scales after the first are stored
again under the same names with the suffix ``_s1``, ``_s2``, ...

The address can set the page's state: ``page.html#field=gaussian&lo=-0.01&hi=0.01&directions=both``
(also ``scale`` (its index), ``elevation``, ``azimuth``, ``zoom``, and ``probe=X,Y``, the vertex under that pixel). The
element ``#status`` says ``data-state="ok"`` (or ``"error"`` and why), with the time to the
first frame and the probe's reading, so a page can be checked headless::

    chromium --headless=new --virtual-time-budget=10000 --dump-dom 'file:///.../page.html#probe=600,300'
"""

from __future__ import annotations

import base64
import html
import importlib.resources
import json
import logging
import pathlib
import re
import zlib
from collections.abc import Sequence

import numpy as np

from ._adapters import drawn_arrays
from ._validation import check_choice
from .curvature import principal_curvatures
from .errors import InvalidMeshError, InvalidOptionError, MeshFileError
from .io._files import atomic_output, check_output
from .io.fields import FIELDS
from .plotting import check_percentiles, choose_up
from .pointcloud import point_cloud_curvatures
from .result import INVALID_REASONS, CurvatureResult, parameter_text

__all__ = ["write_html", "VIEWER_FIELDS"]

logger = logging.getLogger(__name__)

#: The fields the page can show, in the order of its menu.
VIEWER_FIELDS = ("k_min", "k_max", "mean", "gaussian", "shape_index", "curvedness")

#: Fields without a sign (a sequential colour map from the 2nd percentile); the others are signed
#: (a diverging map centred on 0, symmetric limits).
_UNSIGNED = ("curvedness",)

#: The invalid-reason code of vertices marked invalid by a result that carries no reason.
_UNKNOWN_REASON = 255

#: Longest base64 block a browser takes as one string (Chromium's limit is 2**29 - 24 characters).
_MAX_BLOCK = 2**29 - 64

_UPS = ("y", "z", "x")


def write_html(
    path,
    vertices,
    faces=None,
    result: CurvatureResult | Sequence[CurvatureResult] | None = None,
    *,
    field: str = "mean",
    title: str | None = None,
    up: str | None = None,
    elevation: float = 20.0,
    azimuth: float = -30.0,
    percentiles: tuple[float, float] = (2.0, 98.0),
    max_directions: int = 20000,
    length_unit: str | None = None,
    overwrite: bool = False,
    source=None,
) -> pathlib.Path:
    """Write an interactive 3D view of a mesh (or a point cloud) coloured by its curvatures.

    Parameters
    ----------
    path : str or path-like
        The page to write, ``.html`` or ``.htm``. Written atomically (a
        temporary file renamed when complete); an existing file is kept
        unless ``overwrite=True``.
    vertices : array_like of shape (V, 3), or a mesh or point cloud object
        Mesh vertices, or the points of a point cloud. Or, with ``faces``
        left out, what :func:`meshcurv.principal_curvatures` takes alone (a
        trimesh ``Trimesh``, PyVista ``PolyData``, meshio ``Mesh`` or Open3D
        ``TriangleMesh``) or :func:`meshcurv.point_cloud_curvatures` (an
        object of points alone).
    faces : array_like of shape (F, 3) or (F, k), list of index lists, or MeshTopology, optional
        0-based triangles (polygons are fan-triangulated, with a
        ``TriangulationWarning``). None (or an empty array) draws the
        vertices as points.
    result : CurvatureResult or sequence of CurvatureResult, optional
        The curvatures of these vertices; computed with the defaults of
        :func:`meshcurv.principal_curvatures` (or of
        :func:`meshcurv.point_cloud_curvatures` without faces) when not given.
        Several results (of several radii, as
        :func:`meshcurv.multiscale_curvatures` returns them) give the page a
        menu of scales, each named by its radius; the first is shown first.
    field : {'k_min', 'k_max', 'mean', 'gaussian', 'shape_index', 'curvedness'}, default: 'mean'
        The field shown first; the page has a menu of all of them.
    title : str, optional
        The page's heading (default: "meshcurv viewer").
    up : {'y', 'z', 'x'}, optional
        The axis drawn upwards at first; default: chosen from the mesh as for
        the pictures (:func:`meshcurv.plotting.choose_up`: z when the mesh is
        clearly taller along z than along y, else y).
    elevation, azimuth : float, default: 20, -30
        The first view, in degrees: the camera above the horizontal plane and
        turned about the up axis.
    percentiles : (float, float), default: (2, 98)
        Default colour limits: these percentiles of each field's finite values
        at valid vertices. Signed fields (all but curvedness) get symmetric
        limits ``-b, b`` with ``b`` the larger magnitude of the two, and a
        diverging colour map; shape_index always gets -1, 1.
    max_directions : int, default: 20000
        Principal directions are drawn at most at this many vertices, chosen
        evenly in space (one per cell of a grid); 0 leaves them out.
    length_unit : str, optional
        The unit of the coordinates (``'mm'``), shown on the colour bar
        (``1/mm``); default ``1/length``.
    overwrite : bool, default: False
        Replace an existing file.
    source : path-like, optional
        The input file, which the page must never replace.

    Returns
    -------
    pathlib.Path
        ``path``.

    Raises
    ------
    InvalidMeshError
        Bad ``vertices`` or ``faces``.
    InvalidOptionError
        An unknown field or up axis, bad percentiles or ``max_directions``, or
        a ``result`` (or one of several) of another number of vertices.
    MeshFileError
        ``path`` is not ``.html``, exists (without ``overwrite``), is the
        input, or cannot be written.

    Examples
    --------
    >>> import pathlib, tempfile, meshcurv
    >>> from meshcurv.viewer import write_html
    >>> torus = meshcurv.shapes.torus()
    >>> with tempfile.TemporaryDirectory() as folder:
    ...     write_html(pathlib.Path(folder) / "torus.html", torus.vertices, torus.faces, field="gaussian").name
    'torus.html'
    """
    path = pathlib.Path(path)
    if path.suffix.lower() not in (".html", ".htm"):
        raise MeshFileError(f"{path}: the page must be named .html or .htm; got {path.suffix or 'no extension'!r}")
    check_output(path, overwrite=overwrite, source=source)
    field = check_choice(field, "field", VIEWER_FIELDS)
    points, triangles = drawn_arrays(vertices, faces)
    if up is None:
        up, why = choose_up(points)
        logger.info("viewer: up axis %s (%s)", up, why)
    up = check_choice(up, "up", _UPS)
    percentiles = check_percentiles(percentiles)
    max_directions = _check_count(max_directions, "max_directions")
    for text, name in ((title, "title"), (length_unit, "length_unit")):
        if text is not None and not isinstance(text, str):
            raise InvalidOptionError(f"`{name}` must be a string or None; got {type(text).__name__}")
    angles = [_check_angle(value, name) for value, name in ((elevation, "elevation"), (azimuth, "azimuth"))]
    results = _checked_results(_compute(points, triangles) if result is None else result, len(points))
    options = {"field": field, "percentiles": percentiles, "max_directions": max_directions, "length_unit": length_unit}
    meta, arrays = _page_data(points, triangles, results, **options)
    meta.update(title=title or "meshcurv viewer", up=up, elevation=angles[0], azimuth=angles[1])
    with atomic_output(path, overwrite=overwrite) as temporary:
        with open(temporary, "wb") as handle:
            _write_page(handle, meta, arrays)
    logger.info("wrote %s (%d bytes)", path, path.stat().st_size)
    return path


def _compute(points: np.ndarray, triangles: np.ndarray | None) -> CurvatureResult:
    if triangles is None:
        return point_cloud_curvatures(points)
    return principal_curvatures(points, triangles)


def _checked_results(result, n_points: int) -> list[CurvatureResult]:
    """``result`` as a non-empty list of results of ``n_points`` vertices."""
    results = [result] if isinstance(result, CurvatureResult) else result
    if not isinstance(results, (list, tuple)) or not results:
        raise InvalidOptionError(
            f"`result` must be a CurvatureResult or a non-empty list of them; got {type(result).__name__}"
        )
    for index, item in enumerate(results):
        where = "`result`" if len(results) == 1 else f"`result[{index}]`"
        if not isinstance(item, CurvatureResult):
            raise InvalidOptionError(f"{where} must be a CurvatureResult; got {type(item).__name__}")
        if item.n_vertices != n_points:
            raise InvalidOptionError(
                f"{where} has {item.n_vertices} vertices; the mesh has {n_points}: pass the result of these vertices"
            )
    return list(results)


def _check_count(value, name: str) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 0:
        raise InvalidOptionError(f"`{name}` must be a whole number >= 0; got {value!r}")
    return int(value)


def _check_angle(value, name: str) -> float:
    try:
        angle = float(value)
    except (TypeError, ValueError):
        raise InvalidOptionError(f"`{name}` must be an angle in degrees; got {value!r}") from None
    if not np.isfinite(angle):
        raise InvalidOptionError(f"`{name}` must be a finite angle in degrees; got {value!r}")
    return angle


def _label_and_unit(name: str, method: str, length_unit: str | None) -> tuple[str, str]:
    """The words of :data:`meshcurv.io.fields.FIELDS` without their unit, and the unit."""
    match = re.fullmatch(r"(.*?)\s*\(([^()]*)\)", FIELDS[name])
    if match is None:
        raise RuntimeError(f"FIELDS[{name!r}] ends with no unit in parentheses: {FIELDS[name]!r}")
    label, unit = match.group(1), match.group(2)
    if method == "matgeom" and "length" in unit:
        unit = "matGeom's scaling"
    elif length_unit:
        unit = unit.replace("length", length_unit)
    return label, unit


def _default_limits(values: np.ndarray, name: str, percentiles: tuple[float, float]) -> tuple[float, float]:
    """Robust colour limits of a field: percentiles of its finite values, symmetric when it is signed.

    ``shape_index`` always gets (-1, 1). Limits that would be equal (a
    constant field, no finite value) are widened so that ``low < high``.
    """
    if name == "shape_index":
        return -1.0, 1.0
    finite = values[np.isfinite(values)]
    if finite.size == 0:
        return (-1.0, 1.0) if name not in _UNSIGNED else (0.0, 1.0)
    low, high = (float(value) for value in np.percentile(finite, percentiles))
    if name not in _UNSIGNED:
        bound = max(abs(low), abs(high))
        low, high = -bound, bound
    if not high > low:  # a constant field
        spread = abs(high) if high != 0 else 1.0
        low, high = (low - spread, high + spread) if name not in _UNSIGNED else (max(0.0, low - spread), high + spread)
    return low, high


def _direction_sample(points: np.ndarray, eligible: np.ndarray, count: int) -> np.ndarray:
    """At most ``count`` of the ``eligible`` vertices, evenly spread in space.

    Per cell of a grid, the vertex nearest to the cell's centre; the cell side
    is adjusted (a few passes) until the cells holding vertices number between
    0.8 ``count`` and ``count``. Of two chosen vertices closer than half a
    cell (across the face of a cell), the later one is dropped.
    """
    candidates = np.flatnonzero(eligible)
    if candidates.size <= count:
        return candidates
    if count == 0:
        return candidates[:0]
    chosen = points[candidates]
    low = chosen.min(axis=0)
    side = max(float((chosen.max(axis=0) - low).max()), 1e-300) / np.sqrt(count)
    best_side, best_size = None, 0
    for _ in range(12):
        n_cells = np.unique(_cell_keys(chosen, low, side)).size
        if best_size < n_cells <= count:
            best_side, best_size = side, n_cells
            if n_cells >= 0.8 * count:
                break
        side *= np.sqrt(n_cells / count) * (1.05 if n_cells > count else 1.0)
    if best_side is None:
        return np.sort(np.random.default_rng(0).choice(candidates, count, replace=False))
    keys = _cell_keys(chosen, low, best_side)
    centres = (np.floor((chosen - low) / best_side) + 0.5) * best_side + low
    order = np.lexsort((((chosen - centres) ** 2).sum(axis=1), keys))
    _, first = np.unique(keys[order], return_index=True)
    picked = np.sort(order[first])
    from scipy.spatial import cKDTree

    close = cKDTree(chosen[picked]).query_pairs(0.5 * best_side, output_type="ndarray")
    return candidates[np.delete(picked, np.unique(close.max(axis=1)) if close.size else [])]


def _cell_keys(points: np.ndarray, low: np.ndarray, side: float) -> np.ndarray:
    cells = np.floor((points - low) / side).astype(np.int64)
    dims = cells.max(axis=0) + 1
    return (cells[:, 0] * dims[1] + cells[:, 1]) * dims[2] + cells[:, 2]


def _spacing(points: np.ndarray) -> float:
    """Median distance of a point to its nearest neighbour (over a sample of at most 50,000 points)."""
    from scipy.spatial import cKDTree

    sample = points
    if len(points) > 50000:
        sample = points[np.random.default_rng(0).choice(len(points), 50000, replace=False)]
    if len(sample) < 2:
        return 1.0
    distances, _ = cKDTree(sample).query(sample, k=2)
    positive = distances[:, 1][distances[:, 1] > 0]
    return float(np.median(positive)) if positive.size else 1.0


def _page_data(points, triangles, results, *, field, percentiles, max_directions, length_unit):
    """The page's JSON description and its arrays (little-endian, as the page reads them)."""
    low, high = points.min(axis=0), points.max(axis=0)
    offset = (low + high) / 2
    relative = points - offset
    radius = float(np.sqrt((relative**2).sum(axis=1).max())) or 1.0
    arrays = {"positions": relative.astype("<f4")}
    if triangles is not None:
        arrays["faces"] = triangles.astype("<u4")
    else:
        normals = np.nan_to_num(np.asarray(results[0].normals, dtype=np.float64), nan=0.0)
        arrays["normals"] = np.round(np.clip(normals, -1, 1) * 127).astype("i1")
    scales = []
    for index, result in enumerate(results):
        scale, scale_arrays = _scale_data(points, result, percentiles, max_directions, length_unit)
        scale["label"] = _scale_label(result, index, length_unit)
        scales.append(scale)
        suffix = f"_s{index}" if index else ""
        arrays.update({name + suffix: array for name, array in scale_arrays.items()})
    first = results[0]
    size = f"{len(points)} vertices, {len(triangles)} triangles" if triangles is not None else f"{len(points)} points"
    meta = {
        "format": 1,
        "kind": "mesh" if triangles is not None else "points",
        "n_vertices": int(len(points)),
        "n_faces": int(len(triangles)) if triangles is not None else 0,
        "offset": [float(value) for value in offset],
        "radius": radius,
        "point_spacing": _spacing(points),
        "stroke_half_length": scales[0]["stroke_half_length"],
        "subtitle": f"{size}; method {first.method}" + (f"; {len(results)} scales" if len(results) > 1 else ""),
        "details": scales[0]["details"],
        "method": first.method,
        "field": field,
        "fields": scales[0]["fields"],
        "invalid_reasons": {
            **{str(code): text for code, text in enumerate(INVALID_REASONS) if code},
            str(_UNKNOWN_REASON): "estimate undefined",
        },
        "percentiles": list(percentiles),
    }
    if len(results) > 1:
        meta["scales"] = scales
    return meta, arrays


def _scale_data(points, result, percentiles, max_directions, length_unit) -> tuple[dict, dict]:
    """One result's part of the page: its fields' limits and details, and its arrays (unsuffixed names)."""
    reason = np.where(result.valid, 0, _UNKNOWN_REASON).astype(np.uint8)
    if result.invalid_reason is not None:
        reason = np.where(
            result.valid, 0, np.where(result.invalid_reason > 0, result.invalid_reason, _UNKNOWN_REASON)
        ).astype(np.uint8)
    arrays = {
        "k_min": np.asarray(result.k_min, dtype="<f4"),
        "k_max": np.asarray(result.k_max, dtype="<f4"),
        "invalid_reason": reason,
    }
    fields = {}
    for name in VIEWER_FIELDS:
        values = np.where(result.valid, getattr(result, name), np.nan)
        label, unit = _label_and_unit(name, result.method, length_unit)
        limits = list(_default_limits(values, name, percentiles))
        fields[name] = {"label": label, "unit": unit, "signed": name not in _UNSIGNED, "limits": limits}
    stroke = None
    directions = np.isfinite(result.dir_min).all(axis=1) & np.isfinite(result.dir_max).all(axis=1) & result.valid
    if max_directions and directions.any():
        chosen = _direction_sample(points, directions, max_directions)
        arrays["direction_vertices"] = chosen.astype("<u4")
        arrays["dir_min"] = np.asarray(result.dir_min[chosen], dtype="<f4")
        arrays["dir_max"] = np.asarray(result.dir_max[chosen], dtype="<f4")
        stroke = 0.4 * _spacing(points[chosen])
    parameters = parameter_text(result.parameters)
    details = f"method {result.method}" + (f" ({parameters})" if parameters else "")
    return {"fields": fields, "stroke_half_length": stroke, "details": details}, arrays


def _scale_label(result: CurvatureResult, index: int, length_unit: str | None) -> str:
    """The scale menu's name of a result: its radius (the median where it varies by vertex)."""
    radii = None if result.radius is None else np.asarray(result.radius, dtype=np.float64)
    finite = radii[np.isfinite(radii)] if radii is not None else np.empty(0)
    if finite.size == 0:
        return f"{index + 1}: {result.method}"
    unit = f" {length_unit}" if length_unit else ""
    low, high = float(finite.min()), float(finite.max())
    if high <= low * (1 + 1e-9):
        return f"radius {low:.4g}{unit}"
    return f"radius {float(np.median(finite)):.4g}{unit} (median; {low:.3g} to {high:.3g})"


# No network at all: no fetch, no connection, no image or script from elsewhere.
_POLICY = (
    "default-src 'none'; script-src 'unsafe-inline'; style-src 'unsafe-inline'; img-src data: blob:; connect-src 'none'"
)


def _resource(name: str) -> str:
    """A file of the package: ``_viewer.js`` (the page's script), ``_viewer.html`` (its style and body)."""
    return importlib.resources.files("meshcurv").joinpath(name).read_text(encoding="utf-8")


def _json_for_script(value) -> str:
    """JSON safe inside a ``<script>`` element (no ``</script>``, no ``<!--``)."""
    return json.dumps(value, allow_nan=False).replace("<", "\\u003c").replace(">", "\\u003e")


def _write_page(handle, meta: dict, arrays: dict) -> None:
    specs, blocks = {}, []
    for name, array in arrays.items():
        data = np.ascontiguousarray(array)
        dtype = {"f4": "float32", "u4": "uint32", "u1": "uint8", "i1": "int8"}[data.dtype.str[1:]]
        spec: dict[str, object] = {"id": f"array-{name}", "dtype": dtype, "shape": list(data.shape)}
        raw = data.tobytes()
        if name == "faces":  # differences of consecutive indices: small numbers where the mesh is ordered
            raw = zlib.compress(np.diff(data.ravel(), prepend=np.uint32(0)).astype("<u4").tobytes(), 1)
            spec.update(delta=True, compression="deflate")
        encoded = base64.b64encode(raw)
        if len(encoded) > _MAX_BLOCK:
            raise InvalidMeshError(
                f"the array {name} takes {len(encoded)} characters in the page, more than a "
                f"browser reads as one string ({_MAX_BLOCK}); the mesh is too large to view"
            )
        specs[name] = spec
        blocks.append((spec["id"], encoded))
    meta = {**meta, "arrays": specs}
    style, body = _resource("_viewer.html").split("<!-- body -->")
    head = (
        f'<!DOCTYPE html>\n<html lang="en">\n<head>\n<meta charset="utf-8">\n'
        f'<meta http-equiv="Content-Security-Policy" content="{_POLICY}">\n'
        f'<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f"<title>{html.escape(meta['title'])} - meshcurv viewer</title>\n"
        f"<style>{style}</style>\n</head>\n<body>{body}\n"
        f'<script type="application/json" id="meshcurv-meta">{_json_for_script(meta)}</script>\n'
    )
    handle.write(head.encode("utf-8"))
    for identifier, encoded in blocks:
        handle.write(f'<script type="application/octet-stream" id="{identifier}">'.encode("ascii"))
        handle.write(encoded)
        handle.write(b"</script>\n")
    handle.write(f"<script>\n{_resource('_viewer.js')}\n</script>\n</body>\n</html>\n".encode())


def read_page_data(path) -> tuple[dict, dict[str, np.ndarray]]:
    """The JSON description and the arrays embedded in a page written by :func:`write_html`.

    The inverse of the page's encoding, for tests and for reading the data
    back: faces and positions as stored (positions relative to
    ``meta['offset']``, float32).

    Raises
    ------
    MeshFileError
        The file is not a page of :func:`write_html`.
    """
    text = pathlib.Path(path).read_text(encoding="utf-8")
    found = re.search(r'<script type="application/json" id="meshcurv-meta">(.*?)</script>', text, re.S)
    if found is None:
        raise MeshFileError(f"{path}: not a meshcurv viewer page (no meshcurv-meta block)")
    meta = json.loads(found.group(1))
    arrays = {}
    for name, spec in meta["arrays"].items():
        block = re.search(
            f'<script type="application/octet-stream" id="{re.escape(spec["id"])}">(.*?)</script>', text, re.S
        )
        if block is None:
            raise MeshFileError(f"{path}: the block {spec['id']} is missing")
        raw = base64.b64decode(block.group(1))
        if spec.get("compression") == "deflate":
            raw = zlib.decompress(raw)
        dtype = {"float32": "<f4", "uint32": "<u4", "uint8": "u1", "int8": "i1"}[spec["dtype"]]
        array = np.frombuffer(raw, dtype=dtype).reshape(spec["shape"])
        if spec.get("delta"):
            array = np.cumsum(array.ravel(), dtype=np.uint32).reshape(spec["shape"])
        arrays[name] = array
    return meta, arrays
