"""Fuzz every mesh file reader: ``python benchmarks/fuzz_readers.py [--minutes N] [--seed S]``.

For every readable format of :data:`meshcurv.io.FORMATS` (and legacy VTK
POLYDATA beside meshio's UNSTRUCTURED_GRID), mutated valid files are fed to
``read_mesh``, each read in a child process with a time limit and a memory
limit (``RLIMIT_AS``), so that a hang or a blow-up is a finding, not a stuck
run. Mutations:

- truncation at every structural boundary (each line end, each header word,
  the start and end of each element) and at random offsets;
- byte flips, inserted and deleted bytes, duplicated ranges;
- huge declared counts (every integer of the header or of a count line
  replaced by 10**9, 2**31 - 1, 2**63 - 1, -1, 0);
- header garbage: a header line dropped, duplicated, or replaced by random bytes.

A finding is any exception other than the documented ones (MeshFileError,
InvalidMeshError, MissingDependencyError), any warning, a child that does
not finish within ``--timeout`` seconds, or one that runs out of its memory
limit (``--memory`` MiB, far beyond what these small files need). Prints one
line per format and the findings with their inputs (saved in ``--keep``);
exits 1 when there is any.

Text rows (``--mode rows``; half of the time by default): a valid file of
every text format (CSV with and without a header, with semicolons and
decimal commas; XYZ with blanks or tabs; .pts with its count line; TXT;
ASCII PLY clouds and meshes; ASCII PCD; OBJ; OFF; ASCII STL) is written
from known points and faces, and one row is changed: a value dropped, one
added, one moved to the next row (the total stays right), an empty value, a
trailing separator (on one row or on all), a row split or joined with the
next, a word that is not a number; or the file is changed harmlessly (a
blank line, a comment, CRLF, a UTF-8 byte-order mark first). The reader must return exactly the points and
faces written, or raise a MeshFileError naming a line the change touched (or
the count line it contradicts). A different result (a re-cut), an error for
a harmless change or one naming no line is a finding; an error naming another
line is counted apart (``named (another line)``: two OBJ ``v`` rows joined
read as one vertex with a colour, then a face names a vertex beyond them), as
is a value added to a row the format lets hold more (``another valid file``:
OBJ ``v x y z w`` and polygons, an OFF face's colour, a PLY face row that
starts with a new whole number: a polygon), which no reader can tell from
the file written.

Wide rows (``--wide P``, a share of the text cases from a stream of their
own; 0 by default, the draws of earlier rounds): the same changes on files
whose rows hold more than x, y and z, as scanners write them: CSV with a
header naming normals and other columns in any order, XYZ of six columns
(unit normals, read as normals without a header; or colours, which are not),
Leica .pts (a count line, then ``x y z intensity r g b``), ASCII PLY clouds
whose vertex properties come in any order with normals, colours and an
intensity, and ASCII PLY meshes with such vertices, a face property beside
the corner list and an element after the faces. The points (and the faces)
must be those written and the normals too, where the file names them.
"""

from __future__ import annotations

import argparse
import multiprocessing
import pathlib
import random
import re
import sys
import tempfile
import time

import numpy as np

from meshcurv import io, shapes
from meshcurv.errors import InvalidMeshError, MeshFileError, MissingDependencyError

DOCUMENTED = (MeshFileError, InvalidMeshError, MissingDependencyError)
HUGE = [b"1000000000", b"2147483647", b"9223372036854775807", b"-1", b"0", b"99999999999999999999"]


def _legacy_polydata(binary: bool, version: str) -> bytes:
    torus = shapes.torus(n_major=6, n_minor=4)
    vertices, faces = torus.vertices, torus.faces

    def array(values, code):
        if binary:
            return np.asarray(values).astype(">" + code).tobytes() + b"\n"
        return (" ".join(map(str, np.asarray(values).ravel().tolist())) + "\n").encode()

    parts = [
        f"# vtk DataFile Version {version}\nfuzz\n{'BINARY' if binary else 'ASCII'}\nDATASET POLYDATA\n".encode(),
        f"POINTS {len(vertices)} double\n".encode() + array(vertices, "f8"),
    ]
    if version.startswith("5"):
        offsets = np.arange(len(faces) + 1) * 3
        parts.append(b"METADATA\nINFORMATION 0\n\n")
        parts.append(
            f"POLYGONS {len(offsets)} {faces.size}\nOFFSETS vtktypeint64\n".encode()
            + array(offsets, "i8")
            + b"CONNECTIVITY vtktypeint64\n"
            + array(faces, "i8")
        )
    else:
        cells = np.column_stack([np.full(len(faces), 3), faces])
        parts.append(f"POLYGONS {len(faces)} {cells.size}\n".encode() + array(cells, "i4"))
    parts.append(
        f"POINT_DATA {len(vertices)}\nSCALARS k float 1\nLOOKUP_TABLE default\n".encode()
        + array(np.arange(len(vertices)), "f4")
    )
    return b"".join(parts)


