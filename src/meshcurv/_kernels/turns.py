"""Compiled twin of :func:`meshcurv.radius.ball_turn_extremes`: how far the vertex normals turn across each ball
(the reach check of ``quadric``'s and ``normal_cycle_ball``'s default balls, :func:`meshcurv.radius._ball_turns`).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ._common import _JIT
from .neighborhoods import _ball_members, pool_grid


@nb.njit(**_JIT)
def ball_turn_extremes(vertices, normals, radii, centres, pool, creases):
    """``(cosines, bends, sharpest)`` of the ball of each centre: the smallest cosine (clipped to [-1, 1], 1 where
    none) between the centre's normal and a point's of its ball, the largest ``|n_j - n_v| / |x_j - x_v|`` over
    the points of its outer half and the largest ``creases`` of its points (0 where none).

    The ball of centre ``v`` holds the points of ``pool`` within ``radii[v]`` (squared distances summed x, y, z,
    as the k-d tree search of the NumPy twin tests them); rows of NaN in ``normals`` add nothing. Each pair's
    numbers are rounded as the twin's (products summed x, y, z, square roots, one division), and the extremes do
    not depend on the order of the pairs: the result is the twin's to the bit.
    """
    m = centres.shape[0]
    cosines = np.ones(m)
    bends = np.zeros(m)
    sharpest = np.zeros(m)
    if m == 0 or pool.shape[0] == 0:
        return cosines, bends, sharpest
    largest = 0.0
    for c in range(m):
        largest = max(largest, radii[centres[c]])
    points, ids, grid = pool_grid(vertices, pool, largest)
    members = np.empty(64, np.int64)
    for c in range(m):
        v = centres[c]
        radius = radii[v]
        if not math.isfinite(radius):  # no ball (the callers' radii are finite)
            continue
        members, count = _ball_members(points, grid, vertices[v, 0], vertices[v, 1], vertices[v, 2], radius, members)
        half = 0.5 * radius
        lowest, bend, sharp = 1.0, 0.0, 0.0
        for k in range(count):
            j = ids[members[k]]
            dot = normals[j, 0] * normals[v, 0] + normals[j, 1] * normals[v, 1] + normals[j, 2] * normals[v, 2]
            if dot < lowest:  # NaN: no turn
                lowest = max(dot, -1.0)
            if creases[j] > sharp:
                sharp = creases[j]
            dx = vertices[j, 0] - vertices[v, 0]
            dy = vertices[j, 1] - vertices[v, 1]
            dz = vertices[j, 2] - vertices[v, 2]
            apart = math.sqrt(dx * dx + dy * dy + dz * dz)
            if apart >= half:
                ex = normals[j, 0] - normals[v, 0]
                ey = normals[j, 1] - normals[v, 1]
                ez = normals[j, 2] - normals[v, 2]
                chord = math.sqrt(ex * ex + ey * ey + ez * ez) / apart
                if chord > bend:  # NaN: none
                    bend = chord
        cosines[c], bends[c], sharpest[c] = lowest, bend, sharp
    return cosines, bends, sharpest
