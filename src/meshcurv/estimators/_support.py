"""What the estimators share: stage reporting, NaN rows, and the assembly of their result."""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np

from ..defects import VertexDefects
from ..radius import VoxelReading, _voxel_surface
from ..result import CurvatureResult
from ._ring_noise import welded_staircase

logger = logging.getLogger("meshcurv")

#: A progress callback: ``progress(stage, index, total)`` with 1-based ``index``.
ProgressCallback = Callable[[str, int, int], None]


class Stages:
    """Announce the stages of a computation on the ``meshcurv`` logger and to a callback.

    Parameters
    ----------
    names : sequence of str
        The stages, in order.
    progress : callable, optional
        Called as ``progress(stage, index, total)`` when each stage starts.

    Attributes
    ----------
    voxel : VoxelReading
        The call's reading of its mesh's voxel grid (:class:`meshcurv.radius.VoxelReading`), made once and handed
        from the default radius to the estimator and to the warning's sentence on the staircase.
    voxel_default : bool
        True when the ``radius`` handed to the estimator is the default of a voxel surface
        (:func:`meshcurv.radius.voxel_surface_radius`), not one the caller gave.
    """

    def __init__(self, names, progress: ProgressCallback | None = None):
        self.names = tuple(names)
        self.progress = progress
        self.voxel = VoxelReading()
        self.voxel_default = False

    def start(self, name: str) -> None:
        index = self.names.index(name) + 1
        logger.info("%s (%d/%d)", name, index, len(self.names))
        if self.progress is not None:
            self.progress(name, index, len(self.names))


def ball_holds_neighbours(vertices: np.ndarray, cells: np.ndarray, radii, *, every: bool = False) -> np.ndarray:
    """(V,) bool: the vertices whose ball holds one of their neighbours (every one, with ``every``).

    A ball that holds none of the vertex's neighbours (a given radius below
    its shortest edge) holds only its own corner, the cone of the polyhedron
    at the vertex, not the surface: normal_cycle_ball leaves such a vertex
    undefined (issue 29: a radius of 0.07 edge lengths gave valid curvatures
    off by more than half at 42% of a sphere's vertices).

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
    cells : ndarray of shape (C, 2) or (C, 3)
        Edges, or triangles (their three sides).
    radii : float or ndarray of shape (V,)
        The radius of each vertex's ball.
    every : bool, default: False
        True: the vertices whose ball holds all their neighbours (every edge
        at the vertex shorter than its radius; True for a vertex in no cell).

    Returns
    -------
    ndarray of shape (V,), bool
    """
    n = vertices.shape[0]
    radii = np.broadcast_to(np.asarray(radii, dtype=float), (n,))
    held = np.full(n, every, dtype=bool)
    k = cells.shape[1]
    for corner in range(1 if k == 2 else k):
        first, second = cells[:, corner], cells[:, (corner + 1) % k]
        lengths = np.linalg.norm(np.take(vertices, second, axis=0) - np.take(vertices, first, axis=0), axis=1)
        if every:
            held[first[lengths >= radii[first]]] = False
            held[second[lengths >= radii[second]]] = False
        else:
            held[first[lengths < radii[first]]] = True
            held[second[lengths < radii[second]]] = True
    return held


def failed_fits_undefined(vertices: np.ndarray, faces: np.ndarray, radii, failed: np.ndarray) -> np.ndarray:
    """(V,) bool: the vertices left without fitted normals in a ball inside their star: undefined.

    A method that interpolates fitted normals over its faces (icc) has, where
    a fit failed, only the mean of the face normals, whose error of order one
    edge turns into curvatures off by the whole curvature when the ball lies
    inside the star of the vertex (issue 29: icc at a given radius of
    0.07-0.35 edge lengths, whose normal fits over three radii held too few
    points, gave valid values off by more than half at 5-20% of a random
    sphere's vertices). Such a vertex is one whose fit failed, or that shares
    a face with one whose fit did, and whose ball does not hold all its
    neighbours; a ball over the whole star averages the face normals' errors
    out (a double cone's apexes, where no fit is possible, keep their
    symmetric estimate).

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3)
    radii : float or ndarray of shape (V,)
        The radius of each vertex's ball.
    failed : ndarray of shape (V,), bool
        The vertices where no fit was possible.

    Returns
    -------
    ndarray of shape (V,), bool
    """
    near = np.array(failed, dtype=bool, copy=True)
    if not near.any():
        return near
    near[faces[failed[faces].any(axis=1)].ravel()] = True
    return near & ~ball_holds_neighbours(vertices, faces, radii, every=True)


