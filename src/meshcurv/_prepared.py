"""A mesh checked once and made ready for the estimators, with the way back to the caller's vertices.

:func:`prepare_mesh` is the one door of :func:`meshcurv.principal_curvatures`:
it checks and coerces the caller's arrays (or mesh object), puts a scattered
vertex order into a local one, welds coincident vertices, keeps one side of a
double-sided mesh and orients the faces. The estimators receive the
:class:`PreparedMesh` and trust it; what they share is computed once: the
length scales and needle vertices when the mesh is prepared (the orientation
reads them too), the face cross products, zero-area faces, vertex normals and
the defect codes on first use. :meth:`PreparedMesh.expand` puts a result back
on the caller's vertices: one row per vertex given, copies of a welded vertex
sharing its values.
"""

from __future__ import annotations

import dataclasses
import logging
from functools import cached_property
from typing import Any, NamedTuple

import numpy as np

from ._adapters import mesh_arrays
from ._backend import numba_kernels
from ._locality import MIN_VERTICES, is_scattered, local_topology
from ._validation import as_mesh, as_vertices, check_choice
from .defects import (
    BOUNDARY,
    FRAGMENT,
    VertexDefects,
    _defect_codes,
    _needle_corners,
    _needle_vertices,
    _scale_edges,
)
from .errors import InvalidOptionError
from ._geometry import (
    DEGENERATE_AREA_RATIO,
    cross_and_degenerate,
    degenerate_faces,
    face_cross_products,
    finite_rows,
    length_scales_and_median,
    median_edge_length,
    normalize_normal_sums,
    vertex_edge_lengths,
    vertex_normal_and_area_sums,
)
from .orient import ORIENT_CHOICES, oriented_topology
from .result import CurvatureResult, Surface
from .topology import MeshTopology
from .weld import (
    CRACK_TOLERANCE_RATIO,
    OneSided,
    Welding,
    _closed_copies,
    _tangled_vertices,
    drop_double_sided,
    weld_vertices,
)

__all__ = ["PreparedMesh", "prepare_mesh"]

logger = logging.getLogger(__name__)

#: A large mesh (:data:`meshcurv._locality.MIN_VERTICES` vertices or more) whose vertices come in a local order
#: is computed with its faces sorted by their smallest corner (:func:`_local_faces`) when the faces around a
#: vertex lie farther apart than this in its face order (the median, over the vertices of :func:`_face_spans`, of
#: the last row of a vertex's faces minus the first): an icosphere numbers them about F / 40 apart (its up and
#: down triangles; 50,218 at 1M vertices, 142-448 once sorted), and every stage that reads per-face arrays
#: around the vertices (the topology, the face measures, the ball sums) read a new cache line for each face:
#: the default call at 1M vertices took 3.04 CPU s instead of 2.60 (issue 31, ``benchmarks/speed_profile_M26.md``).
FACE_SPAN_LIMIT = 4096

#: ... measured at about this many vertices, evenly spaced (every ``2**k``-th).
FACE_SPAN_SAMPLE = 1024


class _FacePass(NamedTuple):
    """:attr:`PreparedMesh._face_pass`: the (F,) zero-area faces, and what the pass that found them gave on its way:
    the vertex normals and areas (V, 3) and (V,), or the (F, 3) face cross products (None: not given)."""

    degenerate: np.ndarray
    normals_and_areas: tuple[np.ndarray, np.ndarray] | None = None
    cross: np.ndarray | None = None


