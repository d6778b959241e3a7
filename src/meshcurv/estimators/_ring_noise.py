"""Rings noisier than their curvature on a mesh welded across cracks: the ring methods leave them undefined.

A mesh whose faces were detached (a triangle soup whose corners were moved,
written with rounding, or faces moved one by one) is welded across its cracks
(:func:`meshcurv.weld.weld_vertices`): each group of copies becomes one of
them, so the welded vertices keep the scatter of the copies. On a fine mesh
that scatter is larger than what a ring of faces bends by: a vertex moved
``delta`` off the surface changes a 1-ring estimate of ``H`` by about ``2
delta / l^2`` (``l`` the ring's edge length), while the ring itself bends by
``k l^2 / 2``. At ``delta = 0.034 l`` on an icosphere of 16,002 vertices (``l
= 0.03`` on the unit sphere) that is more than ``H`` itself: ``meyer`` gave
108 of its 138 valid vertices off by more than half (issue 29, fuzz 400/109).

The scatter is read from the geometry: a quadric ``h = a u^2 + b u v + c
v^2 + d u + e v + f`` fitted by least squares over the vertex's closed
2-ring, in the frame of its normal, gives the noise ``sigma`` (its residual
per degree of freedom) and the curvature the ring should show (the largest
``|k|`` of the quadric, at least the mesh's scale: :data:`SIGNAL_QUANTILE`).
The ring estimate's noise is ``gain * sigma / l^2`` (``l^2`` from the
vertex's area); where it exceeds :data:`NOISE_SHARE` of that curvature the
vertex is undefined. Only meshes welded across cracks
are read, and on them only the vertices within two rings of a welded
vertex: a clean mesh (its creases fit no quadric) costs nothing.
"""

from __future__ import annotations

import numpy as np

from .._prepared import PreparedMesh
from ..radius import planes_voxel_grid

__all__ = ["NOISE_SHARE", "noisy_rings", "noisy_rings_note", "welded_grid", "welded_staircase", "welded_staircase_note"]

#: A ring whose estimate's noise is more than this share of the curvature its 2-ring's quadric shows is
#: undefined: an error above half of ``|k|`` is then more than three standard deviations away.
NOISE_SHARE = 0.15

#: The least number of points beyond the quadric's six coefficients that a 2-ring must hold to tell its noise
#: (fewer, or fewer points beyond the 1-ring than in it: the vertex is undefined on a mesh welded across cracks,
#: as its ring cannot be checked).
SPARE_POINTS = 3

#: The share of the checked rings whose curvature is at most the one a flat ring is judged against: the
#: mesh's curvature scale (the fuzzer's relation judges an error against the shape's largest ``|k|``).
SIGNAL_QUANTILE = 0.9

#: A method pooling ``N`` vertices' readings divides its noise gain by ``1 + POOLING (N - 1)``
#: (:func:`noisy_rings`'s ``pooled_steps``).
POOLING = 0.4