def _strip_files() -> list[tuple[str, str, bytes]]:
    """Triangle strips beside polygons: legacy VTK (ASCII, binary) and .vtp, half the torus's faces each way.

    One strip per face, and two faces in one strip joined through repeated points (``a b c c d d d e f``: the
    triangles between have no area), as ``vtkStripper`` joins them.
    """
    torus = shapes.torus(n_major=6, n_minor=4)
    vertices, faces = torus.vertices, torus.faces
    half = len(faces) // 2
    strips = [list(face) for face in faces[half:-2].tolist()]
    (a, b, c), (d, e, f) = faces[-2].tolist(), faces[-1].tolist()
    strips.append([a, b, c, c, d, d, d, e, f])
    flat = [value for strip in strips for value in [len(strip), *strip]]
    out = []
    for binary in (False, True):

        def array(values, code, binary=binary):
            if binary:
                return np.asarray(values).astype(">" + code).tobytes() + b"\n"
            return (" ".join(map(str, np.asarray(values).ravel().tolist())) + "\n").encode()

        cells = np.column_stack([np.full(half, 3), faces[:half]])
        out.append(
            (
                f"vtk-strips-{'bin' if binary else 'ascii'}",
                ".vtk",
                f"# vtk DataFile Version 4.2\nfuzz\n{'BINARY' if binary else 'ASCII'}\nDATASET POLYDATA\n".encode()
                + f"POINTS {len(vertices)} double\n".encode()
                + array(vertices, "f8")
                + f"POLYGONS {half} {cells.size}\n".encode()
                + array(cells, "i4")
                + f"TRIANGLE_STRIPS {len(strips)} {len(flat)}\n".encode()
                + array(flat, "i4"),
            )
        )

    def data_array(values, name, kind="Int64", components=1):
        text = " ".join(map(str, np.asarray(values).ravel().tolist()))
        return (
            f'<DataArray type="{kind}" Name="{name}" NumberOfComponents="{components}" format="ascii">'
            f"{text}</DataArray>"
        )

    ends = np.cumsum([len(strip) for strip in strips])
    polys = data_array(faces[:half], "connectivity") + data_array(3 * np.arange(1, half + 1), "offsets")
    vtp = (
        f'<VTKFile type="PolyData"><PolyData><Piece NumberOfPoints="{len(vertices)}">'
        f"<Points>{data_array(vertices, 'points', 'Float64', 3)}</Points><Polys>{polys}</Polys>"
        f"<Strips>{data_array(sum(strips, []), 'connectivity')}{data_array(ends, 'offsets')}</Strips>"
        "</Piece></PolyData></VTKFile>\n"
    )
    out.append(("vtp-strips-ascii", ".vtp", vtp.encode()))
    return out


def seeds(directory: pathlib.Path) -> list[tuple[str, str, bytes]]:
    """``(label, extension, bytes)``: valid small files of every readable format and layout."""
    torus = shapes.torus(n_major=6, n_minor=4)
    mixed = [[0, 1, 7, 6], *torus.faces[2:].tolist()]
    found = []
    for fmt in io.FORMATS.values():
        if fmt.read is None:
            continue
        for extension in fmt.extensions:
            for binary in (True, False):
                for label, faces in (("tri", torus.faces), ("mixed", mixed)):
                    path = directory / f"seed-{label}-{binary}{extension}"
                    try:
                        io.write_mesh(path, torus.vertices, faces, binary=binary, overwrite=True)
                    except (MissingDependencyError, MeshFileError, InvalidMeshError):
                        continue
                    found.append(
                        (f"{extension[1:]}-{label}-{'bin' if binary else 'ascii'}", extension, path.read_bytes())
                    )
    for binary in (True, False):
        for version in ("4.2", "5.1"):
            found.append(
                (f"vtk-polydata{version}-{'bin' if binary else 'ascii'}", ".vtk", _legacy_polydata(binary, version))
            )
    found += _strip_files()
    unique = {}
    for label, extension, data in found:
        unique.setdefault((extension, data), label)
    return [(label, extension, data) for (extension, data), label in unique.items()]


