"""Small symmetric tensors stored as six components, and closed-form tangent eigen-solutions.

A symmetric 3x3 tensor is stored as ``(xx, yy, zz, xy, xz, yz)`` along the last
axis: six numbers instead of nine, and no (N, 3, 3) temporaries.
"""

from __future__ import annotations

import numpy as np

from ._backend import twin

__all__ = ["outer6", "apply6", "tangent_basis", "principal_from_shape_operator", "principal_from_mean_gaussian"]


def principal_from_mean_gaussian(mean: np.ndarray, gaussian: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """``k_min, k_max = H -/+ sqrt(max(H^2 - K, 0))`` without overflow.

    ``H`` and ``K`` are scaled by the power of two just above ``max(|H|, sqrt|K|)``
    before squaring (exact: the same numbers wherever ``H^2`` is a normal
    float), so that the curvatures of a mesh at 1e-200 (about 1e200) are
    finite rather than infinite. NaN where ``H`` or ``K`` is NaN or infinite.
    """
    mean, gaussian = np.asarray(mean, dtype=np.float64), np.asarray(gaussian, dtype=np.float64)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        size = np.maximum(np.abs(mean), np.sqrt(np.abs(gaussian)))
        _, exponent = np.frexp(np.where(np.isfinite(size) & (size > 0), size, 1.0))
        scale = np.ldexp(1.0, exponent)
        h, k = mean / scale, gaussian / scale / scale
        half = scale * np.sqrt(np.maximum(h * h - k, 0.0))
        half = np.where(np.isfinite(mean) & np.isfinite(gaussian), half, np.nan)
        return mean - half, mean + half


def outer6(u: np.ndarray, weights: np.ndarray | None = None) -> np.ndarray:
    """(N, 6) components of ``w * u u^T`` for (N, 3) vectors ``u``."""
    x, y, z = u[:, 0], u[:, 1], u[:, 2]
    out = np.stack([x * x, y * y, z * z, x * y, x * z, y * z], axis=1)
    if weights is not None:
        out *= weights[:, None]
    return out


def apply6(tensor: np.ndarray, u: np.ndarray) -> np.ndarray:
    """(N, 3) product ``T u`` for (N, 6) tensors and (N, 3) vectors."""
    xx, yy, zz, xy, xz, yz = tensor.T
    x, y, z = u.T
    return np.stack([xx * x + xy * y + xz * z, xy * x + yy * y + yz * z, xz * x + yz * y + zz * z], axis=1)


def tangent_basis(normals: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Two (N, 3) unit vectors ``t1, t2`` with ``(t1, t2, n)`` a right-handed orthonormal frame."""
    axis = np.zeros_like(normals)
    smallest = np.argmin(np.abs(normals), axis=1)
    axis[np.arange(normals.shape[0]), smallest] = 1.0
    t1 = np.cross(normals, axis)
    with np.errstate(invalid="ignore", divide="ignore"):
        t1 /= np.linalg.norm(t1, axis=1, keepdims=True)
    t2 = np.cross(normals, t1)
    return t1, t2


@twin("tensors")
def principal_from_shape_operator(
    tensor: np.ndarray, normals: np.ndarray, *, rotate: bool = False, mean_from_trace: bool = False
):
    """Principal curvatures and directions from (N, 6) tensors restricted to the tangent planes.

    The tensor is restricted to the plane orthogonal to each unit normal and its
    2x2 eigen-problem is solved in closed form.

    Parameters
    ----------
    tensor : ndarray of shape (N, 6)
        A shape operator (``u^T S u`` = normal curvature along ``u``), or, with
        ``rotate=True``, a normal-cycle tensor, whose eigenvector of eigenvalue
        ``k`` is orthogonal (in the tangent plane) to the direction of curvature
        ``k`` (an edge across which the surface bends has its bending along the
        edge's normal, not along the edge).
    normals : ndarray of shape (N, 3)
        Unit normals.
    rotate : bool, default: False
        Turn the eigenvectors by 90 degrees in the tangent plane.
    mean_from_trace : bool, default: False
        Take the mean of the two curvatures as half the trace of the full 3x3
        tensor rather than of its tangent restriction. For a normal-cycle
        tensor the trace is the mean-curvature measure, which no tilt of the
        tangent planes inside the region changes; the restriction alone loses
        the part of the measure that leans out of the vertex's tangent plane.

    Returns
    -------
    k_min, k_max : ndarray of shape (N,)
    dir_min, dir_max : ndarray of shape (N, 3)
    """
    t1, t2 = tangent_basis(normals)
    s1 = apply6(tensor, t1)
    a = np.einsum("ij,ij->i", t1, s1)
    b = np.einsum("ij,ij->i", t2, s1)
    c = np.einsum("ij,ij->i", t2, apply6(tensor, t2))
    half_sum = 0.5 * (a + c)
    if mean_from_trace:
        half_sum = 0.5 * (tensor[:, 0] + tensor[:, 1] + tensor[:, 2])
    half_diff = 0.5 * (a - c)
    radius = np.hypot(half_diff, b)
    theta = 0.5 * np.arctan2(b, half_diff)
    cos, sin = np.cos(theta)[:, None], np.sin(theta)[:, None]
    along = cos * t1 + sin * t2  # eigenvector of the larger eigenvalue
    across = -sin * t1 + cos * t2  # eigenvector of the smaller eigenvalue
    if rotate:
        along, across = across, along
    return half_sum - radius, half_sum + radius, across, along
