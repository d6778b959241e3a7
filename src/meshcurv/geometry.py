"""Geometric quantities of triangle meshes, as pure functions over arrays.

Inputs are float64 ``vertices`` of shape (V, 3) and int64 ``faces`` of shape
(F, 3) (0-based); outputs are new float64 arrays. Nothing here validates its
input: the public entry points do that once (:mod:`meshcurv._validation`).
"""

from __future__ import annotations

import numpy as np

from ._backend import numba_kernels

__all__ = [
    "face_cross_products",
    "face_areas",
    "face_normals",
    "signed_volume",
    "vertex_areas",
    "vertex_normals",
    "edge_lengths",
    "vertex_edge_lengths",
    "mean_edge_length",
    "degenerate_face_mask",
    "corner_cotangents",
    "corner_angles",
    "mixed_voronoi_corner_areas",
]

#: Faces with area below this fraction of (mean edge length)^2 count as degenerate.
DEGENERATE_AREA_RATIO = 1e-12


def face_cross_products(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3) ``cross(b - a, c - a)`` for every face ``(a, b, c)``: twice the area times the unit normal.

    Written out component by component (faster than :func:`numpy.cross`, same values).
    """
    kernels = numba_kernels()
    if kernels is not None:
        return kernels.face_cross_products(vertices, faces)
    a = vertices[faces[:, 0]]
    u = vertices[faces[:, 1]] - a
    w = vertices[faces[:, 2]] - a
    return np.stack(
        [u[:, 1] * w[:, 2] - u[:, 2] * w[:, 1], u[:, 2] * w[:, 0] - u[:, 0] * w[:, 2],
         u[:, 0] * w[:, 1] - u[:, 1] * w[:, 0]],
        axis=1,
    )


def face_areas(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F,) area of every face."""
    return 0.5 * np.linalg.norm(face_cross_products(vertices, faces), axis=1)


def face_normals(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3) unit normal of every face, by the right-hand rule on its vertex order.

    A face with zero area has no normal: its row is NaN.
    """
    cross = face_cross_products(vertices, faces)
    norm = np.linalg.norm(cross, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(norm > 0, cross / norm, np.nan)


def signed_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    """Signed volume enclosed by the faces (positive for a closed, outward-wound mesh).

    Computed relative to the centroid of the vertices, which reduces rounding and
    makes the value independent of translation on closed meshes.
    """
    centred = vertices - vertices.mean(axis=0)
    a, b, c = (centred[faces[:, k]] for k in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def vertex_areas(vertices: np.ndarray, faces: np.ndarray, *, areas: np.ndarray | None = None) -> np.ndarray:
    """(V,) barycentric vertex areas: a third of the area of every incident face.

    They sum to the total area of the mesh; an unreferenced vertex gets 0.
    """
    if areas is None:
        areas = face_areas(vertices, faces)
    return np.bincount(faces.ravel(), weights=np.repeat(areas / 3.0, 3), minlength=vertices.shape[0])


def vertex_normals(vertices: np.ndarray, faces: np.ndarray, *, cross: np.ndarray | None = None) -> np.ndarray:
    """(V, 3) unit vertex normals, the area-weighted mean of the incident face normals.

    Oriented like the faces (outward on an outward-wound closed mesh). A vertex
    with no incident face of non-zero area, or whose face normals cancel, is NaN.
    """
    if cross is None:
        cross = face_cross_products(vertices, faces)
    n = vertices.shape[0]
    kernels = numba_kernels()
    if kernels is not None:
        return normalize_normal_sums(kernels.vertex_normal_sums(cross, faces, n))
    flat = faces.ravel()
    summed = np.stack(
        [np.bincount(flat, weights=np.repeat(cross[:, k], 3), minlength=n) for k in range(3)], axis=1
    )
    return normalize_normal_sums(summed)


def normalize_normal_sums(summed: np.ndarray) -> np.ndarray:
    """Unit vectors from (V, 3) sums of face cross products; NaN where they (nearly) cancel."""
    norm = np.linalg.norm(summed, axis=1, keepdims=True)
    scale = np.abs(summed).max(axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(norm > 1e-12 * np.maximum(scale, np.finfo(float).tiny), summed / norm, np.nan)


def edge_lengths(vertices: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(E,) length of each of the given (E, 2) edges."""
    d = vertices[edges[:, 1]] - vertices[edges[:, 0]]
    return np.sqrt(np.einsum("ij,ij->i", d, d))