def _boundaries(data: bytes) -> list[int]:
    marks = {0, len(data)}
    for pattern in (
        rb"\n",
        rb"\s",
        rb"end_header",
        rb"POLYGONS|POINTS|OFFSETS|CONNECTIVITY|POINT_DATA",
        rb"<DataArray|</DataArray>|>",
        rb"PK\x03\x04|PK\x01\x02|PK\x05\x06",
        rb"\nf |\nv ",
    ):
        for match in re.finditer(pattern, data[:200000]):
            marks.update((match.start(), match.end()))
    return sorted(marks)


def mutate(data: bytes, rng: random.Random) -> tuple[str, bytes]:
    choice = rng.randrange(6)
    if choice == 0:  # truncation at a boundary (or next to one)
        cut = rng.choice(_boundaries(data)) + rng.choice([-1, 0, 0, 0, 1])
        return f"cut at {cut}", data[: max(cut, 0)]
    if choice == 1:
        cut = rng.randrange(len(data) + 1)
        return f"cut at {cut}", data[:cut]
    if choice == 2:  # byte flips, insertions, deletions, duplications
        buffer = bytearray(data)
        for _ in range(rng.randint(1, 8)):
            i = rng.randrange(len(buffer) or 1)
            what = rng.randrange(4)
            if what == 0 and buffer:
                buffer[i] = rng.randrange(256)
            elif what == 1:
                del buffer[i : i + rng.randint(1, 16)]
            elif what == 2:
                buffer[i:i] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
            else:
                buffer[i:i] = buffer[i : i + rng.randint(1, 64)]
        return "bytes changed", bytes(buffer)
    if choice == 3:  # a huge (or negative, or zero) declared count
        numbers = list(re.finditer(rb"(?<![\w.\-])\d+(?![\w.])", data[:4096]))
        if numbers:
            match = rng.choice(numbers)
            value = rng.choice(HUGE)
            return f"count at {match.start()} -> {value.decode()}", data[: match.start()] + value + data[match.end() :]
        return "unchanged", data
    if choice == 4:  # header garbage: a line dropped, doubled or replaced
        lines = data[:4096].split(b"\n")
        i = rng.randrange(len(lines))
        what = rng.randrange(3)
        if what == 0:
            del lines[i]
        elif what == 1:
            lines.insert(i, lines[i])
        else:
            lines[i] = bytes(rng.randrange(256) for _ in range(rng.randint(0, 40)))
        return f"header line {i} changed", b"\n".join(lines) + data[4096:]
    # a float where an integer belongs
    numbers = list(re.finditer(rb"(?<![\w.\-])\d+(?![\w.])", data))
    if numbers:
        match = rng.choice(numbers)
        return f"number at {match.start()} -> float", data[: match.start()] + match.group() + b".5" + data[
            match.end() :
        ]
    return "unchanged", data


def _child(path: str, memory_bytes: int, queue) -> None:
    import resource
    import warnings

    resource.setrlimit(resource.RLIMIT_AS, (memory_bytes, memory_bytes))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            io.read_mesh(path)
        queue.put(("ok", ""))
    except DOCUMENTED:
        queue.put(("documented", ""))
    except MemoryError:
        queue.put(("memory", "MemoryError"))
    except BaseException as exc:  # noqa: BLE001 - every other exception is a finding
        queue.put(("crash", f"{type(exc).__name__}: {str(exc)[:300]}"))


def read_in_child(context, path: pathlib.Path, timeout: float, memory_bytes: int) -> tuple[str, str]:
    queue = context.Queue()
    process = context.Process(target=_child, args=(str(path), memory_bytes, queue))
    process.start()
    process.join(timeout)
    if process.is_alive():
        process.kill()
        process.join()
        return "hang", f"no answer within {timeout} s"
    try:
        return queue.get(timeout=1)
    except Exception:  # noqa: BLE001 - the child died without a word (killed by the memory limit)
        return "memory", f"child ended with code {process.exitcode} and no answer"


