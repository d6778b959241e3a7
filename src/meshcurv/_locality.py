"""Memory locality of a mesh's vertex order: a mesh in a scattered order is computed in a local one.

Every ball of the estimators is walked over the mesh's neighbours, so the
vertices near each other on the surface should be near each other in memory.
A mesh whose vertices come in a scattered order (a decimation tool's priority
order, an export sorted by another key, a shuffle) reads a new cache line for
almost every neighbour: ``icc`` on a shuffled icosphere of a million vertices
takes six times as long as on the same mesh in its own order, four times at
100,000 vertices. Such a mesh is computed with its vertices in the Morton
(Z-) order of their coordinates and its faces sorted by their first vertex in
that order (:func:`reordering`), and the results are put back in the caller's order: the numbers
of the mesh in a local order, up to the order of floating-point sums and of
the samples that estimators take in index order (``icc``'s noise level).

A mesh counts as scattered (:func:`is_scattered`) when the median, over its
faces, of the smallest index difference along a side exceeds
:data:`SPAN_LIMIT`. Orders that are local in one direction (rows of a grid,
the slices of marching cubes, an icosphere's triangles) keep one side of
every face short however far apart their rows are (a median of 1), and they
measure as fast as the Morton order. A shuffle within blocks of 256 vertices
(a median of 35-55) makes ``icc`` 17-22% slower at 100,000 and 1M vertices,
one within blocks of 4,096 (about 440) 60%, a whole shuffle six times
at 1M (``benchmarks/order.md``); the reordering costs about a tenth of the
computation.
"""

from __future__ import annotations

import dataclasses
import logging

import numpy as np

from ._backend import twin
from .topology import MeshTopology

logger = logging.getLogger(__name__)

#: A mesh is scattered when the median over its faces of the smallest index difference
#: along a side exceeds this ...
SPAN_LIMIT = 32

#: ... and it has at least this many vertices (a smaller mesh stays in the caches).
MIN_VERTICES = 32768

#: The span is measured on at most this many faces, evenly spaced.
SPAN_SAMPLE = 65536

#: Bits of each coordinate in the Morton codes (three of them in 63 bits).
_BITS = 21

#: The shifts and masks that move bit ``i`` of a 21-bit number to bit ``3 i``.
_SPREAD = (
    (32, 0x1F00000000FFFF),
    (16, 0x1F0000FF0000FF),
    (8, 0x100F00F00F00F00F),
    (4, 0x10C30C30C30C30C3),
    (2, 0x1249249249249249),
)


@dataclasses.dataclass(frozen=True)
class Reordering:
    """A local order of a mesh's vertices and faces, and the way back.

    ``vertices`` (V, 3) and ``faces`` (F, 3) are the mesh in the new order:
    new vertex ``k`` is the caller's vertex ``order[k]``, new face ``j`` the
    caller's face ``face_order[j]`` (its corners renumbered); ``index`` (V,)
    is the new row of each of the caller's vertices (``index[order] = arange(V)``).
    """

    order: np.ndarray
    index: np.ndarray
    face_order: np.ndarray
    vertices: np.ndarray
    faces: np.ndarray

    def original_faces(self, faces: np.ndarray) -> np.ndarray:
        """(F, 3) faces of the new order (the same rows, possibly reversed) in the caller's rows and numbering."""
        rows = np.empty_like(self.face_order)
        rows[self.face_order] = np.arange(rows.size)
        return np.take(self.order[faces], rows, axis=0)  # take: several times faster than indexing rows


def median_side_span(faces: np.ndarray) -> int:
    """Median over (at most :data:`SPAN_SAMPLE`, evenly spaced) (F, 3) ``faces`` of the smallest index
    difference along their sides."""
    if faces.shape[0] == 0:
        return 0
    if faces.shape[0] > SPAN_SAMPLE:
        faces = faces[np.linspace(0, faces.shape[0] - 1, SPAN_SAMPLE).round().astype(np.int64)]
    sides = np.abs(faces - np.roll(faces, 1, axis=1))
    return int(np.median(sides.min(axis=1)))


