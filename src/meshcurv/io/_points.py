"""Point-cloud files: PLY (vertices only), XYZ / CSV text, PCD and LAS / LAZ.

:func:`read_points` returns ``(points, normals)`` (normals None when the file
has none) and :func:`write_points` writes points, normals and per-point fields.
Every failure is a :class:`~meshcurv.errors.MeshFileError` that names the file.
Readers are bounded: the declared counts are checked against the size of the
file before anything is allocated, and a file cut short is an error, not a
smaller cloud.

=========================  ==================  ==========================================================
extension                  format              normals read from
=========================  ==================  ==========================================================
``.ply``                   PLY ascii / binary  ``nx ny nz`` (or ``normal_x ...``); faces, if any, ignored
``.xyz .txt .pts .csv``    text rows           header names ``nx ny nz``; without a header, columns 4-6
                                               when they are unit vectors
``.pcd``                   PCD ascii / binary  ``normal_x normal_y normal_z``; NaN points (organised
                                               clouds' missing measurements) are left out
``.las .laz``              LAS / LAZ (laspy)   extra dimensions ``normal_x`` ... or ``nx`` ...
=========================  ==================  ==========================================================

LAS and LAZ need the ``points`` extra (``pip install 'meshcurv[points]'``:
laspy with the lazrs backend). LAS stores integer coordinates: written files
keep about nine significant digits of the extent (scale = extent / 2^30).
"""

from __future__ import annotations

import pathlib
import re
import warnings

import numpy as np

from .._validation import as_vertices
from ..errors import (
    InvalidMeshError,
    InvalidOptionError,
    MeshFileError,
    MeshQualityWarning,
    MissingDependencyError,
    optional_module,
)
from ._files import atomic_output, check_input, check_output, format_key, named_fields
from ._ply import HEADER_LIMIT, _header, _short, ply_vertex_columns
from ._text import (
    body_rows,
    fixed_rows,
    line_of,
    names_shown,
    not_a_number,
    numbers_by_line,
    row_error,
    without_bom,
)
from .fields import curvature_fields

__all__ = ["read_points", "write_points", "write_point_curvatures", "is_point_cloud", "POINT_EXTENSIONS"]

_TEXT = (".xyz", ".txt", ".pts", ".csv")

#: The extensions :func:`read_points` and :func:`write_points` know.
POINT_EXTENSIONS = (".ply", *_TEXT, ".pcd", ".las", ".laz")

_NORMAL_NAMES = (("nx", "ny", "nz"), ("normal_x", "normal_y", "normal_z"), ("normalx", "normaly", "normalz"))


def read_points(path, *, file_format: str | None = None) -> tuple[np.ndarray, np.ndarray | None]:
    """Read a point cloud: ``(points, normals)``.

    Parameters
    ----------
    path : str or path-like
    file_format : str, optional
        An extension (``"ply"``, ``".xyz"``, ...) overriding that of ``path``.

    Returns
    -------
    points : ndarray of shape (N, 3), float64
    normals : ndarray of shape (N, 3), float64, or None
        None when the file holds no normals.

    Raises
    ------
    MeshFileError
        Missing or empty file, unknown extension, malformed content, declared
        counts beyond the file's size, a file cut short.
    MissingDependencyError
        A LAS / LAZ file without laspy installed.
    """
    path = check_input(path)
    suffix = _suffix(path, file_format)
    reader = {".las": _read_las, ".laz": _read_las, ".ply": _read_ply, ".pcd": _read_pcd}.get(suffix, _read_text)
    try:
        return reader(path)
    except (MeshFileError, MissingDependencyError, MemoryError):
        raise  # ours name the file; a MemoryError is a real lack of memory (sizes are checked first)
    except OSError as exc:
        raise MeshFileError(f"{path}: {exc.strerror or exc}") from exc
    except Exception as exc:  # noqa: BLE001 - any other failure: one error naming the file
        raise MeshFileError(f"{path}: cannot be read as a point cloud ({type(exc).__name__}: {exc})") from exc


