"""Vertices where an edge-based estimate is undefined, and why."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..topology import MeshTopology


@dataclass(frozen=True)
class VertexDefects:
    """Which vertices an estimator built on dihedral angles cannot handle.

    A vertex is invalid when it is unreferenced, on a boundary edge (no dihedral
    angle there), on a non-manifold or inconsistently oriented edge (no
    well-defined pair of faces), a bow-tie vertex (two or more fans of faces
    meeting at a point: no single tangent plane), or a corner of a zero-area
    face (no normal; zero-length edges make zero-area faces).
    """

    invalid_vertices: np.ndarray
    counts: dict

    def messages(self) -> list[str]:
        c = self.counts
        labels = [
            ("boundary_edges", "boundary edges (their vertices have no complete neighbourhood)"),
            ("nonmanifold_edges", "non-manifold edges (3+ faces)"),
            ("bowtie_vertices", "bow-tie vertices (fans meeting at a point)"),
            ("inconsistent_edges", "edges between inconsistently oriented faces"),
            ("degenerate_faces", "zero-area faces"),
            ("unreferenced_vertices", "unreferenced vertices"),
        ]
        found = [f"{c[key]} {text}" for key, text in labels if c[key]]
        if found:
            found.append(f"{int(self.invalid_vertices.sum())} vertices are NaN with valid=False")
        return found


def mesh_defects(topology: MeshTopology, degenerate_faces: np.ndarray) -> VertexDefects:
    """Find the vertices an edge-based estimator must leave undefined."""
    bad_edges = topology.boundary_edges | topology.nonmanifold_edges | topology.inconsistent_edges
    invalid = topology.edge_vertices(bad_edges)
    bowties = topology.bowtie_vertices & ~topology.edge_vertices(topology.nonmanifold_edges)
    invalid |= bowties
    invalid[topology.faces[degenerate_faces].ravel()] = True
    invalid |= ~topology.referenced_vertices
    counts = {
        "boundary_edges": int(topology.boundary_edges.sum()),
        "nonmanifold_edges": int(topology.nonmanifold_edges.sum()),
        "bowtie_vertices": int(bowties.sum()),
        "inconsistent_edges": int(topology.inconsistent_edges.sum()),
        "degenerate_faces": int(degenerate_faces.sum()),
        "unreferenced_vertices": int((~topology.referenced_vertices).sum()),
    }
    return VertexDefects(invalid_vertices=invalid, counts=counts)
