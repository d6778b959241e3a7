"""Cotangent mean curvature and angle-defect Gaussian curvature (Meyer, Desbrun, Schröder, Barr 2003).

At vertex ``i`` with mixed Voronoi area ``A_i``
(:func:`meshcurv.geometry.mixed_voronoi_corner_areas`):

.. math::

    \\mathbf K(x_i) = \\frac{1}{2 A_i} \\sum_{j \\in N(i)} (\\cot \\alpha_{ij} + \\cot \\beta_{ij})
    (x_j - x_i) = -2 H n_i, \\qquad
    K = \\frac{2\\pi - \\sum_f \\theta_f}{A_i}

``alpha_ij, beta_ij`` are the angles opposite edge ``ij`` and ``theta_f`` the
angles at ``i``. ``H = -<K(x_i), n_i> / 2`` with ``n_i`` the area-weighted vertex
normal, so that an outward-wound sphere gives ``+1/r``. The principal curvatures
follow as ``H -/+ sqrt(max(H^2 - K, 0))``. The method gives no principal
directions: ``dir_min`` and ``dir_max`` are NaN.

A 1-ring method: it does not converge pointwise on irregular meshes, and on a
boundary the angle defect is the geodesic curvature of the boundary, not ``K``;
boundary vertices are NaN with ``valid=False``.

References
----------
M. Meyer, M. Desbrun, P. Schröder, A. H. Barr (2003). Discrete
differential-geometry operators for triangulated 2-manifolds. Visualization and
Mathematics III, 35-57. https://doi.org/10.1007/978-3-662-05105-4_2
"""

from __future__ import annotations

import numpy as np

from .._tensors import principal_from_mean_gaussian
from .._geometry import corner_angles, corner_cotangents, mixed_voronoi_corner_areas, vertex_normals
from .._prepared import PreparedMesh
from ._ring_noise import noisy_rings, noisy_rings_note
from ._support import Stages, finish, staircase_undefined

#: The cotangent Laplacian's noise gain (:func:`~meshcurv.estimators._ring_noise.noisy_rings`): on a regular
#: ring of six faces, vertices scattered by ``sigma`` along the normal move ``H`` by ``2.2 sigma / l^2``
#: (standard deviation: the vertex's own weight ``sqrt(48)`` beside its neighbours' ``sqrt(8)``, over ``4 A``);
#: measured 2.0 times the scatter that the 2-ring's quadric leaves, on welded soups of icospheres.
NOISE_GAIN = 2.0

STAGES = ("compute angles", "compute cotangent Laplacian", "retrieve curvatures")


def estimate(mesh: PreparedMesh, *, stages: Stages):
    """Meyer et al. mean and Gaussian curvature. Returns ``(result, problems)``."""
    vertices, topology = mesh.vertices, mesh.topology
    stages.start("compute angles")
    n = vertices.shape[0]
    faces = topology.faces
    degenerate = mesh.degenerate
    defects = mesh.defects()
    good = faces[~degenerate]
    cot = corner_cotangents(vertices, good)
    # a corner whose cross product rounds to zero while its face's area does not (the corner at a vertex
    # so far from its neighbours that their offsets are absorbed, a spike at 1e20): no cotangent weight
    needles = ~np.isfinite(cot).all(axis=1)
    needle_vertices = np.zeros(n, dtype=bool)
    needle_vertices[good[needles].ravel()] = True
    if needles.any():
        good, cot = good[~needles], cot[~needles]
    angles = corner_angles(vertices, good)
    shares = mixed_voronoi_corner_areas(vertices, good)
    areas = np.bincount(good.ravel(), weights=shares.ravel(), minlength=n)

    stages.start("compute cotangent Laplacian")
    laplace = np.zeros((n, 3))
    for k in range(3):  # edge (j, m) opposite corner k, weighted by cot at k
        j, m = good[:, (k + 1) % 3], good[:, (k + 2) % 3]
        d = (vertices[m] - vertices[j]) * cot[:, k, None]
        for axis in range(3):
            laplace[:, axis] += np.bincount(j, weights=d[:, axis], minlength=n)
            laplace[:, axis] -= np.bincount(m, weights=d[:, axis], minlength=n)
    defect = 2 * np.pi - np.bincount(good.ravel(), weights=angles.ravel(), minlength=n)

    stages.start("retrieve curvatures")
    normals = vertex_normals(vertices, good)
    valid = ~defects.invalid_vertices & ~needle_vertices & np.isfinite(normals).all(axis=1) & (areas > 0)
    with np.errstate(invalid="ignore", divide="ignore"):
        mean = -np.einsum("ij,ij->i", laplace, normals) / (4 * areas)
        gaussian = defect / areas
    k_min, k_max = principal_from_mean_gaussian(mean, gaussian)
    directions = np.full((n, 3), np.nan)
    extra = (
        (
            f"{int(needles.sum())} needle faces (a corner angle that rounds to zero: a vertex far from its "
            "neighbours); their vertices have no cotangent Laplacian",
        )
        if needles.any()
        else ()
    )
    valid, staircase = staircase_undefined(mesh, defects, valid, stages=stages)
    noisy = noisy_rings(mesh, valid, _noise_gains(mesh, good, cot, areas)) if mesh.n_cracked else np.zeros_like(valid)
    valid &= ~noisy
    extra = (*extra, *staircase, noisy_rings_note(int(noisy.sum())))
    return finish("meyer", {}, valid, normals, k_min, k_max, directions, directions.copy(), defects, extra)


def _noise_gains(mesh: PreparedMesh, good: np.ndarray, cot: np.ndarray, areas: np.ndarray) -> np.ndarray:
    """(V,) each vertex's :data:`NOISE_GAIN` for its own ring: the spread ``sqrt(2 sum c^2 + (sum c)^2) / (4 A)``
    of its cotangent weights ``c`` (each face's share of an edge's: twice their squares bound the edges'), in units
    of ``l^2`` (the vertex's area times ``2 / sqrt(3)``), over that of a regular ring (``sqrt(56) / (2 sqrt(3))``):
    the fans of a uv sphere's poles, their cotangents large, amplify the scatter more than their area says."""
    n = mesh.vertices.shape[0]
    total, squares = np.zeros(n), np.zeros(n)
    for k in range(3):  # the weight cot at corner k of edge (j, m), at both ends
        for end in ((k + 1) % 3, (k + 2) % 3):
            total += np.bincount(good[:, end], weights=cot[:, k], minlength=n)
            squares += np.bincount(good[:, end], weights=cot[:, k] ** 2, minlength=n)
    regular = np.sqrt(56.0) / (2.0 * np.sqrt(3.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        spread = np.sqrt(2.0 * squares + total**2) / (4.0 * areas) * (mesh.vertex_areas * 2.0 / np.sqrt(3.0))
    return NOISE_GAIN * np.where(np.isfinite(spread), np.maximum(spread / regular, 1.0), 1.0)
