"""Least-squares quadric (osculating jet) fit in the local tangent frame (Cazals and Pouget 2005; Panozzo et al. 2010).

For vertex ``v`` with area-weighted normal ``n`` and tangent frame ``(t_1, t_2)``,
every vertex ``x_j`` in the ball ``B(x_v, r)`` (the vertex itself included) gives
local coordinates ``(u, v, w) = ((x_j - x_v) . t_1, (x_j - x_v) . t_2, (x_j - x_v) . n)``
and the height function

.. math::

    w(u, v) = c_0 + d\\,u + e\\,v + a\\,u^2 + b\\,uv + c\\,v^2

is fitted by least squares (a degree-2 jet: Cazals and Pouget's
osculating jet of order 2; the quadric of Panozzo et al., with the ball of
radius ``r`` instead of a number of rings). The constant and linear terms let
the fit find its own point and tangent plane, which matters on noisy meshes.
With ``p = d``, ``q = e``, ``W = sqrt(1 + p^2 + q^2)``, the first and second
fundamental forms of the graph at ``(0, 0)`` are

.. math::

    I = \\begin{pmatrix} 1 + p^2 & pq \\\\ pq & 1 + q^2 \\end{pmatrix}, \\qquad
    II = \\frac{1}{W} \\begin{pmatrix} 2a & b \\\\ b & 2c \\end{pmatrix}

and the shape operator in meshcurv's sign (positive where the surface bends
away from its normal) is ``-I^{-1} II``; it is turned into a symmetric 3D
tensor ``J I^{-1} (-II) I^{-1} J^T`` with ``J = [t_1 + p n, t_2 + q n]`` and
solved in the plane of the fitted normal ``(n - p t_1 - q t_2) / W``, which is
the normal reported.

A fit needs at least six points: vertices with fewer inside their ball are
NaN with ``valid=False`` (use a larger ``radius``). Boundary vertices are fitted
on their one-sided neighbourhood and kept.

References
----------
F. Cazals and M. Pouget (2005). Estimating differential quantities using
polynomial fitting of osculating jets. Computer Aided Geometric Design 22(2),
121-146. https://doi.org/10.1016/j.cagd.2004.09.004

D. Panozzo, E. Puppo, L. Rocca (2010). Efficient multi-scale curvature and
crease estimation. Proc. Computer Graphics, Computer Vision and Mathematics
(GraVisMa), 9-16.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .._tensors import principal_from_shape_operator, tangent_basis
from ..neighborhoods import resolve_radius, vertex_pairs_in_ball
from ..topology import MeshTopology
from ._common import Stages
from ._support import finish, prepare

STAGES = ("compute normals", "fit quadrics", "retrieve curvatures")

#: Fewest points a fit takes (six coefficients).
MIN_POINTS = 6

_UPPER = np.triu_indices(6)


def fit_coefficients(vertices: np.ndarray, normals: np.ndarray, t1: np.ndarray, t2: np.ndarray,
                     radius: float) -> tuple[np.ndarray, np.ndarray]:
    """(V, 6) coefficients ``c0, d, e, a, b, c`` (in units of ``radius``) and (V,) point counts."""
    n = vertices.shape[0]
    radius = radius if radius > 0 else 1.0  # a mesh of coincident points: any unit (every fit fails)
    normal_matrix = np.zeros((n, 6, 6))
    right = np.zeros((n, 6))
    counts = np.zeros(n)
    for chunk, centre, neighbour in vertex_pairs_in_ball(vertices, radius):
        offset = (vertices[neighbour] - vertices[centre]) / radius
        u = np.einsum("ij,ij->i", offset, t1[centre])
        v = np.einsum("ij,ij->i", offset, t2[centre])
        w = np.einsum("ij,ij->i", offset, normals[centre])
        monomials = np.stack([np.ones_like(u), u, v, u * u, u * v, v * v], axis=1)
        products = monomials[:, _UPPER[0]] * monomials[:, _UPPER[1]]
        columns = np.column_stack([products, monomials * w[:, None], np.ones_like(u)])
        rows = centre - chunk.start
        size = chunk.stop - chunk.start
        gather = sp.csr_matrix((np.ones_like(u), (rows, np.arange(u.size))), shape=(size, u.size))
        sums = np.asarray(gather @ columns)
        block = np.zeros((size, 6, 6))
        block[:, _UPPER[0], _UPPER[1]] = sums[:, :21]
        block[:, _UPPER[1], _UPPER[0]] = sums[:, :21]
        normal_matrix[chunk] = block
        right[chunk] = sums[:, 21:27]
        counts[chunk] = sums[:, 27]
    coefficients = np.full((n, 6), np.nan)
    enough = counts >= MIN_POINTS
    if enough.any():
        matrices = normal_matrix[enough]
        singular = np.linalg.cond(matrices) > 1e12
        solvable = np.flatnonzero(enough)[~singular]
        if solvable.size:
            coefficients[solvable] = np.linalg.solve(normal_matrix[solvable], right[solvable][:, :, None])[:, :, 0]
    return coefficients, counts


def estimate(vertices: np.ndarray, topology: MeshTopology, *, radius, stages: Stages):
    """Quadric fit over balls of radius ``radius``. Returns ``(result, problems)``."""
    stages.start("compute normals")
    radius = resolve_radius(radius, vertices, topology)
    _, _, defects, normals, valid = prepare(vertices, topology)
    frame = np.where(valid[:, None], normals, [0.0, 0.0, 1.0])
    t1, t2 = tangent_basis(frame)

    stages.start("fit quadrics")
    coefficients, counts = fit_coefficients(vertices, frame, t1, t2, radius)

    stages.start("retrieve curvatures")
    _, p, q, a, b, c = coefficients.T
    unit = radius if radius > 0 else 1.0
    a, b, c = a / unit, b / unit, c / unit  # back from units of radius
    width = np.sqrt(1 + p * p + q * q)
    first = np.stack([1 + p * p, p * q, 1 + q * q], axis=1)
    second = -np.stack([2 * a, b, 2 * c], axis=1) / width[:, None]
    det = first[:, 0] * first[:, 2] - first[:, 1] ** 2
    inverse = np.stack([first[:, 2], -first[:, 1], first[:, 0]], axis=1) / det[:, None]

    def as2x2(s):
        return np.stack([np.stack([s[:, 0], s[:, 1]], axis=1), np.stack([s[:, 1], s[:, 2]], axis=1)], axis=1)

    middle = as2x2(inverse) @ as2x2(second) @ as2x2(inverse)
    jacobian = np.stack([t1 + p[:, None] * frame, t2 + q[:, None] * frame], axis=2)  # (V, 3, 2)
    tensor = jacobian @ middle @ jacobian.transpose(0, 2, 1)
    six = tensor[:, [0, 1, 2, 0, 0, 1], [0, 1, 2, 1, 2, 2]]
    fitted = (frame - p[:, None] * t1 - q[:, None] * t2) / width[:, None]
    fitted = np.where(np.isfinite(fitted).all(axis=1, keepdims=True), fitted, normals)
    valid &= np.isfinite(coefficients).all(axis=1)
    k_min, k_max, dir_min, dir_max = principal_from_shape_operator(
        np.where(valid[:, None], six, 0.0), np.where(valid[:, None], fitted, [0.0, 0.0, 1.0]))
    few = int((valid & (counts < MIN_POINTS)).sum() + (~valid & ~defects.invalid_vertices).sum())
    extra = (f"{few} vertices have fewer than {MIN_POINTS} vertices (or a degenerate set) within "
             f"radius {radius:g}; pass a larger `radius`",) if few else ()
    normals_out = np.where(valid[:, None], fitted, normals)
    return finish("quadric", {"radius": radius}, valid, normals_out, k_min, k_max, dir_min, dir_max,
                  defects, extra)
