"""Compiled twins of :mod:`meshcurv.topology`: edges and their faces, bow-tie vertices, components,
neighbour lists.
"""

from __future__ import annotations

import numba as nb
import numpy as np
from numba.extending import overload

from ._common import _JIT, _JIT_INNER, _ONE, _UNSIGNED, run_chunks, threaded
from .geometry import _unadvised_array


#: :func:`meshcurv._kernels.neighborhoods.vertex_face_lists` counts the faces of at most this many ranges of
#: faces at once ((ranges, V) int64 counts).
_BUCKET_CHUNKS = 8


def _bucket_starts(cursor):
    """``(V + 1,)`` starts of the buckets of a counting sort whose (ranges, V) ``cursor`` holds the
    count of each range of items at each vertex; ``cursor`` then becomes where each range's next
    item at each vertex goes (range 0's items first, then range 1's, ...).

    Two passes over the vertices in chunks on threads (:func:`~meshcurv._kernels._common.run_chunks`:
    :func:`_bucket_totals`, :func:`_bucket_cursors`) around a serial running sum; integer sums, the
    same whatever the threads. A ``parallel=True`` kernel did the same in 0.5 s more compile time.
    """
    n_vertices = cursor.shape[1]
    starts = _unadvised_array(n_vertices + 1, np.int64)  # every element written (_bucket_totals, starts[0])
    starts[0] = 0
    n_chunks = _VERTEX_CHUNKS * nb.get_num_threads()
    run_chunks(_bucket_totals, n_vertices, n_chunks, cursor, starts)
    _running_sum(starts)
    run_chunks(_bucket_cursors, n_vertices, n_chunks, cursor, starts)
    return starts


@overload(_bucket_starts, jit_options=_JIT)  # type: ignore[arg-type]  # numba's stub types a TypedDict
def _bucket_starts_compiled(cursor):
    """:func:`_bucket_starts` inside a compiled caller (``_kernels.locality``): the same passes on its thread."""

    def starts_of(cursor):
        n_vertices = cursor.shape[1]
        starts = np.zeros(n_vertices + 1, np.int64)
        _bucket_totals(0, n_vertices, cursor, starts)
        _running_sum(starts)
        _bucket_cursors(0, n_vertices, cursor, starts)
        return starts

    return starts_of


_TWO = _UNSIGNED(2)
_THREE = _UNSIGNED(3)

#: :func:`_bucket_starts` cuts the vertices into this many chunks per thread.
_VERTEX_CHUNKS = 4


@nb.njit(**_JIT)
def _bucket_totals(lo, hi, cursor, starts):
    """:func:`_bucket_starts`: ``starts[v + 1]``, the count of every range at vertex ``v``, for ``v`` in ``lo:hi``."""
    for v in range(lo, hi):
        total = 0
        for c in range(cursor.shape[0]):
            total += cursor[c, v]
        starts[v + 1] = total


@nb.njit(**_JIT)
def _running_sum(starts):
    """``starts`` made its own running sum, in place."""
    for v in range(starts.shape[0] - 1):
        starts[v + 1] += starts[v]


@nb.njit(**_JIT)
def _bucket_cursors(lo, hi, cursor, starts):
    """:func:`_bucket_starts`: ``cursor[c, v]``, where range ``c``'s first item at ``v`` goes, for ``v`` in ``lo:hi``."""
    for v in range(lo, hi):
        at = starts[v]
        for c in range(cursor.shape[0]):
            count = cursor[c, v]
            cursor[c, v] = at
            at += count


def build_edges(faces, n_vertices, template):
    """Edges of the triangles, their faces and counts (see MeshTopology._build): :func:`build_topology`
    without the twins of the sides, ``(edges, face_edges, edge_faces, counts, forward)``."""
    edges, face_edges, edge_faces, counts, forward, _, _, _ = build_topology(faces, n_vertices, template, False)
    return edges, face_edges, edge_faces, counts, forward