def is_point_cloud(path) -> bool:
    """Whether ``path`` holds a point cloud: a points-only format, or a PLY whose header declares no faces.

    For the command line's choice between :func:`meshcurv.read_mesh` and
    :func:`read_points`; reads at most the PLY header. The text tables
    (``.xyz .txt .pts .csv``) are point clouds: :func:`meshcurv.read_mesh`
    reads no mesh from any of them (a ``.csv`` it writes holds per-vertex
    values, without faces).

    Parameters
    ----------
    path : str or os.PathLike

    Returns
    -------
    bool
        True for the extensions ``.xyz .txt .pts .csv .pcd .las .laz`` (the
        file is not opened) and for a PLY whose header declares no face;
        False otherwise, unknown, missing or unreadable files included (the
        mesh reader then says why).
    """
    path = pathlib.Path(path)
    suffix = path.suffix.lower()
    if suffix in (*_TEXT, ".pcd", ".las", ".laz"):
        return True
    if suffix != ".ply":
        return False
    try:
        with open(path, "rb") as handle:
            _, elements, _ = _header(without_bom(handle.read(HEADER_LIMIT + 64)), path)
    except (OSError, MeshFileError):
        return False
    return not any(e.name == "face" and e.count > 0 for e in elements)


def write_point_curvatures(
    path,
    points,
    result,
    *,
    fields=None,
    quality: str | None = "mean",
    overwrite: bool = False,
    source=None,
    binary: bool = True,
) -> pathlib.Path:
    """Write a point cloud with the fields of a curvature result (those of :func:`meshcurv.io.write_curvatures`).

    ``write_points(path, points, point_data=curvature_fields(result, ...))``:
    the normals go out as ``normals_x ...`` with the other fields (``nx ...``
    only when passed to :func:`write_points` directly).

    Parameters
    ----------
    path, points
        As for :func:`write_points`; ``points`` has one row per row of ``result``.
    result, fields, quality
        As for :func:`meshcurv.io.write_curvatures`.
    overwrite, source, binary
        As for :func:`write_points` (defaults False, None, True).

    Returns
    -------
    pathlib.Path
        The point cloud written, ``path``.

    Raises
    ------
    MeshFileError, InvalidMeshError
        As :func:`write_points`.
    InvalidOptionError
        As :func:`meshcurv.io.write_curvatures`.
    """
    point_data = curvature_fields(result, fields=fields, quality=quality)
    return write_points(path, points, point_data=point_data, overwrite=overwrite, source=source, binary=binary)


def _suffix(path: pathlib.Path, file_format: str | None) -> str:
    return format_key(path, file_format, POINT_EXTENSIONS, "point-cloud file")


def _split(columns: dict, path, where: str) -> tuple[np.ndarray, np.ndarray | None]:
    """``(points, normals)`` from named float columns (lower-case names)."""
    if not {"x", "y", "z"} <= set(columns):
        raise MeshFileError(f"{path}: {where} has no x, y and z")
    points = np.column_stack([columns[a] for a in "xyz"]).astype(np.float64)
    normals = None
    for names in _NORMAL_NAMES:
        if set(names) <= set(columns):
            normals = np.column_stack([columns[a] for a in names]).astype(np.float64)
            break
    return points, normals


# -- PLY ----------------------------------------------------------------------------


def _read_ply(path):
    columns = ply_vertex_columns(path)
    return _split({name.lower(): values for name, values in columns.items()}, path, "the PLY 'vertex' element")


# -- text ---------------------------------------------------------------------------

_SEPARATORS = re.compile(rb"[,;\t ]+")
_COMMENT_LINES = re.compile(rb"^[ \t]*(?:#|//)[^\n]*", re.M)
_FIRST_WORD = re.compile(rb"\S")
#: per delimiter, what it becomes: ``;`` files write decimal commas (``1,5;2,5``), so their commas are points
_TRANSLATIONS = {b";": bytes.maketrans(b";,", b" ."), b",": bytes.maketrans(b",", b" ")}


def _read_text(path):
    """Rows of numbers separated by spaces, tabs, commas or semicolons; ``#`` and ``//`` lines are comments."""
    columns = text_columns(path)
    return _split({name.lower(): values for name, values in columns.items()}, path, "the header")