def vertex_edge_lengths(vertices: np.ndarray, edges: np.ndarray) -> np.ndarray:
    """(V,) mean length of the given (E, 2) edges at each vertex: the local resolution (NaN where none)."""
    n = vertices.shape[0]
    kernels = numba_kernels()
    if kernels is not None:
        return kernels.vertex_edge_lengths(vertices, edges, n)
    flat = edges.ravel()
    with np.errstate(invalid="ignore", divide="ignore"):
        return (np.bincount(flat, weights=np.repeat(edge_lengths(vertices, edges), 2), minlength=n)
                / np.bincount(flat, minlength=n))


def mean_edge_length(vertices: np.ndarray, edges: np.ndarray) -> float:
    """Mean length of the given (E, 2) edges (0 when there are none)."""
    if edges.shape[0] == 0:
        return 0.0
    kernels = numba_kernels()
    if kernels is not None:
        return float(kernels.mean_edge_length(vertices, edges))
    return float(edge_lengths(vertices, edges).mean())


def degenerate_face_mask(areas: np.ndarray, length_scale: float) -> np.ndarray:
    """(F,) bool: faces whose area is negligible relative to ``length_scale ** 2``."""
    return areas <= DEGENERATE_AREA_RATIO * length_scale**2


def corner_cotangents(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3) cotangent of the angle at each corner of every face.

    ``cot = (a . b) / |a x b|`` for the two edge vectors ``a, b`` leaving the
    corner; NaN on zero-area faces.
    """
    out = np.zeros(faces.shape, dtype=np.float64)
    for k in range(3):
        p = vertices[faces[:, k]]
        a = vertices[faces[:, (k + 1) % 3]] - p
        b = vertices[faces[:, (k + 2) % 3]] - p
        with np.errstate(invalid="ignore", divide="ignore"):
            out[:, k] = np.einsum("ij,ij->i", a, b) / np.linalg.norm(np.cross(a, b), axis=1)
    return out


def corner_angles(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3) interior angle at each corner of every face, in radians (0 on zero-area faces)."""
    out = np.zeros(faces.shape, dtype=np.float64)
    for k in range(3):
        p = vertices[faces[:, k]]
        a = vertices[faces[:, (k + 1) % 3]] - p
        b = vertices[faces[:, (k + 2) % 3]] - p
        out[:, k] = np.arctan2(np.linalg.norm(np.cross(a, b), axis=1), np.einsum("ij,ij->i", a, b))
    return out


def mixed_voronoi_corner_areas(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(F, 3) the share of each face in the mixed Voronoi area of each of its corners.

    Meyer, Desbrun, Schroeder and Barr (2003), Fig. 4: on a non-obtuse triangle
    the Voronoi region of corner ``i``, ``(|e_ij|^2 cot k + |e_ik|^2 cot j) / 8``;
    on an obtuse one, half the area for the obtuse corner and a quarter for the
    other two. The shares of a face sum to its area; summed per vertex
    (``np.bincount(faces.ravel(), shares.ravel())``) they tile the surface.
    https://doi.org/10.1007/978-3-662-05105-4_2
    """
    cot = corner_cotangents(vertices, faces)
    area = face_areas(vertices, faces)
    squared = np.zeros(faces.shape, dtype=np.float64)  # squared length of the side opposite corner k
    for k in range(3):
        d = vertices[faces[:, (k + 2) % 3]] - vertices[faces[:, (k + 1) % 3]]
        squared[:, k] = np.einsum("ij,ij->i", d, d)
    voronoi = np.zeros(faces.shape, dtype=np.float64)
    for k in range(3):
        j, m = (k + 1) % 3, (k + 2) % 3
        # sides at corner k: k-j (opposite m) and k-m (opposite j)
        voronoi[:, k] = (squared[:, m] * cot[:, m] + squared[:, j] * cot[:, j]) / 8.0
    obtuse_corner = cot < 0
    obtuse = obtuse_corner.any(axis=1)
    mixed = np.where(obtuse[:, None], np.where(obtuse_corner, area[:, None] / 2, area[:, None] / 4), voronoi)
    return np.where(np.isfinite(mixed), mixed, 0.0)
