"""Every rule that chooses a ball radius: the scale at which the surface is measured.

The ball estimators (``icc``, ``quadric``, ``normal_cycle_ball``), point clouds
and label images measure curvature over balls; the radius of the ball sets the
balance between the bias of a large ball (it averages the curvature over a
region, an error of order ``(r k)^2``) and the noise of a small one (noise of
amplitude ``a`` gives an error of order ``a / r^2`` in the curvature). This
module holds the rules that choose it, and the checks of a radius given by
the user:

- :func:`edge_radius`, :func:`component_radii`: :data:`DEFAULT_RADIUS_FACTOR`
  mean edge lengths, each group of components of one scale at its own;
- :func:`local_scale_ratios`: ``icc``'s default radius at each vertex, the
  component's radius times how much coarser or finer the mesh is sampled
  around the vertex (below);
- :func:`noise_level`, :func:`noise_radius`: ``icc``'s radius on smooth and
  noisy meshes, growing with the noise measured on the mesh;
- :func:`local_noise`, :func:`jet_vertex_radii`: ``quadric``'s default, each
  vertex's radius growing with the noise measured around it (:func:`noise_rule`);
- :func:`voxel_radius`, :func:`voxel_surface_radius`: on voxel surfaces
  (marching cubes), about ``sqrt(h R)`` for voxels of size ``h`` and curvature
  radius ``R``; :func:`voxel_vertex_radii`: ``icc``'s default there, each
  vertex at its own (below);
- :func:`scale_ladder`, :func:`stable_scales`: ``radius="adaptive"``, each
  vertex at the rung of a ladder of radii where its estimate is stable;
- :func:`cloud_noise_level`, :func:`cloud_radius`: point clouds, growing with
  their noise in units of their spacing;
- :func:`check_radius`, :func:`resolve_radius`, :func:`small_radius_note`:
  a radius given by the user;
- :func:`enclosing_ball`, :func:`rigid_extent`: the size of a set of points
  that no rigid motion changes (the bound of a given radius, the cap of a
  cloud's default).

The scale of each vertex (issue 30). The rules above set one radius per
surface: the noise rule in units of the mean edge length, the voxel rule in
units of the lattice. Where the sampling of one surface changes (a decimated
or adaptively remeshed model, fine where its detail is), one radius follows
the majority: on a sphere sampled 100 times more densely on one half, the
coarse half's balls held little more than their centre's faces and 38% of its
vertices were off by more than 25% (median 17%). The default of ``icc`` on
meshes that are not voxel surfaces is therefore per vertex: the component's
radius (the noise rule) times :func:`local_scale_ratios`, the vertex's mean
edge length averaged over two rings, over the component's median edge length.
The noise rule is in units of edge lengths, so a part sampled ten times more
coarsely needs a radius ten times larger for the same balance of bias and
noise. Local edge lengths within :data:`LOCAL_EVEN` (2) of the median keep
the component's radius: on the evenly sampled meshes of
``benchmarks/accuracy.py`` the two-ring means still spread from 0.46 to 1.77
of the median (random points; the regular torus, whose outer ring edges are
twice the inner ones; the saddle's grid, stretched by its slopes), and
following that spread made the clean torus 15% and the saddle 15% worse
(median H); beyond :data:`LOCAL_FOLLOW` (4) the radius follows the edges in
proportion (``benchmarks/scale_default.py``). Those fits weigh each point by its area (a part sampled 100 times
more densely must not pull the normals of its coarse neighbours). On voxel
surfaces the rule is set by the lattice and the curvature, not by the edges,
whose lengths change with the orientation of the surface in anisotropic
voxels (a factor 2 at 2:1) without any change of the noise: ``icc``'s default
there gives each vertex ``2 sqrt(h_v R)`` with ``h_v`` the voxel's extent
along its normal, capped where the pilot pass sees the surface bend fast
(:func:`voxel_vertex_radii`; ``parameters["scale"] == "voxel"``); one radius
per surface made a torus of tube radius 4 under 2 x 0.5 x 0.5 voxels 25% off
(median H), now 14%, and halved the errors of thin tori in elongated voxels
(``benchmarks/scale_default.md``). The other ball methods keep the one
radius of :func:`voxel_radius`. ``radius="adaptive"`` (:func:`scale_ladder`, :func:`stable_scales`)
chooses each vertex's scale from its estimates instead, at 1.4-4 times the
cost; the local default costs one sparse product per ring.
"""

from __future__ import annotations

import numbers
import warnings
from collections.abc import Callable
from typing import TYPE_CHECKING, NamedTuple

import numpy as np

from ._backend import numba_kernels, twin
from ._validation import check_positive_float, check_vertex_count, checked_indices, checked_mask, checked_points
from .errors import InvalidOptionError
from .defects import _fragment_vertices, _needle_corners, _needle_vertices, _scale_edges, _scale_vertices
from . import _geometry  # _geometry.median_edge_length: the core, not the checked shell of geometry.py
from ._geometry import (
    COMPONENT_SCALE_SPREAD,
    finite_rows,
    robust_mean_edge_length,
    vertex_edge_lengths,
    vertex_length_scales,
)
from .geometry import _floats, checked_topology_points
from .jets import SETTLED_SLOPE, _fit_jets
from .lattice import VoxelGrid, soup_frame, voxel_grid
from .neighborhoods import (
    _ball_face_sums,
    _ball_pairs,
    _checked_ids,
    check_ball_work,
    face_in_ball_ratios,
    ring_max,
    ring_sums,
)
from .topology import MeshTopology

if TYPE_CHECKING:
    from ._prepared import PreparedMesh

__all__ = [
    "DEFAULT_RADIUS_FACTOR",
    "edge_radius",
    "component_radii",
    "noise_level",
    "noise_radius",
    "noise_radii",
    "scale_centres",
    "voxel_radius",
    "voxel_surface_radius",
    "voxel_vertex_radii",
    "check_radius",
    "resolve_radius",
    "enclosing_ball",
    "rigid_extent",
    "small_radius_note",
    "vertex_radii",
    "local_scale_ratios",
    "scale_ladder",
    "stable_scales",
    "cloud_noise_level",
    "cloud_radius",
    "noise_rule",
    "local_noise",
    "jet_vertex_radii",
]

#: The default ``radius`` is this many mean edge lengths.
DEFAULT_RADIUS_FACTOR = 2.5


class _Measured(NamedTuple):
    """What the rules read of a mesh: a :class:`meshcurv._prepared.PreparedMesh` has these attributes.

    Each public rule of a mesh checks ``vertices`` and finds the length scales
    (:func:`meshcurv.geometry.vertex_length_scales`) and needle vertices
    (:func:`meshcurv.defects.needle_vertices`), then calls its private core
    (the same name with a leading underscore), which takes the prepared mesh
    (or this tuple) and trusts it: the estimators call the cores.
    """

    vertices: np.ndarray
    topology: MeshTopology
    length_scales: np.ndarray
    needles: np.ndarray

    @property
    def scale_extent(self) -> float:
        """:func:`_scale_extent` of the mesh (as ``PreparedMesh.scale_extent``)."""
        return _scale_extent(self.vertices, self.topology, self.needles)

    @property
    def scale_edge_means(self) -> np.ndarray:
        """(V,) the mean length of the :func:`~meshcurv.defects.scale_edges` at each vertex (NaN where none)."""
        return vertex_edge_lengths(self.vertices, _scale_edges(self.topology, self.needles), self.vertices.shape[0])


def _measured(vertices, topology: MeshTopology) -> _Measured:
    """``vertices`` checked, one row per vertex of ``topology``, with their length scales and needle vertices."""
    vertices = checked_topology_points(vertices, topology)
    scales = vertex_length_scales(vertices, topology)
    return _Measured(vertices, topology, scales, _needle_vertices(vertices, topology, scales))


def edge_radius(vertices: np.ndarray, topology: MeshTopology) -> float:
    """``DEFAULT_RADIUS_FACTOR`` times the robust mean edge length (0 for a mesh without edges).

    :func:`meshcurv.geometry.robust_mean_edge_length`: the mean edge length
    without edges beyond 1000 median edge lengths (equal to the mean on any
    ordinary mesh; one spike vertex at 1e10 does not multiply it).
    """
    return _edge_radius(_measured(vertices, topology))


def _edge_radius(mesh: _Measured | PreparedMesh) -> float:
    edges = _scale_edges(mesh.topology, mesh.needles)  # no needle's edge
    return DEFAULT_RADIUS_FACTOR * robust_mean_edge_length(mesh.vertices, edges)


def component_radii(vertices: np.ndarray, topology: MeshTopology) -> list[tuple[float, np.ndarray | None]]:
    """The default radius of each group of components of one scale: ``[(radius, vertices), ...]``.

    ``vertices`` is None when the whole mesh is one group (every component within
    a factor :data:`meshcurv.geometry.COMPONENT_SCALE_SPREAD` of the median edge
    length: the usual case, one radius, :func:`edge_radius`). Otherwise the
    components are grouped by the power of two of their median edge length
    (:func:`meshcurv.geometry.vertex_length_scales`) and each group gets
    ``DEFAULT_RADIUS_FACTOR`` times the robust mean edge length of its own edges,
    with the int64 ids of its vertices: a part at 1e-3 and one at 1e3 are each
    fitted at their own scale.
    """
    return _component_radii(_measured(vertices, topology))


def _component_radii(mesh: _Measured | PreparedMesh) -> list[tuple[float, np.ndarray | None]]:
    return [(DEFAULT_RADIUS_FACTOR * edge_length, members) for edge_length, members, _, _ in _component_edges(mesh)]


def _component_edges(mesh: _Measured | PreparedMesh) -> list[tuple]:
    """``(edge_length, members, inside, edges)`` of each group of :func:`component_radii`: the robust mean length
    of its edges ``edges`` (E, 2) between :func:`meshcurv.defects.scale_vertices`, its vertices ``members``
    (None: the whole mesh) and ``inside`` (V,) bool (None: the whole mesh)."""
    vertices, scales = mesh.vertices, mesh.length_scales
    all_edges = _scale_edges(mesh.topology, mesh.needles)  # no spike's edges (issue 29: a spike raised it 2.6x)
    referenced = _scale_vertices(mesh.topology, mesh.needles)
    used = scales[referenced & (scales > 0)]
    if used.size == 0 or used.min() == used.max():
        return [(robust_mean_edge_length(vertices, all_edges), None, None, all_edges)]
    level = np.full(scales.shape, np.iinfo(np.int64).min)
    positive = referenced & (scales > 0)
    level[positive] = np.round(np.log2(scales[positive])).astype(np.int64)
    groups = []
    for k in np.unique(level[positive]):
        members = np.flatnonzero(level == k)
        inside = np.zeros(scales.shape, dtype=bool)
        inside[members] = True
        edges = all_edges[inside[all_edges[:, 0]]]
        groups.append((robust_mean_edge_length(vertices, edges), members, inside, edges))
    return groups


#: The smallest radius taken, in median edge lengths: a ball far inside one
#: face measures nothing (a unit mistake: m for mm), and below about 1e-8 of
#: the coordinates the ball's geometry is rounding noise.
MIN_RADIUS_EDGES = 1e-3


#: The smallest enclosing ball (:func:`enclosing_ball`) holds every point within this share of its radius: the
#: radius found is the exact one to this share, whatever the pose.
ENCLOSING_TOLERANCE = 1e-12

#: :func:`enclosing_ball` finds the ball of about this many points of a larger set first, then of the points
#: outside it.
ENCLOSING_SAMPLE = 4096

#: A point within this share of its distance (the sine of its angle) of the affine hull of the points already on
#: the sphere of :func:`enclosing_ball`'s ball adds no new sphere (round-off: Gärtner's test).
ENCLOSING_HULL = 1e-10

#: The extent of a set of points is this times the radius of its smallest enclosing ball: the diagonal of the
#: cube around that ball, which is the diagonal of the bounding box of a round cloud (a sphere, a ball) in every
#: pose, and at least the bounding box's diagonal of any set in any pose (the box's sides are at most the
#: ball's diameter).
EXTENT_FACTOR = float(2.0 * np.sqrt(3.0))