@dataclasses.dataclass(frozen=True, eq=False)
class PreparedMesh:
    """A checked, welded, one-sided and oriented mesh, and how it maps to the caller's vertices.

    Attributes
    ----------
    vertices : ndarray of shape (V, 3), float64
        The vertices computed on (in a local order, welded).
    topology : MeshTopology
        Their faces' connectivity (welded, one side of a double-sided mesh, oriented).
    index : ndarray of shape (N,), int64, or None
        The row of ``vertices`` of each of the caller's N vertices (None: the same rows).
    surface : Surface
        The mesh a result keeps for its integrals.
    orient : str
        The orientation applied (``'auto'`` resolved).
    length_scales : ndarray of shape (V,), float64
        The length scale of each vertex (:func:`meshcurv.geometry.vertex_length_scales`), for the
        zero-area faces, the defects, the radius rules, the estimators and the diagnosis. Writable: the
        kernels it is passed to are compiled for writable arrays (a read-only one is another numba signature).
    needles : ndarray of shape (V,), bool
        The needle vertices (:func:`meshcurv.defects.needle_vertices`), for the orientation, the defect codes,
        the radius rules and the diagnosis; read-only. Both are found before the orientation, which changes
        neither (it keeps the edges, sorted, and the corners of each face).
    n_welded, n_double_sided, n_flipped : int
        Vertices welded, faces of a second side dropped, faces reversed.
    n_cracked : int
        Of the vertices welded, those welded across cracks between detached faces
        (:data:`meshcurv.weld.CRACK_TOLERANCE_RATIO`).
    n_copies : int
        Vertices of closed parts stored twice, measured once (:func:`meshcurv.weld.drop_closed_copies`).
    known_median : float or None
        The median length of every edge when the length scales were found with it (None: found on first use,
        :attr:`median_edge_length`).
    unwelded : bool
        Not welded (``weld=False``, or taken as given): its coincident boundary vertices are looked at for tangles
        (:func:`meshcurv.weld.tangled_vertices`); a welded mesh has none left.
    crack_gaps : ndarray of shape (V,), float64, or None
        On a mesh welded across cracks (``n_cracked``), each vertex's largest distance to a caller's vertex joined
        into it (0 where none was): the width of the cracks it closed; None elsewhere.
    """

    vertices: np.ndarray
    topology: MeshTopology
    index: np.ndarray | None
    surface: Surface
    orient: str
    length_scales: np.ndarray
    needles: np.ndarray
    n_welded: int = 0
    n_double_sided: int = 0
    n_flipped: int = 0
    n_copies: int = 0
    n_cracked: int = 0
    known_median: float | None = None
    unwelded: bool = False
    crack_gaps: np.ndarray | None = None

    @classmethod
    def as_given(cls, vertices: np.ndarray, topology: MeshTopology) -> PreparedMesh:
        """A mesh already checked, taken as it is: not welded, reordered or oriented."""
        scales, needles, median = _scales_and_needles(vertices, topology)
        return cls(
            vertices,
            topology,
            None,
            Surface(vertices, topology.faces),
            "keep",
            scales,
            needles,
            known_median=median,
            unwelded=True,
        )

    def with_vertices(self, vertices: np.ndarray) -> PreparedMesh:
        """This mesh with its vertices at ``vertices`` (the same topology and rows): its surface, length scales and
        needles found again, every other reading as here."""
        scales, needles, median = _scales_and_needles(vertices, self.topology)
        return dataclasses.replace(
            self,
            vertices=vertices,
            surface=Surface(vertices, self.topology.faces),
            length_scales=scales,
            needles=needles,
            known_median=median,
        )

    @cached_property
    def scale_extent(self) -> float:
        """The :func:`meshcurv.radius.rigid_extent` of the referenced vertices but the needle vertices (NaN where
        none): the bound of a given radius (:func:`meshcurv.radius.check_radius`), kept for every radius of a call
        (the smallest enclosing ball costs 70 ms of CPU at 1M points)."""
        from .radius import _scale_extent  # radius imports this module

        return _scale_extent(self.vertices, self.topology, self.needles)

    @cached_property
    def median_edge_length(self) -> float:
        """The median length of every edge (:func:`meshcurv.geometry.median_edge_length`, 0 without edges): the
        number the length scales of a mesh of one scale are, kept from their computation (the ball widths of icc's
        coarse level read it: not taken again over 3 E lengths, issue 31)."""
        if self.known_median is not None:
            return self.known_median
        return median_edge_length(self.vertices, self.topology.edges)

    @cached_property
    def cross(self) -> np.ndarray:
        """(F, 3) cross products of the faces' sides (twice their area, along their normal); read-only. Kept from
        the first time they are asked for (those :attr:`_face_pass` builds on its way serve the vertex normals and
        areas, then go: the default method reads no more of them, and they are 24 bytes a face)."""
        spare = self._spare_cross()
        return spare if spare is not None else _read_only(face_cross_products(self.vertices, self.topology.faces))

    @cached_property
    def _face_pass(self) -> _FacePass:
        """The one pass over the faces that finds the zero-area faces (:attr:`degenerate`), and what it gives on
        its way: on a mesh without needles, the compiled pass sums the vertex normals and areas too (no cross
        products kept: :attr:`vertex_normals`, the same sums in the same order, issue 31); otherwise the face
        cross products, unless :attr:`cross` was built first."""
        faces = self.topology.faces
        if "cross" in self.__dict__:
            degenerate = degenerate_faces(self.vertices, self.topology, cross=self.cross, scales=self.length_scales)
            return _FacePass(_read_only(degenerate))
        kernels = numba_kernels("geometry")
        if kernels is not None and not self.needles.any():  # the faces dropped are the zero-area ones (:attr:`dropped`)
            n = self.vertices.shape[0]
            # numba's memory, not numpy's: no huge-page advice (_kernels.geometry._unadvised_empty, issue 31); every
            # face's flag written by the pass
            degenerate = kernels._unadvised_array(faces.shape[0], np.bool_)
            sums = kernels._unadvised_array((n, 3), np.float64, zero=True)
            areas = kernels._unadvised_array(n, np.float64, zero=True)
            kernels._degenerate_normal_and_area_sums(
                self.vertices, faces, self.length_scales, DEGENERATE_AREA_RATIO, degenerate, sums, areas
            )
            summed = (_read_only(_unit_rows(sums)), _read_only(areas))
            return _FacePass(_read_only(degenerate), normals_and_areas=summed)
        cross, degenerate = cross_and_degenerate(self.vertices, faces, self.length_scales, DEGENERATE_AREA_RATIO)
        return _FacePass(_read_only(degenerate), cross=_read_only(cross))

    def _spare_cross(self) -> np.ndarray | None:
        """The cross products :attr:`_face_pass` built, handed over once and let go (None: none built, or handed
        over already)."""
        made = self.__dict__.get("_face_pass")
        if made is None or made.cross is None:
            return None
        self.__dict__["_face_pass"] = made._replace(cross=None)
        return made.cross

    @cached_property
    def degenerate(self) -> np.ndarray:
        """(F,) bool: the zero-area faces (:func:`meshcurv.geometry.degenerate_faces`); read-only (from
        :attr:`_face_pass`)."""
        return self._face_pass.degenerate

    @cached_property
    def scale_edge_means(self) -> np.ndarray:
        """(V,) the mean length of the :func:`~meshcurv.defects.scale_edges` at each vertex (NaN where none): the
        local edge length of the noise fits and of the local scale ratios (:mod:`meshcurv.radius`); read-only."""
        edges = _scale_edges(self.topology, self.needles)
        return _read_only(vertex_edge_lengths(self.vertices, edges, self.vertices.shape[0]))

    def found_degenerate(self, degenerate: np.ndarray) -> None:
        """Keep (F,) ``degenerate``, found by a kernel with the test of :attr:`degenerate` (the same scales and
        ratio), as :attr:`degenerate`: the zero-area faces are not searched twice."""
        self.__dict__.setdefault("degenerate", _read_only(degenerate))

    @cached_property
    def dropped(self) -> np.ndarray:
        """(F,) bool: the faces that weigh nothing in the vertex normals and areas, the zero-area faces and the
        slivers of a needle (faces of a vertex flung away: huge areas, :meth:`VertexDefects.needle_cells`);
        read-only."""
        needle = self.defects().needle_cells(self.topology.faces)
        return self.degenerate if needle is None else _read_only(self.degenerate | needle)

    @cached_property
    def _normals_and_areas(self) -> tuple[np.ndarray, np.ndarray]:
        """:attr:`vertex_normals` and :attr:`vertex_areas`: those :attr:`_face_pass` summed, or one pass over the
        faces' cross products (their sums not kept); the cross products :attr:`_face_pass` built are let go here."""
        if "_face_pass" in self.__dict__ or "degenerate" not in self.__dict__:  # not given (:meth:`found_degenerate`)
            summed = self._face_pass.normals_and_areas
            if summed is not None:  # the face pass summed them (no needle: the faces dropped are its zero-area ones)
                return summed
        dropped = self.dropped
        cross = self.__dict__.get("cross")
        if cross is None:
            cross = self._spare_cross()
        if cross is None:  # the zero-area faces were given (:meth:`found_degenerate`)
            cross = face_cross_products(self.vertices, self.topology.faces)
        sums, areas = vertex_normal_and_area_sums(cross, self.topology.faces, dropped, self.vertices.shape[0])
        return _read_only(_unit_rows(sums)), _read_only(areas)

    @cached_property
    def vertex_normals(self) -> np.ndarray:
        """(V, 3) area-weighted unit normals of the faces not :attr:`dropped` (NaN where none); read-only."""
        return self._normals_and_areas[0]

    @cached_property
    def vertex_areas(self) -> np.ndarray:
        """(V,) a third of the area of the faces not :attr:`dropped` at each vertex (from the pass of
        :attr:`vertex_normals`); read-only."""
        return self._normals_and_areas[1]

    @cached_property
    def _codes(self) -> tuple[np.ndarray, dict]:
        tangled = _tangled_vertices(self.vertices, self.topology, self.length_scales) if self.unwelded else None
        codes = _defect_codes(self.topology, self.degenerate, self.needles, tangled)
        self.topology._release_side_twins()  # the bow-tie vertices are found: no estimator reads the twins
        return codes

    def defects(self, *, boundary: bool = False, fragments: bool = False) -> VertexDefects:
        """The defects as a method sees them: ``boundary=True`` for the methods that keep boundary vertices,
        ``fragments=True`` for those that keep the vertices of parts with no interior vertex (fits over
        Euclidean neighbours: :data:`meshcurv.defects.FRAGMENT`)."""
        codes, counts = self._codes
        tolerated = ({BOUNDARY} if boundary else set()) | ({FRAGMENT} if fragments else set())
        return VertexDefects(codes, counts, frozenset(tolerated), self._needle_members)

    @cached_property
    def _needle_members(self) -> np.ndarray | None:
        """(V,) bool: the needle vertices and the corners of their faces (None: the mesh has no needle)."""
        if not self.needles.any():
            return None
        return self.needles | _needle_corners(self.topology, self.needles)

    def start(self, *, boundary: bool = False, fragments: bool = False) -> tuple[VertexDefects, np.ndarray]:
        """``(defects, valid)``: the defects, and the vertices with neither a defect nor a missing normal."""
        defects = self.defects(boundary=boundary, fragments=fragments)
        valid = ~defects.invalid_vertices & finite_rows(self.vertex_normals)
        return defects, valid

    def notes(self) -> list[str]:
        """What was done to the mesh before the computation, for the call's warning."""
        notes = []
        if self.n_welded:
            cracks = (
                f", of which {self.n_cracked} across cracks up to {CRACK_TOLERANCE_RATIO:g} edge lengths wide "
                "(faces detached from their neighbours: boundary edges on top of each other),"
                if self.n_cracked
                else ""
            )
            notes.append(
                f"welded {self.n_welded} coincident vertices (a triangle soup or split seams){cracks} "
                "before the computation; copies share their values"
            )
        if self.n_copies:
            notes.append(
                f"found closed parts stored twice, their vertices coincident ({self.n_copies} vertices "
                "of copies): each measured once, a copy's vertices get the values of the part they repeat "
                "and totals count it once (result.parameters['n_copy_vertices'])"
            )
        if self.n_double_sided:
            notes.append(
                f"dropped {self.n_double_sided} faces that repeat another face's corners with the "
                "opposite winding (a double-sided mesh): computed on one side "
                "(result.parameters['n_double_sided_faces'])"
            )
        return notes

    def expand(self, result: CurvatureResult) -> CurvatureResult:
        """``result`` on the caller's vertices: row ``i`` is the computed row ``index[i]``."""
        if self.index is None:
            return result
        # np.take: several times faster than indexing the rows of an (N, 3) array; its arrays, new and held by
        # nobody else, made read-only: the result keeps them, not copies (CurvatureResult._of_arrays; a copy of
        # the six fields cost 0.05-0.1 CPU s at 1M vertices, issue 31)
        fields: dict[str, Any] = {
            name: _read_only(np.take(getattr(result, name), self.index, axis=0))
            for name in ("k_min", "k_max", "dir_min", "dir_max", "normals", "valid", "invalid_reason", "radius")
            if getattr(result, name) is not None
        }
        return dataclasses.replace(result, **fields)


