"""Compiled kernel (numba) of the randomized corrected measures on points; mirrors the NumPy path.

Imported only when :func:`meshcurv._backend.numba_kernels` says the compiled
backend is in use. :func:`ball_triangle_sums` does in one pass per centre what
:func:`meshcurv._pointcloud_estimators.corrected_measures` does with arrays:
draw the triangles, turn them, compute the measures of
:func:`meshcurv.estimators.icc.face_measures` and sum them (tests compare the two).
"""

from __future__ import annotations

import numba as nb
import numpy as np

_JIT = dict(cache=True, nogil=True, fastmath=False, error_model="numpy")


@nb.njit(parallel=True, **_JIT)
def ball_triangle_sums(points, normals, index, counts, pattern):
    """(M, 9) sums of ``mu_0, mu_1, mu_2, mu^{X,Y}`` (xx, yy, zz, xy, xz, yz) over the triangles of each ball.

    ``index`` (M, K): the ball's points first (``counts`` of them, >= 3);
    ``pattern`` (T, 3): uniform numbers in [0, 1) that pick three distinct ranks.
    """
    m = index.shape[0]
    out = np.zeros((m, 9))
    for row in nb.prange(m):
        c = counts[row]
        for t in range(pattern.shape[0]):
            a = int(np.floor(pattern[t, 0] * c))
            b = int(np.floor(pattern[t, 1] * (c - 1)))
            if b >= a:
                b += 1
            z = int(np.floor(pattern[t, 2] * (c - 2)))
            low, high = min(a, b), max(a, b)
            if z >= low:
                z += 1
            if z >= high:
                z += 1
            i, j, k = index[row, a], index[row, b], index[row, z]
            ax, ay, az = points[j, 0] - points[i, 0], points[j, 1] - points[i, 1], points[j, 2] - points[i, 2]
            bx, by, bz = points[k, 0] - points[i, 0], points[k, 1] - points[i, 1], points[k, 2] - points[i, 2]
            u0x, u0y, u0z = normals[i, 0], normals[i, 1], normals[i, 2]
            u1x, u1y, u1z = normals[j, 0], normals[j, 1], normals[j, 2]
            u2x, u2y, u2z = normals[k, 0], normals[k, 1], normals[k, 2]
            mx, my, mz = (u0x + u1x + u2x) / 3, (u0y + u1y + u2y) / 3, (u0z + u1z + u2z) / 3
            cx, cy, cz = ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx
            if mx * cx + my * cy + mz * cz < 0:  # turn (i, j, k) into (i, k, j)
                ax, ay, az, bx, by, bz = bx, by, bz, ax, ay, az
                u1x, u1y, u1z, u2x, u2y, u2z = u2x, u2y, u2z, u1x, u1y, u1z
                cx, cy, cz = -cx, -cy, -cz
            out[row, 0] += 0.5 * (mx * cx + my * cy + mz * cz)
            px, py, pz = u0x - u2x, u0y - u2y, u0z - u2z
            qx, qy, qz = u1x - u0x, u1y - u0y, u1z - u0z
            sx = (py * az - pz * ay) + (qy * bz - qz * by)
            sy = (pz * ax - px * az) + (qz * bx - qx * bz)
            sz = (px * ay - py * ax) + (qx * by - qy * bx)
            out[row, 1] += 0.5 * (mx * sx + my * sy + mz * sz)
            out[row, 2] += 0.5 * (u0x * (u1y * u2z - u1z * u2y) + u0y * (u1z * u2x - u1x * u2z)
                                  + u0z * (u1x * u2y - u1y * u2x))
            gx, gy, gz = ay * mz - az * my, az * mx - ax * mz, ax * my - ay * mx
            hx, hy, hz = by * mz - bz * my, bz * mx - bx * mz, bx * my - by * mx
            ex, ey, ez = u2x - u0x, u2y - u0y, u2z - u0z
            out[row, 3] += 0.5 * (gx * ex - hx * qx)
            out[row, 4] += 0.5 * (gy * ey - hy * qy)
            out[row, 5] += 0.5 * (gz * ez - hz * qz)
            out[row, 6] += 0.25 * ((gx * ey - hx * qy) + (gy * ex - hy * qx))
            out[row, 7] += 0.25 * ((gx * ez - hx * qz) + (gz * ex - hz * qx))
            out[row, 8] += 0.25 * ((gy * ez - hy * qz) + (gz * ey - hz * qy))
    return out
