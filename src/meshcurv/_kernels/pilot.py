"""Compiled twin of the interpolation of :func:`meshcurv.jets.sampled_jet_normals`: each centre's normal from
the fitted normals of the samples near it (dense voxel surfaces, issue 30).
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ._common import _JIT, run_chunks, threaded

#: The cubes of the samples' search: cube coordinates fit 21 bits each in one int64 key (as ``jets._cube_samples``).
_BITS = 21
_TOP = (1 << _BITS) - 1


@nb.njit(**_JIT)
def _interpolate_chunk(lo, hi, at, cubes, keys, order, samples, fitted, t1, t2, reach, spread, out, reached):
    """Rows ``lo..hi`` of :func:`interpolated_normals` (``cubes``: (M, 3) the centres' cubes of side ``reach``;
    ``keys``, ``order``: the samples' cube keys, sorted, and their rows)."""
    for i in range(lo, hi):
        g00 = g01 = g02 = g11 = g12 = g22 = 0.0
        m00 = m01 = m02 = m10 = m11 = m12 = m20 = m21 = m22 = 0.0
        ax, ay, az = at[i, 0], at[i, 1], at[i, 2]
        ux, uy, uz = t1[i, 0], t1[i, 1], t1[i, 2]
        vx, vy, vz = t2[i, 0], t2[i, 1], t2[i, 2]
        for dx in range(-1, 2):
            cx = cubes[i, 0] + dx
            if cx < 0 or cx > _TOP:
                continue
            for dy in range(-1, 2):
                cy = cubes[i, 1] + dy
                if cy < 0 or cy > _TOP:
                    continue
                for dz in range(-1, 2):
                    cz = cubes[i, 2] + dz
                    if cz < 0 or cz > _TOP:
                        continue
                    key = (cx << 42) | (cy << 21) | cz
                    first = np.searchsorted(keys, key)
                    for p in range(first, keys.size):
                        if keys[p] != key:
                            break
                        s = order[p]
                        ox = (samples[s, 0] - ax) / reach
                        oy = (samples[s, 1] - ay) / reach
                        oz = (samples[s, 2] - az) / reach
                        w = 1.0 - (ox * ox + oy * oy + oz * oz)
                        if not w > 0.0:
                            continue
                        w = w * w
                        b1 = ox * ux + oy * uy + oz * uz
                        b2 = ox * vx + oy * vy + oz * vz
                        w1, w2 = w * b1, w * b2
                        g00 += w
                        g01 += w * b1
                        g02 += w * b2
                        g11 += w1 * b1
                        g12 += w1 * b2
                        g22 += w2 * b2
                        fx, fy, fz = fitted[s, 0], fitted[s, 1], fitted[s, 2]
                        m00 += w * fx
                        m01 += w * fy
                        m02 += w * fz
                        m10 += w1 * fx
                        m11 += w1 * fy
                        m12 += w1 * fz
                        m20 += w2 * fx
                        m21 += w2 * fy
                        m22 += w2 * fz
        if not g00 > 0.0:
            reached[i] = False
            out[i, 0] = out[i, 1] = out[i, 2] = np.nan
            continue
        reached[i] = True
        # the cofactors of the first column of the symmetric gram matrix: its determinant and, by Cramer's rule,
        # the constant term of the linear fit of each component
        c0 = g11 * g22 - g12 * g12
        c1 = g02 * g12 - g01 * g22
        c2 = g01 * g12 - g02 * g11
        det = g00 * c0 + g01 * c1 + g02 * c2
        if det > spread * g00 * g00 * g00:
            nx = (m00 * c0 + m10 * c1 + m20 * c2) / det
            ny = (m01 * c0 + m11 * c1 + m21 * c2) / det
            nz = (m02 * c0 + m12 * c1 + m22 * c2) / det
        else:
            nx, ny, nz = m00 / g00, m01 / g00, m02 / g00
        out[i, 0], out[i, 1], out[i, 2] = nx, ny, nz  # normalised by the caller, as the twin's


@threaded
def interpolated_normals(at, samples, fitted, tangent1, tangent2, reach, spread):
    """``jets.interpolated_normals``: ``(normals, reached)`` of the centres ``at`` (M, 3) from the ``fitted`` (S, 3)
    unit normals of the ``samples`` (S, 3) within ``reach``.

    The samples are found by cubes of side ``reach`` (a sorted int64 key each, 21 bits a coordinate; the 27
    cubes around each centre), each weighted ``(1 - d^2 / reach^2)^2``; the 3 x 3 weighted least-squares system
    over the tangent plane ``(tangent1, tangent2)`` is solved by Cramer's rule (the NumPy twin: LAPACK), its
    determinant against ``spread`` as the twin's. The sums run in another order than the twin's bincounts: the
    results agree to round-off. Not normalised; NaN and ``reached`` False where no sample is within ``reach``.
    Rows on threads (:func:`~meshcurv._kernels._common.run_chunks`).
    """
    at = np.ascontiguousarray(at, dtype=np.float64)
    samples = np.ascontiguousarray(samples, dtype=np.float64)
    m = at.shape[0]
    out, reached = np.empty((m, 3)), np.empty(m, dtype=np.bool_)
    if m == 0:
        return out, reached
    corner = np.minimum(at.min(axis=0), samples.min(axis=0)) if samples.shape[0] else at.min(axis=0)
    cubes = np.minimum(np.floor((at - corner) / reach), 2.0**20).astype(np.int64)
    of_samples = np.minimum(np.floor((samples - corner) / reach), 2.0**20).astype(np.int64)
    keys = of_samples[:, 0] << 42 | of_samples[:, 1] << 21 | of_samples[:, 2]
    order = np.argsort(keys, kind="stable")
    run_chunks(
        _interpolate_chunk,
        m,
        8 * nb.get_num_threads(),
        at,
        cubes,
        np.ascontiguousarray(keys[order]),
        order.astype(np.int64),
        samples,
        np.ascontiguousarray(fitted, dtype=np.float64),
        np.ascontiguousarray(tangent1, dtype=np.float64),
        np.ascontiguousarray(tangent2, dtype=np.float64),
        float(reach),
        float(spread),
        out,
        reached,
    )
    return out, reached
