"""What a mesh is, and what is questionable about it.

:func:`diagnose` gathers the facts ``meshcurv info`` prints and that
:func:`meshcurv.principal_curvatures` attaches to its result. It reuses what the
:class:`~meshcurv.topology.MeshTopology` has already computed (edge classes, the
vertex adjacency the smoothing uses) and makes one pass over the face geometry.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np

from ._backend import numba_kernels
from . import _geometry
from ._geometry import (
    DEGENERATE_AREA_RATIO,
    degenerate_face_mask,
    vertex_length_scales,
)
from ._validation import as_vertices, check_int_option
from .defects import DEFECTS, NEEDLE, _needle_vertices
from .errors import InvalidMeshError
from .geometry import checked_topology_points, degenerate_faces
from .topology import MeshTopology, as_topology

#: Edges no longer than this times the length scale of their component (its median
#: edge length, :func:`meshcurv.geometry.vertex_length_scales`) count as zero-length.
ZERO_LENGTH_RATIO = 1e-6

#: The phrase after the count of needle vertices (that of the defect table, :data:`meshcurv.defects.DEFECTS`).
NEEDLE_PHRASE = next(defect.counted for defect in DEFECTS if defect.code == NEEDLE)

__all__ = ["MeshDiagnosis", "diagnose", "degenerate_faces", "bowtie_vertices"]


@dataclass(frozen=True)
class MeshDiagnosis:
    """Facts about a triangle mesh: sizes, topology and defects.

    Attributes
    ----------
    n_vertices, n_faces, n_edges : int
    n_components : int
        Connected components of the faces (faces sharing a vertex are connected).
    n_boundary_edges, n_boundary_loops : int
    n_nonmanifold_edges : int
        Edges with three or more faces.
    n_inconsistent_edges : int
        Two-face edges whose faces run them in the same direction (orientation flips).
    n_degenerate_faces : int
        Faces of (near) zero area, repeated corners included: area below ``1e-12``
        x the squared median edge length of their connected component.
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
        Smallest and largest coordinates of the referenced vertices.
    n_bowtie_vertices : int
        Vertices where two or more fans of faces meet at a single point (no
        non-manifold edge there): the neighbourhood is not a disc.
    n_zero_length_edges : int
        Edges whose two ends coincide (length below ``1e-6`` x the median edge
        length of their connected component).
    n_needle_vertices : int
        Vertices flung far from their neighbours (a spike of a corrupted file,
        alone or with a few neighbours): their faces are slivers, and every
        method leaves them and the corners of their faces undefined
        (:func:`meshcurv.defects.needle_vertices`).
    n_flipped_faces : int
        Faces reversed by ``orient=`` before the computation (0 when nothing was
        reversed, and for :func:`diagnose` itself).
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
    n_bowtie_vertices: int = 0
    n_zero_length_edges: int = 0
    n_needle_vertices: int = 0
    n_flipped_faces: int = 0

    @property
    def is_closed(self) -> bool:
        """True when the mesh has no boundary edge."""
        return self.n_boundary_edges == 0

    @property
    def is_clean(self) -> bool:
        """True when nothing questionable was found (boundaries and components aside)."""
        return not (
            self.n_nonmanifold_edges
            or self.n_inconsistent_edges
            or self.n_degenerate_faces
            or self.n_unreferenced_vertices
            or self.n_bowtie_vertices
            or self.n_needle_vertices
        )

    def problems(self, *, boundary: bool = True) -> list[str]:
        """One short phrase per kind of defect found.

        Parameters
        ----------
        boundary : bool, default: True
            Include the boundary edges (a boundary is a defect for some methods
            only).
        """
        found = []
        if self.n_boundary_edges and boundary:
            found.append(f"{self.n_boundary_edges} boundary edges in {self.n_boundary_loops} loops")
        if self.n_nonmanifold_edges:
            found.append(f"{self.n_nonmanifold_edges} non-manifold edges (3+ faces)")
        if self.n_bowtie_vertices:
            found.append(f"{self.n_bowtie_vertices} bow-tie vertices (fans meeting at a point)")
        if self.n_inconsistent_edges:
            found.append(f"{self.n_inconsistent_edges} edges between inconsistently oriented faces")
        if self.n_degenerate_faces:
            found.append(f"{self.n_degenerate_faces} zero-area faces")
        if self.n_zero_length_edges:
            found.append(f"{self.n_zero_length_edges} zero-length edges")
        if self.n_needle_vertices:
            found.append(f"{self.n_needle_vertices} {NEEDLE_PHRASE}")
        if self.n_unreferenced_vertices:
            found.append(f"{self.n_unreferenced_vertices} unreferenced vertices")
        return found

    def as_dict(self) -> dict:
        """The facts as a dict (field name -> value).

        Returns
        -------
        dict
            Every field of the diagnosis, by name.
        """
        return asdict(self)


