"""What a mesh is, and what is questionable about it."""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from .geometry import degenerate_face_mask, face_cross_products, mean_edge_length, signed_volume
from .topology import MeshTopology

__all__ = ["MeshDiagnosis", "diagnose", "degenerate_faces"]


@dataclass(frozen=True)
class MeshDiagnosis:
    """Facts about a triangle mesh: sizes, topology and defects.

    Attributes
    ----------
    n_vertices, n_faces, n_edges : int
    n_components : int
        Connected components of the faces.
    n_boundary_edges, n_boundary_loops : int
    n_nonmanifold_edges : int
        Edges with three or more faces.
    n_inconsistent_edges : int
        Two-face edges whose faces run them in the same direction (orientation flips).
    n_degenerate_faces : int
        Faces of (near) zero area, repeated corners included.
    n_unreferenced_vertices : int
    euler_characteristic : int
        V - E + F over the referenced vertices.
    genus : int or None
        ``(2 - chi) / 2`` for a closed, connected, manifold mesh; None otherwise.
    area : float
    volume : float or None
        Signed enclosed volume for closed meshes; None when there is a boundary.
    mean_edge_length : float
    bounding_box : tuple of two 3-tuples
        Smallest and largest coordinates.
    """

    n_vertices: int
    n_faces: int
    n_edges: int
    n_components: int
    n_boundary_edges: int
    n_boundary_loops: int
    n_nonmanifold_edges: int
    n_inconsistent_edges: int
    n_degenerate_faces: int
    n_unreferenced_vertices: int
    euler_characteristic: int
    genus: int | None
    area: float
    volume: float | None
    mean_edge_length: float
    bounding_box: tuple

    @property
    def is_closed(self) -> bool:
        return self.n_boundary_edges == 0

    @property
    def is_clean(self) -> bool:
        """True when nothing questionable was found (boundaries and components aside)."""
        return not (
            self.n_nonmanifold_edges
            or self.n_inconsistent_edges
            or self.n_degenerate_faces
            or self.n_unreferenced_vertices
        )

    def problems(self) -> list[str]:
        """One short phrase per kind of defect found."""
        found = []
        if self.n_boundary_edges:
            found.append(f"{self.n_boundary_edges} boundary edges in {self.n_boundary_loops} loops")
        if self.n_nonmanifold_edges:
            found.append(f"{self.n_nonmanifold_edges} non-manifold edges (3+ faces)")
        if self.n_inconsistent_edges:
            found.append(f"{self.n_inconsistent_edges} edges between inconsistently oriented faces")
        if self.n_degenerate_faces:
            found.append(f"{self.n_degenerate_faces} zero-area faces")
        if self.n_unreferenced_vertices:
            found.append(f"{self.n_unreferenced_vertices} unreferenced vertices")
        return found

    def as_dict(self) -> dict:
        return asdict(self)


def degenerate_faces(vertices: np.ndarray, topology: MeshTopology, *, cross: np.ndarray | None = None) -> np.ndarray:
    """(F,) bool: faces with a repeated corner or an area below 1e-12 x (mean edge length)^2."""
    if cross is None:
        cross = face_cross_products(vertices, topology.faces)
    areas = 0.5 * np.linalg.norm(cross, axis=1)
    scale = mean_edge_length(vertices, topology.edges)
    return degenerate_face_mask(areas, scale) | topology.degenerate_faces


def diagnose(vertices: np.ndarray, topology: MeshTopology) -> MeshDiagnosis:
    """Describe a mesh: its sizes, topology and defects.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3), float64
    topology : MeshTopology

    Returns
    -------
    MeshDiagnosis
    """
    cross = face_cross_products(vertices, topology.faces)
    degenerate = degenerate_faces(vertices, topology, cross=cross)
    n_boundary = int(topology.boundary_edges.sum())
    n_nonmanifold = int(topology.nonmanifold_edges.sum())
    chi = topology.euler_characteristic
    n_components = topology.n_components
    closed = n_boundary == 0
    genus = (2 - chi) // 2 if closed and n_components == 1 and n_nonmanifold == 0 else None
    used = vertices[topology.referenced_vertices] if topology.referenced_vertices.any() else vertices
    return MeshDiagnosis(
        n_vertices=topology.n_vertices,
        n_faces=topology.n_faces,
        n_edges=topology.n_edges,
        n_components=n_components,
        n_boundary_edges=n_boundary,
        n_boundary_loops=topology.n_boundary_loops,
        n_nonmanifold_edges=n_nonmanifold,
        n_inconsistent_edges=int(topology.inconsistent_edges.sum()),
        n_degenerate_faces=int(degenerate.sum()),
        n_unreferenced_vertices=int((~topology.referenced_vertices).sum()),
        euler_characteristic=chi,
        genus=genus,
        area=float(0.5 * np.linalg.norm(cross, axis=1).sum()),
        volume=signed_volume(vertices, topology.faces) if closed else None,
        mean_edge_length=mean_edge_length(vertices, topology.edges),
        bounding_box=(tuple(used.min(axis=0).tolist()), tuple(used.max(axis=0).tolist())),
    )