# ---------------------------------------------------------------- text rows (issue 29, class 5)
#
# A valid text file is written from known points (and faces), one record per row; one row (or
# the layout of every row) is then changed. The reader must either return exactly the intended
# points and faces, or raise a MeshFileError whose message names a line the change touched. A
# different result is a finding (a silent re-cut), as is an error for a change that leaves the
# file valid (blank lines, CRLF, doubled blanks), an error naming no line or another line, any
# other exception, a warning, a hang or a blow-up.

#: changes that leave the file valid: the reader must read the intended points
HARMLESS = ("none", "blank line", "crlf", "comment line", "byte-order mark")
#: changes to one row (or two): the intended result, or an error naming a touched line
DAMAGING = (
    "drop a value",
    "extra value",
    "move a value to the next row",
    "empty value",
    "trailing separator",
    "trailing separator on every row",
    "split the row",
    "join with the next row",
    "not a number",
)


class Row:
    """One record of a text file: ``prefix + separator.join(words) + suffix``; ``data`` marks the mutable rows."""

    def __init__(self, words, separator=" ", prefix="", data=True, free=False):
        self.words, self.separator, self.prefix, self.data = list(words), separator, prefix, data
        self.free = free  # the format lets this row hold more values (OBJ `v x y z w`, polygons, OFF colours)

    def text(self) -> str:
        return self.prefix + self.separator.join(self.words)


def _number(rng: random.Random) -> str:
    return repr(rng.choice([rng.uniform(-10, 10), float(rng.randint(-5, 5)), rng.uniform(-1e-3, 1e-3)]))


def _cloud(rng: random.Random) -> np.ndarray:
    return np.array([[float(_number(rng)) for _ in range(3)] for _ in range(rng.randint(3, 12))])


def _surface(rng: random.Random) -> tuple[np.ndarray, np.ndarray]:
    torus = shapes.torus(n_major=rng.choice([3, 4, 5]), n_minor=3)
    return np.round(torus.vertices, 6), torus.faces


def _words(values) -> list[str]:
    return [repr(float(v)) if isinstance(v, float) or np.issubdtype(type(v), np.floating) else str(v) for v in values]


def text_case(kind: str, rng: random.Random):
    """``(extension, reader, rows, points, faces, extra_lines)``: a valid file of ``kind`` as rows.

    ``extra_lines`` are the indices of rows an error may also name (a count line that the
    change contradicts).
    """
    faces = None
    extra: list[int] = []
    if kind in ("csv", "csv-header", "csv-semicolon", "xyz", "xyz-tab", "pts", "txt-header"):
        points = _cloud(rng)
        separator = {"csv": ",", "csv-header": ",", "csv-semicolon": ";", "xyz-tab": "\t"}.get(kind, " ")
        rows = []
        if kind in ("csv-header", "csv-semicolon", "txt-header"):
            rows.append(Row(["x", "y", "z"], separator, data=False))
        if kind == "pts":
            rows.append(Row([str(len(points))], data=False))
            extra.append(0)
        for point in points:
            words = _words(point)
            if kind == "csv-semicolon":
                words = [word.replace(".", ",") for word in words]
            rows.append(Row(words, separator))
        extension = {
            "csv": ".csv",
            "csv-header": ".csv",
            "csv-semicolon": ".csv",
            "pts": ".pts",
            "txt-header": ".txt",
        }.get(kind, ".xyz")
        return extension, "points", rows, points, None, extra
    if kind == "ply-cloud":
        points = _cloud(rng)
        header = [
            "ply",
            "format ascii 1.0",
            f"element vertex {len(points)}",
            "property double x",
            "property double y",
            "property double z",
            "end_header",
        ]
        rows = [Row([line], data=False) for line in header] + [Row(_words(p)) for p in points]
        return ".ply", "points", rows, points, None, [2]
    if kind == "pcd":
        points = _cloud(rng)
        header = [
            "VERSION 0.7",
            "FIELDS x y z",
            "SIZE 8 8 8",
            "TYPE F F F",
            "COUNT 1 1 1",
            f"WIDTH {len(points)}",
            "HEIGHT 1",
            f"POINTS {len(points)}",
            "DATA ascii",
        ]
        rows = [Row([line], data=False) for line in header] + [Row(_words(p)) for p in points]
        return ".pcd", "points", rows, points, None, [5, 7]
    points, faces = _surface(rng)
    if kind == "ply-mesh":
        header = [
            "ply",
            "format ascii 1.0",
            f"element vertex {len(points)}",
            "property double x",
            "property double y",
            "property double z",
            f"element face {len(faces)}",
            "property list uchar int vertex_indices",
            "end_header",
        ]
        rows = [Row([line], data=False) for line in header] + [Row(_words(p)) for p in points]
        rows += [Row(["3", *map(str, face)], free=True) for face in faces]  # a whole number added first: a polygon
        return ".ply", "mesh", rows, points, faces, [2, 6]
    if kind == "obj":
        rows = [Row(_words(p), prefix="v ", free=True) for p in points]
        rows += [Row(map(str, face + 1), prefix="f ", free=True) for face in faces]
        return ".obj", "mesh", rows, points, faces, []
    if kind == "off":
        rows = [Row(["OFF"], data=False), Row([f"{len(points)} {len(faces)} 0"], data=False)]
        rows += [Row(_words(p)) for p in points] + [Row(["3", *map(str, face)], free=True) for face in faces]
        return ".off", "mesh", rows, points, faces, [1]
    if kind == "stl":
        rows = [Row(["solid fuzz"], data=False)]
        for face in faces:
            rows += [Row(["facet normal 0 0 1"], data=False), Row(["outer loop"], data=False)]
            rows += [Row(_words(points[i]), prefix="vertex ") for i in face]
            rows += [Row(["endloop"], data=False), Row(["endfacet"], data=False)]
        rows.append(Row(["endsolid fuzz"], data=False))
        return ".stl", "mesh", rows, points, faces, []
    raise ValueError(kind)


