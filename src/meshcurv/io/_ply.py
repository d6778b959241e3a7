"""PLY read with numpy: ASCII and binary (both byte orders), without meshio. This reader:

- looks for ``end_header`` in the first :data:`HEADER_LIMIT` bytes only, and
  refuses a header that ends before it;
- checks every element's declared count against the bytes (binary) or the
  lines (ASCII) the file really holds before it allocates anything for it,
  so a header that declares 50 million faces over 4 is an error;
- treats the end of the file inside any element as an error, never as a
  shorter mesh;
- reads an ASCII body one record per line, as the format writes it: a line
  with more or fewer values than its record needs, or a line after the last
  element, is an error naming the line, never a shift of the records after it;
- reads faces whose records all have the same size (what scanners and most
  tools write) as one structured array, and faces of mixed sizes with a
  walk over the records (the offsets of a variable-size record depend on the
  counts before it) followed by one vectorised gather;
- refuses float vertex indices (``3 0.5 1 2``) instead of truncating them.

Only ``x, y, z`` of the ``vertex`` element and the corner list of the
``face`` element (``vertex_indices``, ``vertex_index`` or its only list
property) are kept by :func:`read_ply`; other elements and properties are
checked for size and skipped. (The other properties of the vertices, such as
the curvature fields meshcurv writes, are read by
:func:`meshcurv.io.fields.read_fields` with the vertex element alone.)
"""

from __future__ import annotations

import pathlib
import re
import struct
from dataclasses import dataclass

import numpy as np

from ..errors import MeshFileError
from ._text import body_rows, fixed_rows, names_shown, row_error, without_bom

__all__ = ["read_ply", "HEADER_LIMIT"]

_TYPES = {
    "char": "i1",
    "int8": "i1",
    "uchar": "u1",
    "uint8": "u1",
    "short": "i2",
    "int16": "i2",
    "ushort": "u2",
    "uint16": "u2",
    "int": "i4",
    "int32": "i4",
    "uint": "u4",
    "uint32": "u4",
    "int64": "i8",
    "uint64": "u8",
    "float": "f4",
    "float32": "f4",
    "double": "f8",
    "float64": "f8",
}
_ORDERS = {"ascii": "", "binary_little_endian": "<", "binary_big_endian": ">"}
_CORNER_NAMES = ("vertex_indices", "vertex_index")

#: The header (``ply`` ... ``end_header``) must end within this many bytes.
HEADER_LIMIT = 1 << 20
_END_HEADER = re.compile(rb"(?:\r\n|\n|\r)end_header[ \t]*(?:\r\n|\n|\r|$)")
_LARGEST_INDEX = 2.0**53  # beyond this a float cannot hold an exact integer


@dataclass
class _Property:
    name: str
    kind: str  # numpy type code without byte order ('f4', 'u1', ...)
    count_kind: str | None = None  # the type of a list's count; None for a scalar


@dataclass
class _Element:
    name: str
    count: int
    properties: list

    @property
    def plural(self) -> str:
        return {"vertex": "vertices"}.get(self.name, self.name + "s")


