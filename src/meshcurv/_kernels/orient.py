"""Compiled twins of :mod:`meshcurv.orient`: the signed volume of each patch of faces, the fast winding numbers."""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ._common import _JIT, run_chunks, threaded


@threaded
def patch_volumes(vertices, faces, patch, flip, n_labels):
    """``orient._patch_volumes``: (P,) signed and (P,) absolute sums of six times each face's volume.

    A face's volume is that of the tetrahedron of its corners and the mean of
    its patch's faces' first corners (near the patch: no cancellation); a face
    to ``flip`` counts reversed. Two passes over the faces, no temporaries;
    one patch (``n_labels`` 1: every label is 0) without reading ``patch``
    (:func:`_one_patch_volume`), several with :func:`_patch_volumes`: two
    compiled functions chosen here, so that a call on one patch (the default's)
    compiles only the first (1.2-1.7 s less CPU on a cold cache, issue 31).
    """
    if n_labels == 1:
        signed, magnitude = _one_patch_volume(vertices, faces, flip)
        return np.full(1, signed), np.full(1, magnitude)
    return _patch_volumes(vertices, faces, patch, flip, n_labels)


#: :func:`_one_patch_volume` sums each of its passes in this many runs, whatever the thread count: the same sums,
#: bit for bit, on any number of threads.
_SUM_RUNS = 64

#: The runs of a pass go to the threads in this many chunks per thread (:func:`~._common.run_chunks`).
_CHUNKS_PER_THREAD = 4


@nb.njit(**_JIT)
def _patch_volumes(vertices, faces, patch, flip, n_labels):
    """:func:`patch_volumes` of ``n_labels`` patches."""
    count = np.zeros(n_labels)
    centre = np.zeros((n_labels, 3))
    for f in range(faces.shape[0]):
        p, a = patch[f], faces[f, 0]
        count[p] += 1.0
        centre[p, 0] += vertices[a, 0]
        centre[p, 1] += vertices[a, 1]
        centre[p, 2] += vertices[a, 2]
    for p in range(n_labels):
        weight = max(count[p], 1.0)
        centre[p, 0] /= weight
        centre[p, 1] /= weight
        centre[p, 2] /= weight
    signed = np.zeros(n_labels)
    magnitude = np.zeros(n_labels)
    for f in range(faces.shape[0]):
        p, a, b, c = patch[f], faces[f, 0], faces[f, 1], faces[f, 2]
        ax, ay, az = vertices[a, 0] - centre[p, 0], vertices[a, 1] - centre[p, 1], vertices[a, 2] - centre[p, 2]
        bx, by, bz = vertices[b, 0] - centre[p, 0], vertices[b, 1] - centre[p, 1], vertices[b, 2] - centre[p, 2]
        cx, cy, cz = vertices[c, 0] - centre[p, 0], vertices[c, 1] - centre[p, 1], vertices[c, 2] - centre[p, 2]
        volume = ax * (by * cz - bz * cy) + ay * (bz * cx - bx * cz) + az * (bx * cy - by * cx)
        signed[p] += -volume if flip[f] else volume
        magnitude[p] += abs(volume)
    return signed, magnitude


def _one_patch_volume(vertices, faces, flip):
    """``(signed, magnitude)``: :func:`patch_volumes` of one patch; the labels (all 0) are not read (16 MB at two
    million faces). Two passes over the faces (the centre, then the volumes: :func:`_volume_chunk`), each cut
    into :data:`_SUM_RUNS` runs summed in order on threads (:func:`~meshcurv._kernels._common.run_chunks`), the
    runs' sums then added in order: the same sums on any number of threads (those of one pass in order, to
    round-off)."""
    n_faces = faces.shape[0]
    sums = np.zeros((_SUM_RUNS, 3))
    centre = np.zeros(3)
    chunks = _CHUNKS_PER_THREAD * nb.get_num_threads()
    run_chunks(_volume_chunk, _SUM_RUNS, chunks, 0, vertices, faces, flip, centre, sums)
    for r in range(_SUM_RUNS):  # in order (Python floats are IEEE doubles, as the compiled sums)
        for k in range(3):
            centre[k] += float(sums[r, k])
    for k in range(3):
        centre[k] /= max(float(n_faces), 1.0)
    run_chunks(_volume_chunk, _SUM_RUNS, chunks, 1, vertices, faces, flip, centre, sums)
    signed = magnitude = 0.0
    for r in range(_SUM_RUNS):
        signed += float(sums[r, 0])
        magnitude += float(sums[r, 1])
    return signed, magnitude


