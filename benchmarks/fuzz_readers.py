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

    parts = [f"# vtk DataFile Version {version}\nfuzz\n{'BINARY' if binary else 'ASCII'}\nDATASET POLYDATA\n".encode(),
             f"POINTS {len(vertices)} double\n".encode() + array(vertices, "f8")]
    if version.startswith("5"):
        offsets = np.arange(len(faces) + 1) * 3
        parts.append(b"METADATA\nINFORMATION 0\n\n")
        parts.append(f"POLYGONS {len(offsets)} {faces.size}\nOFFSETS vtktypeint64\n".encode() + array(offsets, "i8")
                     + b"CONNECTIVITY vtktypeint64\n" + array(faces, "i8"))
    else:
        cells = np.column_stack([np.full(len(faces), 3), faces])
        parts.append(f"POLYGONS {len(faces)} {cells.size}\n".encode() + array(cells, "i4"))
    parts.append(f"POINT_DATA {len(vertices)}\nSCALARS k float 1\nLOOKUP_TABLE default\n".encode()
                 + array(np.arange(len(vertices)), "f4"))
    return b"".join(parts)


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
                    found.append((f"{extension[1:]}-{label}-{'bin' if binary else 'ascii'}", extension,
                                  path.read_bytes()))
    for binary in (True, False):
        for version in ("4.2", "5.1"):
            found.append((f"vtk-polydata{version}-{'bin' if binary else 'ascii'}", ".vtk",
                          _legacy_polydata(binary, version)))
    unique = {}
    for label, extension, data in found:
        unique.setdefault((extension, data), label)
    return [(label, extension, data) for (extension, data), label in unique.items()]


def _boundaries(data: bytes) -> list[int]:
    marks = {0, len(data)}
    for pattern in (rb"\n", rb"\s", rb"end_header", rb"POLYGONS|POINTS|OFFSETS|CONNECTIVITY|POINT_DATA",
                    rb"<DataArray|</DataArray>|>", rb"PK\x03\x04|PK\x01\x02|PK\x05\x06", rb"\nf |\nv "):
        for match in re.finditer(pattern, data[:200000]):
            marks.update((match.start(), match.end()))
    return sorted(marks)


def mutate(data: bytes, rng: random.Random) -> tuple[str, bytes]:
    choice = rng.randrange(6)
    if choice == 0:  # truncation at a boundary (or next to one)
        cut = rng.choice(_boundaries(data)) + rng.choice([-1, 0, 0, 0, 1])
        return f"cut at {cut}", data[:max(cut, 0)]
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
                del buffer[i:i + rng.randint(1, 16)]
            elif what == 2:
                buffer[i:i] = bytes(rng.randrange(256) for _ in range(rng.randint(1, 16)))
            else:
                buffer[i:i] = buffer[i:i + rng.randint(1, 64)]
        return "bytes changed", bytes(buffer)
    if choice == 3:  # a huge (or negative, or zero) declared count
        numbers = list(re.finditer(rb"(?<![\w.\-])\d+(?![\w.])", data[:4096]))
        if numbers:
            match = rng.choice(numbers)
            value = rng.choice(HUGE)
            return f"count at {match.start()} -> {value.decode()}", data[:match.start()] + value + data[match.end():]
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
        return f"number at {match.start()} -> float", data[:match.start()] + match.group() + b".5" + data[match.end():]
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


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--minutes", type=float, default=1.0, help="how long to fuzz (default 1)")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--timeout", type=float, default=10.0, help="seconds per read (default 10)")
    parser.add_argument("--memory", type=int, default=1024, help="MiB of address space per read (default 1024)")
    parser.add_argument("--keep", type=pathlib.Path, default=None, help="folder to save the failing inputs in")
    args = parser.parse_args(argv)
    rng = random.Random(args.seed)
    context = multiprocessing.get_context("fork")
    # a forked child shares the parent's address space size: the limit is above what the parent uses
    import resource

    base = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    memory_bytes = args.memory * 2 ** 20 + 4 * base
    stop = time.monotonic() + 60 * args.minutes
    counts: dict[str, dict[str, int]] = {}
    findings = []
    with tempfile.TemporaryDirectory() as tmp:
        directory = pathlib.Path(tmp)
        corpus = seeds(directory)
        while time.monotonic() < stop:
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
    print(f"total {total} reads in {args.minutes:g} min, {len(findings)} findings (crash, hang or memory); "
          f"documented errors: " + ", ".join(e.__name__ for e in DOCUMENTED))
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
