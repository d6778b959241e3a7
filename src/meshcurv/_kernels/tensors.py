"""Compiled twin of :mod:`meshcurv._tensors`: principal curvatures and directions of shape operators
restricted to the tangent plane.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from ._common import _JIT, _tangent_frame


@nb.njit(inline="always", **_JIT)
def _tangent_eigen(xx, yy, zz, xy, xz, yz, nx, ny, nz, rotate, mean_from_trace):
    """k_min, k_max, dir_min (3), dir_max (3) of one tensor restricted to the plane normal to n."""
    t1x, t1y, t1z, t2x, t2y, t2z = _tangent_frame(nx, ny, nz)
    s1x = xx * t1x + xy * t1y + xz * t1z
    s1y = xy * t1x + yy * t1y + yz * t1z
    s1z = xz * t1x + yz * t1y + zz * t1z
    a = t1x * s1x + t1y * s1y + t1z * s1z
    b = t2x * s1x + t2y * s1y + t2z * s1z
    c = (
        t2x * (xx * t2x + xy * t2y + xz * t2z)
        + t2y * (xy * t2x + yy * t2y + yz * t2z)
        + t2z * (xz * t2x + yz * t2y + zz * t2z)
    )
    half_sum = 0.5 * (a + c)
    if mean_from_trace:
        half_sum = 0.5 * (xx + yy + zz)
    half_diff = 0.5 * (a - c)
    radius = math.hypot(half_diff, b)
    theta = 0.5 * math.atan2(b, half_diff)
    co, si = math.cos(theta), math.sin(theta)
    alx, aly, alz = co * t1x + si * t2x, co * t1y + si * t2y, co * t1z + si * t2z
    acx, acy, acz = -si * t1x + co * t2x, -si * t1y + co * t2y, -si * t1z + co * t2z
    if rotate:
        alx, aly, alz, acx, acy, acz = acx, acy, acz, alx, aly, alz
    return half_sum - radius, half_sum + radius, acx, acy, acz, alx, aly, alz


@nb.njit(inline="always", **_JIT)
def _principal_from_mean_gaussian(mean, gaussian):
    """``_tensors.principal_from_mean_gaussian`` of one vertex: ``k_min, k_max`` (the same operations)."""
    a, b = abs(mean), math.sqrt(abs(gaussian))
    size = b if b > a else a  # max(a, b), written out: numba compiles its max once per caller's options
    exponent = math.frexp(size if math.isfinite(size) and size > 0 else 1.0)[1]
    scale = math.ldexp(1.0, exponent)
    h, k = mean / scale, gaussian / scale / scale
    d = h * h - k
    half = scale * math.sqrt(0.0 if 0.0 > d else d)  # max(d, 0.0)
    if not (math.isfinite(mean) and math.isfinite(gaussian)):
        half = math.nan
    return mean - half, mean + half


@nb.njit(parallel=True, **_JIT)
def principal_from_shape_operator(tensor, normals, rotate, mean_from_trace):
    """``_tensors.principal_from_shape_operator``: (N,) k_min, k_max and (N, 3) dir_min, dir_max."""
    n = tensor.shape[0]
    k_min = np.empty(n)
    k_max = np.empty(n)
    dir_min = np.empty((n, 3))
    dir_max = np.empty((n, 3))
    for i in nb.prange(n):
        lo, hi, d0, d1, d2, d3, d4, d5 = _tangent_eigen(
            tensor[i, 0],
            tensor[i, 1],
            tensor[i, 2],
            tensor[i, 3],
            tensor[i, 4],
            tensor[i, 5],
            normals[i, 0],
            normals[i, 1],
            normals[i, 2],
            rotate,
            mean_from_trace,
        )
        k_min[i], k_max[i] = lo, hi
        dir_min[i, 0], dir_min[i, 1], dir_min[i, 2] = d0, d1, d2
        dir_max[i, 0], dir_max[i, 1], dir_max[i, 2] = d3, d4, d5
    return k_min, k_max, dir_min, dir_max