def _unit(rng: random.Random, n: int) -> np.ndarray:
    """``n`` unit vectors whose written digits are read back as the same floats (and still unit)."""
    vectors = np.array([[rng.gauss(0.0, 1.0) for _ in range(3)] for _ in range(n)])
    return vectors / np.linalg.norm(vectors, axis=1, keepdims=True)


def _colour(rng: random.Random) -> list[str]:
    return [str(rng.randint(2, 255)) for _ in range(3)]  # never a unit vector (read as normals)


def wide_case(kind: str, rng: random.Random):
    """``(extension, reader, rows, points, faces, extra_lines, normals)``: a file of ``kind`` in
    :data:`WIDE_KINDS`, whose rows hold more than x, y and z; ``normals`` None when the file names none."""
    if kind == "ply-mesh-props":
        points, faces = _surface(rng)
    else:
        points = _cloud(rng)
        faces = None
    normals = _unit(rng, len(points))
    columns = {"x": points[:, 0], "y": points[:, 1], "z": points[:, 2]}
    columns.update({"nx": normals[:, 0], "ny": normals[:, 1], "nz": normals[:, 2]})
    if kind in ("csv-normals", "txt-normals"):
        names = ["x", "y", "z", "nx", "ny", "nz", "intensity"]
        rng.shuffle(names)  # any order: the header says which column is which
        columns["intensity"] = np.array([rng.uniform(0, 1) for _ in range(len(points))])
        separator = "," if kind == "csv-normals" else " "
        rows = [Row(names, separator, data=False)]
        rows += [Row(_words([columns[name][i] for name in names]), separator) for i in range(len(points))]
        return (".csv" if kind == "csv-normals" else ".txt"), "points", rows, points, None, [], normals
    if kind in ("xyz-normals", "xyz-rgb"):
        rows = []
        for i, point in enumerate(points):
            tail = _words(normals[i]) if kind == "xyz-normals" else _colour(rng)
            rows.append(Row(_words(point) + tail))
        return ".xyz", "points", rows, points, None, [], (normals if kind == "xyz-normals" else None)
    if kind == "pts-leica":  # a count line, then x y z intensity r g b (Leica's scanners)
        rows = [Row([str(len(points))], data=False)]
        rows += [Row(_words(point) + [str(rng.randint(-2047, 2047)), *_colour(rng)]) for point in points]
        return ".pts", "points", rows, points, None, [0], None
    # PLY: the vertex properties in any order, with normals, colours and an intensity
    types = {"x": "double", "y": "double", "z": "double", "nx": "double", "ny": "double", "nz": "double"}
    types.update({"red": "uchar", "green": "uchar", "blue": "uchar", "intensity": "float"})
    names = list(types)
    rng.shuffle(names)
    colours = np.array([[rng.randint(2, 255) for _ in range(3)] for _ in range(len(points))])
    columns.update({"red": colours[:, 0], "green": colours[:, 1], "blue": colours[:, 2]})
    columns["intensity"] = np.array([float(rng.randint(0, 100)) / 4 for _ in range(len(points))])
    header = ["ply", "format ascii 1.0", "comment wide rows", f"element vertex {len(points)}"]
    header += [f"property {types[name]} {name}" for name in names]
    extra = [3]
    if faces is not None:
        header += [f"element face {len(faces)}"]
        extra.append(len(header) - 1)
        face_properties = ["property list uchar int vertex_indices", "property uchar flags"]
        if rng.random() < 0.5:
            face_properties.reverse()  # the corner list after a scalar
        header += face_properties
        header += ["element edge 2", "property int vertex1", "property int vertex2"]
        extra.append(len(header) - 3)
    header.append("end_header")
    rows = [Row([line], data=False) for line in header]
    rows += [Row([_words([columns[name][i]])[0] for name in names]) for i in range(len(points))]
    if faces is not None:
        for face in faces:
            words = ["3", *map(str, face)]
            flags = str(rng.randint(0, 9))
            words = [*words, flags] if face_properties[0].endswith("vertex_indices") else [flags, *words]
            rows.append(Row(words, free=True))  # a whole number added before the corners: a polygon
        rows += [Row(map(str, faces[0][:2])), Row(map(str, faces[-1][:2]))]
        return ".ply", "mesh", rows, points, faces, extra, None
    return ".ply", "points", rows, points, None, extra, normals