def _unit_rows(sums: np.ndarray) -> np.ndarray:
    """:func:`meshcurv.geometry.normalize_normal_sums` of (V, 3) ``sums``: by its compiled twin where the backend is
    numba (the same values, ``tests/test_kernel_twins.py``; one pass, no (V, 3) temporaries of numpy's)."""
    kernels = numba_kernels("geometry")
    return normalize_normal_sums(sums) if kernels is None else kernels.normalize_normal_sums(sums)


def _read_only(array: np.ndarray) -> np.ndarray:
    """``array``, made read-only: the estimators share it and none may change it."""
    array.flags.writeable = False
    return array


def _scales_and_needles(vertices: np.ndarray, topology: MeshTopology) -> tuple[np.ndarray, np.ndarray, float]:
    """(V,) the length scales, (V,) the needle vertices (read-only) and the median length of every edge of a
    checked mesh."""
    scales, median = length_scales_and_median(vertices, topology)
    return scales, _read_only(_needle_vertices(vertices, topology, scales)), median


def _welded(points: np.ndarray, topology: MeshTopology) -> tuple[Welding | None, int, np.ndarray | None]:
    """``(welding, n_copies, copy_faces)``: the coincident vertices and cracks welded
    (:func:`meshcurv.weld.weld_vertices`), then the closed parts stored twice dropped
    (:func:`meshcurv.weld.drop_closed_copies`), as one welding of the given vertices (None: nothing welded or
    dropped); ``n_copies`` the vertices of the copies (not in its ``n_welded``), ``copy_faces`` the (F,) bool faces
    of the copies (None: none)."""
    welding = weld_vertices(points, topology)
    welded = welding if welding.n_welded else None
    if welded is not None:
        points, topology = welded.vertices, welded.topology
    copies, copy_faces = _closed_copies(points, topology)
    if not copies.n_welded:
        return welded, 0, None
    # one welding: the caller's vertices onto the surface measured once
    first = welded.index if welded is not None else np.arange(points.shape[0])
    counts = (welded.n_welded, welded.n_cracked) if welded is not None else (0, 0)
    return Welding(copies.vertices, copies.topology, copies.index[first], *counts), copies.n_welded, copy_faces


