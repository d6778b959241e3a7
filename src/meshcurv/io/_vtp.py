"""VTK XML PolyData (.vtp), ParaView's own surface format, with the standard library.

meshio reads and writes .vtu but not .vtp. This module writes inline base64
binary arrays (UInt64 headers, little-endian) and reads inline arrays in the
``ascii`` and ``binary`` encodings, compressed with zlib or not, with UInt32 or
UInt64 headers: what ParaView and VTK write by default except appended data,
which is refused with a message. A file of several ``<Piece>`` elements (as
:class:`PieceWriter` writes: one per object of a label image) is read as one
surface, its pieces joined in order, as VTK's reader does.
"""

from __future__ import annotations

import base64
import binascii
import xml.etree.ElementTree as ElementTree
import zlib

import numpy as np

from ..errors import MeshFileError
from ..topology import strip_triangles
from ._text import numbers

__all__ = ["read_vtp", "read_vtp_point_data", "read_vtp_cell_data", "write_vtp", "PieceWriter"]

_TYPES = {f"{u}Int{8 * n}": f"{'u' if u else 'i'}{n}" for n in (1, 2, 4, 8) for u in ("", "U")}
_TYPES.update(Float32="f4", Float64="f8")
_NAMES = {np.dtype(code).newbyteorder("<"): name for name, code in _TYPES.items()}


def _encode(array: np.ndarray) -> str:
    data = np.ascontiguousarray(array).astype(array.dtype.newbyteorder("<"), copy=False).tobytes()
    header = np.array([len(data)], dtype="<u8").tobytes()
    return (base64.b64encode(header) + base64.b64encode(data)).decode("ascii")


def _data_array(parent, array: np.ndarray, name: str | None = None) -> None:
    if array.dtype == bool:
        array = array.astype(np.uint8)
    attributes = {"type": _NAMES[array.dtype.newbyteorder("<")], "format": "binary"}
    if name is not None:
        attributes["Name"] = name
    if array.ndim == 2:
        attributes["NumberOfComponents"] = str(array.shape[1])
    element = ElementTree.SubElement(parent, "DataArray", attributes)
    element.text = _encode(array)


def _piece(vertices: np.ndarray, faces, point_data: dict, cell_data: dict | None = None):
    """The ``<Piece>`` element of a surface, its per-vertex fields and its per-face fields."""
    if isinstance(faces, np.ndarray):
        connectivity = faces.reshape(-1)
        offsets = np.arange(1, faces.shape[0] + 1) * faces.shape[1]
    else:
        connectivity = np.concatenate(faces) if len(faces) else np.zeros(0, dtype=np.int64)
        offsets = np.cumsum([len(face) for face in faces], dtype=np.int64)
    counts = {"NumberOfPoints": str(vertices.shape[0]), **dict.fromkeys(("NumberOfVerts", "NumberOfLines"), "0")}
    piece = ElementTree.Element("Piece", {**counts, "NumberOfStrips": "0", "NumberOfPolys": str(len(offsets))})
    for tag, data in (("PointData", point_data), ("CellData", cell_data)):
        if data is None:
            continue
        scalars = [name for name, value in data.items() if np.ndim(value) == 1]
        vectors = [name for name, value in data.items() if np.ndim(value) == 2]
        attributes = {}
        if scalars:
            attributes["Scalars"] = scalars[0]
        if vectors:
            attributes["Normals" if "normals" in vectors else "Vectors"] = (
                "normals" if "normals" in vectors else vectors[0]
            )
        fields = ElementTree.SubElement(piece, tag, attributes)
        for name, value in data.items():
            _data_array(fields, np.asarray(value), name)
    _data_array(ElementTree.SubElement(piece, "Points"), np.asarray(vertices, dtype=np.float64).reshape(-1, 3))
    polys = ElementTree.SubElement(piece, "Polys")
    _data_array(polys, np.asarray(connectivity, dtype=np.int64), "connectivity")
    _data_array(polys, np.asarray(offsets, dtype=np.int64), "offsets")
    return piece


_ROOT = {"type": "PolyData", "version": "1.0", "byte_order": "LittleEndian", "header_type": "UInt64"}


