"""The breadth-first walk of the normal fits' balls, as it is and written with fewer unpredictable branches
(issue 31 and 30, helper K31).

Records the calls of ``_kernels.jets.fit_jets_connected`` that one default call makes (``--mesh ico1M``: the
icosphere of 998,562 vertices; ``ico100k``; ``voxel``: the marching-cubes sphere R 6 at 0.5 x 0.2 x 0.2 of
``dense_voxel.py``, whose fits run on coarse levels), then replays the walks of each call alone, on one thread, with
``_kernels.neighborhoods._connected_members`` (``current``) and with the variants below, checks that every
variant finds the same members in the same order at every centre (sizes and a polynomial hash of each ball), and
times them in turns (CPU seconds, the median of ``--repeats`` rounds).

- ``flagged``: the member test of each newly reached vertex kept in its queue entry (``2 b + member``) and the
  members written as they leave the queue (the members are the queued vertices inside the ball and allowed, in
  queue order): no branch on the new vertex's distance.
- ``branchless``: ``flagged``, and the neighbours of a vertex inside the ball read without a branch on their
  stamp (every edge of a vertex inside the ball meets it: each new neighbour is queued; an old one is written to
  the slot the popped vertex left).

    python benchmarks/walk_K31.py --mesh ico1M --repeats 5

``--kernel``: instead, the recorded calls of the fits kernel themselves, each timed (CPU s, the median of
``--repeats``, threads as in the call) with a digest of its outputs: run it on two trees in turns
(``PYTHONPATH=<tree>/src``) to compare their times and check that their outputs agree to the bit.
"""

from __future__ import annotations

import argparse
import hashlib
import resource
import time
import warnings

import numba
import numpy as np

import meshcurv
from meshcurv import shapes
from meshcurv._kernels._common import _JIT, _ONE, _UNSIGNED
from meshcurv._kernels.neighborhoods import _connected_members, _outside_edge_meets, _vertex_spans


@numba.njit(inline="always", **_JIT)
def _flagged_walk(vertices, indptr, indices, allowed, v, cutoff, mark, stamp, members, queue, spans, branchless):
    """``_connected_members`` with each queued vertex's member test in its queue entry (``2 b + member``) and the
    members written as they leave the queue; with ``branchless``, a vertex inside the ball reads its neighbours
    without a branch on their stamps."""
    cx, cy, cz = vertices[v, 0], vertices[v, 1], vertices[v, 2]
    cutoff2 = cutoff * cutoff
    mark[v] = stamp
    queue[0] = 2 * v + (1 if allowed[v] else 0)
    head, tail, size = 0, 1, 0
    while head < tail:
        entry = queue[head]
        head += 1
        a = _UNSIGNED(entry >> 1)
        members[_UNSIGNED(size)] = a
        size += entry & 1
        ax, ay, az = vertices[a, 0] - cx, vertices[a, 1] - cy, vertices[a, 2] - cz
        a2 = ax * ax + ay * ay + az * az
        outside = not a2 <= cutoff2
        if branchless and not outside:  # every edge meets the ball: each new neighbour is queued
            for j in range(_UNSIGNED(indptr[a]), _UNSIGNED(indptr[a + _ONE])):
                b = indices[j]
                ub = _UNSIGNED(b)
                fresh = mark[ub] != stamp
                mark[ub] = stamp
                bx, by, bz = vertices[ub, 0] - cx, vertices[ub, 1] - cy, vertices[ub, 2] - cz
                b2 = bx * bx + by * by + bz * bz
                slot = tail if fresh else head - 1  # an old one to the slot a left
                queue[_UNSIGNED(slot)] = 2 * np.int64(b) + ((b2 <= cutoff2) & allowed[ub])
                tail += fresh
            continue
        for j in range(_UNSIGNED(indptr[a]), _UNSIGNED(indptr[a + _ONE])):
            b = indices[j]
            ub = _UNSIGNED(b)
            if mark[ub] == stamp:
                continue
            bx, by, bz = vertices[ub, 0] - cx, vertices[ub, 1] - cy, vertices[ub, 2] - cz
            b2 = bx * bx + by * by + bz * bz
            inside = b2 <= cutoff2
            if (
                outside
                and not inside
                and not _outside_edge_meets(spans, ub, b2, cutoff, mark, stamp, ax, ay, az, bx, by, bz, cutoff2)
            ):
                continue
            mark[ub] = stamp
            queue[_UNSIGNED(tail)] = 2 * np.int64(b) + (inside & allowed[ub])
            tail += 1
    return size


@numba.njit(**_JIT)  # a call per centre, as _connected_members
def _flagged(vertices, indptr, indices, allowed, v, cutoff, mark, stamp, members, queue, spans):
    return _flagged_walk(vertices, indptr, indices, allowed, v, cutoff, mark, stamp, members, queue, spans, False)


@numba.njit(**_JIT)
def _branchless(vertices, indptr, indices, allowed, v, cutoff, mark, stamp, members, queue, spans):
    return _flagged_walk(vertices, indptr, indices, allowed, v, cutoff, mark, stamp, members, queue, spans, True)