def nan_where(invalid: np.ndarray, *arrays: np.ndarray) -> None:
    """Set the rows of ``arrays`` selected by ``invalid`` to NaN, in place."""
    for array in arrays:
        array[invalid] = np.nan


def finish(
    method: str,
    parameters: dict,
    valid: np.ndarray,
    normals: np.ndarray,
    k_min,
    k_max,
    dir_min,
    dir_max,
    defects: VertexDefects,
    extra: tuple[str, ...] = (),
    radius: np.ndarray | None = None,
):
    """NaN where invalid, the one result, and the problem list for the one warning.

    ``radius``: the (V,) radius of each vertex's ball (the methods over balls).
    """
    valid = valid & np.isfinite(k_min) & np.isfinite(k_max)
    nan_where(~valid, k_min, k_max, dir_min, dir_max)
    # the estimators' own arrays, taken without copies (88 bytes per vertex)
    result = CurvatureResult._of_arrays(
        k_min=k_min,
        k_max=k_max,
        dir_min=dir_min,
        dir_max=dir_max,
        normals=normals,
        valid=valid,
        method=method,
        parameters=parameters,
        radius=radius,
    )
    return result, problems(defects, valid, extra)


def staircase_undefined(
    mesh, defects: VertexDefects, valid: np.ndarray, *, stages: Stages | None = None
) -> tuple[np.ndarray, tuple[str, ...]]:
    """``(valid, extra)`` of a method over a ring of faces with no scale (``rusinkiewicz``, ``meyer``): on a voxel
    surface (:func:`meshcurv.radius._voxel_surface`) every vertex undefined, with the phrase that counts them.

    A marching-cubes staircase is a pattern of one voxel that a ring of faces reads as curvature: on the intact
    voxel meshes of ``benchmarks/voxel_ring_methods.md`` 55-95% of ``rusinkiewicz``'s valid vertices and 80-100%
    of ``meyer``'s were off the exact H by more than half of the largest ``|k|`` (median errors 77-1130%), every
    one of them valid (issue 29: never a valid wrong number). Neither has a scale to grow; the call's warning
    names the methods whose balls are scaled to the voxels (:func:`meshcurv.curvature._staircase_note`), which
    takes the grid read here from ``stages`` (:class:`Stages`; read again without it). A voxel surface welded back
    across cracks, no longer read as one, is undefined the same way where its vertices away from the welds lie on a
    grid (:func:`._ring_noise.welded_staircase`).
    """
    if not valid.any():
        return valid, ()
    if not _voxel_surface(mesh, defects.invalid_vertices, reading=None if stages is None else stages.voxel):
        return welded_staircase(mesh, valid)
    return np.zeros_like(valid), (f"{int(valid.sum())} vertices of this voxel surface are NaN (estimate undefined)",)


def on_staircase(mesh, defects: VertexDefects, valid: np.ndarray, *, stages: Stages | None = None) -> bool:
    """True where :func:`staircase_undefined` leaves every vertex undefined: a voxel surface, or a mesh welded
    across cracks whose faces away from the welds lie on a voxel grid (and ``valid`` has a vertex to lose).

    ``matgeom`` reads it to mark its vertices ``valid=False`` while keeping matGeom's numbers
    (:func:`meshcurv.estimators.matgeom.estimate`)."""
    undefined, _ = staircase_undefined(mesh, defects, valid, stages=stages)
    return bool(valid.any()) and not undefined.any()


def problems(defects: VertexDefects, valid: np.ndarray, extra=()) -> list[str]:
    """The phrases of the call's warning: the defects the method met, its own notes, the vertices left NaN."""
    found = defects.messages() + [m for m in extra if m]
    n_invalid = int((~valid).sum())
    if n_invalid:
        found.append(f"{n_invalid} vertices are NaN with valid=False")
    return found