def bowtie_vertices(topology: MeshTopology) -> np.ndarray:
    """(V,) bool: vertices whose faces form more than one fan (:attr:`MeshTopology.bowtie_vertices`)."""
    if not isinstance(topology, MeshTopology):
        raise InvalidMeshError(f"`topology` must be a MeshTopology; got {type(topology).__name__}")
    return topology.bowtie_vertices


def diagnose(vertices: np.ndarray, topology: MeshTopology, *, n_flipped_faces: int = 0) -> MeshDiagnosis:
    """Describe a mesh: its sizes, topology and defects.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3), float64
    topology : MeshTopology or array_like of faces
        The mesh's connectivity; faces ((F, 3) indices, or polygons) are turned
        into one with :meth:`MeshTopology.from_faces`.
    n_flipped_faces : int, default: 0
        Recorded as is (faces reversed by ``orient=`` before the computation),
        0 to the number of faces.

    Raises
    ------
    InvalidMeshError
        ``topology`` not a :class:`~meshcurv.topology.MeshTopology`,
        ``vertices`` not finite float (V, 3) coordinates within
        :data:`~meshcurv._validation.MAX_COORDINATE`, or not one row per
        vertex of the topology.
    InvalidOptionError
        ``n_flipped_faces`` not an integer in ``[0, F]``.

    Returns
    -------
    MeshDiagnosis

    Examples
    --------
    >>> from meshcurv import shapes, MeshTopology, diagnose
    >>> sphere = shapes.icosphere(4)
    >>> d = diagnose(sphere.vertices, MeshTopology.from_faces(sphere.faces))
    >>> d.n_components, d.genus, d.is_clean, d.problems()
    (1, 0, True, [])
    >>> diagnose(sphere.vertices, sphere.faces).n_faces     # faces as they are
    320
    """
    if (
        not isinstance(topology, MeshTopology)
        and not isinstance(topology, (str, bytes))
        and hasattr(topology, "__len__")
    ):  # a face array or polygon list: its topology
        vertices = as_vertices(vertices)
        topology = as_topology(topology, vertices.shape[0])
    vertices = checked_topology_points(vertices, topology)
    n_flipped_faces = check_int_option(n_flipped_faces, "n_flipped_faces", maximum=topology.n_faces)
    return mesh_diagnosis(vertices, topology, n_flipped_faces, vertex_length_scales(vertices, topology))


