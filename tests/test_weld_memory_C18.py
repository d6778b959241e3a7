"""Welding degenerate soups in memory bounded by the mesh (issue 29: bounded memory, nothing hangs).

A soup whose corners are collinear or coincide in bulk puts nearly every pair of its points (or of its boundary
edges) within the weld's tolerance of each other: 6,000 faces made tens of millions of candidate pairs and
1.4 GiB (fuzz 342/923). Each case runs in a child process under an address-space cap of a few hundred MiB above
its size after the imports: the memory that the call needs beyond the interpreter and its libraries must stay
within it. Not timed.
"""

from __future__ import annotations

import subprocess
import sys
import textwrap

import numpy as np
import pytest

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_AS and /proc/self/statm")

#: MiB the call may take beyond the child's size after its imports: a few times the arrays of 6,000 faces and
#: their edges (a few MiB), far below the 1.4 GiB the pairs took.
CAP_MIB = 400

CHILD = """
import os, resource, sys, warnings
os.environ["MESHCURV_BACKEND"] = "numpy"
import numpy as np
import scipy.sparse.csgraph, scipy.spatial
import meshcurv
from meshcurv import MeshTopology
from meshcurv.weld import weld_vertices

n_faces = 6000
rng = np.random.default_rng(342)
kind = sys.argv[1]
faces = np.arange(3 * n_faces).reshape(-1, 3)
if kind == "collinear":  # fuzz 342/923's class: random faces over points on one line
    t = rng.random(3 * n_faces)
    vertices = np.stack([t, 2 * t, 3 * t], axis=1)
    faces = rng.integers(0, 3 * n_faces, size=(n_faces, 3))
else:  # every corner at one point but one
    vertices = np.zeros((3 * n_faces, 3))
    vertices[0] = (1.0, 0.0, 0.0)
weld_vertices(np.eye(3), MeshTopology.from_faces(np.array([[0, 1, 2]])))  # lazy imports done before the cap
size = int(open("/proc/self/statm").read().split()[0]) * os.sysconf("SC_PAGE_SIZE")
cap = size + int(sys.argv[2]) * 2**20
resource.setrlimit(resource.RLIMIT_AS, (cap, resource.getrlimit(resource.RLIMIT_AS)[1]))
try:
    if kind == "collinear":
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            meshcurv.principal_curvatures(vertices, faces, method="quadric", radius=9.0)
        print("result")
    else:
        welded = weld_vertices(vertices, MeshTopology.from_faces(faces))
        print("welded", welded.vertices.shape[0])
except MemoryError:
    print("MemoryError")
except meshcurv.errors.InvalidOptionError as error:
    print("InvalidOptionError", error)
"""


def run_child(kind: str) -> str:
    done = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(CHILD), kind, str(CAP_MIB)],
        capture_output=True,
        text=True,
        check=False,
    )
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout.strip()


def test_collinear_soup_of_random_faces_within_cap():
    # the collinear soup welds into a mesh of no extent: the documented error for a radius beyond it, or a result
    out = run_child("collinear")
    assert out != "MemoryError"
    assert out == "result" or out.startswith("InvalidOptionError")


def test_corners_at_one_point_weld_within_cap():
    # 17,999 corners at one point and one apart are two points, whatever the pairs among the copies
    assert run_child("coincident") == "welded 2"


def test_exact_copies_join_as_pairs_within_tolerance():
    # exact copies found apart from the search give the same welds as the search itself: a square's soup
    from meshcurv import MeshTopology
    from meshcurv.weld import weld_vertices

    square = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    faces = np.array([[0, 1, 2], [0, 2, 3]])
    soup = square[faces.ravel()]
    welded = weld_vertices(soup, MeshTopology.from_faces(np.arange(6).reshape(-1, 3)))
    assert welded.vertices.shape[0] == 4
    assert int(welded.topology.boundary_edges.sum()) == 4  # the square's rim, its diagonal shared