@threaded
def build_topology(faces, n_vertices, template, with_twins):
    """:func:`build_edges_into` on arrays allocated here: ``(edges, face_edges, edge_faces, counts, forward,
    twins, corners, first)``, all in the integer type of ``template``; the last three only when ``with_twins``
    (else empty arrays)."""
    n_faces = faces.shape[0]
    index = template.dtype
    # numba's memory, not numpy's (no huge-page advice: geometry._unadvised_empty); every element read is written
    face_edges = _unadvised_array(3 * n_faces, index)
    edges = _unadvised_array((3 * n_faces, 2), index)
    edge_faces = _unadvised_array((3 * n_faces, 2), index)
    counts = _unadvised_array(3 * n_faces, index)
    forward = _unadvised_array(3 * n_faces, index)
    twins = _unadvised_array(3 * n_faces if with_twins else 0, index)
    corners = _unadvised_array(n_vertices if with_twins else 0, index, zero=True)
    first = _unadvised_array(n_vertices if with_twins else 0, index)
    first.fill(-1)
    n_edges = build_edges_into(
        faces, n_vertices, template, face_edges, edges, edge_faces, counts, forward, twins, corners, first
    )
    return (
        edges[:n_edges],
        face_edges.reshape(n_faces, 3),
        edge_faces[:n_edges],
        counts[:n_edges],
        forward[:n_edges],
        twins,
        corners,
        first,
    )


def build_edges_into(
    faces, n_vertices, template, face_edges, edges, edge_faces, counts, forward, twins, corners, first
):
    """Edges of the triangles, their faces and counts, written into the given arrays; returns their number E.

    ``face_edges`` (3 F,) receives the edge of each side (-1 for a side from a
    vertex to itself), rows ``:E`` of ``edges`` and ``edge_faces`` (at least
    (3 F, 2)), ``counts`` and ``forward`` (at least (3 F,)) those of each edge
    (see MeshTopology._build). ``twins``, of shape (3 F,) or empty (not
    wanted), receives for each side ``3 f + k`` the other side ``t`` of its
    edge when the edge has exactly two sides, in two different faces (the
    edges that join two fans' faces, see :func:`bowtie_from_twins`): ``t``
    where the two sides run the edge both ways, ``-2 - t`` where they run it
    the same way (inconsistently wound faces); -1 for the other sides.
    With the twins, ``corners`` and ``first`` (V,), zeros and -1 on entry,
    receive in the first pass over the faces what :func:`bowtie_walks` needs
    (the corners of the faces without a repeated corner at each vertex, the
    side leaving each vertex of its first such face) and what
    ``MeshTopology.referenced_vertices`` reads: ``first`` is -2 at a vertex
    whose faces all repeat a corner, -1 at an unreferenced vertex.

    Sides are bucketed by their smaller vertex (a counting sort: one pass
    counts, one places, each in face order, in ranges of faces on threads:
    :func:`_sides_in_buckets`); then, in ranges of vertices on threads
    (:func:`~meshcurv._kernels._common.run_chunks`), each bucket is sorted by
    (larger vertex, direction) with a stable insertion sort and its edges
    counted (:func:`_sort_buckets`), and, each range's first edge known from
    the counts of those before it, its edges written out
    (:func:`_write_edges`): the edges come out in lexicographic order, as
    ``np.unique`` would give them, numbered as one pass over the buckets
    numbers them, whatever the number of threads. Every output element is
    written once (no fill beforehand; the rows past the last edge are never
    touched, so never paged in). The buckets are held in the integer type of
    ``template`` (``topology._bucket_template``).
    """
    starts, keys, sides = _sides_in_buckets(faces, n_vertices, template, face_edges, twins, corners, first)
    n_ranges = max(1, min(_VERTEX_CHUNKS * nb.get_num_threads(), n_vertices))
    found = np.zeros(n_ranges + 1, np.int64)  # the edges of each range of buckets, then the first of each
    run_chunks(_sort_buckets, n_ranges, n_ranges, starts, keys, sides, found)
    np.cumsum(found, out=found)
    run_chunks(
        _write_edges,
        n_ranges,
        n_ranges,
        starts,
        keys,
        sides,
        found,
        face_edges,
        edges,
        edge_faces,
        counts,
        forward,
        twins,
    )
    return int(found[n_ranges])