def _welded_one_side(
    points: np.ndarray,
    topology: MeshTopology,
    first: Welding | None,
    copy_faces: np.ndarray | None,
    one_sided: OneSided,
) -> tuple[Welding | None, int, OneSided]:
    """``(welding, n_copies, one_sided)`` of :func:`_welded` and :func:`meshcurv.weld.drop_double_sided` on the faces
    of ``points`` and ``topology`` that the drop ``one_sided`` kept after the weld ``first`` (``copy_faces``: the
    faces of its closed copies): the one side welded from the start, as if it had been given alone. ``welding``
    maps ``points`` onto the one side's vertices; None when nothing was welded, before or now (``one_sided`` is
    then the drop's own: nothing more dropped).

    The weld sees both sides otherwise, where the edges of a doubled face have a second face (its other side) and
    are no boundary: the seams and cracks of the one side stayed open (issue 29, fuzz 450/125: ogre, every face
    twice, kept its 9 seams; a sphere a third of whose faces were detached kept 96% of its vertices undefined), and
    welded in a second pass, the cracks between vertices the first pass had joined were no longer found. The
    vertices of the dropped faces alone (a second side with corners of its own) go to the vertex of the kept side
    the first weld joined them to, and count as welded.
    """
    seen = first.topology if first is not None else topology  # the faces the drop saw
    rows = np.flatnonzero(~copy_faces) if copy_faces is not None else np.arange(topology.n_faces)
    kept_rows = rows[~one_sided.dropped]
    if first is None:  # the drop saw the given faces: its kept ones, of the side it chose, are the one side
        side, kept_points = one_sided.topology, points
        index, dropped_only = np.arange(points.shape[0]), None
    else:
        faces = topology.faces.copy()
        flipped = kept_rows[(one_sided.topology.faces != seen.faces[~one_sided.dropped]).any(axis=1)]
        faces[flipped] = faces[flipped, ::-1]  # the side the drop chose (outward)
        keep = np.ones(topology.n_faces, dtype=bool)
        keep[rows[one_sided.dropped]] = False
        faces = faces[keep]
        referenced = np.zeros(points.shape[0], dtype=bool)
        referenced[topology.faces.ravel()] = True
        on_side = np.zeros(points.shape[0], dtype=bool)
        on_side[faces.ravel()] = True
        # each vertex of the first weld at one of its copies on the kept side (a dropped face repeats a kept
        # face's welded corners: every corner of it has one)
        owner = np.full(first.vertices.shape[0], -1)
        corners = faces.ravel()
        owner[first.index[corners]] = corners
        dropped_only = referenced & ~on_side & (owner[first.index] >= 0)
        remaining = np.flatnonzero(~dropped_only)
        index = np.full(points.shape[0], -1)
        index[remaining] = np.arange(remaining.size)
        kept_points = points[remaining]
        side = MeshTopology._build(np.ascontiguousarray(index[faces]), remaining.size)
        dropped_only = np.flatnonzero(dropped_only)
        index[dropped_only] = index[owner[first.index[dropped_only]]]
    second, n_copies, _ = _welded(kept_points, side)
    if second is not None:
        kept_points, side, index = second.vertices, second.topology, second.index[index]
    elif first is None:  # nothing welded, before or now: the drop's side as it was (its length scales and needles)
        return None, 0, one_sided
    n_welded = (second.n_welded if second is not None else 0) + (0 if dropped_only is None else dropped_only.size)
    welding = Welding(kept_points, side, index, n_welded, second.n_cracked if second is not None else 0)
    return welding, n_copies, drop_double_sided(kept_points, side)


