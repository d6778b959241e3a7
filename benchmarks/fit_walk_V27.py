"""How much of the jet fits' kernel on a dense voxel surface is the walk that finds each ball (issue 30).

The default call on the marching-cubes sphere of ``dense_voxel.py`` (R 6 at 0.5 x 0.2 x 0.2) runs two calls of
``_kernels.jets.fit_jets_connected``: the pilot's fits and the main pass's, both over a coarse level of the
surface (``icc._coarse_level``). Each call is replayed with its own arguments: as it is, with one iteration
instead of two, and as the breadth-first walks alone (``_kernels.neighborhoods._connected_members`` at every
centre, no weights, moments nor solves, one thread), with the fits, the members a ball and the links a member.

    python benchmarks/fit_walk_V27.py --repeats 5
"""

from __future__ import annotations

import argparse
import time
import warnings

import numba
import numpy as np

import meshcurv
from meshcurv import shapes


def _walks():
    """The compiled walks alone: ``walk(vertices, radii, centres, allowed, indptr, indices, spans) -> (members,
    links)`` summed over the centres."""
    from meshcurv._kernels.neighborhoods import _connected_members

    @numba.njit
    def walk(vertices, radii, centres, allowed, indptr, indices, spans):
        n = vertices.shape[0]
        mark = np.full(n, -1, np.int64)
        members = np.zeros(n, np.int64)
        queue = np.zeros(n, np.int64)
        total = 0
        links = 0
        per_centre = radii.shape[0] > 1
        for i in range(centres.shape[0]):
            radius = radii[i if per_centre else 0]
            size = _connected_members(
                vertices, indptr, indices, allowed, centres[i], radius, mark, i, members, queue, spans
            )
            total += size
            for s in range(size):
                links += indptr[members[s] + 1] - indptr[members[s]]
        return total, links

    return walk


def _cpu(function, repeats):
    """Median CPU seconds of ``function()`` over ``repeats`` calls after one."""
    function()
    times = []
    for _ in range(repeats):
        start = time.process_time()
        function()
        times.append(time.process_time() - start)
    return float(np.median(times))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    from meshcurv._kernels import jets as kernels
    from meshcurv._kernels.neighborhoods import _vertex_spans

    mesh = shapes.voxel_sphere(6.0, (0.5, 0.2, 0.2), seed=0)
    calls = []
    fit = kernels.fit_jets_connected

    def recorded(*arguments, **options):
        calls.append((arguments, options))
        return fit(*arguments, **options)

    kernels.fit_jets_connected = recorded
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            meshcurv.principal_curvatures(np.asarray(mesh.vertices, float), mesh.faces[:, ::-1])
    finally:
        kernels.fit_jets_connected = fit
    walk = _walks()
    print("| call | fits | members a fit | links a member | kernel CPU ms | one iteration | walks alone |")
    print("|---|--:|--:|--:|--:|--:|--:|")
    for label, (arguments, options) in zip(("pilot", "main pass"), calls):
        vertices, radii, centres = arguments[0], arguments[2], arguments[7]
        allowed, indptr, indices = arguments[9], arguments[10], arguments[11]
        spans = _vertex_spans(vertices, indptr, indices)
        members, links = walk(vertices, radii, centres, allowed, indptr, indices, spans)
        once = list(arguments)
        once[4] = 1  # iterations
        whole = _cpu(lambda: fit(*arguments, **options), args.repeats)
        single = _cpu(lambda: fit(*once, **options), args.repeats)
        walks = _cpu(lambda: walk(vertices, radii, centres, allowed, indptr, indices, spans), args.repeats)
        print(
            f"| {label} | {centres.size:,} | {members / centres.size:.0f} | {links / members:.1f} | "
            f"{1e3 * whole:.1f} | {1e3 * single:.1f} | {1e3 * walks:.1f} ({100 * walks / whole:.0f}%) |"
        )


if __name__ == "__main__":
    main()
