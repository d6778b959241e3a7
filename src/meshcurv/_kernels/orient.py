"""Compiled twin of :mod:`meshcurv.orient`: the signed volume of each patch of faces."""

from __future__ import annotations

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