def enclosing_ball(points) -> tuple[np.ndarray, float]:
    """The smallest ball that holds every point: its centre and radius.

    Unlike the bounding box along the coordinate axes, the ball is the same for the set in every pose (a rigid
    motion moves it with the points) and whatever the density of the sampling: it rests on 2 to 4 of the
    outermost points.

    Parameters
    ----------
    points : array_like of shape (N, 3)
        Finite coordinates; N >= 1.

    Returns
    -------
    centre : ndarray of shape (3,)
    radius : float
        Every point lies within ``(1 + ENCLOSING_TOLERANCE) * radius`` of ``centre``; no smaller ball holds them.

    Notes
    -----
    Welzl's move-to-front recursion (Gärtner's form) over a support set, grown from the extreme points of a sample
    by the points outside its ball: the ball of the support set, the points outside it gathered in one pass, the
    ball of the support set and (a sample of) those, until none is outside. At 1M points: 2 passes over the
    points, about twice the cost of their bounding box.

    References
    ----------
    E. Welzl, "Smallest enclosing disks (balls and ellipsoids)", New Results and New Trends in Computer Science,
    LNCS 555 (1991), 359-370. doi:10.1007/BFb0038202. B. Gärtner, "Fast and robust smallest enclosing balls",
    ESA 1999, LNCS 1643, 325-338. doi:10.1007/3-540-48481-7_29.

    Examples
    --------
    >>> from meshcurv import shapes
    >>> centre, radius = enclosing_ball(shapes.icosphere(subdivisions=2).vertices)
    >>> print(f"{radius:.6f}")
    1.000000
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    # coordinates far from 1 scaled by a power of two (exact): no square overflows or underflows
    largest = float(max(points.max(), -points.min()))
    scale = 1.0
    if largest > 0.0 and not 2.0**-400 < largest < 2.0**400:
        scale = float(np.ldexp(1.0, np.frexp(largest)[1] - 1))
        points = points / scale
    step = max(1, points.shape[0] // ENCLOSING_SAMPLE)
    sample = points[::step]
    origin = sample[0]
    local = sample - origin
    start = [*np.argmin(local, axis=0), *np.argmax(local, axis=0)]
    centre, squared, support = _enclosing(local, np.asarray(start))
    if step > 1:
        origin = origin + centre
        centre, squared, support = _enclosing(points - origin, support * step)
    return (origin + centre) * scale, float(np.sqrt(squared) * scale)


def rigid_extent(points) -> float:
    """The size of a set of points that no rigid motion changes: :data:`EXTENT_FACTOR` times the radius of its
    smallest enclosing ball (:func:`enclosing_ball`), the diagonal of the cube around that ball; 0.0 for no points.

    Parameters
    ----------
    points : array_like of shape (N, 3)
        Finite coordinates.

    Returns
    -------
    float
        At least the diagonal of the points' bounding box along the axes of any pose; equal to it on a sphere.
    """
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    return EXTENT_FACTOR * enclosing_ball(points)[1] if points.shape[0] else 0.0


def _enclosing(local: np.ndarray, start: np.ndarray) -> tuple[np.ndarray, float, np.ndarray]:
    """``(centre, squared radius, support)``: the smallest ball around the points ``local`` (N, 3), from the ball of
    the points ``start`` (indices); ``support`` the indices whose ball it is."""
    squares = np.einsum("ij,ij->i", local, local)
    support = np.unique(start)
    while True:
        centre, squared = _small_enclosing_ball(local[support])
        # |p - c|^2 - |c|^2 (the coordinates are within a diameter of the origin: round-off of ~1e-16 of r^2)
        excess = squares - 2.0 * (local @ centre)
        limit = squared * (1.0 + ENCLOSING_TOLERANCE) ** 2 - float(centre @ centre)
        outside = np.flatnonzero(excess > limit)
        if outside.size == 0:
            return centre, squared, support
        worst = outside[np.argmax(excess[outside])]
        if np.isin(worst, support):
            # a point of the support set outside its ball: pushes refused as round-off; the ball through the
            # farthest point holds every one
            return centre, float(excess[worst] + centre @ centre), support
        some = np.unique(np.concatenate([support, outside[:: max(1, outside.size // ENCLOSING_SAMPLE)], [worst]]))
        if some.size <= local.shape[0] // 2:
            # the ball of the support set and of (a sample of) the points outside it first: a smaller problem
            inner = _enclosing(local[some], np.searchsorted(some, np.append(support, worst)))[2]
            support = some[inner]
        else:
            support = np.append(support, worst)


def _small_enclosing_ball(points: np.ndarray) -> tuple[np.ndarray, float]:
    """``(centre, squared radius)`` of the smallest ball around a few ``points`` (m, 3): Welzl's recursion with
    Gärtner's move to front, the boundary at most 4 points (each new one off the others' affine hull)."""
    order = list(range(points.shape[0]))
    boundary: list[int] = []
    ball = [points[0], 0.0]

    def recurse(end: int) -> None:
        if len(boundary) == 4:
            return
        k = 0
        while k < end:
            i = order[k]
            offset = points[i] - ball[0]
            if float(offset @ offset) > ball[1] * (1.0 + 4.0 * np.finfo(float).eps):
                sphere = _sphere_through(points[boundary + [i]])
                if sphere is not None:
                    ball[:] = sphere
                    boundary.append(i)
                    recurse(k)
                    boundary.pop()
                    order.insert(0, order.pop(k))
            k += 1

    recurse(len(order))
    return np.asarray(ball[0], dtype=np.float64), float(ball[1])


def _sphere_through(boundary: np.ndarray) -> tuple[np.ndarray, float] | None:
    """``(centre, squared radius)`` of the smallest sphere through the points ``boundary`` (m, 3), m of 1 to 4; None
    where the last lies on the affine hull of the others within :data:`ENCLOSING_HULL` (no new sphere)."""
    origin = boundary[0]
    spans = boundary[1:] - origin
    if spans.shape[0] == 0:
        return origin, 0.0
    last, others = spans[-1], spans[:-1]
    off = last - np.linalg.lstsq(others.T, last, rcond=None)[0] @ others if others.shape[0] else last
    if not float(off @ off) > ENCLOSING_HULL**2 * float(last @ last):
        return None
    # the centre origin + w @ spans, as far from each point: 2 spans @ spans.T w = |spans|^2
    gram = spans @ spans.T
    centre = origin + np.linalg.solve(gram, 0.5 * np.diag(gram)) @ spans
    return centre, float(((boundary - centre) ** 2).sum(axis=1).max())


def check_radius(radius, vertices: np.ndarray, topology: MeshTopology) -> float:
    """``radius`` checked: a positive finite number between a sliver of an edge and the mesh's extent.

    Raises
    ------
    InvalidOptionError
        ``radius`` is not a positive finite real number (strings are refused),
        it is below :data:`MIN_RADIUS_EDGES` median edge lengths, or it exceeds the :func:`rigid_extent` (the diagonal of
        the cube around the smallest enclosing ball, the same in every pose) of the referenced vertices but the
        needle vertices (:func:`meshcurv.defects.scale_vertices`): every ball would hold the whole mesh (a unit
        mistake: mm for m).
    """
    radius = check_positive_float(radius, "radius")
    return _check_radius(radius, _measured(vertices, topology))


def _scale_extent(vertices: np.ndarray, topology: MeshTopology, needles: np.ndarray) -> float:
    """The :func:`rigid_extent` of the referenced vertices but the needle vertices (every vertex of a mesh without
    faces); NaN where there are none."""
    used = vertices[_scale_vertices(topology, needles)] if topology.n_faces else vertices
    return rigid_extent(used) if used.shape[0] else float("nan")


def _check_radius(radius: float, mesh: _Measured | PreparedMesh) -> float:
    vertices, topology = mesh.vertices, mesh.topology
    size = mesh.scale_extent  # once per prepared mesh, whatever the number of radii checked
    if np.isnan(size):
        return radius
    if topology.n_faces and radius < MIN_RADIUS_EDGES * size:
        median = _geometry.median_edge_length(vertices, topology.edges)
        if radius < MIN_RADIUS_EDGES * median:
            raise InvalidOptionError(
                f"`radius` {radius:g} is below {MIN_RADIUS_EDGES:g} of the median edge length {median:g}: "
                f"every ball would hold its centre only and give no curvature; pass a radius of a few edge "
                f"lengths (the default is {DEFAULT_RADIUS_FACTOR:g} mean edge lengths), in the units of the vertices"
            )
    if radius > size:
        median = _geometry.median_edge_length(vertices, topology.edges)
        raise InvalidOptionError(
            f"`radius` {radius:g} is larger than the mesh itself (bounding-box diagonal {size:g} of the cube around "
            f"its smallest enclosing ball, of radius {size / EXTENT_FACTOR:g}: the same in every pose; median edge "
            f"length {median:g}): every ball would hold the whole mesh; pass a radius of a few edge lengths (the "
            f"default is {DEFAULT_RADIUS_FACTOR:g} mean edge lengths), in the units of the vertices"
        )
    return radius


def small_radius_note(radius: float, vertices: np.ndarray, topology: MeshTopology, minimum_edges: float) -> str:
    """The warning's sentence for a given ``radius`` below ``minimum_edges`` median edge lengths, else ''.

    Each ball method states its own minimum (``RADIUS_WARNING_EDGES`` of its
    module), measured where its balls start holding too little of the surface.
    """
    radius, minimum_edges = check_positive_float(radius, "radius"), check_positive_float(minimum_edges, "minimum_edges")
    return _small_radius_note(radius, checked_topology_points(vertices, topology), topology, minimum_edges)


def _small_radius_note(radius: float, vertices: np.ndarray, topology: MeshTopology, minimum_edges: float) -> str:
    if not topology.n_faces:
        return ""
    median = _geometry.median_edge_length(vertices, topology.edges)
    if not radius < minimum_edges * median:
        return ""
    return (
        f"`radius` {radius:g} is {radius / median:.2g} of the median edge length {median:g}: below "
        f"{minimum_edges:g} edge lengths the balls hold too little of the surface and many curvatures are far "
        f"off; pass a radius of a few edge lengths, in the units of the vertices (or leave the default)"
    )


def resolve_radius(radius, vertices: np.ndarray, topology: MeshTopology) -> float:
    """The radius to use: ``radius`` checked (:func:`check_radius`), or the mesh's default when None.

    Raises
    ------
    InvalidOptionError
        ``radius`` is not a positive finite number, or larger than the mesh.
    """
    if radius is None:
        return edge_radius(vertices, topology)
    return check_radius(radius, vertices, topology)


def _resolve_radius(radius: float | None, mesh: _Measured | PreparedMesh) -> float:
    return _edge_radius(mesh) if radius is None else _check_radius(radius, mesh)


#: The noise level is measured with degree-2 jets over balls of this many local edge lengths.
NOISE_FIT_RADIUS = 2.0

#: Noise levels (in mean edge lengths) up to this count as a clean mesh: the
#: fit's own bias on smooth surfaces sampled with 8 or more edges per radius of curvature.
NOISE_FLOOR = 0.005

#: Growth of the default radius, in edge lengths, with the square root of the noise above the floor.
NOISE_GAIN = 9.0

#: The noise level of a larger mesh is measured on about this many of its vertices, chosen by an intrinsic key
#: (:func:`_intrinsic_sample`).
NOISE_SAMPLE = 65536

#: The grids of :func:`_intrinsic_sample`'s keys: the local length in its mean, rounded to ``2^-10`` ...
SAMPLE_LOCAL_STEP = 2.0**-10
#: ... and the squared distance to the centroid in its mean, rounded to ``2^-16``. A key changes under a motion only
#: for a value within its round-off of the middle of two steps. A shift far from the origin makes that round-off
#: far larger than ``1e-16``: igea (134,345 vertices, edges of 5e-4) shifted by 14 units has edge lengths good to
#: 4e-12 of themselves, and with the first steps (``2^-16``, ``2^-20``) one vertex changed class, the noise fits
#: changed, and 32,008 vertices' noisy-patch radii with them; at these a class changes for about one vertex in
#: 1e8 (local lengths: ``2 * 4e-12 / 2^-10``; distances, good to 4e-14: ``1e-9``).
SAMPLE_DISTANCE_STEP = 2.0**-16


def _intrinsic_sample(points: np.ndarray, local: np.ndarray, size: int) -> np.ndarray:
    """(M,) bool: about ``size`` of the rows of ``points`` (M, 3), chosen by what rigid motions, uniform scaling and
    re-indexing keep; ``local`` (M,): a positive length of each point that the motions carry with it (a vertex's
    mean edge length, a point's spacing; where their mean is not positive, the distances alone). All of them when
    there are no more than ``size``.

    Each point's key is its ``local`` length in their mean, rounded to :data:`SAMPLE_LOCAL_STEP`, and its squared
    distance to the points' centroid in their mean, rounded to :data:`SAMPLE_DISTANCE_STEP`; the points are taken
    by whole classes of one key, in the order of a hash of the key (splitmix64's finalizer: the classes taken are
    spread over the surface and over the scales), until at least ``size`` are.

    Why: the median of a sample "evenly spaced in index order" changed with the index, and the index with the
    pose (the vertices are reordered along a Morton curve of their coordinates): nefertiti's vertices as a point
    cloud, turned, read a noise level of 0.01929 instead of 0.01891 and a default radius 0.5% larger at every
    point. A hash of the coordinates' bits was free of the order but not of the pose. Both quantities of the key
    are invariant to round-off (means, not a sample's); a point changes class only when one lies within round-off
    of the middle of two steps of its grid (:data:`SAMPLE_DISTANCE_STEP`). Both are needed:
    a clean sphere's points are all at one distance from the centroid (the local lengths split them), a voxel
    surface's have one of a few edge lengths or spacings (the distances split them). A symmetric shape ties whole
    orbits (an icosphere's 60 or 120 vertices alike): they are taken or left together, so the sample exceeds
    ``size`` by less than the largest class; a sample of some of them would be chosen by their index again. The
    key costs 0.03 s of CPU on a million points (the 65,536 fits it chooses: 0.25 s).
    """
    m = points.shape[0]
    if m <= size:
        return np.ones(m, dtype=bool)
    if not local.mean() > 0:  # (points within round-off of one another, no length of their own: the distances alone)
        local = np.ones(m)
    # the centroid refined by the mean offset from a first guess: a shifted cloud's sum of coordinates far from the
    # origin (igea moved by 14 units) is good to 1e-9 of its extent, the offsets' pairwise sum (a column at a time:
    # no (M, 3) temporary) to 1e-15
    guess = np.einsum("ij->j", points) / m
    # the same operations as written out, into four (M,) buffers (no fresh temporary per operation: 18 of them,
    # each an array of numpy's huge-page advice from 4 MB, issue 31)
    squared, scratch = _scratch(m, np.float64), _scratch(m, np.float64)
    squared.fill(0.0)
    for axis in range(3):
        offsets = np.subtract(points[:, axis], guess[axis], out=scratch)
        offsets -= offsets.sum() / m
        squared += np.multiply(offsets, offsets, out=offsets)
    spread = squared.mean()
    # (capped at 2^40 steps: a cast of a larger float is undefined; such outliers share a class)
    keys, spare = _scratch(m, np.uint64), _scratch(m, np.uint64)
    first = np.rint(np.minimum(np.divide(local, local.mean() * SAMPLE_LOCAL_STEP, out=scratch), 2.0**40, out=scratch))
    np.copyto(keys.view(np.int64), first, casting="unsafe")  # first.astype(np.int64), viewed as uint64
    if spread > 0:
        second = np.divide(squared, spread * SAMPLE_DISTANCE_STEP, out=scratch)
        np.copyto(spare, np.rint(np.minimum(second, 2.0**40, out=second), out=second), casting="unsafe")
    else:
        spare.fill(0)
    with np.errstate(over="ignore"):
        keys *= np.uint64(0x9E3779B97F4A7C15)
        keys += spare
        keys = _mixed(keys, spare)
    spare[...] = keys
    spare.partition(size - 1)
    return keys <= spare[size - 1]


def _scratch(m: int, dtype) -> np.ndarray:
    """An unfilled (M,) array of ``dtype``: numba's memory where its kernels run (no huge-page advice,
    ``_kernels.geometry._unadvised_array``), numpy's otherwise."""
    kernels = numba_kernels("geometry")
    return np.empty(m, dtype) if kernels is None else kernels._unadvised_array(m, dtype)


def _mixed(values: np.ndarray, scratch: np.ndarray | None = None) -> np.ndarray:
    """splitmix64's finalizer of (M,) uint64 ``values``, wrapping (in place): nearby keys land far apart.
    ``scratch``: an (M,) uint64 array for the shifts (overwritten; None: temporaries)."""
    with np.errstate(over="ignore"):
        values ^= np.right_shift(values, np.uint64(30), out=scratch)
        values *= np.uint64(0xBF58476D1CE4E5B9)
        values ^= np.right_shift(values, np.uint64(27), out=scratch)
        values *= np.uint64(0x94D049BB133111EB)
        values ^= np.right_shift(values, np.uint64(31), out=scratch)
    return values


def noise_level(
    vertices: np.ndarray,
    normals: np.ndarray,
    valid: np.ndarray,
    edges: np.ndarray,
    *,
    neighbours: np.ndarray | None = None,
    adjacency: tuple | None = None,
) -> float:
    """Median distance of the vertices to degree-2 jets fitted around them, in local edge lengths.

    The local edge length ``h_v`` of a vertex is the mean length of its edges.
    The vertices are taken by class of ``h_v`` (powers of two around the
    median, so that a mesh of even resolution is one class), and each jet is
    fitted over the ball of :data:`NOISE_FIT_RADIUS` times the mean ``h_v`` of
    its class, the vertex included; its distance is measured in that mean. On a
    smooth, clean mesh the distance is the fit's bias (below
    :data:`NOISE_FLOOR`); under normal noise of uniform amplitude ``a h`` it is
    about ``0.23 a`` (0.1 h: 0.020-0.028). Local classes keep a mesh whose
    resolution varies (a decimated model, 40x between its shortest and longest
    edges) from reading its fine detail as noise at the scale of its mean edge.
    On a mesh of more than :data:`NOISE_SAMPLE` valid vertices, the median is
    taken over about that many of them, chosen by a key that neither the pose
    nor the index changes (:func:`_intrinsic_sample`; the median of 65536 draws
    is within about 1% of that of all vertices, and a sample evenly spaced in
    index order moved the level, and the default radius, by that much under a
    rotation, whose Morton order re-indexes the vertices). A fit whose first
    frame is settled (:data:`NORMAL_SETTLED`) is not refitted in its own frame, as
    for the normals: the level moves by less than 0.1% (7e-4 at most on clean and
    noisy spheres and tori; none above 0.02 h of noise), and a clean mesh needs
    half the fits. 0 when no jet could be fitted.
    """
    vertices = checked_points(vertices)
    n = vertices.shape[0]
    edges = checked_indices(edges, n, columns=2, name="edges")
    valid, normals = checked_mask(valid, n, name="valid"), _floats(normals, "normals", (n, 3))
    if neighbours is not None:
        neighbours = checked_mask(neighbours, n, name="neighbours")
    return _noise_level(vertices, normals, valid, edges, neighbours=neighbours, adjacency=adjacency)


def _noise_level(
    vertices, normals, valid, edges, *, neighbours=None, adjacency=None, local=None, fits: list | None = None
) -> float:
    """:func:`noise_level` of checked arrays: (V, 3) float64 ``vertices`` and ``normals``, (V,) bool ``valid``
    (and ``neighbours``), (E, 2) int64 ``edges`` in range; ``local``: the (V,) mean length of the ``edges`` at
    each vertex, when the caller has it; ``fits``: a list to which ``(centres, offsets, curvedness)`` (M,) of the
    fits are appended (:func:`_noise_fits`, signed; NaN where no jet was fitted)."""
    local = vertex_edge_lengths(vertices, edges, vertices.shape[0]) if local is None else local
    centres = np.flatnonzero(valid & (local > 0))
    if centres.size > NOISE_SAMPLE:
        every = centres.size == vertices.shape[0]  # (no copy of a million rows to key them all)
        chosen = _intrinsic_sample(
            vertices if every else vertices[centres], local if every else local[centres], NOISE_SAMPLE
        )
        centres = centres[chosen]
    if centres.size == 0:
        return 0.0
    offsets, curvedness = _noise_fits(
        vertices, normals, centres, local[centres], neighbours=neighbours, adjacency=adjacency, signed=True
    )
    if fits is not None:  # each centre's own offset and curvedness, for the noisy patches (:func:`_patch_radii`)
        fits.append((centres, offsets, curvedness))
    distances = np.abs(offsets[np.isfinite(offsets)])
    return float(np.median(distances)) if distances.size else 0.0


def _noise_fits(vertices, normals, centres, scale, *, neighbours=None, adjacency=None, facing=None, signed=False):
    """``(distances, curvedness)`` (M,): the fits of :func:`noise_level` at ``centres`` (M,) of local edge lengths
    ``scale`` (M,): each vertex's distance to its degree-2 jet in the mean edge length of its class, and the jet's
    ``sqrt(k_1^2 + k_2^2)`` (the norm of its Hessian); NaN where no jet was fitted (``facing``: the check of
    :func:`meshcurv.jets.fit_jets`); ``signed``: the distances signed along the normals (the vertex above its jet:
    positive)."""
    level = np.round(np.log2(scale / np.median(scale))).astype(np.int64)
    distances = np.full(centres.size, np.nan)
    curvedness = np.full(centres.size, np.nan)
    for k in np.unique(level):
        members = np.flatnonzero(level == k)
        radius = NOISE_FIT_RADIUS * scale[members].mean()
        coefficients, _, _ = _fit_jets(
            vertices,
            normals,
            radius,
            degree=2,
            centres=centres[members],
            neighbours=neighbours,
            adjacency=adjacency,
            compact=True,
            settled=SETTLED_SLOPE,
            facing=facing,
        )
        # the constant term is in units of the radius: NOISE_FIT_RADIUS class mean edge lengths
        distances[members] = (coefficients[:, 0] if signed else np.abs(coefficients[:, 0])) * NOISE_FIT_RADIUS
        a, b, c = coefficients[:, 3], coefficients[:, 4], coefficients[:, 5]
        curvedness[members] = np.sqrt(4.0 * a * a + 2.0 * b * b + 4.0 * c * c) / radius
    return distances, curvedness


def noise_radius(noise: float, edge_length: float) -> float:
    """icc's default radius on a mesh of this noise level (:func:`noise_level`) and mean edge length.

    ``h (1 + NOISE_GAIN sqrt(max(nu - NOISE_FLOOR, 0)))``: one edge length on a clean mesh, where the
    smallest ball has the smallest bias, about 2.2 h under normal noise of amplitude 0.1 h and 3.3 h
    under 0.3 h, where a larger ball averages the noise out (a sweep of both radii over the surfaces
    of ``benchmarks/accuracy.py``).
    """
    return edge_length * (1.0 + NOISE_GAIN * np.sqrt(max(noise - NOISE_FLOOR, 0.0)))


def scale_centres(vertices: np.ndarray, topology: MeshTopology, valid: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(V,) bool: where the default-radius rules fit the surface: ``valid``, and the corners of a needle's faces.

    The corners of a needle vertex's faces are invalid in the results (:data:`meshcurv.defects.NEEDLE`), but
    they lie where they were and their ``normals`` leave the needle's slivers out: the noise fits
    (:func:`noise_radii`) and the voxel pilot (:func:`voxel_surface_radius`) use them as on the mesh without
    the needles, and never a needle vertex (:func:`meshcurv.defects.scale_vertices`). Without the corners,
    two needles on a uv sphere of 86 vertices took 15 of its noise fits away and raised icc's default 20%.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
    topology : MeshTopology
    valid : ndarray of shape (V,) of bool
        The vertices valid for the method (the needle's corners are not).
    normals : ndarray of shape (V, 3)
        Unit vertex normals without the needles' faces (NaN where none).

    Returns
    -------
    ndarray of shape (V,) of bool
        ``valid`` itself when the mesh has no needle vertex.
    """
    mesh = _measured(vertices, topology)
    return _scale_centres(mesh, *_checked_fields(mesh, valid, normals))


def _scale_centres(mesh: _Measured | PreparedMesh, valid: np.ndarray, normals: np.ndarray) -> np.ndarray:
    needles = mesh.needles
    if not needles.any():
        return valid
    corners = _needle_corners(mesh.topology, needles) & finite_rows(normals)
    return (valid | corners) & ~needles


def noise_radii(
    vertices: np.ndarray, topology: MeshTopology, normals: np.ndarray, valid: np.ndarray, *, adjacency=None
) -> tuple[list[tuple[float, np.ndarray | None]], list[float]]:
    """``icc``'s default radius of each group of components of one scale, and their noise levels.

    Each group of :func:`component_radii` gets :func:`noise_radius` of its
    :func:`noise_level`, measured at the :func:`scale_centres` among
    ``valid``, and of the robust mean length of its edges between two
    :func:`meshcurv.defects.scale_vertices` (no needle's edge, no needle in
    a ball).

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
    topology : MeshTopology
    normals : ndarray of shape (V, 3)
        Unit vertex normals (the jets' first frames; NaN where none).
    valid : ndarray of shape (V,) of bool
        The vertices whose fits count.
    adjacency : tuple, optional
        The edge lists the balls walk (:func:`meshcurv.jets.fit_jets`).

    Returns
    -------
    groups : list of (float, ndarray or None)
        ``[(radius, members), ...]`` as :func:`component_radii`.
    levels : list of float
        The noise level of each group.
    """
    mesh = _measured(vertices, topology)
    valid, normals = _checked_fields(mesh, valid, normals)
    return _noise_radii(mesh, normals, valid, adjacency=adjacency)


def _checked_fields(mesh: _Measured, valid, normals) -> tuple[np.ndarray, np.ndarray]:
    """``valid`` a (V,) bool array and ``normals`` a real (V, 3) one (NaN allowed: where there is none)."""
    n = mesh.topology.n_vertices
    return checked_mask(valid, n, name="valid"), _floats(normals, "normals", (n, 3))


def _noise_radii(
    mesh: _Measured | PreparedMesh, normals: np.ndarray, valid: np.ndarray, *, adjacency=None, fits=None
) -> tuple[list[tuple[float, np.ndarray | None]], list[float]]:
    """:func:`noise_radii` of a measured mesh; ``fits``: a list to which each group's ``(centres, offsets,
    curvedness)`` of its noise fits are appended (:func:`_noise_level`)."""
    vertices = mesh.vertices
    usable = _scale_vertices(mesh.topology, mesh.needles)
    centres = _scale_centres(mesh, valid, normals)
    groups: list[tuple[float, np.ndarray | None]] = []
    levels: list[float] = []
    for edge_length, members, part, edges in _component_edges(mesh):  # each group's edges measured once
        inside = centres if part is None else centres & part
        level = (
            _noise_level(
                vertices,
                normals,
                inside,
                edges,
                neighbours=usable,
                adjacency=adjacency,
                local=mesh.scale_edge_means if part is None else None,  # every scale edge: the mesh's own means
                fits=fits,
            )
            if edge_length > 0
            else 0.0
        )
        groups.append((float(noise_radius(level, edge_length)), members))
        levels.append(level)
    return groups, levels


#: ``quadric``'s default radius (:func:`jet_vertex_radii`): ``h (a + b sqrt(max(nu_v - NOISE_FLOOR, 0)))``
#: (:func:`noise_rule`) for ``(a, b)`` this, ``h`` the group's mean edge length and ``nu_v`` the vertex's own noise
#: level (:func:`local_noise`): :data:`DEFAULT_RADIUS_FACTOR` edge lengths on a clean mesh, as before. A jet of
#: degree 4 amplifies noise far more than icc's sums (noise of 0.1 h: median H error 56-108% at 2.5 h on the
#: spheres of ``benchmarks/accuracy.py``), so its radius grows faster with the noise (``benchmarks/quadric_noise.md``).
JET_RADIUS_RULE = (DEFAULT_RADIUS_FACTOR, 20.0)

#: ... at most ``JET_CURVATURE_CAP / c_v`` (``c_v`` the norm of the vertex's Hessian, :func:`local_noise`: a ball
#: wider than the radius of curvature reaches round the shape, where no height function describes it), never
#: below :data:`DEFAULT_RADIUS_FACTOR` edge lengths.
JET_CURVATURE_CAP = 1.0

#: ... with ``c_v^2`` less ``JET_NOISE_HESSIAN (nu_v / h)^2``, the share of the noise in the fits' squared Hessian
#: norm (noise of 0.3 h read 3.7 on the unit sphere of ``benchmarks/accuracy.py`` whose exact norm is 1.41: the
#: share is 150-300 ``(nu_v h)^2 / r_fit^4`` over its spheres and tori, ``r_fit = 2 h``); the largest ``c_v``
#: within the ball's rings, which the noise's tail sets, capped the 0.3 h rows twice as tight as they need.
JET_NOISE_HESSIAN = 10.0


def local_noise(
    vertices: np.ndarray, topology: MeshTopology, normals: np.ndarray, valid: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``(levels, curvedness)`` (V,): the noise level of each vertex and the curvedness of the surface there.

    The fits of :func:`noise_level` (degree-2 jets over balls of :data:`NOISE_FIT_RADIUS` local edge lengths,
    Euclidean balls of the vertices of ``topology``'s faces, a ball holding the other side refused) at every
    ``valid`` vertex, each vertex's distance to its jet (in local edge lengths) and the norm of the jet's Hessian
    ``sqrt(k_1^2 + k_2^2)``, averaged over :data:`LOCAL_RINGS` rings (the root of the mean square for the
    curvedness). The median of the levels is about the mesh's :func:`noise_level`; a patch of the mesh that is
    noisy (faces detached off the surface, a scanned region) reads as noisy where the median does not.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
    topology : MeshTopology
    normals : ndarray of shape (V, 3)
        Unit normals of the fits' first frames (also those of the check of a ball's other side).
    valid : ndarray of shape (V,) of bool
        The vertices fitted.

    Returns
    -------
    levels, curvedness : ndarray of shape (V,)
        NaN where no fit is within reach.
    """
    mesh = _measured(vertices, topology)
    valid, normals = _checked_fields(mesh, valid, normals)
    return _local_noise(mesh, normals, valid)


def _local_noise(
    mesh: _Measured | PreparedMesh, normals: np.ndarray, valid: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    n = mesh.vertices.shape[0]
    local = mesh.scale_edge_means
    centres = np.flatnonzero(valid & np.isfinite(local) & (local > 0))
    if centres.size == 0:
        return np.full(n, np.nan), np.full(n, np.nan)
    facing = np.where(valid[:, None], normals, np.nan)
    distances, curvedness = _noise_fits(
        mesh.vertices,
        normals,
        centres,
        local[centres],
        neighbours=mesh.topology.referenced_vertices,
        facing=facing,
    )
    fitted = np.isfinite(distances) & np.isfinite(curvedness)
    values = np.zeros((n, 2))
    known = np.zeros(n)
    values[centres[fitted]] = np.stack([distances[fitted], curvedness[fitted] ** 2], axis=1)
    known[centres[fitted]] = 1.0
    sums, weights = _ring_sums(mesh.topology.neighbour_lists, LOCAL_RINGS, values, known)
    reached = weights > 0
    with np.errstate(invalid="ignore", divide="ignore"):
        averages = sums / np.where(reached, weights, 1.0)[:, None]
    averages[~reached] = np.nan
    return averages[:, 0], np.sqrt(averages[:, 1])


def jet_vertex_radii(
    groups: list[tuple[float, np.ndarray | None]], levels: np.ndarray, curvedness: np.ndarray
) -> np.ndarray:
    """``quadric``'s default radius at each vertex: :data:`JET_RADIUS_RULE` of its noise level.

    The radius is ``h (a + b sqrt(max(nu_v - NOISE_FLOOR, 0)))``, at most :data:`JET_CURVATURE_CAP` ``/ c_v``
    and at least the group's radius (where the level or the curvedness is NaN: the group's radius; a soup of
    detached faces grew to the size of the shape without it, H 24% off on a hemisphere).

    Parameters
    ----------
    groups : list of (float, ndarray or None)
        :func:`component_radii`: :data:`DEFAULT_RADIUS_FACTOR` times each group's mean edge length ``h``, and
        the int64 ids of its vertices (None: every vertex).
    levels : array_like of shape (V,)
        Each vertex's noise level ``nu_v`` (:func:`local_noise`); NaN where none was measured.
    curvedness : array_like of shape (V,)
        Each vertex's curvedness ``c_v`` (:func:`local_noise`).

    Returns
    -------
    ndarray of shape (V,)
        The radius of each vertex's ball.
    """
    levels = np.asarray(levels, dtype=np.float64)
    curvedness = np.asarray(curvedness, dtype=np.float64)
    base = vertex_radii(groups, levels.size)
    return _jet_vertex_radii(base, levels, curvedness)


def _jet_vertex_radii(base: np.ndarray, levels: np.ndarray, curvedness: np.ndarray) -> np.ndarray:
    edge = base / DEFAULT_RADIUS_FACTOR
    noise = np.where(np.isfinite(levels), levels, 0.0)
    grown = _noise_rule(JET_RADIUS_RULE, edge, noise)
    with np.errstate(divide="ignore", invalid="ignore"):
        squared = curvedness**2 - JET_NOISE_HESSIAN * (noise / edge) ** 2  # the noise's share taken out
        bent = np.where(np.isfinite(squared), np.sqrt(np.maximum(squared, 0.0)), 0.0)
        # no curvedness measured (a soup of faces on no surface): no cap known, so no growth
        cap = np.where(bent > 0, JET_CURVATURE_CAP / bent, np.where(np.isfinite(curvedness), np.inf, 0.0))
    return np.where(np.isfinite(base), np.maximum(base, np.minimum(grown, cap)), base)


#: A default ball whose normals turn from its centre's by more than this (radians) reaches round the surface
#: (:func:`_ball_turns`): a height function over its tangent plane is steep at its rim, which no polynomial of the
#: fits follows. On a circle of curvature ``k`` the normal turns by ``2 asin(d k / 2)`` at the distance ``d``: 1.3 rad
#: is a ball of radius ``1.21 / k``. ``quadric`` over well-sampled spheres, cylinders and tori at a given radius of
#: ``r k`` 1.0 / 1.2 / 1.4 (``k`` the largest ``|k|``): the largest principal curvature off by 3-6% / 8-15% / 16-33%;
#: at its default on ``torus(10, 3, 30, 30)`` (a ball of 4.09 set by the ring's long edges, 1.5 rad) by 27%, valid,
#: on the coarse torus of ``benchmarks/accuracy.py`` (``torus(3, 1, 48, 16)``, 1.15 rad) by 1.7% (1.0 here: 13%,
#: its smaller balls' fits fell to quadrics).
BALL_TURN_CAP = 1.3

#: ... unless an edge in the ball turns its vertex normals by more than this (radians): a crease, sharper than any
#: ball, whose fits are the ball's reading of it (``fandisk``: no ball of its default turns past
#: :data:`BALL_TURN_CAP` without one), where a smooth surface sampled with 10 edges to a circle turns by 0.63 per edge.
CREASE_TURN = 0.6


def _edge_turns(normals: np.ndarray, edges: np.ndarray, n_vertices: int) -> np.ndarray:
    """(V,) the largest angle (radians) between the unit ``normals`` of each vertex and of its edge neighbours.

    Parameters
    ----------
    normals : ndarray of shape (V, 3)
        Unit vertex normals (rows of NaN add nothing).
    edges : ndarray of shape (E, 2)
        The edges (int64 vertex ids).
    n_vertices : int

    Returns
    -------
    ndarray of shape (V,)
        0 at a vertex with no edge.
    """
    out = np.zeros(n_vertices)
    if edges.shape[0] == 0:
        return out
    cosines = np.einsum("ij,ij->i", normals[edges[:, 0]], normals[edges[:, 1]])
    with np.errstate(invalid="ignore"):
        angles = np.arccos(np.clip(cosines, -1.0, 1.0))
    np.fmax.at(out, edges[:, 0], angles)
    np.fmax.at(out, edges[:, 1], angles)
    return out


def _ball_turns(
    vertices: np.ndarray, normals: np.ndarray, radii: np.ndarray, centres: np.ndarray, pool: np.ndarray, creases
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """How far the normals turn across the ball of each centre: its reach round the surface.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
    normals : ndarray of shape (V, 3)
        Unit vertex normals (rows of NaN add nothing).
    radii : ndarray of shape (V,)
        Each vertex's radius.
    centres : ndarray of shape (M,)
        The int64 ids of the balls' centres.
    pool : ndarray of shape (P,)
        The int64 ids of the points that enter the balls.
    creases : ndarray of shape (V,)
        Each vertex's :func:`_edge_turns`.

    Returns
    -------
    turns : ndarray of shape (M,)
        The largest angle (radians) between the centre's normal and a point's of its ball.
    bends : ndarray of shape (M,)
        The largest ``|n_j - n_v| / |x_j - x_v|`` over the points of the ball's outer half (``|x_j - x_v| >= r / 2``):
        the curvature of the circle through the two points with those normals (exact on a sphere and on a
        cylinder's circles, whatever the radius; a fit over the ball reads less), 0 where none.
    sharpest : ndarray of shape (M,)
        The largest :func:`_edge_turns` ``creases`` of the ball's points.
    """
    m = centres.shape[0]
    if m == 0 or pool.shape[0] == 0:
        return np.zeros(m), np.zeros(m), np.zeros(m)
    check_ball_work(vertices[pool], radii[centres], m, centres=vertices[centres])  # both backends refuse alike
    cosines, bends, sharpest = ball_turn_extremes(vertices, normals, radii, centres, pool, creases)
    # the largest angle is that of the smallest cosine (arccos decreases): one arccos per ball, NumPy's on both
    return np.arccos(cosines), bends, sharpest


@twin("turns")
def ball_turn_extremes(
    vertices: np.ndarray, normals: np.ndarray, radii: np.ndarray, centres: np.ndarray, pool: np.ndarray, creases
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """``(cosines, bends, sharpest)`` of the ball of each centre, :func:`_ball_turns`' extremes: the smallest
    cosine between the centre's normal and a point's of its ball (clipped to [-1, 1]; 1 where none), and
    ``bends`` and ``sharpest`` as :func:`_ball_turns` returns them.

    Parameters
    ----------
    vertices, normals, radii, centres, pool, creases
        As :func:`_ball_turns` takes them (``centres`` and ``pool`` not empty).

    Returns
    -------
    cosines, bends, sharpest : ndarray of shape (M,)
    """
    m = centres.shape[0]
    cosines, bends, sharpest = np.ones(m), np.zeros(m), np.zeros(m)
    unit = radii[centres]
    for _, i, j in _ball_pairs(vertices[pool], vertices[centres], unit):
        ids, own = pool[j], centres[i]
        # each sum of three products x, y, z in that order, as the kernel adds them (einsum pairs them otherwise)
        with np.errstate(invalid="ignore", divide="ignore"):  # a coincident copy (weld=False): apart 0, not outer
            apart = np.linalg.norm(vertices[ids] - vertices[own], axis=1)
            chords = np.linalg.norm(normals[ids] - normals[own], axis=1) / apart
            products = normals[ids] * normals[own]
            dots = (products[:, 0] + products[:, 1]) + products[:, 2]
        np.fmin.at(cosines, i, np.clip(dots, -1.0, 1.0))
        outer = apart >= 0.5 * unit[i]
        np.fmax.at(bends, i[outer], chords[outer])
        np.fmax.at(sharpest, i, creases[ids])
    return cosines, bends, sharpest


def voxel_radius(spacing: np.ndarray, curvature_radius: float) -> float:
    """The default measure radius of a voxel surface: ``min(1.5 sqrt(h R), R / 2)``, at least ``1.01 h``.

    ``h`` is the largest voxel size, ``R`` the typical radius of curvature of
    the surface. The staircase of the voxels is noise of amplitude ``h`` that
    a ball of radius ``r`` averages down as ``h / r``, while the ball's own
    bias grows as ``(r / R)^2``: the error is smallest for ``r`` of order
    ``sqrt(h R)`` (Lachaud et al. 2020, digitised surfaces). The factor 1.5
    and the cap ``R / 2`` (beyond it the normals, fitted over three radii,
    reach round the shape) come from a sweep over the marching-cubes meshes of
    ``benchmarks/accuracy.py`` (spheres, ellipsoids and tori, voxels 1:1:1 to
    4:1:1, ``python benchmarks/accuracy.py --voxel-sweep``).
    """
    h = float(np.max(spacing))
    return float(max(VOXEL_FLOOR * h, min(VOXEL_GAIN * np.sqrt(h * curvature_radius), VOXEL_CAP * curvature_radius)))


#: The voxel radius rule ``min(VOXEL_GAIN sqrt(h R), VOXEL_CAP R)`` (see :func:`voxel_radius`).
VOXEL_GAIN = 1.5
VOXEL_CAP = 0.5
#: The least radius of a voxel surface, in its largest voxel size: just above it, never on it. A binary
#: marching-cubes surface has vertices exactly one voxel apart, and a ball of that radius had its rim on them:
#: whether they were in the ball was decided by the last bits of the scale (a 52-vertex label surface scaled by
#: 30: normals 0.4 and curvatures 10-14% of the largest apart; fuzz_labels round 25). 1% off every lattice
#: distance, whose squares are quarters of whole numbers of voxels squared (4.08 is none).
VOXEL_FLOOR = 1.01

#: A voxel surface's default radius is at most this share of the diagonal of its bounding box (a ball of that
#: radius round a compact object's vertex holds most of it; a larger one would be refused if given).
VOXEL_EXTENT_CAP = 0.5

#: The typical radius of curvature of a voxel surface is measured with a first pass at this many voxels:
#: two, and half a percent, so that no ball boundary lies at a distance of the lattice (squared distances
#: of a binary mask's vertices are whole numbers of quarter voxels: 2 voxels, then 2.06) where round-off
#: decides membership (issue 29: a voxel sphere scaled by 1e-8 gave results 2.3e-3 apart).
VOXEL_PILOT = 2.01
#: On a grid read with a tolerance widened for noise (:data:`meshcurv.lattice.VOXEL_NOISE`), the pilot's typical
#: radius of curvature is read only where at least this share of the surface's vertices are valid centres of its
#: first pass (no defect, no boundary). A voxel mesh stored as a soup whose corners moved by 0.03 voxel (issue 29,
#: fuzz 415/108) is welded in part, and its pilot sees 322 of 5,755 vertices with a closed ring, each ball a piece
#: of the surface: ``R`` 2.87 voxels on a sphere of 10, a radius of 1.4 voxels and 6,906 of 11,284 vertices off by
#: half the largest curvature with ``quadric``. Such a mesh is taken as an ordinary one, as before the widening
#: (the noise rules measure its scale, as for a soup that moved by 0.05: no valid centre at all). Holed voxel
#: meshes on their exact grid keep the pilot (``voxel_sphere(4)`` with half of its faces removed: 0.46-0.49 of its
#: vertices valid centres).
VOXEL_PILOT_COVER = 0.5
#: The percentile of the pilot's curvedness ``max(|k_min|, |k_max|)`` over the
#: surface's vertices whose inverse is the typical radius of curvature ``R``.
#: The 75th rather than the median: on the benchmark's ellipsoids (voxel sizes
#: 0.2-1, isotropic and 1 x 0.5 x 0.5 and 2 x 0.5 x 0.5) the median let the most
#: curved quarter of the surface be averaged over balls larger than its radius
#: of curvature (median H error of a flat ellipsoid 33% against 11%); the tori
#: lose at most 2 points (benchmarks/accuracy_voxel.md).
VOXEL_CURVEDNESS_PERCENTILE = 75.0
#: A pilot curvedness below this over the largest voxel size is read as 0 (a flat vertex: a radius of curvature of
#: a million voxels is the fit's round-off, which differs between the backends where the exact value is 0). The
#: percentile and the regions of :func:`voxel_vertex_radii` leave flat vertices out, so a test against 0 let a
#: round-off shift the default radius of one backend (``benchmarks/fuzz_api.md``, round 15, seed 264 case 5890).
VOXEL_FLAT_CURVEDNESS = 1e-6


def voxel_curvature_radius(curvedness: np.ndarray, grid: VoxelGrid) -> float | None:
    """The typical radius of curvature ``R`` of a surface on ``grid`` (:class:`meshcurv.lattice.VoxelGrid`), or None.

    ``curvedness`` (N,): ``max(|k_min|, |k_max|)`` of a first pass at its vertices (NaN: no fit); ``R`` is the
    inverse of the :data:`VOXEL_CURVEDNESS_PERCENTILE` th percentile of those above :data:`VOXEL_FLAT_CURVEDNESS`
    over the largest voxel size (None where none is). The voxel default's (:func:`voxel_surface_radius`) and a
    voxel soup's (``quadric``'s default on a voxel surface stored as a triangle soup: :func:`soup_voxel_grid`)."""
    with np.errstate(invalid="ignore"):  # (NaN: no fit, left out)
        curved = curvedness[
            np.isfinite(curvedness) & (curvedness > VOXEL_FLAT_CURVEDNESS / float(np.max(grid.spacing)))
        ]
    if curved.size == 0:
        return None
    return 1.0 / float(np.percentile(curved, VOXEL_CURVEDNESS_PERCENTILE))


def voxel_rule_radius(grid: VoxelGrid, curvature_radius: float, points: np.ndarray) -> tuple[float, float]:
    """``(radius, extent)``: the default radius of a surface on ``grid`` whose typical radius of curvature is
    ``curvature_radius`` (:func:`voxel_curvature_radius`), :func:`voxel_radius`, at most ``extent``,
    :data:`VOXEL_EXTENT_CAP` of the diagonal of the bounding box of its ``points`` (N, 3) in the grid's axes (the same
    in every pose). The voxel default's and a voxel soup's (:func:`soup_voxel_grid`)."""
    used = grid.along(points)
    extent = VOXEL_EXTENT_CAP * float(np.linalg.norm(used.max(axis=0) - used.min(axis=0)))
    return min(voxel_radius(grid.spacing, curvature_radius), extent), extent


def voxel_surface_radius(
    vertices: np.ndarray, topology: MeshTopology, pilot: Callable[[float], tuple[np.ndarray, np.ndarray, np.ndarray]]
) -> tuple[float, dict] | None:
    """The default radius of a voxel surface and what it was derived from, or None for other meshes.

    The grid is found on the referenced vertices but the needle vertices
    (:func:`meshcurv.defects.scale_vertices`; :func:`meshcurv.lattice.voxel_grid`), and so are the extent
    cap (:data:`VOXEL_EXTENT_CAP`) and the area measured (without the needles' faces);
    the typical radius of curvature ``R`` is the inverse of the
    :data:`VOXEL_CURVEDNESS_PERCENTILE` th percentile of ``max(|k_min|, |k_max|)``
    over those of them that are valid, from a first pass ``pilot(radius) -> (k_min, k_max, valid)``
    (``icc`` at :data:`VOXEL_PILOT` voxels, whose ``valid`` holds the corners of a needle's faces:
    :func:`scale_centres`); the radius is :func:`voxel_radius`. Used for every method
    that takes a radius, so that ``quadric`` and ``normal_cycle_ball`` average the staircase out as
    ``icc`` does.
    """
    return _voxel_surface_radius(_measured(vertices, topology), pilot)


def _voxel_surface_radius(
    mesh: _Measured | PreparedMesh,
    pilot: Callable[[float], tuple[np.ndarray, np.ndarray, np.ndarray]],
    reading: VoxelReading | None = None,
) -> tuple[float, dict] | None:
    """:func:`voxel_surface_radius` of a measured or prepared mesh; ``reading``: the call's
    :class:`VoxelReading`, which keeps the mesh's grid for the later readers of the call."""
    vertices, topology = mesh.vertices, mesh.topology
    # a spike is on no grid (issue 29: one flung to 1e22 made a voxel sphere an ordinary mesh, radius 1.4x), and
    # is in no extent, area or percentile below: the needles' vertices and faces are left out everywhere
    spikes = mesh.needles
    referenced = topology.referenced_vertices & ~spikes
    on_grid = _voxel_surface_grid(mesh, reading=reading)
    if on_grid is None:
        return None
    grid = on_grid[0]
    k_min, k_max, valid, *more = pilot(VOXEL_PILOT * float(np.max(grid.spacing)))  # type: ignore[var-annotated]
    if grid.noise > 0 and np.count_nonzero(referenced & valid) < VOXEL_PILOT_COVER * np.count_nonzero(referenced):
        return None  # a noisy soup, its copies welded in part: the pilot's balls hold pieces of the surface, no R
    curvature_radius = voxel_curvature_radius(np.maximum(np.abs(k_min), np.abs(k_max))[referenced & valid], grid)
    if curvature_radius is None:
        return None
    # a default is never refused as a given radius would be: at most a share of the surface's own extent (a
    # label of a few voxels in a row read a curvature radius of 10 voxels: 4.7 against a diagonal of 4.1)
    radius, extent = voxel_rule_radius(grid, curvature_radius, vertices[referenced])
    found = {
        "surface": "voxel",
        "voxel_spacing": tuple(float(x) for x in grid.spacing),
        "curvature_radius": curvature_radius,
    }
    if more:  # the pilot's normals: each vertex's own scale (icc's default)
        corners = vertices[topology.faces[~spikes[topology.faces].any(axis=1)]]
        area = 0.5 * float(
            np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1).sum()
        )
        rings = int(
            np.clip(np.ceil(radius / _geometry.median_edge_length(vertices, topology.edges)), 1, VOXEL_REGION_RINGS)
        )
        radii, normal_radii = voxel_vertex_radii(
            grid.spacing,
            grid.along(more[0]),  # the normals in the grid's axes, as its spacing (a turned image)
            k_min,
            k_max,
            referenced & valid,
            curvature_radius,
            topology.neighbour_lists,
            radius,
            area=area,
            rings=rings,
        )
        found["vertex_scale"] = (np.minimum(radii, extent), normal_radii)
    return radius, found


def _mesh_voxel_grid(mesh: _Measured | PreparedMesh) -> VoxelGrid | None:
    """The voxel grid of a mesh (:func:`meshcurv.lattice.voxel_grid`) but its needles' vertices and faces, or None,
    also where a part is of another scale than the grid (:func:`_off_grid_scale`).

    A mesh whose vertices left the grid by a little is read from the periodicity of its coordinates, at steps about
    the median of its length scales, and from its faces (each within one voxel). A mesh off every grid is read
    again without its fragments (:func:`meshcurv.defects._fragment_vertices`: faces alone or in strips, on no
    surface): faces detached from a voxel surface beyond the weld leave the rest on its grid (fuzz_api seed 352,
    case 1144: a voxel sphere with half of its faces detached by 0.09 edge lengths was measured at a smooth
    mesh's radius, a vertex 0.56 of the curvature off).
    """
    topology, spikes = mesh.topology, mesh.needles
    referenced = topology.referenced_vertices & ~spikes
    if not referenced.any():
        return None
    # (no needle, most meshes: the faces themselves, no (F,) gather of the needles and no copy of the faces)
    kept = ~spikes[topology.faces].any(axis=1) if spikes.any() else None
    grid = _subset_voxel_grid(mesh, topology.faces if kept is None else topology.faces[kept], referenced)
    if grid is not None and grid.noise == 0:
        return grid
    # (off every grid, or on one only within a tolerance widened for noise: the fragments' own offsets, half of a
    # voxel sphere's faces detached by 0.09 edge lengths, read 0.04 voxel of noise on the grid the rest is on)
    fragments = _fragment_vertices(topology)
    if fragments is None:
        return grid
    on_surface = referenced & ~fragments
    if not on_surface.any():
        return grid
    surface_faces = on_surface[topology.faces].all(axis=1)
    part = _subset_voxel_grid(mesh, topology.faces[surface_faces if kept is None else kept & surface_faces], on_surface)
    return part if grid is None or (part is not None and part.noise < grid.noise) else grid


def _subset_voxel_grid(mesh: _Measured | PreparedMesh, faces: np.ndarray, used: np.ndarray) -> VoxelGrid | None:
    """The voxel grid of the vertices ``used`` ((V,) bool, a non-empty set holding every corner of ``faces``) and
    of ``faces``, read at the median of their length scales, or None, also where they are of another scale than
    the grid (:func:`_off_grid_scale`)."""
    scales = mesh.length_scales[used]
    scale = float(np.median(scales, overwrite_input=True))  # (a copy of its own; _off_grid_scale reads no order)
    if used.all():  # (no copy of a whole mesh)
        grid = voxel_grid(mesh.vertices, faces, spacing=scale)
    else:
        grid = voxel_grid(mesh.vertices[used], (np.cumsum(used) - 1)[faces], spacing=scale)
    if grid is None or _off_grid_scale(scales, grid.spacing):
        return None
    return grid


#: A coordinate repeated by this many vertices is a plane of a grid (``meshcurv.lattice``'s reading), for
#: :func:`_grid_part`.
GRID_PLANE_VERTICES = 3

#: The share of the valid vertices that must have two coordinates on such planes for :func:`_grid_part`.
GRID_PART_SHARE = 0.5


class VoxelReading:
    """The voxel grid of one call's mesh (:func:`_mesh_voxel_grid`), read at its first use and kept for the call's
    later readers (the default radius, the estimator, the warning's sentence on the staircase): one reading a call.

    :class:`meshcurv.estimators._support.Stages` carries one (``stages.voxel``) from
    :func:`meshcurv.curvature.principal_curvatures` to the estimator and back.
    """

    def __init__(self) -> None:
        self._mesh: object = None
        self._grid: VoxelGrid | None = None

    def mesh_grid(self, mesh: _Measured | PreparedMesh) -> VoxelGrid | None:
        """The grid of ``mesh`` (:func:`_mesh_voxel_grid`), read once (again for another mesh)."""
        if self._mesh is not mesh:
            self._grid, self._mesh = _mesh_voxel_grid(mesh), mesh
        return self._grid


def _voxel_surface_grid(
    mesh: _Measured | PreparedMesh,
    *,
    invalid: np.ndarray | None = None,
    valid: np.ndarray | None = None,
    reading: VoxelReading | None = None,
) -> tuple[VoxelGrid, np.ndarray] | None:
    """``(grid, used)``: the one reading of "this mesh is a voxel surface" that every method makes, or None.

    The grid is, in this order, the first found of:

    1. the mesh's (:func:`_mesh_voxel_grid`: but its needles, or without its fragments; ``used`` its referenced
       vertices), kept by ``reading`` (:class:`VoxelReading`) for the call's other readers;
    2. with ``invalid`` ((V,) bool): that of its faces with a corner not ``invalid`` (``used`` their corners): the
       cells of the valid vertices, where faces detached off the grid (a triangle soup beside it, cracks beyond
       the weld: fuzz_api seed 322, case 407) leave the rest on it;
    3. with ``valid`` ((V,) bool): that of the ``valid`` vertices on the grid's planes (:func:`_grid_part`): faces
       detached off a voxel surface and welded to each other, whose faces read no grid.

    The default radius and the staircase's warning read 1; the ring methods' staircase rules 1-2;
    ``normal_cycle_ball``'s holes in the staircase 1-3.
    """
    grid = _mesh_voxel_grid(mesh) if reading is None else reading.mesh_grid(mesh)
    if grid is not None:
        return grid, mesh.topology.referenced_vertices
    # (no vertex invalid and no needle: the faces and vertices of 2 are those 1 read first, and found no grid;
    # not read again: 0.15 CPU s at a million vertices, a sixth of normal_cycle's call, issue 31)
    if invalid is not None and (invalid[mesh.topology.referenced_vertices].any() or mesh.needles.any()):
        faces = mesh.topology.faces[~invalid[mesh.topology.faces].all(axis=1)]
        if faces.shape[0]:
            used = np.zeros(mesh.vertices.shape[0], dtype=bool)
            used[faces] = True
            grid = _subset_voxel_grid(mesh, faces, used)
            if grid is not None:
                return grid, used
    return None if valid is None else _grid_part(mesh.vertices, valid)


def _grid_part(
    vertices: np.ndarray, valid: np.ndarray, share: float = GRID_PART_SHARE
) -> tuple[VoxelGrid, np.ndarray] | None:
    """``(grid, on_planes)``: the grid (:func:`meshcurv.lattice.voxel_grid`) of the ``valid`` vertices ((V,) bool)
    with two coordinates repeated by :data:`GRID_PLANE_VERTICES` vertices or more, where they are at least
    ``share`` of them (:data:`GRID_PART_SHARE`); else None. Faces detached off a voxel surface by cracks beyond the weld and
    welded to each other leave valid vertices off the grid, too many for the mesh's reading (fuzz_api seed
    480, case 968: 97 of 258 valid vertices; a voxel sphere of radius 4 with half its faces detached by 0.06
    voxels: 71 of 326 valid vertices off the clean surface's H by more than half its largest curvature).
    """
    repeated = np.zeros(vertices.shape[0], dtype=int)
    for k in range(3):
        _, inverse, counts = np.unique(vertices[:, k], return_inverse=True, return_counts=True)
        repeated += counts[inverse] >= GRID_PLANE_VERTICES
    on_planes = valid & (repeated >= 2)
    if on_planes.sum() < share * valid.sum():
        return None
    grid = voxel_grid(vertices[on_planes])
    return None if grid is None else (grid, on_planes)


#: A voxel soup's grid turned off the coordinate axes (:func:`soup_voxel_grid`) is read in the axes of its faces'
#: sides (:func:`meshcurv.lattice.soup_frame`), the turned coordinates within this share of their extent of each other
#: taken as one plane's (:func:`_snapped`: a plane's coordinates, turned, differ by round-off; 1e-9 is far from both).
GRID_SNAP = 1e-9
#: ... and the vertices that kept their place on its planes (:func:`_grid_part`) need be only this share of the valid
#: ones, the exact reading of their grid (:func:`meshcurv.lattice.voxel_grid`) deciding: half of the faces detached
#: by 0.05 edges leave 23% of them there (the weld joins the copies off it), and the vertices but the cracks' corners
#: were too few for that reading (62 of ``voxel_sphere(6)``'s).
SOUP_PART_SHARE = 0.15
#: ... and, every face moved, its periodic reading (:func:`meshcurv.lattice.voxel_grid`) is made again at this share
#: of the soup's length scale where it finds none there: the reading needs 8 of its steps across the surface along
#: each axis, and a tube of 2.5 voxels (``voxel_torus(12, 2.5)``: 5 voxels along its axis, edges of 0.99) spans
#: fewer (issue 29, R29's F3: read on no grid in any pose, 180, 124 and 187 valid vertices off its H by more than
#: half of its largest ``|k|`` at the noise rule's radius).
SOUP_FINE_SCALE = 0.5


def soup_voxel_grid(
    mesh: PreparedMesh,
    *,
    invalid: np.ndarray,
    valid: np.ndarray,
    corners: np.ndarray,
    reading: VoxelReading | None = None,
) -> VoxelGrid | None:
    """The voxel grid of a voxel surface stored as a triangle soup, in any pose, or None.

    A soup's faces have corners of their own, moved by a few hundredths of an edge (a mesh exported face by face),
    welded in part (:func:`meshcurv._prepared.prepare_mesh`). Its grid is, in this order, the first found of:

    1. the reading of every method (:func:`_voxel_surface_grid`: the mesh's, or that of its faces with a corner not
       ``invalid``), kept by ``reading`` (:class:`VoxelReading`);
    2. on a mesh welded across cracks: that of the ``valid`` vertices ((V,) bool) on a grid's planes
       (:func:`_grid_part`: the vertices that kept their place), also without the ``corners`` of its cracks ((V,)
       bool: the copies the weld joined, off the grid by the cracks' width, are half of the vertices of
       ``voxel_sphere(10)`` half detached by 0.04 edges; fuzz 559/137), along the coordinate axes, then in the axes
       of its faces' sides (:func:`planes_voxel_grid`);
    3. every face moved (none kept its place): its periodic reading (:func:`meshcurv.lattice.voxel_grid`, widened
       for noise) in those axes, at the soup's length scale, else at :data:`SOUP_FINE_SCALE` of it (a thin tube).

    The grid's ``frame`` holds its axes (None: x, y and z). A default radius that reads no grid here measures the soup
    as a smooth mesh, whose balls the steps bend; the pose must not decide it (issue 29: ``voxel_sphere(6)`` with
    every face detached, turned by (0.3, 0.5, 0.7), read no grid where unturned it did: 433 valid vertices off its H
    by more than half of it against 76).
    """
    found = _voxel_surface_grid(mesh, invalid=invalid, reading=reading)
    if found is not None:
        return found[0]
    if not mesh.n_cracked or not valid.any():
        return None
    vertices, faces = mesh.vertices, mesh.topology.faces
    found, frame = planes_voxel_grid(vertices, faces, (valid, valid & ~corners), SOUP_PART_SHARE)
    if found is not None:
        return found[0]
    if frame is None:
        return None
    turned = vertices @ frame.T
    used = mesh.topology.referenced_vertices & ~mesh.needles
    kept = faces[used[faces].all(axis=1)]
    if not kept.shape[0]:
        return None
    scales = mesh.length_scales[used]
    points, faces = turned[used], (np.cumsum(used) - 1)[kept]
    scale = float(np.median(scales))
    grid = voxel_grid(points, faces, spacing=scale) or voxel_grid(points, faces, spacing=SOUP_FINE_SCALE * scale)
    if grid is None or _off_grid_scale(scales, grid.spacing):
        return None
    return grid._replace(frame=frame if grid.frame is None else grid.frame @ frame)


def planes_voxel_grid(
    vertices: np.ndarray, faces: np.ndarray, parts: tuple, share: float = GRID_PART_SHARE
) -> tuple[tuple[VoxelGrid, np.ndarray] | None, np.ndarray | None]:
    """``(found, frame)``: ``found`` the ``(grid, on_planes)`` (:func:`_grid_part`) of the first of the ``parts``
    ((V,) bool each) of ``vertices`` (V, 3) at least ``share`` of whose vertices lie on a grid's planes, along the
    coordinate axes, else in the axes of the sides of the ``faces`` (F, 3) (:func:`meshcurv.lattice.soup_frame`; the
    grid's ``frame``), or None; ``frame`` those axes where they were read (None: not read, or none found).

    A voxel surface whose faces were detached and welded back across the cracks keeps the vertices that kept their
    place on its grid's planes, in any pose: the reading of :func:`soup_voxel_grid` (``quadric``) and of
    :func:`meshcurv.estimators._ring_noise.welded_grid` (the ring methods, ``normal_cycle_ball``)."""
    for part in parts:
        found = _grid_part(vertices, part, share)
        if found is not None:
            return found, None
    frame = soup_frame(vertices, faces)
    if frame is None:
        return None, None
    snapped = _snapped(vertices @ frame.T)
    for part in parts:
        found = _grid_part(snapped, part, share)
        if found is not None:
            return (found[0]._replace(frame=frame), found[1]), frame
    return None, frame


def _snapped(points: np.ndarray) -> np.ndarray:
    """``points`` (N, 3) with each coordinate within :data:`GRID_SNAP` of their extent (plus their round-off) of the
    one before it (in sorted order, along each axis) replaced by the first of its run: a plane's coordinates, turned
    into the grid's axes, equal again (they differed by round-off). The extent, not the largest ``|coordinate|``:
    the same wherever the mesh sits (a tolerance growing with the distance from the origin read no grid at 1e5
    sizes away, and a grid of spacing 0 at 2**20)."""
    extent = float(np.ptp(points, axis=0).max())
    tolerance = GRID_SNAP * extent + 8.0 * np.finfo(float).eps * float(np.abs(points).max())
    snapped = points.copy()
    for k in range(3):
        order = np.argsort(points[:, k], kind="stable")
        values = points[order, k]
        starts = np.concatenate([[True], np.diff(values) > tolerance])
        snapped[order, k] = values[starts][np.cumsum(starts) - 1]
    return snapped


def _voxel_surface(
    mesh: PreparedMesh,
    invalid: np.ndarray,
    *,
    valid: np.ndarray | None = None,
    reading: VoxelReading | None = None,
) -> bool:
    """Whether the mesh is a voxel surface, or its faces with a corner not ``invalid`` are, or (with ``valid``)
    most of its valid vertices lie on a grid (:func:`_voxel_surface_grid`)."""
    return _voxel_surface_grid(mesh, invalid=invalid, valid=valid, reading=reading) is not None


def _off_grid_scale(scales: np.ndarray, spacing: np.ndarray) -> bool:
    """Whether a part of the mesh (``scales``: the length scales of its vertices) is of another scale than the
    voxel grid found, beyond :data:`meshcurv.geometry.COMPONENT_SCALE_SPREAD` of its voxel sizes.

    Such a part lies "on" the grid only within the grid's tolerance (a part of 2 units beside a voxel surface of
    1e12 units, issue 29), and a voxel radius (at least a voxel) would measure it whole: the mesh is then taken
    as an ordinary one, each group of components of one scale at its own radius.
    """
    scales = scales[scales > 0]  # (a part whose edges all have length 0 has no scale)
    if scales.size == 0:
        return False
    return bool(
        scales.min() * COMPONENT_SCALE_SPREAD < np.min(spacing)
        or scales.max() > COMPONENT_SCALE_SPREAD * np.max(spacing)
    )


#: The scale of each vertex of a voxel surface (:func:`voxel_vertex_radii`, ``icc``'s default):
#: ``r_v = VOXEL_LOCAL_GAIN h_v^a R^(1 - a)`` with ``a = VOXEL_LOCAL_EXPONENT`` ...
VOXEL_LOCAL_GAIN = 2.0
VOXEL_LOCAL_EXPONENT = 0.5
#: ... at most ``VOXEL_LOCAL_CAP / c_v`` (``c_v`` the vertex's curvedness) ...
VOXEL_LOCAL_CAP = 1.0
#: ... and ``VOXEL_GAUSS_CAP / sqrt(|K_v|)`` ...
VOXEL_GAUSS_CAP = 0.5
#: ... and ``sqrt(area / (LADDER_AREA pi))`` (normal fits over half a sphere of the surface's area), and
#: ``VOXEL_CAP R`` (:func:`voxel_radius`) except on the tube-like vertices, curved one way
#: (``sqrt|K_v| <= c_v / VOXEL_TUBE``), where it rises to ``1 / c_v``;
#: at least the largest voxel size. The normals are fitted over ``min(3 r_v, max(VOXEL_NORMAL_CAP / c_v,
#: VOXEL_NORMAL_VOXELS h_max))``.
VOXEL_NORMAL_CAP = 1.5
VOXEL_NORMAL_VOXELS = 4.0
#: The normal fits' radius over the measure radius (as icc's ``NORMAL_RADIUS_RATIO`` elsewhere). 2 and 4 were
#: worse on the tuning voxel meshes (geometric mean of the median H error 1.30% -> 1.75% and 1.36%), as were
#: ``VOXEL_NORMAL_CAP`` 1.0 and 2.0 (1.62%, 1.35%; ``benchmarks/scale_default.md``).
VOXEL_NORMAL_RATIO = 3.0
#: The pilot's curvatures are averaged over this many rings of each vertex.
VOXEL_LOCAL_RINGS = 2
#: The region whose most curved vertex sets a vertex's curvature radius: at most this many rings.
VOXEL_REGION_RINGS = 24
#: ... when that radius exceeds this many times the surface's (fully from twice this).
VOXEL_REGION_APART = 2.0
#: A vertex is tube-like in proportion to ``1 - VOXEL_TUBE sqrt|K_v| / c_v`` (clipped to [0, 1]).
VOXEL_TUBE = 2.0

#: How ``parameters["scale_rule"]`` names the rule.
VOXEL_SCALE_RULE = (
    "voxel: r_v = max(h_max, min(2 sqrt(h_v R), 1 / c_v, 0.5 / sqrt|K_v|, sqrt(area / (18 pi)), "
    "R / 2 + t_v (1 / c_v - R / 2)+)), t_v = clip(1 - 2 sqrt|K_v| / c_v, 0, 1), h_v the voxel "
    "extent along the pilot's normal, R the surface's curvature radius (a region flatter than 2 R: its "
    "own), c_v and K_v the pilot's "
    "curvedness and Gaussian curvature over 2 rings; normals over min(3 r_v, max(1.5 / c_v, 4 h_max))"
)


def _ring_max(neighbour_lists: tuple, rings: int, values: np.ndarray) -> np.ndarray:
    """(V,) the largest of ``values`` over each vertex and the vertices within ``rings`` edges of it
    (:func:`meshcurv.neighborhoods.ring_max`: compiled, on threads, with numba)."""
    return ring_max(neighbour_lists, rings, values)


def voxel_vertex_radii(
    spacing,
    normals: np.ndarray,
    k_min: np.ndarray,
    k_max: np.ndarray,
    valid: np.ndarray,
    curvature_radius: float,
    neighbour_lists: tuple,
    fallback: float,
    *,
    area: float = np.inf,
    rings: int = 0,
) -> tuple[np.ndarray, np.ndarray]:
    """``(radii, normal_radii)`` (V,): the measure and normal-fit radius of each vertex of a voxel surface.

    Parameters
    ----------
    spacing : array_like of shape (3,)
        The voxel sizes along x, y, z (:func:`meshcurv.lattice.voxel_grid`).
    normals : ndarray of shape (V, 3)
        The pilot's unit normals.
    k_min, k_max : ndarray of shape (V,)
        The pilot's principal curvatures (``icc`` at :data:`VOXEL_PILOT` voxels); a vertex whose curvedness is
        below :data:`VOXEL_FLAT_CURVEDNESS` over the largest voxel size is flat (0).
    valid : ndarray of shape (V,) of bool
        The vertices whose pilot values are used.
    curvature_radius : float
        The surface's typical radius of curvature ``R`` (:func:`voxel_surface_radius`).
    neighbour_lists : tuple of ndarray
        The mesh's edge lists (:attr:`meshcurv.topology.MeshTopology.neighbour_lists`).
    fallback : float
        The radius of the vertices without pilot values in reach (:func:`voxel_radius`).
    area : float, default: inf
        The surface's area: no radius exceeds ``sqrt(area / (LADDER_AREA pi))`` (as the adaptive ladder).
    rings : int, default: 0
        The region of a vertex: its curvature radius ``R_v`` is that of the most curved vertex within this
        many rings (about the ball of ``fallback`` in edge lengths); 0: the vertex alone.

    Returns
    -------
    radii, normal_radii : ndarray of shape (V,)

    Notes
    -----
    The staircase of the voxels is noise whose amplitude at a vertex is the
    voxel's extent along the normal, ``h_v = |diag(spacing) n_v|`` (in
    anisotropic voxels it changes with the orientation of the surface: a factor
    4 between the faces of a sphere at 2 x 0.5 x 0.5). The radius grows with it
    as ``r_v = G h_v^a R^(1 - a)`` (:data:`VOXEL_LOCAL_GAIN` 2,
    :data:`VOXEL_LOCAL_EXPONENT` 1/2: the balance of the ball's bias with the
    staircase's noise of :func:`voxel_radius`, each vertex with its own ``h_v``;
    ``a = 2/3``, ``G = 2.5`` was 10% worse on the tuning meshes), and is capped where the pilot sees the surface bend
    fast: ``1 / c_v`` (a thin tube, ``c_v = max(|k_min|, |k_max|)`` averaged
    over :data:`VOXEL_LOCAL_RINGS` rings) and ``0.5 / sqrt(|K_v|)`` (a tip,
    curved both ways, where the curvature changes within the ball; a tube's
    ``K`` is small), and, as the rungs of the adaptive ladder, by
    ``sqrt(area / (18 pi))`` (:data:`LADDER_AREA`: a small closed surface, whose
    curvature changes within balls of a few voxels). The cap of the one-radius
    rule, ``R / 2`` (:data:`VOXEL_CAP`), stays where the surface is curved both
    ways: the flank of an ellipsoid next to its tip has a small curvature and a
    small ``K`` of its own, but its ball reaches the tip (a bias that the pilot,
    at two voxels, does not see); on a tube-like vertex (``k_min`` small
    against ``k_max``: ``t_v = 1 - 2 sqrt|K_v| / c_v`` clipped to [0, 1]) the cap
    rises towards ``1 / c_v``, which a tube needs in elongated voxels (a torus
    of tube radius 4 under 2 x 0.5 x 0.5 voxels: median H error of 25% of
    ``|H|`` at one radius for the surface). The radius is at least the largest voxel size (the
    staircase's period along the coarse axis; :data:`VOXEL_FLOOR` times it, off the lattice's distances). The normals are fitted over
    ``min(3 r_v, max(1.5 / c_v, 4 h_max))`` (:data:`VOXEL_NORMAL_CAP`,
    :data:`VOXEL_NORMAL_VOXELS`): a ball of three radii round a tube reaches
    its far side, where a jet no longer describes it (the isotropic tori of the
    tuning set: 1.5 to 1.0% median H error), but a fit spans a few of the
    longest voxels (the torus under 2 x 0.5 x 0.5 voxels: 8.0 against 6.8%). The exponents are dimensionless, so the radii scale
    with the mesh. Constants tuned on the binary marching-cubes meshes of
    ``benchmarks/accuracy.py --voxel`` (``benchmarks/scale_default.md``).
    """
    spacing = np.asarray(spacing, dtype=np.float64)
    largest = float(np.max(spacing))
    with np.errstate(invalid="ignore"):
        extent = np.sqrt(np.sum((normals * spacing) ** 2, axis=1))
        curvedness = np.maximum(np.abs(k_min), np.abs(k_max))
        gauss = np.abs(k_min * k_max)
    flat = curvedness <= VOXEL_FLAT_CURVEDNESS / largest  # round-off: 0, on both backends
    curvedness, gauss = np.where(flat, 0.0, curvedness), np.where(flat, 0.0, gauss)
    known = valid & np.isfinite(curvedness) & np.isfinite(gauss)
    extent = np.where(np.isfinite(extent) & (extent > 0), extent, largest)
    curvedness, gauss, weights = _ring_sums(
        neighbour_lists,
        VOXEL_LOCAL_RINGS,
        np.where(known, curvedness, 0.0),
        np.where(known, gauss, 0.0),
        known.astype(np.float64),
    )
    reached = weights > 0
    weights = np.where(reached, weights, 1.0)
    curvedness, gauss = curvedness / weights, gauss / weights
    # a region whose most curved vertex within `rings` rings (its ball) is much flatter than the surface's
    # typical curvature radius R (another part: a big sphere beside a thin tube) takes its own, 2 to 4 R
    # passing from one to the other (the flank of an ellipsoid, within 2 R, keeps R: its ball reaches the tip)
    region = _ring_max(neighbour_lists, rings, np.where(reached, curvedness, 0.0))
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(region > 0, 1.0 / (region * curvature_radius), 1.0)
        share = np.clip((ratio - VOXEL_REGION_APART) / VOXEL_REGION_APART, 0.0, 1.0)
        curvature_radius = curvature_radius * ratio**share  # type: ignore[assignment]  # (V,) from here on
    a = VOXEL_LOCAL_EXPONENT
    radii = VOXEL_LOCAL_GAIN * extent**a * curvature_radius ** (1.0 - a)
    with np.errstate(divide="ignore"):
        radii = np.minimum(radii, VOXEL_LOCAL_CAP / curvedness)
        radii = np.minimum(radii, VOXEL_GAUSS_CAP / np.sqrt(gauss))
        radii = np.minimum(radii, np.sqrt(area / (LADDER_AREA * np.pi)))
        tube = np.clip(1.0 - VOXEL_TUBE * np.sqrt(gauss) / np.where(curvedness > 0, curvedness, np.inf), 0.0, 1.0)
        general = VOXEL_CAP * curvature_radius
        radii = np.minimum(radii, general + tube * np.maximum(1.0 / curvedness - general, 0.0))
    radii = np.maximum(radii, VOXEL_FLOOR * largest)
    with np.errstate(divide="ignore"):
        normal_radii = np.minimum(
            VOXEL_NORMAL_RATIO * radii,
            np.maximum(VOXEL_NORMAL_CAP / curvedness, VOXEL_NORMAL_VOXELS * VOXEL_FLOOR * largest),
        )
    unknown = ~reached | ~np.isfinite(radii)
    radii[unknown], normal_radii[unknown] = fallback, VOXEL_NORMAL_RATIO * fallback
    return radii, normal_radii


#: The local edge length of a vertex is averaged (in log) over this many rings around it.
LOCAL_RINGS = 2
#: Local edge lengths within this factor of the component's median keep the component's radius ...
LOCAL_EVEN = 2.0
#: ... beyond this factor the radius follows them in proportion; in between it passes from one to the other.
LOCAL_FOLLOW = 4.0


def _ring_sums(neighbour_lists: tuple, rings: int, *arrays: np.ndarray) -> list[np.ndarray]:
    """Each of ``arrays`` (V, ...) summed ``rings`` times over every vertex and its edge neighbours
    (``neighbour_lists``: :attr:`meshcurv.topology.MeshTopology.neighbour_lists`;
    :func:`meshcurv.neighborhoods.ring_sums`: compiled, on threads, with numba)."""
    return ring_sums(neighbour_lists, rings, *arrays)


def local_scale_ratios(vertices: np.ndarray, topology: MeshTopology) -> np.ndarray:
    """(V,) the factor of each vertex's radius over its component's: how much coarser or finer it is sampled.

    ``rho_v`` is the vertex's mean edge length averaged in log over its
    :data:`LOCAL_RINGS` rings (the geometric mean of about 19 vertices on an
    even mesh), over the median edge length of its connected component
    (:func:`meshcurv.geometry.vertex_length_scales`). The factor is 1 while
    ``rho_v`` is within :data:`LOCAL_EVEN` of 1 (the spread of a triangulation
    of even density: 0.46-1.77 on the meshes of ``benchmarks/accuracy.py``),
    ``rho_v`` itself beyond :data:`LOCAL_FOLLOW` (a real change of
    resolution: a decimated or adaptively remeshed part), linear in log in
    between (continuous), and clipped to ``[1 / 16, 16]``
    (:data:`meshcurv.geometry.COMPONENT_SCALE_SPREAD`). Vertices without edges get 1.
    Only the edges between two :func:`meshcurv.defects.scale_vertices` count (a needle's edges, 1e3 long
    beside edges of 0.1, would make its neighbours' radii 9 times larger).
    """
    return _local_scale_ratios(_measured(vertices, topology))


def _local_scale_ratios(mesh: _Measured | PreparedMesh) -> np.ndarray:
    topology, scales = mesh.topology, mesh.length_scales
    n = topology.n_vertices
    local = mesh.scale_edge_means
    known = np.isfinite(local) & (local > 0) & (scales > 0)
    if not known.any():
        return np.ones(n)
    raw = local[known] / scales[known]
    if raw.min() >= 1.0 / LOCAL_EVEN and raw.max() <= LOCAL_EVEN:  # the ring means of these stay within too
        return np.ones(n)
    logs = np.where(known, np.log(np.where(known, local, 1.0) / np.where(known, scales, 1.0)), 0.0)
    logs, weights = _ring_sums(topology.neighbour_lists, LOCAL_RINGS, logs, known.astype(np.float64))
    with np.errstate(invalid="ignore", divide="ignore"):
        logs = np.where(weights > 0, logs / np.where(weights > 0, weights, 1.0), 0.0)
    even, follow = np.log(LOCAL_EVEN), np.log(LOCAL_FOLLOW)
    size = np.abs(logs)
    factor = np.where(size <= even, 0.0, np.where(size >= follow, size, (size - even) * follow / (follow - even)))
    limit = np.log(COMPONENT_SCALE_SPREAD)
    return np.exp(np.clip(np.sign(logs) * factor, -limit, limit))


def vertex_radii(groups: list[tuple[float, np.ndarray | None]], n_vertices: int) -> np.ndarray:
    """(V,) the radius of each vertex from ``[(radius, members or None), ...]`` (:func:`component_radii`).

    Parameters
    ----------
    groups : list of (float, ndarray or None)
        Each group's radius (finite, >= 0: 0 for a mesh without edges) and the ids of its vertices
        (1-d, in ``[0, n_vertices)``); ``members`` None: every vertex (a mesh of one scale, the only group).
    n_vertices : int
        V.

    Returns
    -------
    ndarray of shape (V,)
        NaN at the vertices of no group.

    Raises
    ------
    InvalidOptionError
        ``groups`` is not a non-empty list of pairs, a radius is not a finite number >= 0, a group of every
        vertex (None) is not the only group, ``n_vertices`` is not a positive integer.
    InvalidMeshError
        ``members`` that are not 1-d vertex ids in range.
    """
    n_vertices = check_vertex_count(n_vertices)
    if isinstance(groups, (str, bytes)) or not isinstance(groups, (list, tuple)) or not groups:
        raise InvalidOptionError(f"`groups` must be a non-empty list of (radius, members) pairs; got {groups!r:.60}")
    checked = []
    for group in groups:
        if not isinstance(group, (list, tuple)) or len(group) != 2:
            raise InvalidOptionError(f"`groups` must hold (radius, members) pairs; got {group!r:.60}")
        radius, members = group
        if members is None and len(groups) > 1:
            raise InvalidOptionError("`groups`: members None (every vertex) is only allowed in a list of one group")
        ids = None if members is None else _checked_ids(members, n_vertices, name="members")
        checked.append((_length(radius, "radius"), ids))
    return _vertex_radii(checked, n_vertices)


def _length(value, name: str) -> float:
    """``value`` as a float, finite and >= 0 (:func:`check_positive_float`, 0 let through)."""
    if isinstance(value, numbers.Real) and not isinstance(value, (bool, np.bool_)) and value == 0:
        return 0.0
    try:
        return check_positive_float(value, name)
    except InvalidOptionError:
        raise InvalidOptionError(f"`{name}` must be a finite number >= 0; got {value!r:.40}") from None


def _vertex_radii(groups: list[tuple[float, np.ndarray | None]], n_vertices: int) -> np.ndarray:
    """:func:`vertex_radii` of checked ``groups`` (those of :func:`_component_radii`, :func:`_noise_radii`)."""
    radii = np.full(n_vertices, groups[0][0] if groups[0][1] is None else np.nan)
    for radius, members in groups:
        if members is not None:
            radii[members] = radius
    return radii


#: The adaptive scale (``radius="adaptive"``): rungs ``r0 sqrt(2)^j`` from the default radius ``r0``...
LADDER_RATIO = float(np.sqrt(2.0))
#: ... up to this many median edge lengths ...
LADDER_HIGH = 12.0
#: ... and never a ball whose normal fits (three radii) would cover half a sphere of the surface's area:
#: ``r <= sqrt(area / (LADDER_AREA pi))``.
LADDER_AREA = 18.0
#: The change between rungs is averaged over this many rings of each vertex ...
STABLE_RINGS = 2
#: ... and mixed with its median over the mesh with this weight.
STABLE_POOL = 0.5


def scale_ladder(base: float, median_edge: float, area: float) -> np.ndarray:
    """The radii of the adaptive scale: ``base sqrt(2)^j`` up to ``min(12 h, sqrt(area / (18 pi)))``, at least 2.

    ``base`` is the default radius (:func:`noise_radius`, :func:`voxel_radius`), ``h`` the median edge
    length. From ``benchmarks/scale.md`` (variant B, the ladder anchored at the default).
    """
    top = min(LADDER_HIGH * median_edge, float(np.sqrt(area / (LADDER_AREA * np.pi))))
    count = int(np.floor(np.log(max(top, base) / base) / np.log(LADDER_RATIO) + 1e-9)) + 1
    return base * LADDER_RATIO ** np.arange(max(count, 2))


def stable_scales(k_min: np.ndarray, k_max: np.ndarray, neighbour_lists: tuple) -> np.ndarray:
    """(V,) the rung of each vertex where its estimates change least along the ladder.

    ``k_min``, ``k_max`` (J, V): the curvatures at the J rungs of :func:`scale_ladder`. The change
    ``D_j = |dH| + |dk_min| + |dk_max|`` between rungs ``j`` and ``j + 1`` is averaged over the
    :data:`STABLE_RINGS` rings of each vertex and mixed half and half with its median over the mesh
    (:data:`STABLE_POOL`); the vertex takes the upper rung of the pair where it is smallest, or the
    first rung when that pair is the first (its estimates agree from the start). Noise error falls
    and bias grows with the radius: the estimate is flattest where they balance, which needs no model
    of the noise (a Lepski rule with one, measured, did worse: ``benchmarks/scale.md``).
    """
    mean = 0.5 * (k_min + k_max)
    change = np.abs(np.diff(mean, axis=0)) + np.abs(np.diff(k_min, axis=0)) + np.abs(np.diff(k_max, axis=0))
    finite = np.isfinite(change)
    total, count = _ring_sums(
        neighbour_lists, STABLE_RINGS, np.where(finite, change, 0.0).T, finite.astype(np.float64).T
    )
    with np.errstate(invalid="ignore", divide="ignore"):
        local = (total / count).T
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # a rung NaN at every vertex
        pooled = np.nanmedian(local, axis=1, keepdims=True)
    mixed = (1 - STABLE_POOL) * local + STABLE_POOL * pooled
    mixed = np.where(np.isfinite(mixed), mixed, np.inf)
    best = np.argmin(mixed, axis=0)
    return np.where(best == 0, 0, np.minimum(best + 1, k_min.shape[0] - 1))


# -- point clouds (meshcurv.point_cloud_curvatures) ----------------------------------------------------

#: The default radius of a point cloud, ``s (a + b sqrt(max(nu - NOISE_FLOOR, 0)))`` for a median spacing
#: ``s`` and noise level ``nu`` (in spacings), per method: ``(a, b)`` (a sweep of ``benchmarks/pointcloud.py``).
CLOUD_RADIUS_RULES = {"corrected_measures": (3.0, 11.0), "jets": (3.0, 22.0)}

#: A cloud's noise level is measured with degree-2 jets over balls of this many spacings ...
CLOUD_NOISE_FIT_RADIUS = 3.0

#: ... on about this many points (at least), chosen by a key that neither the pose nor the index changes
#: (:func:`_intrinsic_sample`) ...
CLOUD_NOISE_SAMPLE = 16384

#: ... and is their median over the balls fitted on one side, when at least this many are (or half of the sample,
#: when that is fewer); NaN otherwise: the few balls that noise leaves one-sided are no sample of the cloud
#: (``benchmarks/pointcloud_diagnostics.md``).
CLOUD_NOISE_LEAST_FITS = 10

#: A default radius is at most this share of the cloud's :func:`rigid_extent` (the diagonal of the cube around its
#: smallest enclosing ball: a round cloud's bounding-box diagonal, in every pose).
CLOUD_EXTENT_CAP = 0.25


def cloud_noise_level(points, normals, spacing, centres, usable, *, facing=None) -> float:
    """Median distance of the points to degree-2 jets over :data:`CLOUD_NOISE_FIT_RADIUS` spacings, in spacings.

    ``centres`` are the usable points, of which about :data:`CLOUD_NOISE_SAMPLE` are fitted, chosen by their
    spacing (the distance to their nearest neighbour among ``usable``) and their distance to the centres'
    centroid (:func:`_intrinsic_sample`): the level is the same in every pose and order of the points.
    A ball holding points that face away from its centre (more than :data:`meshcurv.jets.AWAY_FRACTION` of it,
    the ``facing`` check of :func:`meshcurv.jets.fit_jets`: the other face of a part thinner than the ball, or
    another part) is not fitted: a jet through both faces of a plate reads half its thickness as noise, and the
    radius that noise calls for reaches across the whole cloud (``benchmarks/pointcloud.md``, "a thin part read
    as noise").

    Parameters
    ----------
    points : array_like of shape (P, 3)
        Finite coordinates.
    normals : array_like of shape (P, 3)
        Unit normals of the fits' first frames (NaN where there is none: no fit there).
    spacing : float
        The cloud's median spacing, finite and >= 0 (0: coincident points, no noise measured: 0).
    centres : array_like of shape (M,), int
        The ids of the points to fit around.
    usable : array_like of shape (P,), bool
        The points that may enter the balls.
    facing : array_like of shape (P, 3), optional
        The normals of the check (default: ``normals``; a zero row faces away from every centre: a point whose side
        is undecided).

    Returns
    -------
    float
        NaN when fewer than :data:`CLOUD_NOISE_LEAST_FITS` balls (or half of the sample) are fitted on one side:
        no level is measured (noise of about a spacing or more, whose turned normals face away in every ball, or a
        part thinner than the ball). 0 when ``spacing`` is 0.

    Raises
    ------
    InvalidMeshError
        ``points``, ``normals``, ``centres`` or ``usable`` of the wrong shape, dtype or range; NaN or infinite
        points.
    InvalidOptionError
        ``spacing`` is not a finite number >= 0.
    """
    points = checked_points(points, name="points")
    n = points.shape[0]
    normals = _floats(normals, "normals", (n, 3))
    spacing = _length(spacing, "spacing")
    centres = _checked_ids(centres, n)
    usable = checked_mask(usable, n, name="usable")
    facing = normals if facing is None else _floats(facing, "facing", (n, 3))
    return _cloud_noise_level(points, normals, spacing, centres, usable, facing)


def _cloud_noise_level(points, normals, spacing: float, centres, usable, facing, problems=None, *, local=None) -> float:
    """:func:`cloud_noise_level` of checked arrays; where it is NaN, the note of the call is added to ``problems``
    (a list). ``local`` (P,): each point's own spacing, the key of the sample (:func:`_intrinsic_sample`; default:
    the distance to its nearest neighbour among ``usable``)."""
    if spacing <= 0 or centres.size == 0:
        return 0.0
    sample = centres
    if centres.size > CLOUD_NOISE_SAMPLE:
        lengths = _nearest_distances(points, centres, usable) if local is None else local[centres]
        positive = lengths > 0  # (a point on another has no spacing to key it by: left out of the sample)
        sample = centres[positive][_intrinsic_sample(points[centres[positive]], lengths[positive], CLOUD_NOISE_SAMPLE)]
    radius = CLOUD_NOISE_FIT_RADIUS * spacing
    coefficients, _, _ = _fit_jets(
        points, normals, radius, degree=2, iterations=1, centres=sample, neighbours=usable, facing=facing
    )
    heights = np.abs(coefficients[sample, 0]) * CLOUD_NOISE_FIT_RADIUS  # c00 is in units of the radius
    heights = heights[np.isfinite(heights)]
    if heights.size and heights.size >= min(CLOUD_NOISE_LEAST_FITS, (sample.size + 1) // 2):
        return float(np.median(heights))
    if problems is not None:
        problems.append(
            f"the noise level was not measured (parameters['noise'] is NaN): {heights.size} of the {sample.size} "
            f"balls of {CLOUD_NOISE_FIT_RADIUS:g} spacings sampled were fitted on one side, the others held points "
            "facing the other way or too few (noise of about a spacing or more, which turns the normals, or a part "
            "thinner than the ball); the radius rules take the level of a clean sample"
        )
    return np.nan


def _nearest_distances(points, centres, usable) -> np.ndarray:
    """(M,) the distance of each of ``centres`` to its nearest other point among ``usable``."""
    from scipy.spatial import cKDTree  # imported on use: keeps `import meshcurv` fast

    pool = np.flatnonzero(usable)
    if pool.size < 2:
        return np.zeros(centres.size)
    distances, found = cKDTree(points[pool]).query(points[centres], k=2)
    return np.where(pool[found[:, 0]] == centres, distances[:, 1], distances[:, 0])


def _checked_radii(radii) -> list[float]:
    """The ``radii`` of a multi-scale call: a non-empty sequence of positive finite numbers, as floats."""
    if isinstance(radii, (str, bytes)) or np.ndim(radii) != 1 or len(radii) == 0:
        raise InvalidOptionError(f"`radii` must be a non-empty sequence of radii; got {radii!r}")
    return [check_positive_float(radius, "radii") for radius in radii]


def _notes_by_radius(notes: dict[float, str]) -> str:
    """The one warning of a multi-scale call from each radius's notes (``""``: none has any): the note
    they all share, or each radius's own, named with it."""
    texts = set(notes.values())
    if not any(texts):
        return ""
    if len(texts) == 1:
        return texts.pop()
    return "; ".join(f"at radius {radius:g}: {text}" for radius, text in notes.items() if text)


def noise_rule(rule, spacing: float, noise: float) -> float:
    """``spacing (a + b sqrt(max(noise - NOISE_FLOOR, 0)))`` for ``rule = (a, b)``."""
    return float(_noise_rule(rule, spacing, noise))


def _noise_rule(rule, spacing, noise):
    """:func:`noise_rule` of numbers or arrays (elementwise)."""
    a, b = rule
    return spacing * (a + b * np.sqrt(np.maximum(noise - NOISE_FLOOR, 0.0)))


def cloud_radius(spacing: float, noise: float, method: str = "corrected_measures") -> float:
    """The default radius of a point cloud's ``method`` at this median ``spacing`` and ``noise`` (in spacings)."""
    return noise_rule(CLOUD_RADIUS_RULES[method], spacing, noise)


#: A patch of a group of components noisier than the group (:func:`_patch_radii`): each vertex's noise level is
#: the spread (standard deviation) of the noise fits' signed offsets over this many rings ...
PATCH_RINGS = 2
#: ... and its radius is :func:`noise_radius` of that level where it exceeds the group's by more than this factor
#: (every clean mesh of ``benchmarks/accuracy.py --quick`` stays below it; at 1.25 the coarse irregular
#: ellipsoid, whose fits' bias changes from vertex to vertex, grew at 59% of its vertices, p95 H error 7 -> 24%) ...
PATCH_MARGIN = 2.0
#: ... passing from the group's radius to it over this factor beyond the margin (continuous).
PATCH_RAMP = 1.25
#: ... and at most this many of its radii of curvature (``1 / c_v``, the fits' curvedness over the same vertices,
#: noise included): a coarse clean surface's fits are biased where it bends fast, where no larger ball helps.
PATCH_CAP = 1.0
#: A vertex takes the largest growth within this many rings of it (its ball holds the patch's noise).
PATCH_REACH = 1


#: ... or, where the rings are smaller than this (walks along them: 9 at the corners of a face alone, 16 or more
#: inside a closed mesh of valence 3 or more), over the Euclidean ball of :data:`NOISE_FIT_RADIUS` edge lengths
#: (the noise fits' own ball).
PATCH_LEAST = 12


def _patch_levels(
    vertices: np.ndarray, neighbour_lists: tuple, fits: list, edge: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """``(levels, curvedness)`` (V,): each vertex's noise level, the standard deviation of the signed offsets of
    the noise fits ``fits`` (``[(centres, offsets, curvedness), ...]``, :func:`_noise_level`) within
    :data:`PATCH_RINGS` rings, or within
    :data:`NOISE_FIT_RADIUS` times ``edge`` (V,) of the vertex where its rings are small (:data:`PATCH_LEAST`),
    and the root mean square of the fits' curvedness over the same vertices; NaN where no fit is.

    The spread of the signed offsets, not the median distance of :func:`noise_level`: a jet's bias on a clean
    surface (the third-order terms at a coarse ellipsoid's tips) has one sign over a region and leaves it, while
    noise changes sign from vertex to vertex; and a noisy patch is seen where its vertices are a minority of a
    vertex's rings (the corners of faces detached among intact ones), whose offsets the median would leave out."""
    n_vertices = vertices.shape[0]
    values, known = np.zeros((n_vertices, 3)), np.zeros(n_vertices)
    for centres, offsets, curvedness in fits:
        fitted = np.isfinite(offsets) & np.isfinite(curvedness)
        values[centres[fitted]] = np.stack([offsets[fitted], offsets[fitted] ** 2, curvedness[fitted] ** 2], axis=1)
        known[centres[fitted]] = 1.0
    sums, weights, walks = _ring_sums(neighbour_lists, PATCH_RINGS, values, known, np.ones(n_vertices))
    # (the mesh's rings, not its fits': on a mesh of more than NOISE_SAMPLE vertices few vertices are fitted)
    sparse_rows = np.flatnonzero((walks < PATCH_LEAST) & np.isfinite(edge) & (edge > 0))
    fitted = np.flatnonzero(known > 0)
    if sparse_rows.size and fitted.size:
        from scipy.spatial import cKDTree  # imported where used: scipy.spatial costs a fresh process 0.13 CPU s

        reach = NOISE_FIT_RADIUS * edge[sparse_rows]
        balls = cKDTree(vertices[fitted]).query_ball_point(vertices[sparse_rows], reach)
        counts = np.fromiter(map(len, balls), dtype=np.int64, count=sparse_rows.size)
        members = fitted[np.concatenate(balls).astype(np.int64)] if counts.sum() else np.zeros(0, dtype=np.int64)
        rows = np.repeat(np.arange(sparse_rows.size), counts)
        for k in range(3):
            sums[sparse_rows, k] = np.bincount(rows, values[members, k], minlength=sparse_rows.size)
        weights[sparse_rows] = counts
    with np.errstate(invalid="ignore", divide="ignore"):
        means = sums / np.where(weights > 0, weights, 1.0)[:, None]
        spread = np.sqrt(np.maximum(means[:, 1] - means[:, 0] ** 2, 0.0))
    reached = weights > 0
    return np.where(reached, spread, np.nan), np.where(reached, np.sqrt(means[:, 2]), np.nan)


def _patch_factor(mesh: _Measured | PreparedMesh, fits: list, edge: np.ndarray, base: np.ndarray) -> np.ndarray:
    """(V,) the factor of each vertex's radius over ``base`` (V,) from the noise ``fits`` (:func:`_patch_radii`)."""
    if not _patch_possible(fits, edge, base):  # every factor 1: the rings of the levels not summed
        return np.ones(mesh.vertices.shape[0])
    local, curvedness = _patch_levels(mesh.vertices, mesh.topology.neighbour_lists, fits, edge)
    with np.errstate(invalid="ignore", divide="ignore"):
        wanted = edge * (1.0 + NOISE_GAIN * np.sqrt(np.maximum(local - NOISE_FLOOR, 0.0)))
        # at most PATCH_CAP radii of curvature (the fits' curvedness, the noise's share left in: a clean surface's
        # bias read as noise would take its own curvature away)
        wanted = np.minimum(wanted, np.where(curvedness > 0, PATCH_CAP / curvedness, np.inf))
        q = np.where(np.isfinite(wanted) & (base > 0), wanted / base, 1.0)
        share = np.clip(np.log(np.maximum(q, 1.0) / PATCH_MARGIN) / np.log(PATCH_RAMP), 0.0, 1.0)
    factor = np.where(q > PATCH_MARGIN, q**share, 1.0)
    # a vertex beside the patch holds its noise in its ball: the largest factor within PATCH_REACH rings
    return _ring_max(mesh.topology.neighbour_lists, PATCH_REACH, factor)


def _patch_possible(fits: list, edge: np.ndarray, base: np.ndarray) -> bool:
    """False when no vertex can be a noisy patch: the largest signed offset of the ``fits`` (its size ``L``) bounds
    every vertex's level (:func:`_patch_levels`: the spread of some of the offsets, at most the root of their mean
    square, at most ``L``; taken ``L (1 + 1e-6)`` for the rounding of those sums), and the ratio ``q`` of
    :func:`_patch_factor` computed at that level, in the same operations (each rounding is monotone), stays at or
    below :data:`PATCH_MARGIN` everywhere (a NaN ``q``: a vertex that keeps its radius). Then every factor is 1
    (on a clean smooth mesh the offsets are the fits' bias, 1e-8 edge lengths on a 1M icosphere: the rings of
    the levels cost 0.2 CPU s there)."""
    largest = 0.0
    for _, offsets, curvedness in fits:
        fitted = np.isfinite(offsets) & np.isfinite(curvedness)
        if fitted.any():
            largest = max(largest, float(np.max(np.abs(offsets[fitted]))))
    level = np.float64(largest * (1.0 + 1e-6))
    gain = 1.0 + NOISE_GAIN * np.sqrt(np.maximum(level - NOISE_FLOOR, 0.0))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        return bool(np.any(edge * gain / base > PATCH_MARGIN))


def _patch_radii(
    mesh: _Measured | PreparedMesh,
    groups: list[tuple[float, np.ndarray | None]],
    levels: list[float],
    fits: list,
    ratios: np.ndarray,
    normals: np.ndarray,
) -> tuple[np.ndarray, np.ndarray]:
    """``(base, radii)`` (V,): icc's default radius of each vertex without and with its noisy patch.

    ``base`` is the group's radius (:func:`_noise_radii`: ``groups``, their noise ``levels`` and ``fits``) times
    the vertex's local factor ``ratios`` (:func:`local_scale_ratios`), ``normals`` (V, 3) the vertex normals (NaN
    where none); ``radii`` is at least ``base``: where the
    vertex's own level (:func:`_patch_levels`) calls for a radius ``r_v`` (:func:`noise_radius`, in the group's
    edge lengths times the local factor, at most :data:`PATCH_CAP` over the fits' curvedness; the fits within reach
    of a patch made again without the balls that hold the other side of the surface) of ``q = r_v / base``
    more than ``m =`` :data:`PATCH_MARGIN`, it is ``base q^t`` with ``t = clip(log(q / m) / log(p), 0, 1)``
    (``p =`` :data:`PATCH_RAMP`: ``r_v`` from ``q = m p`` on, continuous); and at least ``base`` times
    :func:`_holed_factor` where its ball misses the surface beside a crack or detached faces.
    """
    n = mesh.vertices.shape[0]
    base = _vertex_radii(groups, n) * ratios
    edges = [
        (group_radius / (1.0 + NOISE_GAIN * np.sqrt(max(level - NOISE_FLOOR, 0.0))), members)
        for (group_radius, members), level in zip(groups, levels)
    ]
    edge = _vertex_radii(edges, n) * ratios
    factor = _patch_factor(mesh, fits, edge, base)
    if np.any(factor > 1.0):
        # the fits within reach of a patch again, refusing a ball that holds the other side of the surface (a part
        # thinner than the ball, whose two sides the fits read as noise: the rim of a 3 x 3 x 0.15 ellipsoid)
        reach = _ring_max(mesh.topology.neighbour_lists, PATCH_RINGS + PATCH_REACH, (factor > 1.0).astype(np.float64))
        refitted = []
        for centres, offsets, curvedness in fits:
            near = reach[centres] > 0
            if near.any():
                offsets, curvedness = offsets.copy(), curvedness.copy()
                offsets[near], curvedness[near] = _noise_fits(
                    mesh.vertices,
                    normals,
                    centres[near],
                    mesh.scale_edge_means[centres[near]],
                    neighbours=_scale_vertices(mesh.topology, mesh.needles),
                    facing=normals,
                    signed=True,
                )
            refitted.append((centres, offsets, curvedness))
        factor = _patch_factor(mesh, refitted, edge, base)
    return base, base * np.maximum(factor, _holed_factor(mesh, base, normals))


#: A vertex's ball beside a crack or detached faces (:func:`_holed_factor`): where its surface-connected part holds
#: less than this share of the disc ``pi r^2`` (an intact ball: 0.8 to 1; icc's ``HOLE_SHARE`` for a voxel
#: surface's holes) ...
HOLED_SHARE = 0.8
#: ... and the faces of the Euclidean ball that the surface-connected walk does not reach (faces detached beyond the
#: weld, the other side of a crack) hold at least this share of it (a rim: none; a hanging face's free corner:
#: 0.3-0.8; the welded corners of half-detached faces: 0.14 and more) ...
HOLED_BEYOND = 0.1
#: ... the radius grows by ``HOLED_SHARE / share``, at most this factor (icc's ``HOLE_GROWTH``) ...
HOLED_GROWTH = 2.0
#: ... and each vertex takes the largest growth within this many rings of it, about the reach of its normal fits
#: (icc's ``NORMAL_RADIUS_RATIO``): a cracked region at one scale. The corners welded across the cracks hold a full
#: disc of kinked faces with nothing beyond, yet read H off by half of it at the group's radius (a half-detached
#: icosphere(40): 3-9 per draw at one ring; an ellipsoid (3, 2, 1) at 32 subdivisions, 31% detached by 0.058 h: 22
#: at one ring, 10 at two, none at three; the coarse ellipsoid at 16 subdivisions: p95 of the H error 8.8% -> 9.8%).
HOLED_REACH = 3


def _holed_factor(mesh: _Measured | PreparedMesh, base: np.ndarray, normals: np.ndarray) -> np.ndarray:
    """(V,) the factor of each vertex's radius over ``base`` (V,) where its ball misses the surface around it.

    A face detached beyond the weld, or a crack, leaves a vertex a ball that holds a piece of one or two faces while
    the surface goes on beyond its boundary edges: its estimate is that of a few faces, whose corners' normals and
    kinks it amplifies (a unit icosphere(40) with half of its faces detached by 0.054 edge lengths: 20-60 valid
    vertices off by more than half of H at one edge length, none at 1.5). Such a vertex (finite ``normals``, on no
    fragment, within ``base`` of a boundary vertex) whose surface-connected ball holds a share ``s`` of its disc below
    :data:`HOLED_SHARE`, and whose Euclidean ball holds faces the connected one does not (at least
    :data:`HOLED_BEYOND` of the disc), grows by ``min(HOLED_SHARE / s, HOLED_GROWTH)``; then the largest factor
    within :data:`HOLED_REACH` rings. A rim (nothing beyond: a hemisphere, a saddle, a cylinder) and a closed mesh
    (no boundary edge: nothing computed) keep their radii. The shares are those of
    :func:`meshcurv.neighborhoods.face_in_ball_ratios` (needles' faces left out).
    """
    topology, vertices = mesh.topology, mesh.vertices
    n = vertices.shape[0]
    factor = np.ones(n)
    if not topology.boundary_edges.any():
        return factor
    finite = finite_rows(normals) & np.isfinite(base) & (base > 0)
    fragments = _fragment_vertices(topology)
    if fragments is not None:
        finite &= ~fragments
    rims = np.flatnonzero(topology.boundary_vertices)
    rows = np.flatnonzero(finite)
    if rows.size == 0 or rims.size == 0:
        return factor
    from scipy.spatial import cKDTree  # imported past the closed mesh's return: scipy.spatial costs 0.13 CPU s

    distance, _ = cKDTree(vertices[rims]).query(vertices[rows])
    ids = rows[distance <= base[rows]]
    if ids.size == 0:
        return factor
    faces = topology.faces
    corners = vertices[faces]
    areas = 0.5 * np.linalg.norm(np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]), axis=1)
    usable = ~mesh.needles[faces].any(axis=1) if mesh.needles.any() else np.ones(faces.shape[0], dtype=bool)
    radii = np.where(finite, base, np.max(base[ids]))  # the walks' radii (only those of ``ids`` are read)
    own = _ball_face_sums(vertices, faces, radii, areas[:, None], usable=usable, connected=True, centres=ids)[:, 0]
    disc = np.pi * base[ids] ** 2
    sparse = own < HOLED_SHARE * disc
    ids, own, disc = ids[sparse], own[sparse], disc[sparse]
    if ids.size == 0:
        return factor
    kept = np.flatnonzero(usable)
    centroids = corners[kept].mean(axis=1)
    reach = float(np.max(np.linalg.norm(corners[kept] - centroids[:, None, :], axis=2))) if kept.size else 0.0
    balls = cKDTree(centroids).query_ball_point(vertices[ids], base[ids] + reach)
    counts = np.fromiter(map(len, balls), dtype=np.int64, count=ids.size)
    members = kept[np.concatenate(balls).astype(np.int64)] if counts.sum() else np.zeros(0, dtype=np.int64)
    row = np.repeat(np.arange(ids.size), counts)
    shares = face_in_ball_ratios(corners[members], vertices[ids[row]], base[ids[row]])
    every = np.bincount(row, shares * areas[members], minlength=ids.size)
    holed = every - own >= HOLED_BEYOND * disc
    with np.errstate(divide="ignore"):
        factor[ids[holed]] = np.minimum(HOLED_SHARE * disc[holed] / own[holed], HOLED_GROWTH)
    return _ring_max(topology.neighbour_lists, HOLED_REACH, factor)