def _header(data: bytes, path):
    """``(format, [_Element], offset of the body)``; every malformed header is a MeshFileError."""
    if not data.startswith(b"ply") or data[3:4] not in (b"\n", b"\r", b""):
        raise MeshFileError(f"{path}: not a PLY file (it should start with a line 'ply'; starts with {data[:20]!r})")
    match = _END_HEADER.search(data, 0, HEADER_LIMIT + 16)
    if match is None or match.start() > HEADER_LIMIT:
        if len(data) <= HEADER_LIMIT:
            raise MeshFileError(f"{path}: the PLY header ends before its 'end_header' line (the file is cut short)")
        raise MeshFileError(f"{path}: no 'end_header' line in the first {HEADER_LIMIT} bytes; not a PLY header")
    file_format, elements = None, []
    lines = data[: match.start()].decode("ascii", "replace").splitlines()
    for number, line in enumerate(lines[1:], start=2):
        words = line.split()
        if not words or words[0] in ("comment", "obj_info"):
            continue
        where = f"{path}: PLY header line {number} ({line.strip()[:60]!r})"
        if words[0] == "format" and file_format is None:
            if len(words) != 3 or words[1] not in _ORDERS:
                raise MeshFileError(f"{where}: the format must be ascii, binary_little_endian or binary_big_endian")
            file_format = words[1]
        elif words[0] == "element":
            if len(words) != 3 or not words[2].isdigit():
                raise MeshFileError(f"{where}: an element needs a name and a count")
            elements.append(_Element(words[1], int(words[2]), []))
        elif words[0] == "property" and elements:
            if len(words) == 3 and words[1] in _TYPES:
                elements[-1].properties.append(_Property(words[2], _TYPES[words[1]]))
            elif len(words) == 5 and words[1] == "list" and words[2] in _TYPES and words[3] in _TYPES:
                if _TYPES[words[2]][0] == "f":
                    raise MeshFileError(f"{where}: the count of a list must be an integer type")
                elements[-1].properties.append(_Property(words[4], _TYPES[words[3]], _TYPES[words[2]]))
            else:
                raise MeshFileError(f"{where}: not a property of a known type")
        else:
            raise MeshFileError(f"{where}: not a PLY header line")
    if file_format is None:
        raise MeshFileError(f"{path}: the PLY header has no 'format' line")
    for element in elements:
        names = [p.name for p in element.properties]
        if len(set(names)) != len(names):
            raise MeshFileError(f"{path}: the PLY element {element.name!r} names a property twice")
    return file_format, elements, match.end()


def _roles(elements, path):
    """The vertex element, the face element and the index of its corner list."""
    by_name = {element.name: element for element in elements}
    vertex, face = by_name.get("vertex"), by_name.get("face")
    if vertex is None or not {"x", "y", "z"} <= {p.name for p in vertex.properties if p.count_kind is None}:
        raise MeshFileError(f"{path}: the PLY header has no 'vertex' element with x, y and z properties")
    if any(p.count_kind is not None for p in vertex.properties):
        raise MeshFileError(f"{path}: the PLY 'vertex' element has a list property; not supported")
    if face is None:
        raise MeshFileError(f"{path}: the PLY file has no 'face' element (a point cloud, not a surface)")
    lists = [i for i, p in enumerate(face.properties) if p.count_kind is not None]
    named = [i for i in lists if face.properties[i].name in _CORNER_NAMES]
    if not named and len(lists) != 1:
        raise MeshFileError(f"{path}: the PLY 'face' element has no 'vertex_indices' list property")
    corners = (named or lists)[0]
    if face.properties[corners].kind[0] == "f":
        raise MeshFileError(f"{path}: the PLY face indices are stored as floats; vertex indices must be integers")
    return vertex, face, corners


def _too_short(path, element, need, available, unit="bytes") -> MeshFileError:
    return MeshFileError(
        f"{path}: the PLY header declares {element.count} {element.plural} but the file holds only "
        f"{available} {unit} for them ({need} needed at least); the file is cut short or its header is wrong"
    )


def read_ply(path):
    """Read the vertices and faces of a PLY file, ASCII or binary.

    Returns
    -------
    vertices : ndarray of shape (V, 3), float64
    faces : ndarray of shape (F, k), int64, or a list of int64 arrays when
        the faces have different numbers of corners.

    Raises
    ------
    MeshFileError
        A header cut short or malformed, counts larger than the file can
        hold, the end of the file inside an element, float indices.
    """
    with open(path, "rb") as handle:
        data = without_bom(handle.read())
    file_format, elements, offset = _header(data, path)
    vertex, face, corners = _roles(elements, path)
    if file_format == "ascii":
        vertices, faces = _read_ascii(data, offset, elements, vertex, face, corners, path)
    else:
        vertices, faces = _read_binary(data, offset, _ORDERS[file_format], elements, vertex, face, corners, path)
    if len(faces) == 0:
        raise MeshFileError(f"{path}: the PLY file holds no faces")
    return vertices, faces


# ---------------------------------------------------------------- binary


def _read_binary(data, position, order, elements, vertex, face, corners, path):
    vertices = faces = None
    for element in elements:
        available = len(data) - position
        if all(p.count_kind is None for p in element.properties):
            record = np.dtype([(p.name, order + p.kind) for p in element.properties])
            need = element.count * record.itemsize
            if need > available:
                raise _too_short(path, element, need, available)
            if element is vertex:
                table = np.frombuffer(data, record, count=element.count, offset=position)
                vertices = np.column_stack([table[axis].astype(np.float64) for axis in "xyz"])
            position += need
            continue
        keep = corners if element is face else None
        lists, position = _binary_lists(data, position, order, element, keep, path)
        if element is face:
            faces = lists
    return vertices, faces


