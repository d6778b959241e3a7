"""CPU time of the stages every mesh method shares, each alone, on an icosphere (issue 31).

The topology build, the bow-tie walks, the components, the neighbour lists,
the diagnosis's measured facts, the suspect edges of ``drop_double_sided``,
the orientation (``face_flips``), the defect codes and the faces around each
vertex: each timed alone on the same topology, the median CPU time of
``--repeats`` calls after a warm-up call (pages touched, kernels loaded).
Repeated calls reuse the memory freed by the last one, so the page faults
of fresh arrays that a real call pays (about a third of the build at 1M)
are mostly missing here: whole calls are ``profile_call.py`` and
``profile_ring.py``. For an A/B, run it with ``PYTHONPATH=<tree>/src`` of
each tree, alternating processes::

    .venv/bin/python benchmarks/profile_shared.py --size 1M --repeats 9 --stages build,bowtie
"""

from __future__ import annotations

import argparse
import os
import time

import numpy as np

import meshcurv
from meshcurv import defects, orient, weld
from meshcurv._backend import numba_kernels
from meshcurv._geometry import vertex_length_scales
from meshcurv.topology import MeshTopology

SIZES = {"10k": 32, "100k": 100, "1M": 316, "4M": 632}


def stages(vertices: np.ndarray, faces: np.ndarray) -> dict:
    """The timed calls, by name, on one topology of ``faces``."""
    topology_kernels = numba_kernels("topology")
    diagnosis_kernels = numba_kernels("diagnosis")
    neighborhood_kernels = numba_kernels("neighborhoods")
    n = vertices.shape[0]
    topology = MeshTopology._build(faces, n)
    scales = vertex_length_scales(vertices, topology)
    no_needles = np.zeros(n, dtype=bool)
    no_degenerate = np.zeros(faces.shape[0], dtype=bool)
    twins, first, corners = topology._side_twins, topology._first_sides, topology._corner_counts
    return {
        "build": lambda: MeshTopology._build(faces, n),
        "bowtie": lambda: topology_kernels.bowtie_walks(twins, first, corners),
        "components": lambda: topology_kernels.component_labels(topology.edges, topology.referenced_vertices, n),
        "neighbour_lists": lambda: topology_kernels.neighbour_lists(topology.edges, n),
        "mesh_facts": lambda: diagnosis_kernels.mesh_facts(
            vertices, faces, topology.edges, topology.referenced_vertices, scales, 1e-12, 1e-6
        ),
        "suspects": lambda: weld._suspect_edges(topology),
        "face_flips": lambda: orient.face_flips(vertices, topology, outward=True, needles=no_needles),
        "defect_codes": lambda: defects.defect_codes(topology, no_degenerate, no_needles),
        "vertex_face_lists": lambda: neighborhood_kernels.vertex_face_lists(faces, n, 2),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", default="1M", choices=sorted(SIZES))
    parser.add_argument("--repeats", type=int, default=9)
    parser.add_argument("--stages", default="", help="comma-separated names (default: all)")
    args = parser.parse_args(argv)
    mesh = meshcurv.shapes.icosphere(SIZES[args.size])
    vertices = np.ascontiguousarray(mesh.vertices)
    faces = np.ascontiguousarray(mesh.faces, dtype=np.int64)
    calls = stages(vertices, faces)
    names = args.stages.split(",") if args.stages else list(calls)
    tree = os.path.dirname(os.path.dirname(os.path.abspath(meshcurv.__file__)))
    print(f"icosphere({SIZES[args.size]}), {vertices.shape[0]} vertices; meshcurv from {tree}")
    for name in names:
        call = calls[name]
        call()  # warm-up
        times = []
        for _ in range(args.repeats):
            start = time.process_time()
            call()
            times.append(time.process_time() - start)
        print(f"{name:18s} {1000 * float(np.median(times)):8.1f} CPU ms  (load {os.getloadavg()[0]:.1f})")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