def write_vtp(path, vertices: np.ndarray, faces, point_data: dict, cell_data: dict | None = None) -> None:
    """Write a surface and its per-vertex (and per-face) fields (scalars and 3-vectors) as VTK XML PolyData."""
    root = ElementTree.Element("VTKFile", _ROOT)
    ElementTree.SubElement(root, "PolyData").append(_piece(vertices, faces, point_data, cell_data))
    ElementTree.indent(root)
    ElementTree.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)


class PieceWriter:
    """A VTK XML PolyData file written one ``<Piece>`` at a time: many surfaces, one file, bounded memory.

    VTK's reader (ParaView's) appends the pieces of a file into one
    dataset; every piece must carry the same point and cell arrays. Use as
    a context manager on an open binary file; :meth:`add` writes one piece.
    """

    def __init__(self, handle) -> None:
        self._handle = handle
        self.n_pieces = 0

    def __enter__(self) -> PieceWriter:
        attributes = " ".join(f'{key}="{value}"' for key, value in _ROOT.items())
        self._handle.write(f"<?xml version='1.0' encoding='utf-8'?>\n<VTKFile {attributes}>\n  <PolyData>\n".encode())
        return self

    def add(self, vertices: np.ndarray, faces, point_data: dict, cell_data: dict | None = None) -> None:
        piece = _piece(vertices, faces, point_data, cell_data)
        ElementTree.indent(piece, level=2)
        self._handle.write(b"    " + ElementTree.tostring(piece, encoding="utf-8", xml_declaration=False) + b"\n")
        self.n_pieces += 1

    def __exit__(self, *exc) -> None:
        self._handle.write(b"  </PolyData>\n</VTKFile>\n")


def _decode(element, path, *, header: str, order: str, compressed: bool) -> np.ndarray:
    kind = element.get("type")
    if kind not in _TYPES:
        raise MeshFileError(f"{path}: unsupported DataArray type {kind!r}")
    dtype = np.dtype(order + _TYPES[kind])
    encoding = element.get("format", "ascii")
    text = (element.text or "").strip()
    if encoding == "ascii":
        values = _numbers(text, path)
        if dtype.kind in "iu":
            bad = ~(np.abs(values) <= 2.0**53) | (values != np.floor(values))
            if bad.any():
                raise MeshFileError(
                    f"{path}: a DataArray of type {kind} holds a value that is not an integer "
                    f"({values[bad][0]!r}); indices must be whole numbers"
                )
        with np.errstate(over="ignore", invalid="ignore"):  # beyond Float32: inf, refused later
            values = values.astype(dtype)
    elif encoding == "binary":
        values = np.frombuffer(
            _binary(text, path, np.dtype(order + ("u8" if header == "UInt64" else "u4")), compressed), dtype=dtype
        )
    else:
        raise MeshFileError(
            f"{path}: DataArray format {encoding!r} is not supported (only inline 'ascii' and 'binary'); "
            "resave it from ParaView with appended data off, or as .vtu"
        )
    components = int(element.get("NumberOfComponents", "1"))
    return values.reshape(-1, components) if components > 1 else values


def _numbers(text: str, path) -> np.ndarray:
    values = numbers(text.encode("ascii", "replace"))
    if values is None:
        raise MeshFileError(
            f"{path}: a data array cannot be decoded (an ascii DataArray holds a word that is not a number)"
        )
    return values


