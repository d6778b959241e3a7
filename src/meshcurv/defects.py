"""The defects of a mesh that leave a vertex's curvature undefined: one table, one code per vertex.

Each defect has a code (the value of ``CurvatureResult.invalid_reason`` at the
vertices it makes invalid), the sentence a user reads for such a vertex
(:data:`INVALID_REASONS`) and the phrase the call's one warning uses to count
it. A vertex gets the code of the first defect that applies to it, in the
order of :data:`DEFECTS`; a vertex that is invalid for no defect of the mesh
(too few neighbours in its ball, a failed fit) gets :data:`UNDEFINED`.

The codes are computed once per call (:func:`defect_codes`); each estimator
says which defects it copes with (``tolerates`` of
:class:`meshcurv.estimators.Estimator`: the methods over balls keep boundary
vertices), and :class:`VertexDefects` gives the vertices it must leave
undefined and the phrases of its warning.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .topology import MeshTopology

__all__ = ["Defect", "DEFECTS", "POINT_CLOUD_REASONS", "INVALID_REASONS", "UNDEFINED", "BOUNDARY", "VertexDefects",
           "defect_codes"]


@dataclass(frozen=True)
class Defect:
    """One kind of defect.

    Attributes
    ----------
    code : int
        Its code in ``CurvatureResult.invalid_reason``.
    name : str
        Its name in the counts (``"boundary_edges"``: what is counted, edges, faces or vertices).
    reason : str
        Why a vertex it touches is invalid (:data:`INVALID_REASONS`).
    counted : str
        The warning's phrase after the count (``"12 zero-area faces"``).
    """

    code: int
    name: str
    reason: str
    counted: str


#: The defects, in the order in which a vertex takes the first that applies.
DEFECTS = (
    Defect(1, "unreferenced_vertices", "unreferenced vertex (in no face)", "unreferenced vertices"),
    Defect(2, "nonmanifold_edges", "on a non-manifold edge (3+ faces)", "non-manifold edges (3+ faces)"),
    Defect(3, "bowtie_vertices", "bow-tie vertex (fans of faces meeting at a point)",
           "bow-tie vertices (fans meeting at a point)"),
    Defect(4, "inconsistent_edges", "on an edge between inconsistently oriented faces",
           "edges between inconsistently oriented faces"),
    Defect(5, "degenerate_faces", "corner of a zero-area face", "zero-area faces"),
    Defect(6, "boundary_edges", "on a boundary edge (this method needs a closed neighbourhood)",
           "boundary edges (their vertices have no complete neighbourhood)"),
)

#: The code of a boundary vertex (a defect only for the methods that need a closed neighbourhood).
BOUNDARY = 6

#: Why a point of a point cloud (:func:`meshcurv.point_cloud_curvatures`) is invalid, beyond the last
#: two reasons: codes 7 and 8.
POINT_CLOUD_REASONS = (
    "point cloud: side undecided (two sheets closer than the spacing, or stacked with normals the same way)",
    "point cloud: every ball held the other side of a thin part or a neighbouring part",
)

#: The code of a vertex invalid for no defect of the mesh: its estimate itself is undefined.
UNDEFINED = len(DEFECTS) + len(POINT_CLOUD_REASONS) + 1

#: What ``CurvatureResult.invalid_reason`` codes mean: code ``c`` is ``INVALID_REASONS[c]``.
INVALID_REASONS = (
    "valid",
    *(defect.reason for defect in DEFECTS),
    *POINT_CLOUD_REASONS,
    "estimate undefined (too few neighbours in the ball, a failed fit, or a non-finite value)",
)

#: The order of the phrases in the warning.
_WARNING_ORDER = ("boundary_edges", "nonmanifold_edges", "bowtie_vertices", "inconsistent_edges",
                  "degenerate_faces", "unreferenced_vertices")
_COUNTED = {defect.name: defect.counted for defect in DEFECTS}


def defect_codes(topology: MeshTopology, degenerate: np.ndarray) -> tuple[np.ndarray, dict[str, int]]:
    """(V,) int8 code of the first defect at each vertex (0: none), and the count of each defect.

    Parameters
    ----------
    topology : MeshTopology
        The mesh's connectivity.
    degenerate : ndarray of shape (F,), bool
        The zero-area faces (:func:`meshcurv.geometry.degenerate_faces`).

    Returns
    -------
    codes : ndarray of shape (V,), int8
        Codes of :data:`DEFECTS`.
    counts : dict
        ``{defect.name: count}``: edges, faces or vertices, as the name says.
        A bow-tie vertex on a non-manifold edge is counted with that edge only.
    """
    nonmanifold = topology.edge_vertices(topology.nonmanifold_edges)
    bowties = topology.bowtie_vertices & ~nonmanifold
    corners = np.zeros(topology.n_vertices, dtype=bool)
    corners[topology.faces[degenerate].ravel()] = True
    members = {
        "unreferenced_vertices": ~topology.referenced_vertices,
        "nonmanifold_edges": nonmanifold,
        "bowtie_vertices": bowties,
        "inconsistent_edges": topology.edge_vertices(topology.inconsistent_edges),
        "degenerate_faces": corners,
        "boundary_edges": topology.edge_vertices(topology.boundary_edges),
    }
    codes = np.zeros(topology.n_vertices, dtype=np.int8)
    for defect in reversed(DEFECTS):  # the first defect that applies is written last
        codes[members[defect.name]] = defect.code
    counts = {
        "boundary_edges": int(topology.boundary_edges.sum()),
        "nonmanifold_edges": int(topology.nonmanifold_edges.sum()),
        "bowtie_vertices": int(bowties.sum()),
        "inconsistent_edges": int(topology.inconsistent_edges.sum()),
        "degenerate_faces": int(degenerate.sum()),
        "unreferenced_vertices": int((~topology.referenced_vertices).sum()),
    }
    return codes, counts


@dataclass(frozen=True, eq=False)
class VertexDefects:
    """The defects of a mesh as one method sees them.

    Attributes
    ----------
    codes : ndarray of shape (V,), int8
        :func:`defect_codes`.
    counts : dict
        The count of each defect.
    tolerated : frozenset of int
        The codes the method copes with (their vertices stay valid).
    """

    codes: np.ndarray
    counts: dict
    tolerated: frozenset = frozenset()

    @property
    def invalid_vertices(self) -> np.ndarray:
        """(V,) bool: the vertices the method must leave undefined."""
        invalid = self.codes != 0
        for code in self.tolerated:
            invalid &= self.codes != code
        return invalid

    def messages(self) -> list[str]:
        """The warning's phrases: the count of each defect the method does not cope with."""
        shown = {defect.name for defect in DEFECTS if defect.code not in self.tolerated}
        return [f"{self.counts[name]} {_COUNTED[name]}" for name in _WARNING_ORDER
                if name in shown and self.counts[name]]

    def reasons(self, valid: np.ndarray) -> np.ndarray:
        """(V,) int8 :data:`INVALID_REASONS` codes of the vertices not ``valid`` (0 where valid).

        An invalid vertex takes its defect's code, or :data:`UNDEFINED` when it
        has none the method does not cope with.
        """
        codes = np.where(self.invalid_vertices, self.codes, UNDEFINED).astype(np.int8)
        return np.where(valid, 0, codes).astype(np.int8)
