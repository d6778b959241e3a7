"""Compiled twin of the interpolation of :func:`meshcurv.jets.sampled_jet_normals`: each centre's normal from
the fitted normals of the samples near it, or any field from its samples' values (the sampled ball sums of
``icc``; dense voxel surfaces, issue 30).
"""

from __future__ import annotations

import numba as nb
import numpy as np

from ._common import _JIT, run_chunks, threaded

#: The cubes of the samples' search: cube coordinates fit 21 bits each in one int64 key (as ``jets._cube_samples``).
_BITS = 21
_TOP = (1 << _BITS) - 1


#: A cube is beyond the reach when its squared distance from the centre, in sides, exceeds this: 1 and a margin
#: far above the round-off of the cubes' coordinates (a sample on a cube's face may be filed on either side).
_REACH_SLACK = 1.0 + 1e-6


@nb.njit(inline="always", **_JIT)
def _cube_gap(x, low, reach, cube, step):
    """The squared distance, in sides, from the coordinate ``x`` in cube ``cube`` (of side ``reach`` from ``low``) to
    the neighbour cube ``cube + step`` (``step`` -1, 0 or 1) along its axis."""
    if step == 0:
        return 0.0
    inside = (x - low) / reach - cube  # 0 to 1 in its cube
    gap = inside if step < 0 else 1.0 - inside
    return gap * gap if gap > 0.0 else 0.0


@nb.njit(**_JIT)
def _interpolate_chunk(
    lo,
    hi,
    at,
    cubes,
    keys,
    order,
    samples,
    fitted,
    t1,
    t2,
    facing,
    sample_normals,
    agreement,
    reach,
    spread,
    out,
    reached,
    corner,
):
    """Rows ``lo..hi`` of :func:`interpolated_normals` (``cubes``: (M, 3) the centres' cubes of side ``reach``
    from ``corner``;
    ``keys``, ``order``: the samples' cube keys, sorted, and their rows; ``facing`` (M, 3) or (0, 3): without
    rows, every sample in reach counts)."""
    k = fitted.shape[1]
    moments = np.zeros((3, k))
    check = facing.shape[0] > 0
    for i in range(lo, hi):
        g00 = g01 = g02 = g11 = g12 = g22 = 0.0
        moments[:, :] = 0.0
        ax, ay, az = at[i, 0], at[i, 1], at[i, 2]
        ux, uy, uz = t1[i, 0], t1[i, 1], t1[i, 2]
        vx, vy, vz = t2[i, 0], t2[i, 1], t2[i, 2]
        for dx in range(-1, 2):
            cx = cubes[i, 0] + dx
            if cx < 0 or cx > _TOP:
                continue
            gap_x = _cube_gap(ax, corner[0], reach, cubes[i, 0], dx)
            for dy in range(-1, 2):
                cy = cubes[i, 1] + dy
                if cy < 0 or cy > _TOP:
                    continue
                # a column of cubes whose nearest point is beyond the reach holds no sample of positive weight
                # (skipped, as each of its samples would be: the same sums)
                across = gap_x + _cube_gap(ay, corner[1], reach, cubes[i, 1], dy)
                if across > _REACH_SLACK:
                    continue
                # the three cubes along z are consecutive keys (z is the lowest bits): one search, then the
                # samples of the three in key order, as three searches visited them (27 searches a centre cost
                # about half of the interpolation); a cube beyond the reach left out
                below = across + _cube_gap(az, corner[2], reach, cubes[i, 2], -1) > _REACH_SLACK
                above = across + _cube_gap(az, corner[2], reach, cubes[i, 2], 1) > _REACH_SLACK
                low_z = cubes[i, 2] if below else max(cubes[i, 2] - 1, 0)
                high_z = cubes[i, 2] if above else min(cubes[i, 2] + 1, _TOP)
                row = (cx << 42) | (cy << 21)
                last = row | high_z
                first = np.searchsorted(keys, row | low_z)
                for p in range(first, keys.size):
                    if keys[p] > last:
                        break
                    s = order[p]
                    if check and not (
                        facing[i, 0] * sample_normals[s, 0]
                        + facing[i, 1] * sample_normals[s, 1]
                        + facing[i, 2] * sample_normals[s, 2]
                        > agreement
                    ):
                        continue
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
                    for c in range(k):
                        f = fitted[s, c]
                        moments[0, c] += w * f
                        moments[1, c] += w1 * f
                        moments[2, c] += w2 * f
        if not g00 > 0.0:
            reached[i] = False
            out[i, :] = np.nan
            continue
        reached[i] = True
        # the cofactors of the first column of the symmetric gram matrix: its determinant and, by Cramer's rule,
        # the constant term of the linear fit of each component
        c0 = g11 * g22 - g12 * g12
        c1 = g02 * g12 - g01 * g22
        c2 = g01 * g12 - g02 * g11
        det = g00 * c0 + g01 * c1 + g02 * c2
        if det > spread * g00 * g00 * g00:
            for c in range(k):
                out[i, c] = (moments[0, c] * c0 + moments[1, c] * c1 + moments[2, c] * c2) / det
        else:
            for c in range(k):
                out[i, c] = moments[0, c] / g00  # (normals: normalised by the caller, as the twin's)


@threaded
def interpolated_normals(
    at, samples, fitted, tangent1, tangent2, reach, spread, facing=None, sample_normals=None, agreement=0.0
):
    """``jets.interpolated_normals``: ``(values, reached)`` of the centres ``at`` (M, 3) from the ``fitted`` (S, k)
    values of the ``samples`` (S, 3) within ``reach`` (unit normals, k = 3; or any fields).

    The samples are found by cubes of side ``reach`` (a sorted int64 key each, 21 bits a coordinate; the 27
    cubes around each centre, in nine searches), each weighted ``(1 - d^2 / reach^2)^2``; the 3 x 3 weighted
    least-squares system over the tangent plane ``(tangent1, tangent2)`` is solved by Cramer's rule (the NumPy twin: LAPACK), its
    determinant against ``spread`` as the twin's. With ``facing`` (M, 3) and ``sample_normals`` (S, 3), only the
    samples whose normal's cosine with the centre's exceeds ``agreement`` count. The sums run in
    another order than the twin's bincounts: the results agree to round-off. Not normalised; NaN and ``reached``
    False where no sample is within ``reach``. Rows on threads (:func:`~meshcurv._kernels._common.run_chunks`).
    """
    at = np.ascontiguousarray(at, dtype=np.float64)
    samples = np.ascontiguousarray(samples, dtype=np.float64)
    fitted = np.ascontiguousarray(fitted, dtype=np.float64)
    m = at.shape[0]
    out, reached = np.full((m, fitted.shape[1]), np.nan), np.zeros(m, dtype=np.bool_)
    if m == 0:
        return out, reached
    if facing is None or sample_normals is None:
        facing = sample_normals = np.zeros((0, 3))
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
        fitted,
        np.ascontiguousarray(tangent1, dtype=np.float64),
        np.ascontiguousarray(tangent2, dtype=np.float64),
        np.ascontiguousarray(facing, dtype=np.float64),
        np.ascontiguousarray(sample_normals, dtype=np.float64),
        float(agreement),
        float(reach),
        float(spread),
        out,
        reached,
        corner,
    )
    return out, reached
