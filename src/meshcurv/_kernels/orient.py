"""Compiled twin of :mod:`meshcurv.orient`: the signed volume of each patch of faces."""

from __future__ import annotations

import numba as nb
import numpy as np

from ._common import _JIT


@nb.njit(**_JIT)
def patch_volumes(vertices, faces, patch, flip, n_labels):
    """``orient._patch_volumes``: (P,) signed and (P,) absolute sums of six times each face's volume.

    A face's volume is that of the tetrahedron of its corners and the mean of
    its patch's faces' first corners (near the patch: no cancellation); a face
    to ``flip`` counts reversed. Two passes over the faces, no temporaries.
    """
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