def noisy_rings(
    mesh: PreparedMesh,
    valid: np.ndarray,
    gain: float | np.ndarray,
    *,
    pooled_steps: int = 0,
    normals: np.ndarray | None = None,
    normal_gain: float = 0.0,
) -> np.ndarray:
    """(V,) bool: the ``valid`` vertices whose ring estimate is noisier than :data:`NOISE_SHARE` of the curvature.

    Parameters
    ----------
    mesh : PreparedMesh
        The mesh computed on.
    valid : ndarray of shape (V,), bool
        The vertices the method has an estimate for.
    gain : float or ndarray of shape (V,)
        The method's noise gain (each vertex's): its estimate of ``H`` moves by about ``gain * sigma / l^2`` for vertices
        scattered by ``sigma`` along the normal (``l^2`` the vertex's area times ``2 / sqrt(3)``).
    pooled_steps : int, default: 0
        The rings of ``valid`` vertices whose estimates the method pools (normal_cycle's smoothing): the gain is
        divided by ``1 + 0.4 (N - 1)``, ``N`` the ``valid`` vertices within that many rings (the noise of
        dihedral angles summed over a region partly cancels: measured 2.0, 0.40, 0.08, 0.04 times ``sigma / l^2``
        over 0, 1, 3, 5 rings of an icosphere soup).
    normals : ndarray of shape (V, 3), optional
        The vertex normals the method reads (rusinkiewicz: fitted ones at open fans). Their angles off the
        quadric's normals over the closed 1-ring, RMS ``theta``, add ``normal_gain * theta / l`` to the noise.
    normal_gain : float, default: 0
        The method's gain for the normals' noise.

    Returns
    -------
    ndarray of shape (V,), bool
        All False unless the mesh was welded across cracks (``mesh.n_cracked``).
    """
    n = mesh.vertices.shape[0]
    noisy = np.zeros(n, dtype=bool)
    if not mesh.n_cracked or mesh.index is None or not valid.any():
        return noisy
    import scipy.sparse as sp  # imported on use: keeps `import meshcurv` fast

    indptr, indices = mesh.topology.neighbour_lists
    own = np.arange(n)
    ring = sp.csr_matrix(  # the closed 1-rings
        (
            np.ones(indices.size + n),
            (np.concatenate([np.repeat(own, np.diff(indptr)), own]), np.concatenate([indices, own])),
        ),
        shape=(n, n),
    )
    welded = np.bincount(mesh.index, minlength=n) > 1  # copies joined here (exact or across a crack)
    near = ring @ (ring @ welded.astype(np.float64)) > 0  # within two rings of a welded vertex
    centres = np.flatnonzero(valid & near)
    if centres.size == 0:
        return noisy
    gain = np.broadcast_to(np.asarray(gain, dtype=np.float64), (n,))[centres]
    if pooled_steps > 0:  # the valid vertices within pooled_steps rings of each centre
        reach = ring[centres]
        for _ in range(pooled_steps - 1):
            reach = reach @ ring
            reach.data[:] = 1.0
        pooled = reach @ valid.astype(np.float64)
        gain = gain / (1.0 + POOLING * np.maximum(pooled - 1.0, 0.0))
    region = ring[centres] @ ring  # each centre's closed 2-ring
    region = region.tocoo()
    rows, columns = region.row.astype(np.int64), region.col.astype(np.int64)
    inner = np.asarray(ring[centres[rows], columns]).ravel() > 0  # in the closed 1-ring: what the estimate reads
    vertices = mesh.vertices
    frame = mesh.vertex_normals[centres]
    lengths_squared = mesh.vertex_areas[centres] * (2.0 / np.sqrt(3.0))
    first = np.cross(frame, np.where(np.abs(frame[:, :1]) < 0.9, [[1.0, 0.0, 0.0]], [[0.0, 1.0, 0.0]]))
    with np.errstate(invalid="ignore", divide="ignore"):
        first /= np.linalg.norm(first, axis=1, keepdims=True)
        scale = 1.0 / np.sqrt(lengths_squared)
    second = np.cross(frame, first)
    offsets = vertices[columns] - vertices[centres[rows]]
    u = np.einsum("ij,ij->i", offsets, first[rows]) * scale[rows]
    v = np.einsum("ij,ij->i", offsets, second[rows]) * scale[rows]
    h = np.einsum("ij,ij->i", offsets, frame[rows]) * scale[rows]  # heights in units of l
    monomials = np.column_stack([u * u, u * v, v * v, u, v, np.ones_like(u)])
    m = centres.size
    products = monomials[:, :, None] * monomials[:, None, :]
    normal_matrix = np.stack(
        [np.bincount(rows, weights=products[:, a, b], minlength=m) for a in range(6) for b in range(6)], axis=1
    ).reshape(m, 6, 6)
    right = np.stack([np.bincount(rows, weights=monomials[:, a] * h, minlength=m) for a in range(6)], axis=1)
    counts = np.bincount(rows, minlength=m)
    usable = np.asarray(np.isfinite(normal_matrix).all(axis=(1, 2)) & np.isfinite(right).all(axis=1))
    usable &= np.abs(np.linalg.det(np.where(usable[:, None, None], normal_matrix, np.eye(6)))) > 1e-12
    coefficients = np.zeros((m, 6))
    coefficients[usable] = np.linalg.solve(normal_matrix[usable], right[usable][:, :, None])[:, :, 0]
    residuals = h - np.einsum("ij,ij->i", monomials, coefficients[rows])
    spread = np.bincount(rows, weights=np.where(inner, residuals * residuals, 0.0), minlength=m)
    inner_counts = np.bincount(rows, weights=inner, minlength=m)
    # the quadric needs the 2-ring's outer points (at least as many as the 1-ring's neighbours: a fan welded alone,
    # among open fans, fits its own scatter as curvature) and spare ones to tell its scatter
    usable &= (counts >= 6 + SPARE_POINTS) & (counts - inner_counts >= inner_counts - 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        # the closed 1-ring's scatter off the 2-ring's quadric (its residuals shrunk by the fit's 6 coefficients)
        sigma = np.sqrt(spread / (inner_counts * np.maximum(1.0 - 6.0 / counts, 1.0 / counts)))  # in units of l
    a, b, c = coefficients[:, 0], coefficients[:, 1], coefficients[:, 2]
    length = np.sqrt(lengths_squared)
    noise = gain * sigma / length
    if normals is not None and normal_gain > 0:
        theta = _normal_scatter(normals, columns, rows, inner, u, v, (first, second, frame), coefficients, m)
        noise = np.hypot(noise, normal_gain * theta / length)
    with np.errstate(invalid="ignore", divide="ignore"):
        curvature = (np.abs(a + c) + np.sqrt((a - c) ** 2 + b * b)) / length  # the quadric's largest |k|
        # a flat part's rings are judged against the mesh's curvature (its rings' SIGNAL_QUANTILE): an error
        # small beside that is small, as on a plane of a CAD part
        known = curvature[usable & np.isfinite(curvature)]
        floor = float(np.quantile(known, SIGNAL_QUANTILE)) if known.size else 0.0
        # the estimate's noise gain * sigma / l^2 against NOISE_SHARE of the curvature
        noisy[centres] = ~usable | ~(noise <= NOISE_SHARE * np.maximum(curvature, floor))
    return noisy


def _normal_scatter(normals, columns, rows, inner, u, v, axes, coefficients, m) -> np.ndarray:
    """(M,) the RMS angle (radians) between ``normals`` at the closed 1-rings' vertices and the normals of their
    centres' quadrics there (either sign: the frames' normals are the mesh's)."""
    first, second, frame = axes
    slope_u = 2 * coefficients[rows, 0] * u + coefficients[rows, 1] * v + coefficients[rows, 3]
    slope_v = coefficients[rows, 1] * u + 2 * coefficients[rows, 2] * v + coefficients[rows, 4]
    fitted = frame[rows] - slope_u[:, None] * first[rows] - slope_v[:, None] * second[rows]
    given = normals[columns]
    across = np.linalg.norm(np.cross(fitted, given), axis=1)
    along = np.abs(np.einsum("ij,ij->i", fitted, given))
    with np.errstate(invalid="ignore"):
        angles = np.arctan2(across, along)
    angles = np.where(inner, angles, 0.0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.sqrt(
            np.bincount(rows, weights=angles * angles, minlength=m) / np.bincount(rows, weights=inner, minlength=m)
        )


def welded_grid(mesh: PreparedMesh, valid: np.ndarray):
    """``(grid, on_planes)`` of the ``valid`` vertices ((V,) bool) of a mesh welded across cracks, where most of them
    lie on a voxel grid's planes in any pose (:func:`meshcurv.radius.planes_voxel_grid`, as ``quadric`` reads a voxel
    soup), else None.

    A voxel surface with faces detached by a few hundredths of an edge and welded back across the cracks keeps
    its staircase, but the vertices welded from detached copies only are off the grid by the cracks' width, so
    that neither the mesh nor its faces with a valid corner read as one (the rules of
    :func:`meshcurv.radius._voxel_surface_grid` that :func:`._support.staircase_undefined` reads): its vertices
    that kept their place still have two coordinates on the grid's planes. A ring of faces reads the steps as
    curvature (``voxel_sphere(10)``, half its faces detached by 0.03 edges: ``rusinkiewicz`` 2,272 of 3,661 valid
    vertices off the sphere's H by more than half of it, issue 29).
    """
    if not mesh.n_cracked or not valid.any():
        return None
    # a grid turned off the coordinate axes: in the frame of the faces' sides (the intact faces' lie in the voxels'
    # faces), where the coordinates of a plane repeat again (turned by a rotation, ``voxel_sphere(10)`` half detached
    # by 0.03 edges: ``rusinkiewicz`` 2,199 of 3,698 valid vertices off)
    return planes_voxel_grid(mesh.vertices, mesh.topology.faces, (valid,))[0]


def welded_staircase(mesh: PreparedMesh, valid: np.ndarray) -> tuple[np.ndarray, tuple[str, ...]]:
    """``(valid, extra)``: on a mesh welded across cracks whose faces away from the welds lie on a voxel grid
    (:func:`welded_grid`), every vertex undefined, with the phrase that counts them; else ``valid`` as given and
    no phrase."""
    if welded_grid(mesh, valid) is None:
        return valid, ()
    return np.zeros_like(valid), (welded_staircase_note(int(valid.sum())),)


def welded_staircase_note(count: int) -> str:
    """The warning's phrase for ``count`` vertices of :func:`welded_staircase`."""
    return (
        f"{count} vertices of this voxel surface are NaN (estimate undefined): it was welded across cracks between "
        "detached faces, and its faces away from the cracks lie on a voxel grid: a ring of faces reads the voxels' "
        "staircase as curvature"
    )


def noisy_rings_note(count: int) -> str:
    """The warning's phrase for ``count`` vertices of :func:`noisy_rings` ('' for none)."""
    if not count:
        return ""
    return (
        f"{count} vertices are NaN (estimate undefined): the mesh was welded across cracks between detached faces, "
        "and their rings are scattered by more than the curvature they resolve (a ring method reads the scatter as "
        "curvature; the methods over balls, 'icc' or 'quadric', average it out)"
    )