def _binary_lists(data, position, order, element, keep, path):
    """Read (or skip) an element with list properties: ``(faces or None, new position)``."""
    properties = element.properties
    sizes = [np.dtype(p.count_kind if p.count_kind else p.kind).itemsize for p in properties]
    available = len(data) - position
    if element.count * sum(sizes) > available:  # every record holds at least its counts and scalars
        raise _too_short(path, element, element.count * sum(sizes), available)
    if element.count == 0:
        return (np.zeros((0, 3), np.int64) if keep is not None else None), position
    # the common case: every record as the first one; one structured array
    layout: list[tuple] = []
    head = position
    for i, p in enumerate(properties):
        if p.count_kind is None:
            layout.append((f"p{i}", order + p.kind))
            head += sizes[i]
            continue
        if head + sizes[i] > len(data):
            raise _too_short(path, element, element.count * sum(sizes), available)
        n = int(np.frombuffer(data, order + p.count_kind, count=1, offset=head)[0])
        if n < 0:
            raise MeshFileError(f"{path}: a PLY list of the {element.name} element has a negative count")
        if head + sizes[i] + n * np.dtype(p.kind).itemsize > len(data):
            raise MeshFileError(f"{path}: the PLY file ends inside its {element.plural} (cut short)")
        layout += [(f"n{i}", order + p.count_kind), (f"p{i}", order + p.kind, (n,))]
        head += sizes[i] + n * np.dtype(p.kind).itemsize
    record = np.dtype(layout)
    if element.count * record.itemsize <= available:
        table = np.frombuffer(data, record, count=element.count, offset=position)
        counts = [name for name, *_ in layout if name.startswith("n")]
        if all((table[name] == table[name][0]).all() for name in counts):
            found = None
            if keep is not None:
                found = table[f"p{keep}"].astype(np.int64).reshape(element.count, -1)
            return found, position + element.count * record.itemsize
    return _walk_binary(data, position, order, element, keep, sizes, path)


def _walk_binary(data, position, order, element, keep, sizes, path):
    """Records of different sizes: walk them, then gather the kept lists in one pass."""
    plan: list[tuple[struct.Struct | None, int, int]] = []
    for p, size in zip(element.properties, sizes):
        if p.count_kind is None:
            plan.append((None, size, 0))
        else:
            code = {"i1": "b", "u1": "B", "i2": "h", "u2": "H", "i4": "i", "u4": "I", "i8": "q", "u8": "Q"}
            plan.append((struct.Struct(order + code[p.count_kind]), size, np.dtype(p.kind).itemsize))
    end = len(data)
    starts: list[int] = []
    counts: list[int] = []
    for _ in range(element.count):
        for i, (counter, size, item) in enumerate(plan):
            if counter is None:
                position += size
                continue
            if position + size > end:
                raise MeshFileError(f"{path}: the PLY file ends inside its {element.plural} (cut short)")
            (n,) = counter.unpack_from(data, position)
            position += size
            if n < 0 or position + n * item > end:
                raise MeshFileError(f"{path}: the PLY file ends inside its {element.plural} (cut short)")
            if i == keep:
                starts.append(position)
                counts.append(n)
            position += n * item
        if position > end:
            raise MeshFileError(f"{path}: the PLY file ends inside its {element.plural} (cut short)")
    if keep is None:
        return None, position
    kind = np.dtype(order + element.properties[keep].kind)
    lengths = np.array(counts, dtype=np.int64)
    first = np.repeat(
        np.array(starts, dtype=np.int64) - np.cumsum(lengths * kind.itemsize) + lengths * kind.itemsize,
        lengths * kind.itemsize,
    )
    byte_index = first + np.arange(first.size)
    values = np.frombuffer(data, np.uint8)[byte_index].view(kind).astype(np.int64)
    return _split(values, lengths), position


def _split(values: np.ndarray, counts: np.ndarray):
    if counts.size and (counts == counts[0]).all():
        return values.reshape(counts.size, int(counts[0]))
    return np.split(values, np.cumsum(counts)[:-1])