@nb.njit(**_JIT)
def _volume_chunk(lo, hi, stage, vertices, faces, flip, centre, sums):
    """Runs ``lo`` to ``hi - 1`` of a pass of :func:`_one_patch_volume`, each run's sums in its row of ``sums``:
    ``stage`` 0, the sums of the faces' first corners; 1, the signed and absolute sums of six times each face's
    volume about ``centre`` (a face to ``flip`` reversed)."""
    n_faces = faces.shape[0]
    runs = sums.shape[0]
    cx, cy, cz = centre[0], centre[1], centre[2]
    for r in range(lo, hi):
        first = r * n_faces // runs
        last = (r + 1) * n_faces // runs
        if stage == 0:
            sx, sy, sz = 0.0, 0.0, 0.0
            for f in range(first, last):
                a = faces[f, 0]
                sx += vertices[a, 0]
                sy += vertices[a, 1]
                sz += vertices[a, 2]
            sums[r, 0], sums[r, 1], sums[r, 2] = sx, sy, sz
            continue
        signed = 0.0
        magnitude = 0.0
        for f in range(first, last):
            a, b, c = faces[f, 0], faces[f, 1], faces[f, 2]
            ax, ay, az = vertices[a, 0] - cx, vertices[a, 1] - cy, vertices[a, 2] - cz
            bx, by, bz = vertices[b, 0] - cx, vertices[b, 1] - cy, vertices[b, 2] - cz
            qx, qy, qz = vertices[c, 0] - cx, vertices[c, 1] - cy, vertices[c, 2] - cz
            volume = ax * (by * qz - bz * qy) + ay * (bz * qx - bx * qz) + az * (bx * qy - by * qx)
            signed += -volume if flip[f] else volume
            magnitude += abs(volume)
        sums[r, 0], sums[r, 1] = signed, magnitude


@threaded
def face_winding_numbers(corners, centres, dipoles, moments, radii, positions, own, depth, beta):
    """``orient.face_winding_numbers``: (M,) the fast winding number of the triangles ``corners`` (S, 3, 3) at
    ``positions`` (M, 3), the face ``own[m]`` left out at ``positions[m]``.

    A walk of the tree from its root per query (a stack of at most ``depth + 1`` nodes), the queries in chunks on
    threads (:func:`~._common.run_chunks`); the same terms as the NumPy twin, summed in the walk's order.
    """
    total = np.zeros(positions.shape[0])
    limit = (beta * radii) ** 2
    chunks = _CHUNKS_PER_THREAD * nb.get_num_threads()
    run_chunks(
        _winding_chunk,
        positions.shape[0],
        chunks,
        corners,
        centres,
        dipoles,
        moments,
        limit,
        positions,
        own,
        depth,
        total,
    )
    return total / (4.0 * np.pi)