def mesh_diagnosis(
    vertices: np.ndarray,
    topology: MeshTopology,
    n_flipped_faces: int,
    scales: np.ndarray,
    *,
    n_needle_vertices: int | None = None,
) -> MeshDiagnosis:
    """:func:`diagnose` of checked inputs: (V, 3) float64 ``vertices`` of ``topology``, ``n_flipped_faces``
    in ``[0, F]`` and the (V,) ``scales`` of :func:`meshcurv.geometry.vertex_length_scales` (a prepared
    mesh has them already: ``principal_curvatures`` checks its inputs once and measures them once).
    ``n_needle_vertices``: their count when known (``counts`` of :func:`meshcurv.defects.defect_codes`),
    else found here (:func:`meshcurv.defects.needle_vertices`: one pass over the edges on a mesh without
    a long edge)."""
    faces = topology.faces
    referenced = topology.referenced_vertices
    n_unreferenced = int(topology.n_vertices - referenced.sum())
    kernels = numba_kernels("diagnosis")
    if kernels is not None:
        lower, upper, area, six_volume, scale, n_degenerate, n_zero_length = kernels.mesh_facts(
            vertices, faces, topology.edges, referenced, scales, DEGENERATE_AREA_RATIO, ZERO_LENGTH_RATIO
        )
    else:
        used = vertices if n_unreferenced == 0 else vertices[referenced]
        centre = used.mean(axis=0)
        cross = _geometry.face_cross_products(vertices, faces)
        lengths = _geometry.edge_lengths(vertices, topology.edges)
        double_areas = np.sqrt(np.einsum("ij,ij->i", cross, cross))
        area = float(0.5 * double_areas.sum())
        # the cross products are translation-invariant: a . (b x c) = (a - o) . cross(b - a, c - a)
        six_volume = float(np.einsum("ij,ij->i", vertices[faces[:, 0]] - centre, cross).sum())
        scale = float(lengths.mean()) if lengths.size else 0.0
        n_degenerate = int(
            (degenerate_face_mask(0.5 * double_areas, scales[faces[:, 0]]) | topology.degenerate_faces).sum()
        )
        n_zero_length = int((lengths <= ZERO_LENGTH_RATIO * scales[topology.edges[:, 0]]).sum())
        lower, upper = used.min(axis=0), used.max(axis=0)
    n_boundary = int(topology.boundary_edges.sum())
    nonmanifold = topology.nonmanifold_edges
    n_nonmanifold = int(nonmanifold.sum())
    chi = topology.euler_characteristic
    n_components = topology.n_components
    closed = n_boundary == 0
    genus = (2 - chi) // 2 if closed and n_components == 1 and n_nonmanifold == 0 else None
    volume = float(six_volume) / 6.0 if closed and faces.shape[0] else None
    if n_needle_vertices is None:
        n_needle_vertices = int(_needle_vertices(vertices, topology, scales).sum())
    bowties = bowtie_vertices(topology)
    if n_nonmanifold:
        bowties = bowties & ~topology.edge_vertices(nonmanifold)
    return MeshDiagnosis(
        n_vertices=topology.n_vertices,
        n_faces=topology.n_faces,
        n_edges=topology.n_edges,
        n_components=n_components,
        n_boundary_edges=n_boundary,
        n_boundary_loops=topology.n_boundary_loops,
        n_nonmanifold_edges=n_nonmanifold,
        n_inconsistent_edges=int(topology.inconsistent_edges.sum()),
        n_degenerate_faces=int(n_degenerate),
        n_unreferenced_vertices=n_unreferenced,
        euler_characteristic=chi,
        genus=genus,
        area=float(area),
        volume=volume,
        mean_edge_length=float(scale),
        bounding_box=(tuple(lower.tolist()), tuple(upper.tolist())),
        n_bowtie_vertices=int(bowties.sum()),
        n_zero_length_edges=int(n_zero_length),
        n_needle_vertices=int(n_needle_vertices),
        n_flipped_faces=int(n_flipped_faces),
    )


def quality_message(
    method: str, problems: list[str], diagnosis: MeshDiagnosis | None, *, notes: list[str] | tuple = ()
) -> str | None:
    """The text of the one :class:`~meshcurv.errors.MeshQualityWarning` of a call, or None.

    ``problems`` are the estimator's own phrases (what it did about the
    defects); the diagnosis adds the defects they do not mention (bow-tie
    vertices; all its defects but boundaries when the estimator reported none)
    and the number of faces ``orient=`` reversed. ``notes``, what was done to
    the mesh before the computation (welding, a second side dropped), come
    first.
    """
    parts = list(problems)
    if diagnosis is not None:
        if not parts:  # the method handled everything it met; say what else was found
            parts = diagnosis.problems(boundary=False)
        elif diagnosis.n_bowtie_vertices and not any("bow-tie" in p for p in parts):
            parts.insert(0, f"{diagnosis.n_bowtie_vertices} bow-tie vertices (fans meeting at a point)")
        if diagnosis.n_flipped_faces:
            parts.append(f"orient reversed {diagnosis.n_flipped_faces} faces before the computation")
    if not parts:
        return f"{method}: " + "; ".join(notes) if notes else None
    suffix = " (details: result.diagnosis)" if diagnosis is not None else ""
    return f"{method}: " + "; ".join([*notes, *parts]) + suffix