def text_columns(path) -> dict[str, np.ndarray]:
    """The columns of a text table of numbers (CSV, XYZ, TXT, PTS) by name: the header's, or x, y, z, ...

    Rows are separated by spaces or tabs, by commas, or by semicolons (then
    with decimal commas, ``1,5;2,5``), as on the first row. Blank lines and
    lines starting with ``#`` or ``//`` are skipped; a first line of words is
    the header. A row holding one whole number is a count of the rows that
    follow it (``.pts``), checked against them. Every row must hold as many
    values as the header has names (without a header: as most rows): a row
    with more or fewer values, an empty value (``1,,3``, ``1,2,3,``) or a word
    that is not a number is a :class:`~meshcurv.errors.MeshFileError` naming
    its line, never a shift of the values after it.
    """
    data = without_bom(pathlib.Path(path).read_bytes())
    if b"#" in data or b"//" in data:
        data = _COMMENT_LINES.sub(b"", data)  # the newlines stay: line numbers are the file's
    first = _FIRST_WORD.search(data)
    if first is None:
        raise MeshFileError(f"{path}: no points in the file")
    start = data.rfind(b"\n", 0, first.start()) + 1
    end = data.find(b"\n", start)
    end = len(data) if end < 0 else end
    line = line_of(data, start)
    words = _SEPARATORS.split(data[start:end].strip())
    names = None
    if all(numbers_by_line(word) is None for word in words):  # no word is a number: a header
        names = [word.decode("utf-8", "replace").strip().strip('"').strip("'") for word in words]
        start, line = end + 1, line + 1
    body = data[start:]
    if _FIRST_WORD.search(body) is None:
        raise MeshFileError(f"{path}: a header line and no points" if names else f"{path}: no points in the file")
    body = _undelimited(body, path, line)
    parsed = numbers_by_line(body)
    if parsed is None:
        raise not_a_number(path, body, line)
    values, counts = parsed
    rows = np.flatnonzero(counts)  # the non-blank lines
    found = counts[rows]
    first_value = np.cumsum(counts)[rows] - found
    keep = _counted_blocks(path, values, found, first_value, line + rows)
    if not keep.any():
        raise MeshFileError(f"{path}: no points in the file (only counts of points)")
    if names is not None:
        width = len(names)
    else:
        # as most rows of 3 values or more (a point needs 3); on a tie, as the first of them
        candidates = found[keep][found[keep] >= 3] if (found[keep] >= 3).any() else found[keep]
        frequency = np.bincount(candidates)
        width = int(candidates[0]) if frequency[candidates[0]] == frequency.max() else int(frequency.argmax())
        if width < 3:
            most = "" if (found[keep] == width).all() else " (most rows)"
            raise MeshFileError(f"{path}: rows of {width} numbers{most}; a point needs x, y and z")
    wrong = keep & (found != width)
    if wrong.any():
        i = int(np.argmax(wrong))
        meaning = (
            names_shown(names) if names else "as most rows: x, y, z" + (f" and {width - 3} more" if width > 3 else "")
        )
        raise row_error(path, int(line + rows[i]), int(found[i]), width, meaning)
    if not keep.all():
        values = np.delete(values, first_value[~keep])
    table = values.reshape(-1, width)
    if names is None:
        names = ["x", "y", "z"]
        if width >= 6:
            length = np.linalg.norm(table[:, 3:6], axis=1)
            if np.median(np.abs(length - 1.0)) < 1e-3:  # unit vectors: normals (not colours)
                names += ["nx", "ny", "nz"]
        names += [f"column{i}" for i in range(len(names), width)]
    return {name: table[:, i] for i, name in enumerate(names)}


def _undelimited(body: bytes, path, line: int) -> bytes:
    """``body`` with its delimiters (those of its first row: ``,`` or ``;``) turned into spaces.

    An empty value (two delimiters with nothing but blanks between them, or
    one at the start or end of a row) is an error naming its line.
    """
    first = _FIRST_WORD.search(body)
    start = 0 if first is None else first.start()
    end = body.find(b"\n", start)
    row = body[start : len(body) if end < 0 else end]
    delimiter = b";" if b";" in row else b"," if b"," in row else None
    if delimiter is None:
        return body
    if not body.endswith(b"\n"):
        body += b"\n"
    buffer = np.frombuffer(body, dtype=np.uint8)
    is_delimiter = buffer == delimiter[0]
    marks = np.flatnonzero(is_delimiter | (buffer == ord("\n")))  # the last one is the final newline
    content = ~((buffer <= 32) | is_delimiter)  # blanks (and control bytes, which no number holds)
    bounds = np.concatenate([[0], marks[:-1] + 1])
    filled = np.add.reduceat(content, bounds, dtype=np.int64) > 0  # a field (or a blank line) holds something
    beside = is_delimiter[marks]
    beside[1:] |= is_delimiter[marks[:-1]]
    empty = ~filled & beside
    if empty.any():
        position = int(bounds[np.argmax(empty)])
        number = line + line_of(body, position) - 1
        start = body.rfind(b"\n", 0, position) + 1
        shown = body[start : body.find(b"\n", position)].strip()[:60].decode("utf-8", "replace")
        raise MeshFileError(
            f"{path}: line {number}: an empty value in {shown!r} (every "
            f"{delimiter.decode()!r} stands between two numbers)"
        )
    return body.translate(_TRANSLATIONS[delimiter])