@nb.njit(**_JIT)
def _winding_chunk(lo, hi, corners, centres, dipoles, moments, limit, positions, own, depth, total):
    """The queries ``lo`` to ``hi - 1`` of :func:`face_winding_numbers`: ``4 pi`` times their winding numbers."""
    n_faces = corners.shape[0]
    n_leaves = 1 << depth
    first_leaf = n_leaves - 1
    stack = np.zeros(depth + 2, dtype=np.int64)
    for m in range(lo, hi):
        qx, qy, qz = positions[m, 0], positions[m, 1], positions[m, 2]
        skip = own[m]
        sum_ = 0.0
        stack[0] = 0
        top = 1
        while top > 0:
            top -= 1
            k = stack[top]
            rx, ry, rz = centres[k, 0] - qx, centres[k, 1] - qy, centres[k, 2] - qz
            squared = rx * rx + ry * ry + rz * rz
            if squared > limit[k]:
                cubed = squared * math.sqrt(squared)
                trace = moments[k, 0, 0] + moments[k, 1, 1] + moments[k, 2, 2]
                mx = moments[k, 0, 0] * rx + moments[k, 0, 1] * ry + moments[k, 0, 2] * rz
                my = moments[k, 1, 0] * rx + moments[k, 1, 1] * ry + moments[k, 1, 2] * rz
                mz = moments[k, 2, 0] * rx + moments[k, 2, 1] * ry + moments[k, 2, 2] * rz
                dot = dipoles[k, 0] * rx + dipoles[k, 1] * ry + dipoles[k, 2] * rz
                sum_ += (dot + trace) / cubed - 3.0 * (rx * mx + ry * my + rz * mz) / (cubed * squared)
                sum_ += _second_order(moments, k, rx, ry, rz, squared, cubed)
            elif k >= first_leaf:
                leaf = k - first_leaf
                for f in range(leaf * n_faces // n_leaves, (leaf + 1) * n_faces // n_leaves):
                    if f != skip:
                        sum_ += _solid_angle(corners, f, qx, qy, qz)
            else:
                stack[top] = 2 * k + 2
                stack[top + 1] = 2 * k + 1
                top += 2
        total[m] = sum_


@nb.njit(inline="always", **_JIT)
def _second_order(moments, k, rx, ry, rz, squared, cubed):
    """The third term of node ``k``'s expansion at ``r`` (its second moments ``T``, columns 3 to 11 of
    ``moments``): ``15 / 2 T[r, r, r] / |r|^7 - 3 / 2 (2 T_aab r_b + T_abb r_a) / |r|^5``."""
    r = (rx, ry, rz)
    cubic = 0.0
    traces = 0.0
    for a in range(3):
        for b in range(3):
            tr = moments[k, a, 3 + 3 * b] * rx + moments[k, a, 4 + 3 * b] * ry + moments[k, a, 5 + 3 * b] * rz
            cubic += r[a] * r[b] * tr
            if a == b:
                traces += 2.0 * tr
        traces += (moments[k, a, 3] + moments[k, a, 7] + moments[k, a, 11]) * r[a]
    return 7.5 * cubic / (cubed * squared * squared) - 1.5 * traces / (cubed * squared)


@nb.njit(inline="always", **_JIT)
def _solid_angle(corners, f, qx, qy, qz):
    """The solid angle of the face ``f`` of ``corners`` at ``(qx, qy, qz)`` (Van Oosterom and Strackee 1983); 0 in
    its plane (``|a . (b x c)|`` at most ``1e-12 |a||b||c|``)."""
    ax, ay, az = corners[f, 0, 0] - qx, corners[f, 0, 1] - qy, corners[f, 0, 2] - qz
    bx, by, bz = corners[f, 1, 0] - qx, corners[f, 1, 1] - qy, corners[f, 1, 2] - qz
    cx, cy, cz = corners[f, 2, 0] - qx, corners[f, 2, 1] - qy, corners[f, 2, 2] - qz
    la = math.sqrt(ax * ax + ay * ay + az * az)
    lb = math.sqrt(bx * bx + by * by + bz * bz)
    lc = math.sqrt(cx * cx + cy * cy + cz * cz)
    numerator = ax * (by * cz - bz * cy) + ay * (bz * cx - bx * cz) + az * (bx * cy - by * cx)
    if abs(numerator) <= 1e-12 * la * lb * lc:
        return 0.0
    denominator = (
        la * lb * lc
        + (ax * bx + ay * by + az * bz) * lc
        + (ax * cx + ay * cy + az * cz) * lb
        + (bx * cx + by * cy + bz * cz) * la
    )
    return 2.0 * math.atan2(numerator, denominator)