def _header_values(text: str, count: int, header_type: np.dtype, path) -> np.ndarray:
    """The first ``count`` header integers of a base64 binary DataArray, or a MeshFileError."""
    chars = 4 * -(-count * header_type.itemsize // 3)
    raw = base64.b64decode(text[:chars])
    if len(raw) < count * header_type.itemsize:
        raise MeshFileError(f"{path}: a binary DataArray is empty or cut short (no complete header)")
    return np.frombuffer(raw, header_type, count=count)


def _binary(text: str, path, header_type: np.dtype, compressed: bool) -> bytes:
    """The bytes of a base64 binary DataArray; declared sizes checked before anything is allocated."""
    if not compressed:
        n_bytes = int(_header_values(text, 1, header_type, path)[0])
        data = base64.b64decode(text[4 * -(-header_type.itemsize // 3) :])
        if len(data) < n_bytes:
            raise MeshFileError(f"{path}: a binary DataArray declares {n_bytes} bytes but holds {len(data)}")
        return data[:n_bytes]
    # header: number of blocks, block size, last block size, compressed size of each block
    n_blocks = int(_header_values(text, 3, header_type, path)[0])
    if n_blocks * header_type.itemsize > len(text):
        raise MeshFileError(f"{path}: a compressed DataArray declares {n_blocks} blocks; the file holds far fewer")
    head = _header_values(text, 3 + n_blocks, header_type, path)
    block_size, last_size, sizes = int(head[1]), int(head[2]), head[3:].astype(np.int64)
    raw = base64.b64decode(text[4 * -(-(3 + n_blocks) * header_type.itemsize // 3) :])
    if int(sizes.sum()) > len(raw):
        raise MeshFileError(f"{path}: a compressed DataArray declares {int(sizes.sum())} bytes but holds {len(raw)}")
    blocks, start = [], 0
    for i, size in enumerate(sizes.tolist()):
        expected = last_size if i == n_blocks - 1 and last_size else block_size
        inflater = zlib.decompressobj()
        block = inflater.decompress(raw[start : start + size], expected + 1)  # never more than declared
        if len(block) != expected or not inflater.eof:
            raise MeshFileError(f"{path}: a compressed DataArray block does not hold its declared {expected} bytes")
        blocks.append(block)
        start += size
    return b"".join(blocks)


def _root(path):
    """``(root element, decoding options)`` of a VTK XML PolyData file."""
    try:
        root = ElementTree.parse(path).getroot()
    except ElementTree.ParseError as exc:
        raise MeshFileError(f"{path}: not a VTK XML file ({exc})") from None
    if root.tag != "VTKFile" or root.get("type") != "PolyData":
        raise MeshFileError(f"{path}: not a VTK PolyData file (root <{root.tag} type={root.get('type')!r}>)")
    compressed = root.get("compressor") is not None
    options = {
        "header": root.get("header_type", "UInt32"),
        "order": "<" if root.get("byte_order", "LittleEndian") == "LittleEndian" else ">",
        "compressed": compressed,
    }
    return root, options


def _arrays(path, tag: str) -> dict[str, np.ndarray]:
    """The named ``tag`` (``PointData``, ``CellData``) arrays of every piece, joined: (N,) or (N, k), as stored."""
    root, options = _root(path)
    pieces: list[dict[str, np.ndarray]] = []
    for piece in root.findall("PolyData/Piece"):
        out: dict[str, np.ndarray] = {}
        for element in piece.findall(f"{tag}/DataArray"):
            try:
                out[element.get("Name") or f"array_{len(out)}"] = _decode(element, path, **options)
            except MeshFileError:
                raise
            except (ValueError, zlib.error, binascii.Error) as exc:
                raise MeshFileError(f"{path}: a data array cannot be decoded ({exc})") from exc
        pieces.append(out)
    if len(pieces) <= 1:
        return pieces[0] if pieces else {}
    names = list(pieces[0])
    if any(list(piece) != names for piece in pieces[1:]):
        raise MeshFileError(f"{path}: the pieces of the file do not carry the same {tag} arrays")
    try:
        return {name: np.concatenate([piece[name] for piece in pieces]) for name in names}
    except ValueError as exc:
        raise MeshFileError(f"{path}: the {tag} array pieces do not match ({exc})") from exc


def read_vtp_point_data(path) -> dict[str, np.ndarray]:
    """The named point-data arrays of a VTK XML PolyData file (every piece, joined): (V,) or (V, k), as stored."""
    return _arrays(path, "PointData")


def read_vtp_cell_data(path) -> dict[str, np.ndarray]:
    """The named cell-data arrays of a VTK XML PolyData file (every piece, joined): (F,) or (F, k), as stored."""
    return _arrays(path, "CellData")


#: The cell elements of a piece read, and what they are called in messages.
_CELLS = {"Polys": "polygon", "Strips": "triangle strip"}


def _read_piece(piece, path, options):
    """``(vertices, connectivity, offsets)`` of one ``<Piece>``: its polygons, then the triangles of its triangle
    strips (``<Strips>``, as VTK's ``vtkStripper`` and PyVista's ``strip()`` write them)."""
    points = piece.find("Points/DataArray")
    cells = [piece.find(tag) for tag in _CELLS]
    if points is None or all(element is None for element in cells):
        raise MeshFileError(f"{path}: the PolyData has no points or no polygons (nor triangle strips)")
    try:
        vertices = _decode(points, path, **options).astype(np.float64).reshape(-1, 3)
    except MeshFileError:
        raise
    except (ValueError, zlib.error, binascii.Error) as exc:
        raise MeshFileError(f"{path}: a data array cannot be decoded ({exc})") from exc
    declared = piece.get("NumberOfPoints")
    if declared is not None and declared.strip() != str(vertices.shape[0]):
        raise MeshFileError(
            f"{path}: the PolyData declares {declared.strip()[:20]} points but holds {vertices.shape[0]}"
        )
    polys, strips = (_cell_arrays(element, path, options) for element in cells)
    connectivity, offsets = polys
    if (np.diff(offsets, prepend=0) < 3).any():
        raise MeshFileError(f"{path}: the polygon offsets do not match the connectivity")
    if strips[1].size:
        triangles = strip_triangles(*strips)
        offsets = np.concatenate([offsets, connectivity.size + 3 * np.arange(1, triangles.shape[0] + 1)])
        connectivity = np.concatenate([connectivity, triangles.ravel()])
    return vertices, connectivity, offsets


def _cell_arrays(element, path, options) -> tuple[np.ndarray, np.ndarray]:
    """``(connectivity, offsets)`` of a ``<Polys>`` or ``<Strips>`` element (empty when there is none)."""
    if element is None:
        return np.zeros(0, dtype=np.int64), np.zeros(0, dtype=np.int64)
    arrays = {array.get("Name"): array for array in element.findall("DataArray")}
    if "connectivity" not in arrays or "offsets" not in arrays:
        raise MeshFileError(f"{path}: the {_CELLS[element.tag]}s lack a connectivity or an offsets array")
    try:
        connectivity = _decode(arrays["connectivity"], path, **options).astype(np.int64)
        offsets = _decode(arrays["offsets"], path, **options).astype(np.int64)
    except MeshFileError:
        raise
    except (ValueError, zlib.error, binascii.Error) as exc:
        raise MeshFileError(f"{path}: a data array cannot be decoded ({exc})") from exc
    if (offsets.size and offsets[-1] != connectivity.size) or (np.diff(offsets, prepend=0) < 0).any():
        raise MeshFileError(f"{path}: the {_CELLS[element.tag]} offsets do not match the connectivity")
    return connectivity.ravel(), offsets.ravel()


def read_vtp(path):
    """Read the points and polygons of a VTK XML PolyData file (its pieces joined into one surface)."""
    root, options = _root(path)
    pieces = [_read_piece(piece, path, options) for piece in root.findall("PolyData/Piece")]
    if not pieces:
        raise MeshFileError(f"{path}: the PolyData has no points or no polygons")
    if len(pieces) == 1:
        vertices, connectivity, offsets = pieces[0]
    else:
        starts = np.cumsum([0] + [len(v) for v, _, _ in pieces[:-1]])
        ends = np.cumsum([0] + [c.size for _, c, _ in pieces[:-1]])
        vertices = np.concatenate([v for v, _, _ in pieces])
        connectivity = np.concatenate([c + start for (_, c, _), start in zip(pieces, starts)])
        offsets = np.concatenate([o + end for (_, _, o), end in zip(pieces, ends)])
    if vertices.shape[0] == 0 or offsets.size == 0:
        raise MeshFileError(f"{path}: the PolyData has no points or no polygons")
    sizes = np.diff(offsets, prepend=0)
    if (sizes == sizes[0]).all():
        return vertices, connectivity.reshape(-1, int(sizes[0]))
    return vertices, np.split(connectivity, offsets[:-1])