def _counted_blocks(path, values, found, first_value, lines) -> np.ndarray:
    """Which rows are points: not the rows of one whole number that count the rows after them (``.pts``)."""
    single = found == 1
    if not single[0]:
        return np.ones(found.size, dtype=bool)  # a row of one value elsewhere is a row of the wrong length
    heads = np.flatnonzero(single)
    declared = values[first_value[heads]]
    follow = np.diff(np.append(heads, found.size)) - 1
    whole = (declared >= 0) & (declared == np.floor(declared))
    if not whole[0]:
        raise MeshFileError(
            f"{path}: line {lines[0]}: 1 value ({float(declared[0])!r}), expected a count of points or x, y, z"
        )
    bad = whole & (declared != follow)
    if bad.any():
        i = int(np.argmax(bad))
        raise MeshFileError(
            f"{path}: line {lines[heads[i]]}: a count of {int(declared[i])} points, but "
            f"{follow[i]} rows follow it (up to the next count or the end of the file)"
        )
    keep = np.ones(found.size, dtype=bool)
    keep[heads[whole]] = False
    return keep


# -- PCD ----------------------------------------------------------------------------

_PCD_TYPES = {
    (kind, size): f"{kind.lower()}{size}" for kind in "FIU" for size in (1, 2, 4, 8) if kind != "F" or size > 2
}


def _read_pcd(path):
    data = without_bom(path.read_bytes())
    header, position = {}, 0
    for _ in range(64):
        end = data.find(b"\n", position)
        if end < 0:
            raise MeshFileError(f"{path}: the PCD header ends before its DATA line (the file is cut short)")
        line = data[position:end].decode("ascii", "replace").strip()
        position = end + 1
        if not line or line.startswith("#"):
            continue
        key, *words = line.split()
        header[key.upper()] = words
        if key.upper() == "DATA":
            break
    else:
        raise MeshFileError(f"{path}: no DATA line in the first 64 lines; not a PCD file")
    try:
        fields = [f.lower() for f in header["FIELDS"]]
        sizes = [int(s) for s in header.get("SIZE", ["4"] * len(fields))]
        types = [t.upper() for t in header.get("TYPE", ["F"] * len(fields))]
        counts = [int(c) for c in header.get("COUNT", ["1"] * len(fields))]
        n = int(header["POINTS"][0]) if "POINTS" in header else int(header["WIDTH"][0]) * int(header["HEIGHT"][0])
        kind = header["DATA"][0].lower()
    except (KeyError, ValueError, IndexError) as exc:
        raise MeshFileError(f"{path}: malformed PCD header ({type(exc).__name__}: {exc})") from None
    if not len(fields) == len(sizes) == len(types) == len(counts) or n < 0 or min(counts, default=1) < 1:
        raise MeshFileError(f"{path}: the PCD header's FIELDS, SIZE, TYPE and COUNT do not match")
    if kind == "binary_compressed":
        raise MeshFileError(f"{path}: PCD 'binary_compressed' (LZF) is not supported; save it as binary or ascii")
    if kind == "ascii":
        width = sum(counts)
        body = data[position:]
        if n * width * 2 > len(body) + 1:
            raise _short(path, n, "points", len(body))
        values, found, first_value, lines = body_rows(data, position, path)  # one point per line
        shown = names_shown(f"{f}[{c}]" if c > 1 else f for f, c in zip(fields, counts))
        table = fixed_rows(values, found[:n], first_value[:n], lines[:n], width, path, shown)
        if found.size < n:
            raise _short(path, n, "points", len(body))
        if found.size > n:
            raise MeshFileError(f"{path}: line {int(lines[n])}: a row after the {n} points the header declares")
        starts = np.cumsum([0] + counts[:-1])
        columns = {f: table[:, s] for f, s in zip(fields, starts)}
    elif kind == "binary":
        try:
            record = np.dtype(
                [(f"f{i}", "<" + _PCD_TYPES[t, s], (c,)) for i, (t, s, c) in enumerate(zip(types, sizes, counts))]
            )
        except KeyError:
            raise MeshFileError(f"{path}: a PCD field has an unknown TYPE/SIZE pair") from None
        need = n * record.itemsize
        if position + need > len(data):
            raise _short(path, n, "points", len(data) - position, need)
        table = np.frombuffer(data, record, count=n, offset=position)
        columns = {f: table[f"f{i}"][:, 0] for i, f in enumerate(fields)}
    else:
        raise MeshFileError(f"{path}: unknown PCD DATA kind {kind!r} (ascii, binary)")
    points, normals = _split(columns, path, "the PCD FIELDS")
    finite = np.isfinite(points).all(axis=1)
    if not finite.all():
        warnings.warn(
            f"{path}: {int((~finite).sum())} of {n} points have NaN coordinates (missing measurements): left out",
            MeshQualityWarning,
            stacklevel=3,
        )
        points = points[finite]
        normals = None if normals is None else normals[finite]
    return points, normals