def is_scattered(n_vertices: int, faces: np.ndarray) -> bool:
    """Whether a mesh of ``n_vertices`` and (F, 3) ``faces`` is large and in a scattered order (see the module)."""
    return n_vertices >= MIN_VERTICES and median_side_span(faces) > SPAN_LIMIT


def reordering(vertices: np.ndarray, faces: np.ndarray) -> Reordering | None:
    """The (V, 3) ``vertices`` in the order of their Morton codes (Z-order on a grid of ``2**21``
    cells along the longest side of the bounding box; stable) and the (F, 3) ``faces`` renumbered
    and sorted by their smallest new corner (stable). None when the bounding box is wider than
    the float range (no codes of overflowed coordinates)."""
    n = vertices.shape[0]
    with np.errstate(over="ignore", invalid="ignore"):
        lo = vertices.min(axis=0) if n else np.zeros(3)
        extent = float((vertices.max(axis=0) - lo).max()) if n else 0.0
    if not np.isfinite(extent):
        return None
    scale = (2**_BITS - 1) / extent if extent > 0 else 0.0
    return Reordering(*morton_reordering(vertices, faces, lo, scale, _BITS, np.array(_SPREAD, dtype=np.uint64)))


@twin("locality")
def morton_reordering(
    vertices: np.ndarray, faces: np.ndarray, lo: np.ndarray, scale: float, bits: int, spread: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """The fields of :class:`Reordering`: the vertices in the order of their Morton codes (``bits`` bits
    per axis of ``(x - lo) * scale``, spread to every third bit by the (steps, 2) uint64 ``(shift, mask)``
    rows of ``spread``; stable), the faces renumbered and sorted by their smallest new corner (stable)."""
    n = vertices.shape[0]
    codes = np.zeros(n, dtype=np.uint64)
    for axis in range(3):
        x = ((vertices[:, axis] - lo[axis]) * scale).astype(np.uint64) & np.uint64(2**bits - 1)
        for shift, mask in spread:
            x = (x | (x << shift)) & mask
        codes |= x << np.uint64(axis)
    order = np.argsort(codes, kind="stable")
    index = np.empty_like(order)
    index[order] = np.arange(n)
    renumbered = index[faces]
    face_order = np.argsort(renumbered.min(axis=1), kind="stable")
    return order, index, face_order, np.take(vertices, order, axis=0), np.take(renumbered, face_order, axis=0)


def local_topology(
    vertices: np.ndarray, faces: np.ndarray | MeshTopology, *, scattered: bool | None = None
) -> tuple[np.ndarray, MeshTopology, Reordering | None]:
    """``(vertices, topology, reordering)``: the topology of the checked (F, 3) triangles ``faces`` (or the
    given :class:`MeshTopology`, its vertex count checked), in a local order (:func:`reordering`) when the
    mesh is scattered (:func:`is_scattered`; ``scattered``: its answer when the caller found it, None: found
    here).

    ``reordering`` is None, and ``vertices`` the caller's, for a mesh in a local order; otherwise
    ``vertices`` and the topology are those of the new order (a given :class:`MeshTopology` is
    rebuilt for it).
    """
    n = vertices.shape[0]
    if isinstance(faces, MeshTopology):
        topology = faces.for_vertices(n)
        triangles = topology.faces
    else:
        topology = None
        triangles = faces
    if scattered is None:
        scattered = is_scattered(n, triangles)
    local = reordering(vertices, triangles) if scattered else None
    if local is None:  # a local order (or a bounding box wider than the float range): as given
        return vertices, topology if topology is not None else MeshTopology._build(triangles, n), None
    logger.info(
        "the vertices come in a scattered order (median index difference along a face's shortest "
        "side: %d): computed in their Morton order",
        median_side_span(triangles),
    )
    return local.vertices, MeshTopology._build(local.faces, n), local