TEXT_KINDS = (
    "csv",
    "csv-header",
    "csv-semicolon",
    "xyz",
    "xyz-tab",
    "pts",
    "txt-header",
    "ply-cloud",
    "pcd",
    "ply-mesh",
    "obj",
    "off",
    "stl",
)

#: Files whose rows hold more than x, y and z (``--wide``): :func:`wide_case`.
WIDE_KINDS = ("csv-normals", "txt-normals", "xyz-normals", "xyz-rgb", "pts-leica", "ply-cloud-props", "ply-mesh-props")


def mutate_rows(rows: list, change: str, rng: random.Random) -> tuple[str, set]:
    """Apply ``change`` to ``rows``: ``(text, touched, free)``, the file, the 1-based lines it touched, and
    whether the change made another valid file (a value added to a row that may hold more)."""
    before = "\n".join(row.text() for row in rows) + "\n"
    data_rows = [i for i, row in enumerate(rows) if row.data]
    i = rng.choice(data_rows)
    row = rows[i]
    touched = {i}
    newline = "\n"
    if change == "drop a value":
        del row.words[rng.randrange(len(row.words))]
    elif change == "extra value":
        row.words.insert(rng.randrange(len(row.words) + 1), _number(rng))
    elif change == "move a value to the next row" and i + 1 < len(rows) and rows[i + 1].data:
        rows[i + 1].words.insert(0, row.words.pop())
        touched.add(i + 1)
    elif change == "empty value":
        row.words.insert(rng.randrange(len(row.words) + 1), "")
    elif change == "trailing separator":
        row.words.append("")
    elif change == "trailing separator on every row":
        for other in data_rows:
            rows[other].words.append("")
        touched = set(data_rows)
    elif change == "not a number":
        row.words[rng.randrange(len(row.words))] = rng.choice(["x", "1.2.3", "--1", "nan1", "1e", "0x10"])
    elif change == "blank line":
        rows.insert(i + 1, Row([""], data=False))
    elif change == "comment line" and rows[0].text().split()[0] not in ("ply", "OFF", "solid", "VERSION"):
        rows.insert(i + 1, Row(["# a comment"], data=False))
    elif change == "crlf":
        newline = "\r\n"
    elif change == "split the row" and len(row.words) > 1:
        cut = rng.randrange(1, len(row.words))
        rows.insert(i + 1, Row(row.words[cut:], row.separator, data=True))
        row.words = row.words[:cut]
        touched.add(i + 1)
    elif change == "join with the next row" and i + 1 < len(rows) and rows[i + 1].data:
        row.words += rows[i + 1].words
        del rows[i + 1]
        touched.add(i + 1)
    lead = "\ufeff" if change == "byte-order mark" else ""  # what Excel and Notepad put first in UTF-8
    lines = [row.text() for row in rows]
    text = lead + newline.join(lines) + newline
    applied = change in DAMAGING and text != before
    free = change in ("extra value", "join with the next row") and row.free
    return text, ({t + 1 for t in touched} if applied else set()), free