# -- LAS / LAZ ----------------------------------------------------------------------


def _laspy(path):
    return optional_module("laspy", f"{path}: reading or writing LAS / LAZ needs laspy: pip install 'meshcurv[points]'")


def _read_las(path):
    laspy = _laspy(path)
    try:
        with laspy.open(path) as reader:
            header = reader.header
            count = int(header.point_count)
            if path.suffix.lower() != ".laz" and not header.are_points_compressed:
                need = int(header.offset_to_point_data) + count * int(header.point_format.size)
                if need > path.stat().st_size:
                    raise _short(path, count, "points", path.stat().st_size, need)
            data = reader.read()
        points = np.column_stack([np.asarray(getattr(data, axis), dtype=np.float64) for axis in "xyz"])
        extra = {name.lower(): name for name in data.point_format.extra_dimension_names}
        normals = None
        for names in _NORMAL_NAMES:
            if set(names) <= set(extra):
                normals = np.column_stack([np.asarray(data[extra[n]], dtype=np.float64) for n in names])
                break
    except MeshFileError:
        raise
    except Exception as exc:  # noqa: BLE001 - laspy raises many kinds on a bad file
        raise MeshFileError(f"{path}: not a readable LAS / LAZ file ({type(exc).__name__}: {exc})") from None
    if points.shape[0] != count:
        raise MeshFileError(f"{path}: the header declares {count} points; {points.shape[0]} were read")
    return points, normals


# -- writing ------------------------------------------------------------------------


def _columns(points, normals, point_data) -> dict[str, np.ndarray]:
    """Named float64 columns: x, y, z, nx, ny, nz, then each field (vectors as ``name_x`` ...)."""
    columns = {a: points[:, i] for i, a in enumerate("xyz")}
    if normals is not None:
        columns.update({a: normals[:, i] for i, a in enumerate(("nx", "ny", "nz"))})
    for name, value in named_fields(point_data).items():
        if value.dtype.kind not in "biuf":
            raise InvalidOptionError(f"`point_data[{name!r}]` must be a numeric array; got dtype {value.dtype}")
        value = value.astype(np.float64)
        if value.shape == (points.shape[0],):
            columns[name] = value
        elif value.shape == (points.shape[0], 3):
            columns.update({f"{name}_{a}": value[:, i] for i, a in enumerate("xyz")})
        else:
            raise MeshFileError(
                f"field {name!r} must have shape ({points.shape[0]},) or ({points.shape[0]}, 3); got {value.shape}"
            )
    return columns


