"""Fuzz every mesh file reader: ``python benchmarks/fuzz_readers.py [--examples N]``.

For every readable format of :data:`meshcurv.io.FORMATS`, hypothesis feeds
``read_mesh`` (and, when it returns a mesh, ``principal_curvatures``) with
random bytes, mutated valid files (bytes flipped, cut, duplicated, spliced)
and random text built from the format's own tokens. The only exceptions
allowed are the documented ones: MeshFileError, InvalidMeshError,
InvalidOptionError, MissingDependencyError. Any other exception, or any
warning other than meshcurv's own, counts as a crash and is printed with the
input that caused it. Prints one line per format and a total; exits 1 on a crash.
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import tempfile
import traceback
import warnings

from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import meshcurv
from meshcurv import io, shapes
from meshcurv.errors import (InvalidMeshError, InvalidOptionError, MeshcurvWarning, MeshFileError,
                             MissingDependencyError)

DOCUMENTED = (MeshFileError, InvalidMeshError, InvalidOptionError, MissingDependencyError)
TOKENS = ["v ", "vt ", "vn ", "f ", "1", "2", "3", "-1", "0", "1e308", "nan", "inf", "/", "//", " ", "\n", "#",
          "ply\n", "format ascii 1.0\n", "format binary_little_endian 1.0\n", "element vertex 3\n",
          "element face 1\n", "property float x\n", "property list uchar int vertex_indices\n",
          "end_header\n", "OFF\n", "solid x\n", "facet normal 0 0 1\n", "outer loop\n", "vertex 0 0 0\n",
          "endloop\n", "endfacet\n", "endsolid\n", "# vtk DataFile Version 3.0\n", "ASCII\n",
          "DATASET POLYDATA\n", "POINTS 3 float\n", "POLYGONS 1 4\n", "<VTKFile", "<PolyData>",
          "<Piece NumberOfPoints=\"3\" NumberOfPolys=\"1\">", "<DataArray", "</VTKFile>", "3 0 1 2\n"]


def seeds(directory: pathlib.Path) -> dict[str, bytes]:
    """One valid small file per readable extension, written by meshcurv itself."""
    torus = shapes.torus(n_major=6, n_minor=4)
    found = {}
    for fmt in io.FORMATS.values():
        if fmt.read is None:
            continue
        for extension in fmt.extensions:
            path = directory / f"seed{extension}"
            try:
                io.write_mesh(path, torus.vertices, torus.faces)
            except MissingDependencyError:
                continue
            found[extension] = path.read_bytes()
    return found


def mutate(data: bytes, draw) -> bytes:
    buffer = bytearray(data)
    for _ in range(draw(st.integers(1, 8))):
        if not buffer:
            break
        choice = draw(st.integers(0, 4))
        i = draw(st.integers(0, len(buffer) - 1))
        if choice == 0:
            buffer[i] = draw(st.integers(0, 255))
        elif choice == 1:
            del buffer[i:]
        elif choice == 2:
            j = draw(st.integers(i, len(buffer)))
            buffer[i:i] = buffer[i:j]
        elif choice == 3:
            buffer[i:i] = draw(st.binary(max_size=16))
        else:
            buffer[i:i] = draw(st.sampled_from(TOKENS)).encode()
    return bytes(buffer)


def fuzz(extension: str, seed: bytes, directory: pathlib.Path, examples: int) -> tuple[int, list]:
    tried = [0]
    crashes: list = []
    path = directory / f"fuzz{extension}"

    @settings(max_examples=examples, deadline=None, database=None,
              suppress_health_check=list(HealthCheck))
    @given(data=st.data(), kind=st.integers(0, 2))
    def run(data, kind):
        if kind == 0:
            content = data.draw(st.binary(max_size=512))
        elif kind == 1:
            content = mutate(seed, data.draw)
        else:
            content = "".join(data.draw(st.lists(st.sampled_from(TOKENS), max_size=60))).encode()
        path.write_bytes(content)
        tried[0] += 1
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("error")
                warnings.simplefilter("ignore", MeshcurvWarning)
                vertices, faces = io.read_mesh(path)
                if len(vertices) <= 20000:
                    meshcurv.principal_curvatures(vertices, faces)
        except DOCUMENTED:
            pass
        except Exception:  # anything else is a crash: keep the input
            crashes.append((content[:200], traceback.format_exc(limit=3)))

    run()
    return tried[0], crashes


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--examples", type=int, default=500, help="inputs per format (default 500)")
    args = parser.parse_args(argv)
    total = 0
    all_crashes = 0
    with tempfile.TemporaryDirectory() as tmp:
        directory = pathlib.Path(tmp)
        for extension, seed in sorted(seeds(directory).items()):
            tried, crashes = fuzz(extension, seed, directory, args.examples)
            total += tried
            all_crashes += len(crashes)
            print(f"{extension:6s} {tried:6d} inputs  {len(crashes)} crashes")
            for content, trace in crashes[:3]:
                print(f"    input {content!r}\n    " + trace.replace("\n", "\n    "))
    print(f"total  {total:6d} inputs  {all_crashes} crashes (only documented errors allowed: "
          + ", ".join(e.__name__ for e in DOCUMENTED) + ")")
    return 1 if all_crashes else 0


if __name__ == "__main__":
    sys.exit(main())