def _sides_in_buckets(faces, n_vertices, template, face_edges, twins, corners, first):
    """:func:`build_edges_into`'s two passes over the faces: ``corners`` and ``first`` written (with the
    ``twins``), -1 in ``face_edges`` and ``twins`` at the sides from a vertex to itself, and the other sides in
    buckets by their smaller vertex: ``(starts, keys, sides)``, bucket ``v`` being ``starts[v]:starts[v + 1]``
    of ``keys`` (2 * larger vertex + 1 where the side runs backward) and ``sides`` (``3 f + k``), in face
    order.

    Each of a few ranges of the faces, one per thread, counts its sides at each vertex
    (:func:`_count_sides`), then places them (:func:`_place_sides`) around the counting sort's starts
    (:func:`_bucket_starts`): a bucket holds the first range's sides, then the next's, each in face order,
    the order of one pass over all the faces whatever the number of threads. The first range writes
    ``corners`` and ``first`` itself, the others their own rows of a scratch that :func:`_merge_corners`
    adds to them. (One serial pass took 0.08 CPU s of the 0.19 of the build at 1M vertices, issue 31, S32.)
    """
    n_faces = faces.shape[0]
    n_ranges = max(1, min(nb.get_num_threads(), _BUCKET_CHUNKS, n_faces))
    with_twins = twins.shape[0] > 0
    cursor = _unadvised_array((n_ranges, n_vertices), np.int64, zero=True)
    n_more = n_ranges - 1 if with_twins else 0
    more_corners = _unadvised_array((n_more, n_vertices if n_more else 0), template.dtype, zero=True)
    more_first = _unadvised_array((n_more, n_vertices if n_more else 0), template.dtype)
    more_first.fill(-1)
    run_chunks(
        _count_sides, n_ranges, n_ranges, faces, cursor, face_edges, twins, corners, first, more_corners, more_first
    )
    if n_more:
        run_chunks(
            _merge_corners, n_vertices, _VERTEX_CHUNKS * nb.get_num_threads(), corners, first, more_corners, more_first
        )
    starts = _bucket_starts(cursor).astype(template.dtype)
    n_sides = int(starts[n_vertices])
    sort_key = _unadvised_array(n_sides, template.dtype)  # every slot placed once
    side_of = _unadvised_array(n_sides, template.dtype)
    run_chunks(_place_sides, n_ranges, n_ranges, faces, cursor, sort_key, side_of)
    return starts, sort_key, side_of


@nb.njit(inline="always", **_JIT)
def _range_of(n_items, r, n_ranges):
    """``(start, stop)`` of range ``r`` of ``n_items`` cut into ``n_ranges`` (those of ``run_chunks``)."""
    return n_items * r // n_ranges, n_items * (r + 1) // n_ranges


@nb.njit(inline="always", **_JIT)
def _count_range(faces, lo, hi, counts, face_edges, twins, corners, first):
    """:func:`_count_sides` of the faces ``lo:hi``, their corners and first sides in ``corners`` and ``first``."""
    with_twins = twins.shape[0] > 0
    for f in range(lo, hi):
        proper = faces[f, 0] != faces[f, 1] and faces[f, 1] != faces[f, 2] and faces[f, 2] != faces[f, 0]
        for k in range(3):
            a = faces[f, k]
            b = faces[f, (k + 1) % 3]
            if with_twins:
                if proper:
                    corners[a] += 1
                    if first[a] < 0:
                        first[a] = 3 * f + k
                elif first[a] == -1:
                    first[a] = -2
            if a != b:
                counts[_UNSIGNED(b if b < a else a)] += 1  # min(a, b): numba compiles min once per caller's options
            else:  # a side from a vertex to itself: no edge
                face_edges[3 * f + k] = -1
                if with_twins:
                    twins[3 * f + k] = -1


@nb.njit(**_JIT)
def _count_sides(lo, hi, faces, cursor, face_edges, twins, corners, first, more_corners, more_first):
    """:func:`_sides_in_buckets`' counts of the face ranges ``lo`` to ``hi - 1`` in ``cursor``: range 0's
    corners and first sides in ``corners`` and ``first``, range ``r``'s in row ``r - 1`` of ``more_corners`` and
    ``more_first`` (empty: no twins wanted)."""
    for r in range(lo, hi):
        start, stop = _range_of(faces.shape[0], r, cursor.shape[0])
        if r == 0 or more_corners.shape[0] == 0:
            _count_range(faces, start, stop, cursor[r], face_edges, twins, corners, first)
        else:
            _count_range(faces, start, stop, cursor[r], face_edges, twins, more_corners[r - 1], more_first[r - 1])


@nb.njit(**_JIT)
def _merge_corners(lo, hi, corners, first, more_corners, more_first):
    """:func:`_sides_in_buckets`: the corners and first sides of the face ranges after the first added to
    ``corners`` and ``first`` at the vertices ``lo:hi``, as one pass over all the faces would have found them
    (the first side of a face without a repeated corner, else -2 where a face repeating one holds the vertex)."""
    for v in range(lo, hi):
        total = corners[v]
        found = first[v]
        for r in range(more_corners.shape[0]):
            total += more_corners[r, v]
            side = more_first[r, v]
            if found < 0 and side >= 0:
                found = side
            elif found == -1 and side == -2:
                found = -2
        corners[v] = total
        first[v] = found