def write_points(
    path,
    points,
    normals=None,
    *,
    point_data=None,
    overwrite: bool = False,
    binary: bool = True,
    source=None,
    file_format: str | None = None,
) -> pathlib.Path:
    """Write a point cloud with its normals and per-point fields.

    Parameters
    ----------
    path : str or path-like
    points : array_like of shape (N, 3)
    normals : array_like of shape (N, 3), optional
    point_data : dict of str to array_like of shape (N,) or (N, 3), optional
        Per-point fields (vectors as ``name_x, name_y, name_z``); LAS / LAZ
        files keep only the points and normals (as extra dimensions).
    overwrite : bool, default: False
    binary : bool, default: True
        PLY and PCD: binary (little endian) or ASCII.
    source : path-like, optional
        The input file, which the output may not replace.
    file_format : str, optional
        An extension overriding that of ``path``.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    MeshFileError
        Unknown extension, existing file without ``overwrite``, the input file,
        a field of the wrong shape, a folder that cannot be written.
    InvalidMeshError
        ``points`` not of shape (N, 3), ``normals`` not of the shape of ``points``.
    InvalidOptionError
        ``point_data`` not a dict, a name that is not an identifier (it would
        break the file's header), an array that is not numeric.
    """
    path = check_output(path, overwrite=overwrite, source=source)
    suffix = _suffix(path, file_format)
    points = as_vertices(points, name="points")
    normals = None if normals is None else np.asarray(normals, dtype=np.float64)
    if normals is not None and normals.shape != points.shape:  # not reshaped: (N/2, 6) would pass as (N, 3)
        raise InvalidMeshError(f"`normals` must have shape {points.shape}, one per point; got {normals.shape}")
    columns = _columns(points, normals, point_data)
    with atomic_output(path, overwrite=overwrite) as temporary:
        try:
            if suffix in (".las", ".laz"):
                _write_las(temporary, path, points, normals)
            elif suffix == ".ply":
                _write_ply(temporary, columns, binary)
            elif suffix == ".pcd":
                _write_pcd(temporary, columns, binary)
            else:
                separator = "," if suffix == ".csv" else " "
                table = np.column_stack(list(columns.values()))
                with open(temporary, "w", encoding="ascii") as handle:
                    handle.write(separator.join(columns) + "\n")
                    np.savetxt(handle, table, fmt="%.17g", delimiter=separator)
        except OSError as exc:  # name the file asked for, not the temporary
            raise MeshFileError(f"{path}: cannot be written ({exc.strerror or exc})") from exc
    return path


def _write_table(temporary, header: list[str], columns: dict, binary: bool) -> None:
    """The header lines, then the columns as little-endian float64 rows or as text rows."""
    table = np.column_stack(list(columns.values()))
    with open(temporary, "wb") as handle:
        handle.write(("\n".join(header) + "\n").encode("ascii"))
        if binary:
            handle.write(np.ascontiguousarray(table, dtype="<f8").tobytes())
        else:
            np.savetxt(handle, table, fmt="%.17g")


def _write_ply(temporary, columns, binary):
    n = next(iter(columns.values())).shape[0]
    lines = ["ply", f"format {'binary_little_endian' if binary else 'ascii'} 1.0", f"element vertex {n}"]
    _write_table(temporary, lines + [f"property double {name}" for name in columns] + ["end_header"], columns, binary)


def _write_pcd(temporary, columns, binary):
    n = next(iter(columns.values())).shape[0]
    names = [{"nx": "normal_x", "ny": "normal_y", "nz": "normal_z"}.get(name, name) for name in columns]
    lines = [
        "# .PCD v0.7 - Point Cloud Data file format",
        "VERSION 0.7",
        "FIELDS " + " ".join(names),
        "SIZE " + " ".join(["8"] * len(names)),
        "TYPE " + " ".join(["F"] * len(names)),
        "COUNT " + " ".join(["1"] * len(names)),
        f"WIDTH {n}",
        "HEIGHT 1",
        "VIEWPOINT 0 0 0 1 0 0 0",
        f"POINTS {n}",
        f"DATA {'binary' if binary else 'ascii'}",
    ]
    _write_table(temporary, lines, columns, binary)


def _write_las(temporary, path, points, normals):
    laspy = _laspy(path)
    header = laspy.LasHeader(point_format=3, version="1.4")
    low, high = points.min(axis=0), points.max(axis=0)
    header.offsets = low
    header.scales = np.maximum((high - low) / 2.0**30, 1e-12)
    if normals is not None:
        header.add_extra_dims([laspy.ExtraBytesParams(name=n, type=np.float64) for n in ("nx", "ny", "nz")])
    data = laspy.LasData(header)
    data.x, data.y, data.z = points[:, 0], points[:, 1], points[:, 2]
    if normals is not None:
        data.nx, data.ny, data.nz = normals[:, 0], normals[:, 1], normals[:, 2]
    try:
        data.write(str(temporary), do_compress=path.suffix.lower() == ".laz")
    except Exception as exc:  # noqa: BLE001 - laspy's writer errors
        raise MeshFileError(f"{path}: cannot be written as LAS / LAZ ({type(exc).__name__}: {exc})") from None