def _text_child(path: str, reader: str, memory_bytes: int, queue) -> None:
    import resource
    import warnings

    resource.setrlimit(resource.RLIMIT_AS, (memory_bytes, memory_bytes))
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            normals = None
            if reader == "points":
                points, normals = io.read_points(path)
                faces = None
            else:
                points, faces = io.read_mesh(path)
                faces = np.asarray(faces) if isinstance(faces, np.ndarray) else [list(f) for f in faces]
        queue.put(("read", (points, faces, normals)))
    except MeshFileError as exc:
        queue.put(("error", str(exc)))
    except MissingDependencyError as exc:
        queue.put(("skipped", str(exc)))
    except DOCUMENTED as exc:
        queue.put(("other documented", f"{type(exc).__name__}: {exc}"))
    except MemoryError:
        queue.put(("memory", "MemoryError"))
    except BaseException as exc:  # noqa: BLE001 - every other exception is a finding
        queue.put(("crash", f"{type(exc).__name__}: {str(exc)[:300]}"))


def judge_text(context, directory, kind, rng, timeout, memory_bytes) -> tuple[str, str, str, bytes]:
    """One text case: ``(outcome, change, detail, content)``; outcome ``correct``, ``named`` or a finding."""
    if kind in WIDE_KINDS:
        extension, reader, rows, points, faces, extra, normals = wide_case(kind, rng)
    else:
        (extension, reader, rows, points, faces, extra), normals = text_case(kind, rng), None
    change = rng.choice(HARMLESS + DAMAGING + DAMAGING)
    text, touched, free = mutate_rows(rows, change, rng)
    content = text.encode()
    path = directory / f"rows{extension}"
    path.write_bytes(content)
    queue = context.Queue()
    process = context.Process(target=_text_child, args=(str(path), reader, memory_bytes, queue))
    process.start()
    process.join(timeout)
    if process.is_alive():
        process.kill()
        process.join()
        return "hang", change, f"no answer within {timeout} s", content
    try:
        outcome, payload = queue.get(timeout=1)
    except Exception:  # noqa: BLE001 - the child died without a word
        return "memory", change, f"child ended with code {process.exitcode}", content
    if outcome == "read":
        got_points, got_faces, got_normals = payload
        if faces is None:
            same = got_points.shape == points.shape and np.array_equal(got_points, points)
            if kind in WIDE_KINDS:  # the normals the file names, or none (colours are not normals)
                same &= (got_normals is None) if normals is None else np.array_equal(got_normals, normals)
        else:  # the corners' coordinates, face by face (STL readers merge the repeated corners)
            same = (
                isinstance(got_faces, np.ndarray)
                and got_faces.shape == faces.shape
                and np.array_equal(got_points[got_faces], points[faces])
            )
        if same:
            return "correct", change, "", content
        if free:  # `v x y z` -> `v x y a z`: a valid vertex with w; a face of 4 corners; an OFF face's colour
            return "another valid file", change, "", content
        if got_points.shape == points.shape and np.array_equal(got_points, points):
            return (
                "wrong normals",
                change,
                f"normals read: {got_normals is not None}, written: {normals is not None}",
                content,
            )
        return "re-cut", change, f"read {got_points.shape[0]} points, not the {len(points)} written", content
    if outcome != "error":
        return outcome, change, payload, content
    if change in HARMLESS or not touched:
        return "refused a valid file", change, payload, content
    named = {int(n) for n in re.findall(r"line (\d+)", payload)}
    if not named:
        return "error names no line", change, payload, content
    if not named & (touched | {e + 1 for e in extra}):  # e.g. two OBJ `v` rows joined: a vertex with a colour,
        return "named (another line)", change, payload, content  # then a face beyond the vertices
    return "named", change, "", content