# ---------------------------------------------------------------- ASCII


def _integers(values: np.ndarray, path, what: str, lines=None) -> np.ndarray:
    """``values`` as int64; a value that is not a whole number is an error (naming its line: ``lines``, per value)."""
    bad = ~(np.abs(values) <= _LARGEST_INDEX) | (values != np.floor(values))
    if bad.any():
        where = f" line {int(np.asarray(lines)[bad][0])}:" if lines is not None else ""
        raise MeshFileError(
            f"{path}:{where} a PLY {what} is not an integer ({float(values[bad][0])!r}); indices must be whole numbers"
        )
    return values.astype(np.int64)


def _read_ascii(data, offset, elements, vertex, face, corners, path):
    """One record per line, as the format says: a line of the wrong length is an error naming it."""
    values, counts, first_value, lines = body_rows(data, offset, path)
    row, vertices, faces = 0, None, None
    for element in elements:
        available = counts.size - row
        rows = slice(row, row + min(element.count, available))  # the rows there are are checked first
        row += element.count
        if element.count > available:
            try:
                _ascii_element(values, counts[rows], first_value[rows], lines[rows], element, None, path)
            except MeshFileError as exc:
                raise MeshFileError(
                    f"{exc} (and the file ends before the {element.count} {element.plural} the header declares)"
                ) from None
            end = f" after line {int(lines[-1])}" if lines.size else ""
            raise MeshFileError(
                f"{path}: the PLY header declares {element.count} {element.plural} but the file "
                f"ends{end}, {available} rows later; the file is cut short or its header is wrong"
            )
        found = _ascii_element(
            values, counts[rows], first_value[rows], lines[rows], element, corners if element is face else None, path
        )
        if element is vertex:
            names = [p.name for p in element.properties]
            vertices = found[:, [names.index(axis) for axis in "xyz"]]
        elif element is face:
            faces = found
    if vertices is not None and faces is not None and len(faces):
        flat = faces if isinstance(faces, np.ndarray) else np.concatenate(faces)
        bad = (flat < 0) | (flat >= len(vertices))
        if bad.any():
            sizes = (
                np.full(len(faces), faces.shape[1])
                if isinstance(faces, np.ndarray)
                else np.array([len(f) for f in faces])
            )
            index = int(np.searchsorted(np.cumsum(sizes), np.argmax(bad.ravel()), side="right"))
            line = int(lines[sum(e.count for e in elements[: elements.index(face)]) + index])
            raise MeshFileError(
                f"{path}: line {line}: a face uses vertex {int(flat.ravel()[bad.ravel()][0])}; the "
                f"file has {len(vertices)} vertices, numbered from 0"
            )
    if row < counts.size:
        declared = ", ".join(f"{element.count} {element.plural}" for element in elements)
        raise MeshFileError(
            f"{path}: line {int(lines[row])}: a row after the last element (the header declares {declared})"
        )
    return vertices, faces


def _ascii_element(values, counts, first_value, lines, element, keep, path):
    """The rows of one element: a table of scalars, or the kept list of a list element (None when not kept)."""
    if all(p.count_kind is None for p in element.properties):
        names = [p.name for p in element.properties]
        return fixed_rows(values, counts, first_value, lines, len(names), path, f"{element.name}: {names_shown(names)}")
    return _ascii_lists(values, counts, first_value, lines, element, keep, path)