@nb.njit(**_JIT)
def _place_sides(lo, hi, faces, cursor, sort_key, side_of):
    """:func:`_sides_in_buckets`' placing of the sides of the face ranges ``lo`` to ``hi - 1``."""
    for r in range(lo, hi):
        fill = cursor[r]
        start, stop = _range_of(faces.shape[0], r, cursor.shape[0])
        for f in range(start, stop):
            for k in range(3):
                a = faces[f, k]
                b = faces[f, (k + 1) % 3]
                if a != b:
                    low = _UNSIGNED(b if b < a else a)  # min(a, b)
                    slot = _UNSIGNED(fill[low])
                    fill[low] += 1
                    sort_key[slot] = 2 * (b if b > a else a) + (1 if a > b else 0)  # max(a, b)
                    side_of[slot] = 3 * f + k


@nb.njit(**_JIT)
def _sort_buckets(lo, hi, bucket_start, sort_key, side_of, found):
    """:func:`build_edges_into`: the buckets of the vertex ranges ``lo`` to ``hi - 1`` (of ``found.shape[0] - 1``)
    sorted in place by key (a stable insertion sort: the buckets are small), and the edges of range ``r`` (its
    distinct larger vertices) counted in ``found[r + 1]``."""
    n_vertices = bucket_start.shape[0] - 1
    n_ranges = found.shape[0] - 1
    for r in range(lo, hi):
        n_edges = 0
        for v in range(n_vertices * r // n_ranges, n_vertices * (r + 1) // n_ranges):
            start, stop = _UNSIGNED(bucket_start[v]), _UNSIGNED(bucket_start[v + 1])  # unsigned: see _twin_walk
            for i in range(start + _ONE, stop):
                key = sort_key[i]
                side = side_of[i]
                j = _UNSIGNED(i)
                while j > start and sort_key[j - _ONE] > key:
                    sort_key[j] = sort_key[j - _ONE]
                    side_of[j] = side_of[j - _ONE]
                    j -= _ONE
                sort_key[j] = key
                side_of[j] = side
            previous_high = -1
            for i in range(start, stop):
                high = sort_key[i] >> 1
                if high != previous_high:
                    n_edges += 1
                    previous_high = high
        found[r + 1] = n_edges


@nb.njit(**_JIT)
def _write_edges(
    lo, hi, bucket_start, sort_key, side_of, first_edge, face_edges, edges, edge_faces, counts, forward, twins
):
    """:func:`build_edges_into`: the edges of the sorted buckets of the vertex ranges ``lo`` to ``hi - 1``, range
    ``r``'s numbered from ``first_edge[r]``; ``twins`` empty: not wanted.

    The twins are written as the sides come (the sides of an edge are next to each other): -1 for an edge's first
    side, its second side and the first made each other's twins when they lie in two faces, and both set back to -1
    if a third side comes. (A pass over each edge's sides once it was closed cost 0.085 of this kernel's 0.125 CPU s
    on the 1M icosphere; 0.042 now, the same arrays: issue 31, helper S30.)"""
    n_vertices = bucket_start.shape[0] - 1
    n_ranges = first_edge.shape[0] - 1
    with_twins = twins.shape[0] > 0
    for r in range(lo, hi):
        e = first_edge[r] - 1
        for v in range(n_vertices * r // n_ranges, n_vertices * (r + 1) // n_ranges):
            start, stop = _UNSIGNED(bucket_start[v]), _UNSIGNED(bucket_start[v + 1])  # unsigned: see _twin_walk
            previous_high = -1
            lone = side_of[start] if stop > start else 0  # the current edge's first side, and its key
            lone_key = sort_key[start] if stop > start else 0
            for i in range(start, stop):
                key = sort_key[i]
                high = key >> 1
                backward = key & 1
                side = side_of[i]
                face = np.int64(_UNSIGNED(side) // _THREE)  # back to signed: -1 and a face share a type
                if high != previous_high:
                    e += 1
                    previous_high = high
                    edge = _UNSIGNED(e)
                    edges[edge, 0] = v
                    edges[edge, 1] = high
                    edge_faces[edge, 0] = -1 if backward else face
                    edge_faces[edge, 1] = face if backward else -1
                    counts[edge] = 1
                    forward[edge] = 0 if backward else 1
                    if with_twins:
                        twins[_UNSIGNED(side)] = -1
                        lone, lone_key = side, key
                else:
                    edge = _UNSIGNED(e)
                    count = counts[edge]
                    if count == 1:
                        if edge_faces[edge, 1] == -1:
                            edge_faces[edge, 1] = face
                        else:
                            edge_faces[edge, 0] = face
                    counts[edge] = count + 1
                    if not backward:
                        forward[edge] += 1
                    if with_twins:
                        if count == 1 and _UNSIGNED(lone) // _THREE != _UNSIGNED(side) // _THREE:
                            if (lone_key & 1) != backward:  # run both ways: consistently wound
                                twins[_UNSIGNED(lone)] = side
                                twins[_UNSIGNED(side)] = lone
                            else:
                                twins[_UNSIGNED(lone)] = -2 - side
                                twins[_UNSIGNED(side)] = -2 - lone
                        else:  # in the face of the first side, or a third side or more: no twins
                            twins[_UNSIGNED(side)] = -1
                            if count == 2:
                                twins[_UNSIGNED(lone)] = -1
                                twins[_UNSIGNED(side_of[i - _ONE])] = -1
                face_edges[_UNSIGNED(side)] = e


@nb.njit(inline="always", **_JIT)
def _find(parent, x):
    while parent[x] != x:
        parent[x] = parent[parent[x]]
        x = parent[x]
    return x


@nb.njit(inline="always", **_JIT)
def _position(faces, f, v):
    """The position (0, 1 or 2) of vertex ``v`` in face ``f``."""
    if faces[f, 0] == v:
        return 0
    if faces[f, 1] == v:
        return 1
    return 2


@nb.njit(inline="always", **_JIT)
def _fan_walk(faces, face_edges, edge_faces, linked, proper, v, f, side):
    """Faces reached from face ``f`` at vertex ``v`` leaving through its side ``side`` (an edge at ``v``),
    face to face across linked edges around ``v``, until ``f`` comes back or a side that is not linked
    stops the walk: ``(faces reached, f not counted; whether f came back)``."""
    start = f
    reached = 0
    while True:
        e = face_edges[f, side]
        if not linked[e]:
            return reached, False
        g = edge_faces[e, 0] if edge_faces[e, 1] == f else edge_faces[e, 1]
        if not proper[g]:
            return reached, False
        if g == start:
            return reached, True
        reached += 1
        q = _position(faces, g, v)
        # g's two sides at v are (q, q + 1) and (q + 2, q): leave through the one it was not entered by
        side = (q + 2) % 3 if face_edges[g, q] == e else q
        f = g


@nb.njit(parallel=True, **_JIT)
def bowtie_vertices(faces, face_edges, edge_faces, linked, proper, n_vertices):
    """Vertices whose face corners fall in more than one fan (see MeshTopology.bowtie_vertices).

    A corner at ``v`` is joined to another across each of its two sides at
    ``v`` whose edge is linked (two faces, both without a repeated vertex): at
    most two joins per corner, so each fan is a chain or a cycle of faces. The
    fan of one corner of every vertex is walked face to face around the vertex
    (both ways when it is a chain) and the vertex is a bow-tie when the walk
    reaches fewer than its proper corners. One pass over the faces counts the
    corners; the walks run in parallel, one vertex each.
    """
    n_faces = faces.shape[0]
    corners = np.zeros(n_vertices, np.int64)
    first = np.full(n_vertices, -1, np.int64)
    for f in range(n_faces):
        if proper[f]:
            for k in range(3):
                v = faces[f, k]
                corners[v] += 1
                if first[v] < 0:
                    first[v] = f
    several = np.zeros(n_vertices, np.bool_)
    for v in nb.prange(n_vertices):
        f = first[v]
        if f < 0:
            continue
        p = _position(faces, f, v)
        ahead, closed = _fan_walk(faces, face_edges, edge_faces, linked, proper, v, f, p)
        reached = 1 + ahead
        if not closed:  # a chain: the other way too
            reached += _fan_walk(faces, face_edges, edge_faces, linked, proper, v, f, (p + 2) % 3)[0]
        several[v] = reached < corners[v]
    return several


@nb.njit(inline="always", **_JIT)
def _twin_walk(twins, side, leaving):
    """:func:`_fan_walk` on the twins of :func:`build_edges_into`: the faces reached around a vertex from
    the face of ``side`` (a side of that face at the vertex, ``leaving`` it or entering it) through that
    side. One read of ``twins`` a face, no read of the faces: crossing a consistently wound edge, the
    next side at the vertex is the one after the twin (``leaving``) or the one before it; crossing an
    inconsistent one swaps the two."""
    start = _UNSIGNED(side) // _THREE
    reached = 0
    while True:
        signed = twins[side]
        if signed == -1:
            return reached, False
        if signed < -1:  # the two faces run the edge the same way
            signed = -2 - signed
            leaving = not leaving
        t = _UNSIGNED(signed)  # unsigned from here: no code for negative indices and quotients
        g = t // _THREE
        if g == start:
            return reached, True
        reached += 1
        k = t - _THREE * g
        if leaving:
            side = t + _ONE if k < _TWO else t - _TWO
        else:
            side = t + _TWO if k < _ONE else t - _ONE


@nb.njit(**_JIT)
def bowtie_from_twins(faces, twins, n_vertices):
    """:func:`bowtie_vertices` from the twins of the sides (:func:`build_edges_into`), the same vertices.

    A side has a twin exactly when its edge is linked (two faces, two
    different ones; a face with a repeated corner never has one: each of its
    edges has two of its own sides), so the walk crosses to the twin's face
    without looking up edges. One pass over the faces counts the corners of
    the faces without a repeated corner (the pass :func:`build_edges_into`
    makes along with its own), then :func:`bowtie_walks`.
    """
    n_faces = faces.shape[0]
    corners = np.zeros(n_vertices, np.int64)
    first = np.full(n_vertices, -1, np.int64)  # the side leaving v of its first proper face
    for f in range(n_faces):
        a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
        if a != b and b != c and c != a:
            for k in range(3):
                v = faces[f, k]
                corners[v] += 1
                if first[v] < 0:
                    first[v] = 3 * f + k
    return bowtie_walks(twins, first, corners)


@threaded
def bowtie_walks(twins, first, corners):
    """(V,) bool: the vertices whose fan, walked from the side ``first[v]`` (a side leaving ``v`` of its first
    face without a repeated corner; negative: none) over the ``twins``, reaches fewer than its ``corners[v]``
    corners (see :func:`bowtie_from_twins`). The walks run in chunks of vertices on threads
    (:func:`~meshcurv._kernels._common.run_chunks`; a ``parallel=True`` loop took 1 s more to compile)."""
    n_vertices = first.shape[0]
    several = np.zeros(n_vertices, np.bool_)
    run_chunks(_bowtie_chunk, n_vertices, _VERTEX_CHUNKS * nb.get_num_threads(), twins, first, corners, several)
    return several


@overload(bowtie_walks, jit_options=_JIT)  # type: ignore[arg-type]  # numba's stub types a TypedDict
def _bowtie_walks_compiled(twins, first, corners):
    """:func:`bowtie_walks` inside a compiled caller (:func:`bowtie_from_twins`): the walks on its thread."""

    def walks(twins, first, corners):
        several = np.zeros(first.shape[0], np.bool_)
        _bowtie_chunk(0, first.shape[0], twins, first, corners, several)
        return several

    return walks


@nb.njit(**_JIT)
def _bowtie_chunk(lo, hi, twins, first, corners, several):
    """:func:`bowtie_walks` of the vertices ``lo`` to ``hi - 1``."""
    for v in range(lo, hi):
        several[v] = _several_fans(twins, first[v], corners[v])


@nb.njit(**_JIT_INNER)
def _several_fans(twins, side, n_corners):
    """Whether the fan of ``side`` (leaving its vertex; -1: none) reaches fewer than the vertex's ``n_corners``
    corners."""
    if side < 0:
        return False
    leaving = _UNSIGNED(side)
    ahead, closed = _twin_walk(twins, leaving, True)
    reached = 1 + ahead
    if not closed:  # a chain: the other way too, from the side entering v
        k = leaving % _THREE
        reached += _twin_walk(twins, leaving + _TWO if k < _ONE else leaving - _ONE, False)[0]
    return reached < n_corners


@nb.njit(**_JIT_INNER)
def _union_edges(edges, n_vertices):
    """Union-find over the edges: (V,) parents whose roots are each component's smallest vertex (unsigned
    indices: see :func:`_twin_walk`)."""
    parent = np.empty(n_vertices, _UNSIGNED)
    for v in range(n_vertices):
        parent[v] = v
    for e in range(edges.shape[0]):
        a = _find(parent, _UNSIGNED(edges[e, 0]))
        b = _find(parent, _UNSIGNED(edges[e, 1]))
        if a != b:
            parent[b if b > a else a] = b if b < a else a  # max(a, b), min(a, b)
    return parent


@nb.njit(**_JIT)
def component_labels(edges, referenced, n_vertices):
    """(V,) component of each vertex of the edge graph (0, 1, ... by first vertex; -1: unreferenced) and the count."""
    parent = _union_edges(edges, n_vertices)
    labels = np.empty(n_vertices, np.int64)
    for v in range(n_vertices):  # -1 (numba's np.full compiles two functions more, issue 31)
        labels[v] = -1
    count = 0
    for v in range(n_vertices):
        if not referenced[v]:
            continue
        root = _find(parent, _UNSIGNED(v))
        if labels[root] < 0:
            labels[root] = count
            count += 1
        labels[v] = labels[root]
    return labels, count


@threaded
def neighbour_lists(edges, n_vertices):
    """CSR lists of the edge neighbours of every vertex: ``(indptr, indices)``.

    Each of a few ranges of the (sorted) edges, one per thread, counts, then
    places, the ends of its own edges (:func:`_count_ends`, :func:`_place_ends`,
    on threads: :func:`~meshcurv._kernels._common.run_chunks`), around the
    counting sort's starts (:func:`_bucket_starts`): a vertex's list holds the
    ends of the first range's edges, then of the next, each in edge order,
    which is the order of one pass over all the edges (each list increasing),
    whatever the number of threads. ``indices`` has the type of ``edges`` (int32
    where the mesh fits, :func:`meshcurv.topology.index_dtype`): half the memory
    that the walks of the balls read.
    """
    n_edges = edges.shape[0]
    n_ranges = max(1, min(nb.get_num_threads(), _BUCKET_CHUNKS, n_edges))
    # cursor[r, v]: ends at vertex v of edge range r, then where range r's next such end goes
    # numba's memory, not numpy's (no huge-page advice: geometry._unadvised_empty, issue 31)
    cursor = _unadvised_array((n_ranges, n_vertices), np.int64, zero=True)
    run_chunks(_count_ends, n_ranges, n_ranges, edges, cursor)
    indptr = _bucket_starts(cursor)
    indices = _unadvised_array(indptr[n_vertices], edges.dtype)  # every slot placed once
    run_chunks(_place_ends, n_ranges, n_ranges, edges, cursor, indices)
    return indptr, indices


@nb.njit(**_JIT)
def _count_ends(lo, hi, edges, cursor):
    """:func:`neighbour_lists`' counts of the edge ranges ``lo`` to ``hi - 1`` in ``cursor``."""
    n_edges = edges.shape[0]
    n_ranges = cursor.shape[0]
    for r in range(lo, hi):
        counts = cursor[r]
        for e in range(n_edges * r // n_ranges, n_edges * (r + 1) // n_ranges):
            counts[_UNSIGNED(edges[e, 0])] += 1
            counts[_UNSIGNED(edges[e, 1])] += 1


@nb.njit(**_JIT)
def _place_ends(lo, hi, edges, cursor, indices):
    """:func:`neighbour_lists`' placing of the ends of the edge ranges ``lo`` to ``hi - 1``."""
    n_edges = edges.shape[0]
    n_ranges = cursor.shape[0]
    for r in range(lo, hi):
        fill = cursor[r]
        for e in range(n_edges * r // n_ranges, n_edges * (r + 1) // n_ranges):
            a, b = edges[e, 0], edges[e, 1]
            p, q = _UNSIGNED(a), _UNSIGNED(b)
            indices[_UNSIGNED(fill[p])] = b
            fill[p] += 1
            indices[_UNSIGNED(fill[q])] = a
            fill[q] += 1


@threaded
def double_sided_suspects(faces, edge_faces, counts, forward):
    """(E,) bool: the edges ``weld.drop_double_sided`` looks at, in one pass over the edges.

    An edge is a suspect when it has three faces or more (non-manifold), or
    two consistently oriented faces whose corner sums are equal (both hold
    the edge's ends, so their third corners are the same vertex: a lone
    triangle stored with both windings). The NumPy path builds the corner sums
    of every face and gathers them per edge (four temporaries of the size of
    the edges or faces). In chunks of edges on threads
    (:func:`~meshcurv._kernels._common.run_chunks`, :func:`_suspects_chunk`):
    a pass on the path of every call, each edge's answer its own.
    """
    n_edges = counts.shape[0]
    out = np.zeros(n_edges, np.bool_)
    run_chunks(_suspects_chunk, n_edges, _VERTEX_CHUNKS * nb.get_num_threads(), faces, edge_faces, counts, forward, out)
    return out


@nb.njit(**_JIT)
def _suspects_chunk(lo, hi, faces, edge_faces, counts, forward, out):
    """:func:`double_sided_suspects` of the edges ``lo`` to ``hi - 1``."""
    for e in range(lo, hi):
        count = counts[e]
        if count > 2:
            out[e] = True
        elif count == 2 and forward[e] == 1:
            f, g = _UNSIGNED(edge_faces[e, 0]), _UNSIGNED(edge_faces[e, 1])  # both faces: >= 0
            out[e] = faces[f, 0] + faces[f, 1] + faces[f, 2] == faces[g, 0] + faces[g, 1] + faces[g, 2]


@nb.njit(**_JIT)
def _sampled_face_spans(faces, n_vertices, shift):
    """(S,) for the vertices ``0, 2**shift, 2 * 2**shift, ...``: the last row of ``faces`` (F, 3) around each minus
    the first, -1 where no face holds it (``_prepared._face_spans``, in one pass over the faces)."""
    n_sampled = ((n_vertices - 1) >> shift) + 1
    first = np.full(n_sampled, -1, np.int64)
    spans = np.full(n_sampled, -1, np.int64)
    mask = (1 << shift) - 1
    for f in range(faces.shape[0]):
        for k in range(3):
            v = faces[f, k]
            if v & mask == 0:
                s = _UNSIGNED(v >> shift)
                if first[s] < 0:
                    first[s] = f
                spans[s] = f - first[s]  # the rows come in order: the last one seen is the last
    return spans


@threaded
def _faces_by_smallest_corner(faces, n_vertices):
    """``(order, sorted_faces)``: the (F,) rows of ``faces`` (F, 3) in the order of their smallest corner, stable
    (a counting sort: ``np.argsort(faces.min(axis=1), kind="stable")``), and the (F, 3) faces in that order
    (numba's memory: ``_kernels.geometry._unadvised_array``'s reason).

    Each of a few ranges of the faces, one per thread, counts, then places, its own faces
    (:func:`_count_smallest`, :func:`_place_smallest`, on threads:
    :func:`~meshcurv._kernels._common.run_chunks`) around the counting sort's starts (:func:`_bucket_starts`):
    a bucket holds the first range's faces, then the next's, each in face order, which is the order of one
    pass over all the faces, whatever the number of threads (issue 31, S32: the serial pass took 0.06 CPU s
    of a normal_cycle call at 1M vertices, all of it on the call's critical path).
    """
    n_faces = faces.shape[0]
    n_ranges = max(1, min(nb.get_num_threads(), _BUCKET_CHUNKS, n_faces))
    cursor = _unadvised_array((n_ranges, n_vertices), np.int64, zero=True)
    run_chunks(_count_smallest, n_ranges, n_ranges, faces, cursor)
    _bucket_starts(cursor)
    order = _unadvised_array(n_faces, np.int64)  # every row placed once
    out = _unadvised_array((n_faces, 3), np.int64)
    run_chunks(_place_smallest, n_ranges, n_ranges, faces, cursor, order, out)
    return order, out


@nb.njit(**_JIT)
def _count_smallest(lo, hi, faces, cursor):
    """:func:`_faces_by_smallest_corner`'s counts of the face ranges ``lo`` to ``hi - 1`` in ``cursor``."""
    for r in range(lo, hi):
        counts = cursor[r]
        start, stop = _range_of(faces.shape[0], r, cursor.shape[0])
        for f in range(start, stop):
            counts[_UNSIGNED(min(faces[f, 0], faces[f, 1], faces[f, 2]))] += 1


@nb.njit(**_JIT)
def _place_smallest(lo, hi, faces, cursor, order, out):
    """:func:`_faces_by_smallest_corner`'s placing of the face ranges ``lo`` to ``hi - 1``."""
    for r in range(lo, hi):
        fill = cursor[r]
        start, stop = _range_of(faces.shape[0], r, cursor.shape[0])
        for f in range(start, stop):
            a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
            low = _UNSIGNED(min(a, b, c))
            row = _UNSIGNED(fill[low])
            fill[low] += 1
            order[row] = f
            out[row, 0], out[row, 1], out[row, 2] = a, b, c