def run_text_rows(context, directory, rng, stop, timeout, memory_bytes, counts, findings, keep, wide=0.0) -> None:
    """Text cases until ``stop``; counts per kind: ``correct`` / ``named`` / each finding.

    A share ``wide`` of the cases is of :data:`WIDE_KINDS`, decided by a stream of its own (seeded by
    the first draw of ``rng`` only when ``wide`` is not 0, so that the default draws those of earlier rounds).
    """
    widen = random.Random(rng.random() if wide else 0)
    while time.monotonic() < stop:
        kind = rng.choice(WIDE_KINDS) if wide and widen.random() < wide else rng.choice(TEXT_KINDS)
        outcome, change, detail, content = judge_text(context, directory, kind, rng, timeout, memory_bytes)
        row = counts.setdefault(f"rows {kind}", {})
        row[outcome] = row.get(outcome, 0) + 1
        if outcome not in ("correct", "named", "named (another line)", "another valid file", "skipped"):
            findings.append((f"rows {kind}", change, outcome, detail, content))
            if keep is not None:
                keep.mkdir(parents=True, exist_ok=True)
                (keep / f"finding{len(findings)}-{kind}.txt").write_bytes(content)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=1.0, help="how long to fuzz (default 1)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--timeout", type=float, default=10.0, help="seconds per read (default 10)")
    parser.add_argument("--memory", type=int, default=1024, help="MiB of address space per read (default 1024)")
    parser.add_argument("--keep", type=pathlib.Path, default=None, help="folder to save the failing inputs in")
    parser.add_argument(
        "--mode",
        choices=["bytes", "rows", "both"],
        default="both",
        help="byte mutations of every format, text rows changed in every text format, or both "
        "(half the time each; default)",
    )
    parser.add_argument(
        "--wide",
        type=float,
        default=0.0,
        help="share of the text-row cases whose rows hold more than x, y and z: normals, colours, an intensity, "
        "PLY properties in any order, a face property and an element after the faces (default: 0: the draws of "
        "earlier rounds)",
    )
    args = parser.parse_args(argv)
    rng = random.Random(args.seed)
    context = multiprocessing.get_context("fork")
    # a forked child shares the parent's address space size: the limit is above what the parent uses
    import resource

    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    memory_bytes = args.memory * 2**20 + 4 * base
    stop = time.monotonic() + 60 * args.minutes
    counts: dict[str, dict[str, int]] = {}
    findings = []
    with tempfile.TemporaryDirectory() as tmp:
        directory = pathlib.Path(tmp)
        if args.mode != "bytes":
            middle = stop if args.mode == "rows" else time.monotonic() + 30 * args.minutes
            run_text_rows(
                context, directory, rng, middle, args.timeout, memory_bytes, counts, findings, args.keep, args.wide
            )
        corpus = seeds(directory)
        while args.mode != "rows" and time.monotonic() < stop:
            label, extension, data = rng.choice(corpus)
            how, content = mutate(data, rng)
            path = directory / f"case{extension}"
            path.write_bytes(content)
            outcome, detail = read_in_child(context, path, args.timeout, memory_bytes)
            row = counts.setdefault(label, {})
            row[outcome] = row.get(outcome, 0) + 1
            if outcome in ("crash", "hang", "memory"):
                findings.append((label, how, outcome, detail, content))
                if args.keep is not None:
                    args.keep.mkdir(parents=True, exist_ok=True)
                    (args.keep / f"finding{len(findings)}{extension}").write_bytes(content)
    total = sum(sum(row.values()) for row in counts.values())
    for label, row in sorted(counts.items()):
        print(f"{label:28s} " + "  ".join(f"{key} {value}" for key, value in sorted(row.items())))
    for label, how, outcome, detail, content in findings[:20]:
        print(f"FINDING {outcome} in {label} ({how}): {detail}\n    input starts {content[:120]!r}")
    rows = sum(sum(row.values()) for label, row in counts.items() if label.startswith("rows "))
    print(
        f"total {total} reads in {args.minutes:g} min ({rows} text-row cases, {total - rows} byte mutations), "
        f"{len(findings)} findings (byte mutations: crash, hang or memory; text rows: also a result other than "
        "the points written, or an error naming no line); documented errors: "
        + ", ".join(e.__name__ for e in DOCUMENTED)
    )
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