def _ascii_lists(values, counts, first_value, lines, element, keep, path):
    """The records of an element with list properties, one per line, walked property by property for all lines."""
    if counts.size == 0:
        return np.zeros((0, 3), np.int64) if keep is not None else None
    position = first_value.copy()
    end = first_value + counts
    sizes = {}
    for i, p in enumerate(element.properties):
        if p.count_kind is None:
            position += 1
            continue
        inside = position < end
        n = np.where(inside, values[np.minimum(position, values.size - 1)], 0.0)
        bad = inside & ((n < 0) | (n != np.floor(n)))
        if bad.any():
            row = int(np.argmax(bad))
            raise MeshFileError(
                f"{path}: line {int(lines[row])}: the {element.name} list count of {p.name} is not "
                f"a whole number ({n[row]!r})"
            )
        sizes[i] = np.minimum(n, counts).astype(np.int64)  # beyond its line: the row is too short anyway
        if i == keep:
            starts = position + 1
        position += 1 + sizes[i]
    need = position - first_value
    wrong = need != counts
    if wrong.any():
        row = int(np.argmax(wrong))
        parts = [
            p.name if i not in sizes else f"{p.name}: a count of {sizes[i][row]} and {sizes[i][row]} values"
            for i, p in enumerate(element.properties)
        ]
        raise row_error(path, int(lines[row]), int(counts[row]), int(need[row]), f"{element.name}: {', '.join(parts)}")
    if keep is None:
        return None
    lengths = sizes[keep]
    if (lengths < 3).any():
        row = int(np.argmax(lengths < 3))
        raise MeshFileError(f"{path}: line {int(lines[row])}: a face of {lengths[row]} corners; a face needs 3 or more")
    if (lengths == lengths[0]).all():
        table = values[starts[:, None] + np.arange(lengths[0])]
        return _integers(table, path, "face index", np.broadcast_to(lines[:, None], table.shape))
    flat = np.repeat(starts - np.cumsum(lengths) + lengths, lengths) + np.arange(lengths.sum())
    return _split(_integers(values[flat], path, "face index", np.repeat(lines, lengths)), lengths)


def ply_vertex_columns(path) -> dict[str, np.ndarray]:
    """The properties of the ``vertex`` element of a PLY file (ASCII or binary) by their names in the header.

    Only the vertex element is read (the elements after it, such as a
    surface's faces, are not parsed): the columns of a point cloud and of a
    mesh alike. ASCII values are float64; binary ones keep their stored type.
    """
    path = pathlib.Path(path)
    data = without_bom(path.read_bytes())
    file_format, elements, offset = _header(data, path)
    vertex = next((e for e in elements if e.name == "vertex"), None)
    if vertex is None:
        raise MeshFileError(f"{path}: the PLY header has no 'vertex' element")
    if any(p.count_kind is not None for p in vertex.properties):
        raise MeshFileError(f"{path}: the PLY 'vertex' element has a list property; not supported")
    before = elements[: elements.index(vertex)]
    if any(p.count_kind is not None for e in before for p in e.properties):
        raise MeshFileError(f"{path}: the PLY file has a list element before its vertices; not supported")
    if file_format == "ascii":  # one record per line: a line of the wrong length is named, never re-cut
        skip = sum(e.count for e in before)
        # each value takes at least two bytes (a digit and a separator): bound the count first
        if (sum(e.count * len(e.properties) for e in before) + vertex.count * len(vertex.properties)) * 2 > len(
            data
        ) - offset + 1:
            raise _short(path, vertex.count, "vertices", len(data) - offset)
        values, counts, first_value, lines = body_rows(data, offset, path, n_rows=skip + vertex.count)
        row = 0
        for element in [*before, vertex]:  # the rows there are are checked before a missing one is reported
            rows = slice(row, row + element.count)
            row += element.count
            names = [p.name for p in element.properties]
            shown = f"{element.name}: {names_shown(names)}"
            table = fixed_rows(values, counts[rows], first_value[rows], lines[rows], len(names), path, shown)
        if counts.size < skip + vertex.count:
            raise _short(path, vertex.count, "vertices", len(data) - offset)
        return {p.name: table[:, i] for i, p in enumerate(vertex.properties)}
    order = _ORDERS[file_format]
    position = offset
    for element in before:
        position += element.count * np.dtype([(p.name, order + p.kind) for p in element.properties]).itemsize
    record = np.dtype([(p.name, order + p.kind) for p in vertex.properties])
    need = vertex.count * record.itemsize
    if position + need > len(data):
        raise _short(path, vertex.count, "vertices", max(len(data) - position, 0), need)
    table = np.frombuffer(data, record, count=vertex.count, offset=position)
    return {p.name: table[p.name] for p in vertex.properties}


def _short(path, count, what, available, need=None) -> MeshFileError:
    needed = f" ({need} needed)" if need is not None else ""
    return MeshFileError(
        f"{path}: the header declares {count} {what} but the file holds only {available} bytes "
        f"for them{needed}; the file is cut short or its header is wrong"
    )