def _folded(welding: Welding) -> bool:
    """Whether two faces on an edge the weld made (both ends welded) have their third corners at the same point: a
    face and its copy on a second side, glued by the weld along their boundary (the second side of an open or
    cracked mesh stored with corners of its own). Only the edges between welded vertices are looked at: on an edge
    of two faces, the third corners from the faces' corner sums; on an edge of more, every pair of its faces."""
    topology, points = welding.topology, welding.vertices
    joined = np.bincount(welding.index, minlength=points.shape[0]) > 1
    edges, counts = topology.edges, topology.edge_face_counts
    on_weld = joined[edges[:, 0]] & joined[edges[:, 1]]
    sums = topology.faces.sum(axis=1)
    pairs = np.flatnonzero(on_weld & (counts == 2))
    ends = edges[pairs].sum(axis=1)
    third = sums[topology.edge_faces[pairs]] - ends[:, None]
    if (points[third[:, 0]] == points[third[:, 1]]).all(axis=1).any():
        return True
    crowded = on_weld & (counts > 2)
    if not crowded.any():
        return False
    sides = topology.face_edges
    face, side = np.nonzero((sides >= 0) & crowded[np.maximum(sides, 0)])
    keys = np.column_stack([sides[face, side].astype(float), points[topology.faces[face, (side + 2) % 3]]])
    return bool(np.unique(keys, axis=0).shape[0] < keys.shape[0])


