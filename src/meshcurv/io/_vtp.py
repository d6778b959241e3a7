"""VTK XML PolyData (.vtp), ParaView's own surface format, with the standard library.

meshio reads and writes .vtu but not .vtp. This module writes inline base64
binary arrays (UInt64 headers, little-endian) and reads inline arrays in the
``ascii`` and ``binary`` encodings, compressed with zlib or not, with UInt32 or
UInt64 headers: what ParaView and VTK write by default except appended data,
which is refused with a message.
"""

from __future__ import annotations

import base64
import binascii
import xml.etree.ElementTree as ElementTree
import zlib

import numpy as np

from ..errors import MeshFileError
from ._text import numbers

__all__ = ["read_vtp", "read_vtp_point_data", "write_vtp"]

_TYPES = {
    "Int8": "i1", "UInt8": "u1", "Int16": "i2", "UInt16": "u2", "Int32": "i4", "UInt32": "u4",
    "Int64": "i8", "UInt64": "u8", "Float32": "f4", "Float64": "f8",
}
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


def write_vtp(path, vertices: np.ndarray, faces, point_data: dict) -> None:
    """Write a surface and its per-vertex fields (scalars and 3-vectors) as VTK XML PolyData."""
    if isinstance(faces, np.ndarray):
        connectivity = faces.reshape(-1)
        offsets = np.arange(1, faces.shape[0] + 1) * faces.shape[1]
    else:
        connectivity = np.concatenate(faces)
        offsets = np.cumsum([len(face) for face in faces])
    root = ElementTree.Element(
        "VTKFile", {"type": "PolyData", "version": "1.0", "byte_order": "LittleEndian", "header_type": "UInt64"}
    )
    piece = ElementTree.SubElement(
        ElementTree.SubElement(root, "PolyData"),
        "Piece",
        {"NumberOfPoints": str(vertices.shape[0]), "NumberOfVerts": "0", "NumberOfLines": "0",
         "NumberOfStrips": "0", "NumberOfPolys": str(len(offsets))},
    )
    scalars = [name for name, value in point_data.items() if np.ndim(value) == 1]
    vectors = [name for name, value in point_data.items() if np.ndim(value) == 2]
    attributes = {}
    if scalars:
        attributes["Scalars"] = scalars[0]
    if vectors:
        attributes["Normals" if "normals" in vectors else "Vectors"] = "normals" if "normals" in vectors else vectors[0]
    fields = ElementTree.SubElement(piece, "PointData", attributes)
    for name, value in point_data.items():
        _data_array(fields, np.asarray(value), name)
    _data_array(ElementTree.SubElement(piece, "Points"), np.asarray(vertices, dtype=np.float64))
    polys = ElementTree.SubElement(piece, "Polys")
    _data_array(polys, np.asarray(connectivity, dtype=np.int64), "connectivity")
    _data_array(polys, np.asarray(offsets, dtype=np.int64), "offsets")
    ElementTree.indent(root)
    ElementTree.ElementTree(root).write(path, encoding="utf-8", xml_declaration=True)


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
            bad = ~(np.abs(values) <= 2.0 ** 53) | (values != np.floor(values))
            if bad.any():
                raise MeshFileError(f"{path}: a DataArray of type {kind} holds a value that is not an integer "
                                    f"({values[bad][0]!r}); indices must be whole numbers")
        with np.errstate(over="ignore", invalid="ignore"):  # beyond Float32: inf, refused later
            values = values.astype(dtype)
    elif encoding == "binary":
        values = np.frombuffer(_binary(text, path, np.dtype(order + ("u8" if header == "UInt64" else "u4")),
                                       compressed), dtype=dtype)
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
        raise MeshFileError(f"{path}: a data array cannot be decoded (an ascii DataArray holds a word that is not a number)")
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
        data = base64.b64decode(text[4 * -(-header_type.itemsize // 3):])
        if len(data) < n_bytes:
            raise MeshFileError(f"{path}: a binary DataArray declares {n_bytes} bytes but holds {len(data)}")
        return data[:n_bytes]
    # header: number of blocks, block size, last block size, compressed size of each block
    n_blocks = int(_header_values(text, 3, header_type, path)[0])
    if n_blocks * header_type.itemsize > len(text):
        raise MeshFileError(f"{path}: a compressed DataArray declares {n_blocks} blocks; the file holds far fewer")
    head = _header_values(text, 3 + n_blocks, header_type, path)
    block_size, last_size, sizes = int(head[1]), int(head[2]), head[3:].astype(np.int64)
    raw = base64.b64decode(text[4 * -(-(3 + n_blocks) * header_type.itemsize // 3):])
    if int(sizes.sum()) > len(raw):
        raise MeshFileError(f"{path}: a compressed DataArray declares {int(sizes.sum())} bytes but holds {len(raw)}")
    blocks, start = [], 0
    for i, size in enumerate(sizes.tolist()):
        expected = last_size if i == n_blocks - 1 and last_size else block_size
        inflater = zlib.decompressobj()
        block = inflater.decompress(raw[start:start + size], expected + 1)  # never more than declared
        if len(block) != expected or not inflater.eof:
            raise MeshFileError(f"{path}: a compressed DataArray block does not hold its declared {expected} bytes")
        blocks.append(block)
        start += size
    return b"".join(blocks)


def _root(path):
    """``(piece, decoding options)`` of a VTK XML PolyData file."""
    try:
        root = ElementTree.parse(path).getroot()
    except ElementTree.ParseError as exc:
        raise MeshFileError(f"{path}: not a VTK XML file ({exc})") from None
    if root.tag != "VTKFile" or root.get("type") != "PolyData":
        raise MeshFileError(f"{path}: not a VTK PolyData file (root <{root.tag} type={root.get('type')!r}>)")
    compressed = root.get("compressor") is not None
    options = {"header": root.get("header_type", "UInt32"),
               "order": "<" if root.get("byte_order", "LittleEndian") == "LittleEndian" else ">",
               "compressed": compressed}
    return root.find("PolyData/Piece"), options


def read_vtp_point_data(path) -> dict[str, np.ndarray]:
    """The named point-data arrays of a VTK XML PolyData file: (V,) or (V, k), as stored."""
    piece, options = _root(path)
    arrays = piece.findall("PointData/DataArray") if piece is not None else []
    out: dict[str, np.ndarray] = {}
    for element in arrays:
        try:
            out[element.get("Name") or f"array_{len(out)}"] = _decode(element, path, **options)
        except MeshFileError:
            raise
        except (ValueError, zlib.error, binascii.Error) as exc:
            raise MeshFileError(f"{path}: a data array cannot be decoded ({exc})") from exc
    return out


def read_vtp(path):
    """Read the points and polygons of a VTK XML PolyData file."""
    piece, options = _root(path)
    points = piece.find("Points/DataArray") if piece is not None else None
    polys = piece.find("Polys") if piece is not None else None
    if points is None or polys is None:
        raise MeshFileError(f"{path}: the PolyData has no points or no polygons")
    arrays = {element.get("Name"): element for element in polys.findall("DataArray")}
    if "connectivity" not in arrays or "offsets" not in arrays:
        raise MeshFileError(f"{path}: the polygons lack a connectivity or an offsets array")
    try:
        vertices = _decode(points, path, **options).astype(np.float64).reshape(-1, 3)
        connectivity = _decode(arrays["connectivity"], path, **options).astype(np.int64)
        offsets = _decode(arrays["offsets"], path, **options).astype(np.int64)
    except MeshFileError:
        raise
    except (ValueError, zlib.error, binascii.Error) as exc:
        raise MeshFileError(f"{path}: a data array cannot be decoded ({exc})") from exc
    declared = piece.get("NumberOfPoints")
    if declared is not None and declared.strip() != str(vertices.shape[0]):
        raise MeshFileError(f"{path}: the PolyData declares {declared.strip()[:20]} points but holds {vertices.shape[0]}")
    if vertices.shape[0] == 0 or offsets.size == 0:
        raise MeshFileError(f"{path}: the PolyData has no points or no polygons")
    sizes = np.diff(offsets, prepend=0)
    if offsets[-1] != connectivity.size or (sizes < 3).any():
        raise MeshFileError(f"{path}: the polygon offsets do not match the connectivity")
    if (sizes == sizes[0]).all():
        return vertices, connectivity.reshape(-1, int(sizes[0]))
    return vertices, np.split(connectivity, offsets[:-1])
