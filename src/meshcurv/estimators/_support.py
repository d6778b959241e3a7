"""What the neighbourhood estimators share: their defects and their result assembly."""

from __future__ import annotations

import numpy as np

from ..geometry import degenerate_faces, face_cross_products, vertex_normals
from ..result import CurvatureResult
from ..topology import MeshTopology
from ._common import nan_where
from ._defects import VertexDefects, mesh_defects


def defects_without_boundary(topology: MeshTopology, degenerate: np.ndarray) -> VertexDefects:
    """The vertices an estimator that copes with boundaries must leave undefined.

    Those of :func:`~meshcurv.estimators._defects.mesh_defects` (unreferenced
    vertices, ends of non-manifold or inconsistently oriented edges, corners of
    zero-area faces, ...) except that boundary vertices stay valid.
    """
    full = mesh_defects(topology, degenerate)
    # boundary vertices stay valid, unless they are bow-ties (two fans touching at the rim)
    invalid = full.invalid_vertices & ~(topology.boundary_vertices & ~topology.bowtie_vertices)
    invalid |= topology.edge_vertices(topology.nonmanifold_edges | topology.inconsistent_edges)
    invalid[topology.faces[degenerate].ravel()] = True
    invalid |= ~topology.referenced_vertices
    return VertexDefects(invalid_vertices=invalid, counts={**full.counts, "boundary_edges": 0})


def proper_vertex_normals(vertices: np.ndarray, faces: np.ndarray, cross: np.ndarray,
                          degenerate: np.ndarray) -> np.ndarray:
    """:func:`~meshcurv.geometry.vertex_normals` of the faces that are not ``degenerate`` (F,) bool.

    A degenerate face's cross product adds +0 instead: the same sums as
    without its row, and no copy of the faces.
    """
    used = np.where(degenerate[:, None], 0.0, cross) if degenerate.any() else cross
    return vertex_normals(vertices, faces, cross=used)


def prepare(vertices: np.ndarray, topology: MeshTopology):
    """Face cross products, degenerate faces, defects (boundary kept) and vertex normals.

    Returns ``(cross, degenerate, defects, normals, valid)``; ``valid`` excludes
    the defects and vertices without a normal.
    """
    cross = face_cross_products(vertices, topology.faces)
    degenerate = degenerate_faces(vertices, topology, cross=cross)
    defects = defects_without_boundary(topology, degenerate)
    normals = proper_vertex_normals(vertices, topology.faces, cross, degenerate)
    valid = ~defects.invalid_vertices & np.isfinite(normals).all(axis=1)
    return cross, degenerate, defects, normals, valid


def finish(method: str, parameters: dict, valid: np.ndarray, normals: np.ndarray, k_min, k_max,
           dir_min, dir_max, defects: VertexDefects, extra: tuple[str, ...] = ()):
    """NaN where invalid, the one result, and the problem list for the one warning."""
    valid = valid & np.isfinite(k_min) & np.isfinite(k_max)
    nan_where(~valid, k_min, k_max, dir_min, dir_max)
    found = [m for m in defects.messages() if "valid=False" not in m] + [m for m in extra if m]
    n_invalid = int((~valid).sum())
    if n_invalid:
        found.append(f"{n_invalid} vertices are NaN with valid=False")
    # the estimators' own arrays, taken without copies (88 bytes per vertex)
    result = CurvatureResult._of_arrays(k_min=k_min, k_max=k_max, dir_min=dir_min, dir_max=dir_max,
                                        normals=normals, valid=valid, method=method, parameters=parameters)
    return result, found