def _coincident(welding: Welding) -> Welding:
    """``welding`` with its vertices at the same point (the same coordinates) made one."""
    _, first, inverse = np.unique(welding.vertices, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    faces = np.ascontiguousarray(inverse[welding.topology.faces])
    n_welded = welding.n_welded + welding.vertices.shape[0] - first.size
    return Welding(welding.vertices[first], MeshTopology._build(faces, first.size), inverse[welding.index], n_welded)


# vertices looked at for a coincident copy before a mesh that is not welded is searched for a second side stored
# with vertices of its own (:func:`_second_side_apart`): every vertex of such a side has one
SECOND_SIDE_PROBES = 3


def _second_side_apart(points: np.ndarray, topology: MeshTopology) -> tuple[Welding, OneSided] | None:
    """A second side of ``points`` and ``topology`` (not welded) stored with vertices of its own: ``(welding,
    one_sided)``, the faces of one side kept as given (their corners, in ``points``' order) and each vertex of the
    dropped side mapped onto the kept vertex at its point; None when there is none.

    Without a weld, the two sides share no vertex and :func:`meshcurv.weld.drop_double_sided` sees none: it is asked
    again of the vertices at the same point made one. Only when :data:`SECOND_SIDE_PROBES` vertices spread over the
    faces each have a copy at their point (one pass over the coordinates each): a mesh whose every face is stored
    twice has one for every vertex. The kept side's faces and vertices are the given ones, so that the kept side's
    values are those of the side given alone (``method='matgeom'``: matGeom's)."""
    faces = topology.faces
    n_faces = faces.shape[0]
    if n_faces < 2 or points.shape[0] < 6:
        return None
    probes = faces[np.linspace(0, n_faces - 1, SECOND_SIDE_PROBES).astype(np.int64), 0]
    for probe in probes:
        if np.count_nonzero((points == points[probe]).all(axis=1)) < 2:
            return None
    coincident = _coincident(Welding(points, topology, np.arange(points.shape[0]), 0))
    on_points = drop_double_sided(coincident.vertices, coincident.topology)
    if not on_points.n_dropped:
        return None
    # of each pair, the face whose own corners wind as the side kept (the drop keeps a pair's first face, turned
    # where the other winding is the outward one): the kept side's faces on their own vertices, none turned
    kept_keys = _rotated(on_points.topology.faces)
    keys = _rotated(coincident.topology.faces)
    wanted = _rows_in(keys, kept_keys, coincident.vertices.shape[0])
    if np.count_nonzero(wanted) != kept_keys.shape[0]:  # faces repeated with one winding too: left as they are
        return None
    kept_faces = faces[wanted]
    used = np.zeros(points.shape[0], dtype=bool)
    used[kept_faces] = True
    point_of = coincident.index
    if np.unique(point_of[used]).size == np.count_nonzero(used):
        # each vertex at the kept vertex of its point (a vertex the kept faces hold is its own)
        kept_of_point = np.full(coincident.vertices.shape[0], -1, dtype=np.int64)
        kept_of_point[point_of[used]] = np.flatnonzero(used)
        twin = kept_of_point[point_of]
    else:
        # the side kept has coincident vertices of its own (a seam of copies, as ogre.obj's 9: fuzz_api 730/156),
        # so a point does not name one kept vertex: each dropped face's corners at the corners of the kept face it
        # repeats; None where that is not one vertex each (copies tangled into one part: left as given)
        twin = _twins_by_faces(faces, wanted, point_of)
        if twin is None:
            return None
    own = used | (twin < 0)  # a vertex no kept face holds stays where no kept vertex is at its point
    new_row = np.cumsum(own) - 1
    index = new_row[np.where(own, np.arange(points.shape[0]), twin)]
    side = MeshTopology._build(np.ascontiguousarray(new_row[kept_faces]), int(own.sum()))
    kept = OneSided(side, ~wanted, on_points.n_dropped)
    return Welding(points[own], side, index, 0), kept


def _twins_by_faces(faces: np.ndarray, wanted: np.ndarray, point_of: np.ndarray) -> np.ndarray | None:
    """(V,) int64: each vertex's twin on the side kept (``wanted`` faces of ``faces``, their vertices their own), -1
    for a vertex of no face; None where a dropped face repeats no kept face or a vertex would have two twins.

    A dropped face is a kept face's points in the other winding (``point_of``: each vertex's point): its corner at
    a point is the twin of the kept face's corner at that point."""
    n_vertices = point_of.shape[0]
    twin = np.full(n_vertices, -1, dtype=np.int64)
    kept, dropped = faces[wanted], faces[~wanted]
    used = np.unique(kept)
    twin[used] = used
    if dropped.shape[0] == 0:
        return twin
    # both as point triples starting at their smallest point, the dropped ones turned to the kept winding
    kept_order = np.argmin(point_of[kept], axis=1)[:, None] + np.arange(3)
    kept = np.take_along_axis(kept, kept_order % 3, axis=1)
    dropped = dropped[:, ::-1]
    dropped_order = np.argmin(point_of[dropped], axis=1)[:, None] + np.arange(3)
    dropped = np.take_along_axis(dropped, dropped_order % 3, axis=1)
    keys = np.unique(np.vstack([point_of[kept], point_of[dropped]]), axis=0, return_inverse=True)[1].reshape(-1)
    kept_keys, dropped_keys = keys[: kept.shape[0]], keys[kept.shape[0] :]
    order = np.argsort(kept_keys, kind="stable")
    at = np.searchsorted(kept_keys[order], dropped_keys)
    found = at < order.size
    found[found] = kept_keys[order[at[found]]] == dropped_keys[found]
    if not found.all() or np.unique(kept_keys).size != kept_keys.size:  # a face of no twin, or two kept faces alike
        return None
    partners = kept[order[at]]
    ends, starts = dropped.reshape(-1), partners.reshape(-1)
    # a dropped vertex at a seam of the kept side (copies of one point, each in some of the kept faces) repeats the
    # corners of several copies: its twin is the copy the most of its faces repeat, then the first (G68's open case:
    # a seamed side kept, the second side on copies without the seam, was left as given: area twice)
    pairs, counts = np.unique(np.column_stack([ends, starts]), axis=0, return_counts=True)
    pairs = pairs[np.lexsort((pairs[:, 1], -counts, pairs[:, 0]))]
    first = np.r_[True, pairs[1:, 0] != pairs[:-1, 0]]
    claimed = np.full(n_vertices, -1, dtype=np.int64)
    claimed[pairs[first, 0]] = pairs[first, 1]
    shared = twin[ends] >= 0  # a vertex of both sides: its own twin
    if (point_of[starts] != point_of[claimed[ends]]).any() or (starts[shared] != ends[shared]).any():
        return None
    free = twin < 0
    twin[free] = claimed[free]
    return twin


def _rotated(faces: np.ndarray) -> np.ndarray:
    """The (F, 3) ``faces`` each rotated to start at its smallest corner (the winding kept)."""
    start = np.argmin(faces, axis=1)
    return np.take_along_axis(faces, (start[:, None] + np.arange(3)) % 3, axis=1)


def _rows_in(rows: np.ndarray, among: np.ndarray, n_vertices: int) -> np.ndarray:
    """(R,) bool: each row of the (R, 3) ``rows`` (indices below ``n_vertices``) among the rows of ``among``."""
    if n_vertices < 2**21:  # three corners in one integer
        packed = [(r[:, 0].astype(np.int64) << 42) | (r[:, 1].astype(np.int64) << 21) | r[:, 2] for r in (rows, among)]
        return np.isin(packed[0], packed[1])
    codes = np.unique(np.vstack([rows, among]), axis=0, return_inverse=True)[1].reshape(-1)
    return np.isin(codes[: rows.shape[0]], codes[rows.shape[0] :])


def prepare_mesh(vertices, faces=None, *, orient: str, weld: bool, stacklevel: int = 3) -> PreparedMesh:
    """Check ``vertices`` and ``faces`` once and prepare them: :class:`PreparedMesh`.

    ``faces`` None: ``vertices`` is a mesh object (:func:`meshcurv._adapters.mesh_arrays`).
    ``orient`` is one of :data:`meshcurv.orient.ORIENT_CHOICES` but ``'auto'``; ``weld`` a bool.
    The faces' triangulation warning is attributed ``stacklevel`` frames up.

    Raises
    ------
    InvalidMeshError
        The arrays are not a mesh (shapes, dtypes, non-finite values, indices).
    InvalidOptionError
        ``orient`` or ``weld`` is not one of their values.
    """
    if faces is None:
        vertices, faces = mesh_arrays(vertices)
    if isinstance(faces, MeshTopology):  # its faces were checked when it was built
        callers = as_vertices(vertices)
    else:
        callers, faces = as_mesh(vertices, faces, stacklevel=stacklevel + 1)
    # whether the vertices come in a scattered order: asked once (8 ms of CPU at 1M vertices), of the faces given
    scattered = is_scattered(callers.shape[0], faces.faces if isinstance(faces, MeshTopology) else faces)
    triangles, face_order = _local_faces(callers.shape[0], faces, scattered)
    points, topology, local = local_topology(callers, triangles, scattered=scattered)
    if not isinstance(orient, str) or orient not in ORIENT_CHOICES:
        check_choice(orient, "orient", ORIENT_CHOICES)  # raises: not an orientation
    if not isinstance(weld, (bool, np.bool_)):
        raise InvalidOptionError(f"`weld` must be True or False; got {weld!r}")
    welded, n_copies, copy_faces = _welded(points, topology) if weld else (None, 0, None)
    given = points, topology  # the mesh before the weld, in the local order
    if welded is not None:
        points, topology = welded.vertices, welded.topology
    one_sided = drop_double_sided(points, topology)  # a double-sided mesh: its faces of one winding
    if not weld and not one_sided.n_dropped:  # a second side with vertices of its own, found without a weld
        own_side = _second_side_apart(points, topology)
        if own_side is not None:
            welded, one_sided = own_side
            points, topology = welded.vertices, welded.topology
    seen = welded  # the weld whose vertices the drop saw
    if weld and welded is not None and welded.n_welded and _folded(welded):
        # a second side with corners of its own: its faces repeat the first's points, not their vertices
        coincident = _coincident(welded)
        on_points = drop_double_sided(coincident.vertices, coincident.topology)
        if on_points.n_dropped:
            seen, one_sided = coincident, on_points
    n_double_sided = one_sided.n_dropped
    if weld and one_sided.n_dropped:  # the weld saw both sides: again on the one kept (:func:`_welded_one_side`)
        again, n_copies, one_sided = _welded_one_side(*given, seen, copy_faces, one_sided)
        if again is not None:  # else nothing was welded, before or now: the side as the drop left it
            welded, points = again, again.vertices
            n_double_sided += one_sided.n_dropped
    median = None  # the median edge: found with the length scales, else on first use
    if one_sided.length_scales is not None and one_sided.needles is not None:  # found on these faces
        scales, needles = one_sided.length_scales, one_sided.needles
    else:
        scales, needles, median = _scales_and_needles(points, one_sided.topology)
    topology, n_flipped = oriented_topology(points, one_sided.topology, orient, needles)
    # the row computed for each of the caller's vertices (welded vertices, in the local order)
    index = None if welded is None else welded.index
    if local is not None:
        index = local.index if welded is None else welded.index[local.index]
    if local is not None and welded is None:  # the mesh the caller gave, its faces oriented (and one-sided)
        surface = Surface(
            callers,
            np.take(local.order, topology.faces)
            if n_double_sided
            else _caller_rows(local.original_faces(topology.faces), face_order),
        )
    elif face_order is not None and welded is None and not n_double_sided:  # the caller's faces, in their rows
        surface = Surface(points, faces if n_flipped == 0 else _caller_rows(topology.faces, face_order))
    else:
        surface = Surface(points, topology.faces, index)
    return PreparedMesh(
        points,
        topology,
        index,
        surface,
        orient,
        scales,
        needles,
        welded.n_welded if welded is not None else 0,
        n_double_sided,
        n_flipped,
        n_copies,
        welded.n_cracked if welded is not None else 0,
        median,
        not weld,
        crack_gaps=_joined_gaps(given[0], welded) if welded is not None and welded.n_cracked else None,
    )


def _joined_gaps(points: np.ndarray, welding: Welding) -> np.ndarray:
    """(W,) read-only: each vertex of ``welding`` (of the (V, 3) ``points``) at its largest distance from the given
    vertices it joined (0 where it joined none: :attr:`PreparedMesh.crack_gaps`)."""
    out = np.zeros(welding.vertices.shape[0])
    rows = np.flatnonzero(welding.index >= 0)
    distances = np.linalg.norm(points[rows] - welding.vertices[welding.index[rows]], axis=1)
    moved = distances > 0
    np.maximum.at(out, welding.index[rows[moved]], distances[moved])
    return _read_only(out)


def _face_spans(faces: np.ndarray, n_vertices: int, shift: int) -> np.ndarray:
    """(S,) for the vertices ``0, 2**shift, 2 * 2**shift, ...`` below ``n_vertices``: the last row of the (F, 3)
    ``faces`` around each minus the first, -1 where no face holds it."""
    kernels = numba_kernels("topology")
    if kernels is not None:  # one pass over the faces, no (F, 3) temporaries
        return kernels._sampled_face_spans(faces, n_vertices, shift)
    rows, corners = np.nonzero((faces & ((1 << shift) - 1)) == 0)
    slots = faces[rows, corners] >> shift
    n_sampled = ((n_vertices - 1) >> shift) + 1
    first = np.full(n_sampled, faces.shape[0], dtype=np.int64)
    last = np.full(n_sampled, -1, dtype=np.int64)
    np.minimum.at(first, slots, rows)
    np.maximum.at(last, slots, rows)
    return np.where(last >= 0, last - first, -1)


def _faces_apart(n_vertices: int, faces: np.ndarray) -> bool:
    """Whether the (F, 3) ``faces`` of a mesh of ``n_vertices`` lie far apart around its vertices: at least
    :data:`meshcurv._locality.MIN_VERTICES` vertices, and the median of :func:`_face_spans` over about
    :data:`FACE_SPAN_SAMPLE` of them above :data:`FACE_SPAN_LIMIT`."""
    if n_vertices < MIN_VERTICES or faces.shape[0] == 0:
        return False
    shift = max(0, (n_vertices // FACE_SPAN_SAMPLE).bit_length() - 1)  # every 2**shift-th vertex
    spans = _face_spans(faces, n_vertices, shift)
    spans = spans[spans >= 0]
    return bool(spans.size) and float(np.median(spans)) > FACE_SPAN_LIMIT


def _local_faces(
    n_vertices: int, faces: np.ndarray | MeshTopology, scattered: bool
) -> tuple[np.ndarray | MeshTopology, np.ndarray | None]:
    """``(faces, order)``: the checked (F, 3) ``faces`` of a mesh of ``n_vertices`` whose vertices are in a local
    order (not ``scattered``, the caller's answer of :func:`meshcurv._locality.is_scattered`: a scattered mesh has
    its faces reordered with its vertices) and whose faces lie apart (:func:`_faces_apart`) sorted by their smallest
    corner (stable), ``order`` (F,) the caller's row of each; ``faces`` as given and None otherwise (a
    :class:`MeshTopology` is kept as built).

    The curvatures do not depend on the faces' order beyond the order of floating-point sums (the sums over the
    faces of a vertex or of a ball): up to round-off, and where ``k_max`` and ``k_min`` nearly meet (a sphere's
    umbilics) up to the square root of the round-off of ``H^2 - K`` (``tests/test_face_order_M27.py``)."""
    if isinstance(faces, MeshTopology) or scattered or not _faces_apart(n_vertices, faces):
        return faces, None
    kernels = numba_kernels("topology")
    if kernels is not None:  # a counting sort, its faces in numba's memory (_kernels.geometry._unadvised_array)
        order, ordered = kernels._faces_by_smallest_corner(faces, n_vertices)
    else:
        order = np.argsort(faces.min(axis=1), kind="stable")
        ordered = np.take(faces, order, axis=0)
    logger.info("the faces around each vertex lie far apart in their order: computed sorted by their smallest corner")
    return ordered, order


def _caller_rows(faces: np.ndarray, order: np.ndarray | None) -> np.ndarray:
    """The (F, 3) ``faces`` in the order :func:`_local_faces` sorted (row ``j`` the caller's row ``order[j]``) put
    back in the caller's rows (``faces`` itself when ``order`` is None)."""
    if order is None:
        return faces
    rows = np.zeros_like(order)
    rows[order] = np.arange(order.size)
    return np.take(faces, rows, axis=0)
