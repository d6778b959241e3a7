"""Instructions of the default method's two kernels, counted by valgrind's callgrind (issue 31).

Wall and CPU times on a shared machine move with the load; the number of instructions a kernel executes does
not. This script makes one default call on an icosphere, records the arguments of the normal fits
(``_kernels.jets.fit_jets_connected``, the degree-3 call) and of the ball sums
(``_kernels.neighborhoods.connected_face_sums``), calls the chosen kernel once more to warm it, then once with
callgrind's instrumentation on (a three-line C helper built with the system's compiler and valgrind's
``callgrind.h``), and prints the instructions of that call per centre. Run under callgrind, from the repository::

    valgrind --tool=callgrind --instr-atstart=no --callgrind-out-file=/tmp/kernel.%p \\
        python benchmarks/kernel_instructions.py --size 100k --kernel fits --centres 20000 --dumps /tmp

``--size voxel``: the dense voxel sphere of ``benchmarks/dense_voxel.py`` instead (its fits run twice, on coarse
levels: ``--call 0`` the pilot's, ``--call -1`` (default) the main pass's sampled fits; issue 30).
``--centres``: the first centres only (the fits' ``centres``, the sums' range of vertices), for a shorter run;
``--dumps``: the directory of callgrind's output files (the newest ``*.1`` there is the measured call's).
Outside valgrind the script runs too and prints 0 instructions.
"""

from __future__ import annotations

import argparse
import ctypes
import glob
import os
import subprocess
import tempfile
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes
from meshcurv._kernels import jets, neighborhoods

SIZES = {"10k": 32, "100k": 100, "1M": 316, "voxel": 0}

HELPER = """#include <valgrind/callgrind.h>
void start(void) { CALLGRIND_ZERO_STATS; CALLGRIND_START_INSTRUMENTATION; }
void stop(void) { CALLGRIND_STOP_INSTRUMENTATION; CALLGRIND_DUMP_STATS_AT("kernel"); }
"""


def _helper(directory: str) -> ctypes.CDLL:
    source = os.path.join(directory, "helper.c")
    with open(source, "w") as handle:
        handle.write(HELPER)
    library = os.path.join(directory, "helper.so")
    subprocess.run(["cc", "-O2", "-shared", "-fPIC", "-o", library, source], check=True)
    return ctypes.CDLL(library)


def _mesh(size: str):
    """``(vertices, faces, label)`` of the mesh of ``--size``: an icosphere, or ``voxel``, the dense voxel sphere of
    ``benchmarks/dense_voxel.py`` (R 6 at 0.5 x 0.2 x 0.2, 10,172 vertices: its normal fits run on coarse levels)."""
    if size == "voxel":
        sphere = shapes.voxel_sphere(6.0, (0.5, 0.2, 0.2), seed=0)
        return np.asarray(sphere.vertices, float), sphere.faces[:, ::-1], "voxel sphere R 6 at 0.5 x 0.2 x 0.2"
    sphere = shapes.icosphere(SIZES[size])
    return sphere.vertices, sphere.faces, f"icosphere({SIZES[size]})"


def _recorded(size: str) -> dict:
    """The arguments of the two kernels in one default call (copies taken before each call): per kernel, a list
    of the calls' arguments, in the order of the calls (the voxel sphere fits twice: its pilot, then its main
    pass)."""
    calls: dict = {}

    def recording(module, name, keep):
        original = getattr(module, name)

        def wrapper(*args):
            if keep(args):
                copies = [a.copy() if isinstance(a, np.ndarray) else _copied(a) for a in args]
                for copy, given in zip(copies, args):
                    if isinstance(given, np.ndarray):
                        copy.flags.writeable = given.flags.writeable
                calls.setdefault(name, []).append(copies)
            return original(*args)

        setattr(module, name, wrapper)
        return original

    originals = (
        recording(jets, "fit_jets_connected", lambda args: args[3] == 3),
        recording(neighborhoods, "connected_face_sums", lambda args: True),
    )
    try:
        vertices, faces, _ = _mesh(size)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            meshcurv.principal_curvatures(vertices, faces)
    finally:
        jets.fit_jets_connected, neighborhoods.connected_face_sums = originals
    return calls


def _copied(value):
    return (
        tuple(_copied(a) for a in value)
        if isinstance(value, tuple)
        else value.copy()
        if hasattr(value, "copy")
        else value
    )


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", choices=sorted(SIZES), default="100k")
    parser.add_argument("--kernel", choices=["fits", "sums"], default="fits")
    parser.add_argument("--centres", type=int, default=0, help="the first centres only (0: all)")
    parser.add_argument("--dumps", default=".", help="where callgrind writes its files (--callgrind-out-file)")
    parser.add_argument(
        "--call", type=int, default=-1, help="which of the kernel's calls (0: the first; default -1, the last)"
    )
    options = parser.parse_args(argv)
    calls = {name: recorded[options.call] for name, recorded in _recorded(options.size).items()}
    if options.kernel == "fits":
        args = calls["fit_jets_connected"]
        if options.centres:
            args[7] = args[7][: options.centres]
        n_centres = args[7].shape[0]

        def call():
            jets.fit_jets_connected(*args)

    else:
        args = calls["connected_face_sums"]
        if options.centres:
            args[12] = min(args[12], args[11] + options.centres)
        n_centres = args[12] - args[11]

        def call():  # fresh sums and scratch: the scratch is stamped with the centres it was used for
            fresh = list(args)
            fresh[9], fresh[10] = args[9].copy(), _copied(args[10])
            neighborhoods.connected_face_sums(*fresh)

    with tempfile.TemporaryDirectory() as directory:
        helper = _helper(directory)
        pattern = os.path.join(options.dumps, "*.1")
        before = set(glob.glob(pattern))
        call()  # warm: compiled or loaded, pages touched
        helper.start()
        call()
        helper.stop()
    dumps = sorted(set(glob.glob(pattern)) - before, key=os.path.getmtime)
    instructions = 0
    for dump in dumps[-1:]:
        with open(dump) as handle:
            instructions = next((int(line.split()[1]) for line in handle if line.startswith("totals:")), 0)
    print(
        f"{options.kernel} on {_mesh(options.size)[2]} (call {options.call}), {n_centres} centres: "
        f"{instructions:,} instructions, "
        f"{instructions / max(n_centres, 1):,.0f} per centre"
    )


if __name__ == "__main__":
    main()