def _replay(walk):
    """``replay(vertices, radii, centres, allowed, indptr, indices, spans) -> (sizes, hashes)`` of ``walk``."""

    @numba.njit(**{**_JIT, "cache": False})  # a closure: not cached
    def replay(vertices, radii, centres, allowed, indptr, indices, spans):
        n = vertices.shape[0]
        m = centres.shape[0]
        mark = np.full(n, -1, np.int64)
        members = np.zeros(n, np.int64)
        queue = np.zeros(n, np.int64)
        sizes = np.empty(m, np.int64)
        hashes = np.empty(m, np.uint64)
        per_centre = radii.shape[0] > 1
        for i in range(m):
            size = walk(
                vertices,
                indptr,
                indices,
                allowed,
                centres[i],
                radii[i if per_centre else 0],
                mark,
                i,
                members,
                queue,
                spans,
            )
            h = np.uint64(1469598103934665603)
            for s in range(size):
                h = (h ^ np.uint64(members[s])) * np.uint64(1099511628211)
            sizes[i] = size
            hashes[i] = h
        return sizes, hashes

    return replay


WALKS = {"current": _connected_members, "flagged": _flagged, "branchless": _branchless}

MESHES = ("ico1M", "ico100k", "voxel")


def _mesh(name):
    if name == "ico1M":
        return shapes.icosphere(316)
    if name == "ico100k":
        return shapes.icosphere(100)
    return shapes.voxel_sphere(6.0, (0.5, 0.2, 0.2), seed=0)


def _recorded_calls(mesh):
    """The positional arguments of each ``fit_jets_connected`` call of one default call on ``mesh``."""
    from meshcurv._kernels import jets as kernels

    calls = []
    fit = kernels.fit_jets_connected

    def recorded(*arguments, **options):
        copies = []  # (a later stage of the call may write to an array it passed)
        for given in arguments:
            copy = given.copy() if isinstance(given, np.ndarray) else given
            if isinstance(given, np.ndarray):
                copy.flags.writeable = given.flags.writeable
            copies.append(copy)
        calls.append(tuple(copies))
        return fit(*arguments, **options)

    kernels.fit_jets_connected = recorded
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            meshcurv.principal_curvatures(np.asarray(mesh.vertices, float), mesh.faces)
    finally:
        kernels.fit_jets_connected = fit
    return calls


def _kernel_times(args):
    """CPU s of each recorded call of the fits kernel, and a digest of its outputs."""
    from meshcurv._kernels import jets as kernels

    calls = _recorded_calls(_mesh(args.mesh))
    print(f"mesh {args.mesh}, meshcurv from {meshcurv.__file__}")
    for k, arguments in enumerate(calls):
        outputs = kernels.fit_jets_connected(*arguments)
        digest = hashlib.sha1()
        for output in outputs:
            digest.update(np.ascontiguousarray(output).tobytes())
        times, system = [], []
        for _ in range(args.repeats):
            start, before = time.process_time(), resource.getrusage(resource.RUSAGE_SELF).ru_stime
            kernels.fit_jets_connected(*arguments)
            times.append(time.process_time() - start)
            system.append(resource.getrusage(resource.RUSAGE_SELF).ru_stime - before)
        print(
            f"call {k}: {arguments[7].size:,} centres, CPU s median {np.median(times):.3f} "
            f"(all {' '.join(f'{t:.3f}' for t in times)}; system {np.median(system):.3f}), "
            f"outputs {digest.hexdigest()[:16]}",
            flush=True,
        )


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--mesh", default="ico1M", choices=MESHES)
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--walks", default=",".join(WALKS))
    parser.add_argument("--kernel", action="store_true", help="time the recorded kernel calls themselves")
    args = parser.parse_args(argv)
    if args.kernel:
        _kernel_times(args)
        return
    names = args.walks.split(",")
    replays = {name: _replay(WALKS[name]) for name in names}
    calls = _recorded_calls(_mesh(args.mesh))
    print(f"mesh {args.mesh}: {len(calls)} calls of the fits kernel; CPU s of the walks alone, one thread")
    print("| call | centres | members a ball | " + " | ".join(names) + " | same members |")
    print("|---|--:|--:|" + "--:|" * len(names) + "---|")
    for k, arguments in enumerate(calls):
        vertices, radii, centres = arguments[0], arguments[2], arguments[7]
        allowed, indptr, indices = arguments[9], arguments[10], arguments[11]
        spans = _vertex_spans(vertices, indptr, indices)
        inputs = (vertices, radii, centres, allowed, indptr, indices, spans)
        found = {name: replay(*inputs) for name, replay in replays.items()}
        first = found[names[0]]
        same = all(np.array_equal(first[0], f[0]) and np.array_equal(first[1], f[1]) for f in found.values())
        times = {name: [] for name in names}
        for _ in range(args.repeats):  # in turns: the load moves all alike
            for name, replay in replays.items():
                start = time.process_time()
                replay(*inputs)
                times[name].append(time.process_time() - start)
        cells = " | ".join(f"{np.median(times[name]):.3f}" for name in names)
        print(f"| {k} | {centres.size:,} | {first[0].mean():.1f} | {cells} | {'yes' if same else 'NO'} |", flush=True)


if __name__ == "__main__":
    main()
