"""Analytic surfaces as triangle meshes, with their exact curvatures at the vertices.

Shared by tests, documentation and benchmarks. Every function returns an
:class:`AnalyticMesh` whose faces are wound counter-clockwise seen from outside
(normals outward; for height fields, upward), so that the exact curvatures follow
meshcurv's sign convention: positive where the surface bends away from its normal.
The exception is the marching-cubes meshes of voxelised solids (:func:`voxel_sphere`,
:func:`voxel_ellipsoid`, :func:`voxel_torus`; they need scikit-image): their faces are
wound inward as marching cubes returns them, while their exact values are outward.

Examples
--------
>>> from meshcurv import shapes
>>> torus = shapes.torus()          # matGeom's torusMesh default: R 30, r 10, 60 x 60
>>> torus.vertices.shape, torus.faces.shape
((3600, 3), (7200, 3))
>>> float(torus.k_max.max())        # the tube: 1 / r
0.1
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ._validation import check_int_option, check_positive_float, checked_spacing
from .errors import InvalidMeshError, InvalidOptionError, optional_module
from .geometry import mean_edge_length
from .topology import MeshTopology

__all__ = [
    "AnalyticMesh",
    "icosphere",
    "uv_sphere",
    "torus",
    "ellipsoid",
    "cylinder",
    "saddle",
    "random_sphere",
    "random_ellipsoid",
    "hemisphere",
    "with_normal_noise",
    "VoxelMesh",
    "voxel_sphere",
    "voxel_ellipsoid",
    "voxel_torus",
    "ellipsoid_closest_points",
]


@dataclass(frozen=True, eq=False)
class AnalyticMesh:
    """A triangle mesh sampled from a surface with known curvatures.

    Attributes
    ----------
    name : str
    vertices : ndarray of shape (V, 3), float64
    faces : ndarray of shape (F, 3), int64
    k_min, k_max : ndarray of shape (V,)
        Exact principal curvatures at the vertices (1/length).
    dir_min, dir_max : ndarray of shape (V, 3)
        Exact principal directions; NaN at umbilics, where they are undefined.
    normals : ndarray of shape (V, 3)
        Exact unit normals, on the side the faces are wound towards.
    quads : ndarray of shape (Q, 4) or None
        The quad faces the triangles were split from, when the mesh is a quad grid.
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    k_min: np.ndarray
    k_max: np.ndarray
    dir_min: np.ndarray
    dir_max: np.ndarray
    normals: np.ndarray
    quads: np.ndarray | None = None

    @property
    def mean(self) -> np.ndarray:
        """(V,) exact mean curvature ``(k_min + k_max) / 2``."""
        return (self.k_min + self.k_max) / 2

    @property
    def gaussian(self) -> np.ndarray:
        """(V,) exact Gaussian curvature ``k_min * k_max``."""
        return self.k_min * self.k_max


def _analytic_fields(mesh: AnalyticMesh) -> dict:
    return {field.name: getattr(mesh, field.name) for field in dataclasses.fields(AnalyticMesh)}


def _make(name, vertices, faces, k_min, k_max, dir_min, dir_max, normals, quads=None) -> AnalyticMesh:
    k_min = np.broadcast_to(np.asarray(k_min, dtype=float), vertices.shape[:1]).copy()
    k_max = np.broadcast_to(np.asarray(k_max, dtype=float), vertices.shape[:1]).copy()
    scale = np.maximum(np.abs(k_min), np.abs(k_max))
    umbilic = np.abs(k_max - k_min) <= 1e-9 * np.maximum(scale, np.finfo(float).tiny)
    dir_min = np.array(np.broadcast_to(dir_min, vertices.shape), dtype=float)
    dir_max = np.array(np.broadcast_to(dir_max, vertices.shape), dtype=float)
    dir_min[umbilic] = np.nan
    dir_max[umbilic] = np.nan
    return AnalyticMesh(
        name=name,
        vertices=vertices,
        faces=np.ascontiguousarray(faces, dtype=np.int64),
        k_min=k_min,
        k_max=k_max,
        dir_min=dir_min,
        dir_max=dir_max,
        normals=np.asarray(normals, dtype=float),
        quads=quads,
    )


def _implicit(points: np.ndarray, gradient: np.ndarray, hessian6: np.ndarray):
    """Curvatures of the level set of F through ``points``, normal along grad F.

    Normal curvature along a unit tangent ``t`` is ``t^T Hess(F) t / |grad F|``:
    the principal curvatures and directions are the eigenpairs of ``P Hess(F) P
    / |grad F|`` in the tangent plane (``P = I - n n^T``). They are solved here
    with LAPACK (``numpy.linalg.eigh``), independently of the library's own 2x2
    solver (:func:`meshcurv._tensors.principal_from_shape_operator`), so that
    the exact values the tests compare with do not share its code. ``n n^T``
    times a large number is added to move the normal's eigenvalue above the
    others (a zero curvature would otherwise share its eigenvalue 0).
    """
    norm = np.linalg.norm(gradient, axis=1)
    normals = gradient / norm[:, None]
    xx, yy, zz, xy, xz, yz = (hessian6 / norm[:, None]).T
    hessian = np.stack([np.stack([xx, xy, xz], -1), np.stack([xy, yy, yz], -1), np.stack([xz, yz, zz], -1)], -2)
    projector = np.eye(3) - normals[:, :, None] * normals[:, None, :]
    shape = projector @ hessian @ projector
    lift = 1.0 + 10.0 * np.linalg.norm(shape, axis=(1, 2))
    values, vectors = np.linalg.eigh(shape + lift[:, None, None] * normals[:, :, None] * normals[:, None, :])
    # ascending: the two tangent eigenpairs first, the lifted normal last
    k_min, k_max = values[:, 0], values[:, 1]
    dir_min, dir_max = vectors[:, :, 0], vectors[:, :, 1]
    return k_min, k_max, dir_min, dir_max, normals


def _quads_to_triangles(quads: np.ndarray, rng: np.random.Generator | None = None) -> np.ndarray:
    """Split quads ``a, b, c, d`` into ``(a, b, c), (a, c, d)``, as matGeom's triangulateFaces.

    With a generator, each quad is split along a random diagonal instead
    (``(a, b, d), (b, c, d)`` half of the time).
    """
    first = np.stack([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]], axis=1)
    if rng is not None:
        other = np.stack([quads[:, [0, 1, 3]], quads[:, [1, 2, 3]]], axis=1)
        first = np.where(rng.random((quads.shape[0],))[:, None, None] < 0.5, first, other)
    return first.reshape(-1, 3)


def _jittered(coordinates, steps, bounds, jitter: float, seed: int):
    """The grid ``coordinates`` moved by ``jitter`` (:func:`torus`): ``(moved, generator, name suffix)``.

    Each array of ``coordinates`` in turn gets uniform noise in ``[-jitter *
    step, jitter * step]`` from one generator seeded with ``seed``, none where
    ``|value| >= bound`` (a boundary; no bound: None). Without jitter the
    coordinates are returned as they are, with no generator and no suffix.
    """
    if not jitter:
        return coordinates, None, ""
    if not 0 <= jitter < 0.5:
        raise InvalidOptionError(f"`jitter` must be in [0, 0.5) (a fraction of the grid spacing); got {jitter!r}")
    rng = np.random.default_rng(seed)
    moved = []
    for values, step, bound in zip(coordinates, steps, bounds):
        noise = rng.uniform(-jitter * step, jitter * step, size=values.shape)
        if bound is not None:
            noise[np.abs(values) >= bound] = 0.0
        moved.append(values + noise)
    return moved, rng, f", jitter {jitter:g}"


def _ellipsoid_exact(points: np.ndarray, semi_axes: np.ndarray):
    """:func:`_implicit` on the centred axis-aligned ellipsoid ``sum(x_k**2 / a_k**2) = 1`` (outward)."""
    inv2 = 1.0 / semi_axes**2
    hessian = np.zeros((points.shape[0], 6))
    hessian[:, :3] = 2 * inv2
    return _implicit(points, 2 * points * inv2, hessian)


def _icosahedron() -> tuple[np.ndarray, np.ndarray]:
    """The 12 unit vertices (cyclic permutations of ``(+-1, +-phi, 0)``) and 20 outward faces."""
    signs = np.array([[-1, 1], [1, 1], [-1, -1], [1, -1]]) * [1.0, (1 + 5**0.5) / 2]
    base = np.column_stack([signs, np.zeros(4)])
    v = np.concatenate([np.roll(base, k, axis=1) for k in range(3)])
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    f = "0 11 5 0 5 1 0 1 7 0 7 10 0 10 11 1 5 9 5 11 4 11 10 2 10 7 6 7 1 8 3 9 4 3 4 2 3 2 6 3 6 8 3 8 9 4 9 5 "
    f += "2 4 11 6 2 10 8 6 7 9 8 1"
    return v, np.array(f.split(), dtype=np.int64).reshape(-1, 3)


def _subdivided_sphere(subdivisions: int) -> tuple[np.ndarray, np.ndarray]:
    """Unit icosphere: every icosahedron edge split into ``subdivisions`` parts, projected."""
    n = check_int_option(subdivisions, "subdivisions", minimum=1)
    corners, ico_faces = _icosahedron()
    i, j = (a.ravel() for a in np.meshgrid(np.arange(n + 1), np.arange(n + 1), indexing="ij"))
    inside = i + j <= n
    i, j = i[inside], j[inside]
    local = np.full((n + 1, n + 1), -1)
    local[i, j] = np.arange(i.size)
    weights = np.stack([n - i - j, i, j], axis=1)  # on corners A, B, C
    # a key per grid point that is the same from every face sharing it
    ids = np.where(weights[None] > 0, ico_faces[:, None, :], 12)  # (20, m, 3); 12 = no corner
    w = np.broadcast_to(weights, ids.shape)
    order = np.argsort(ids, axis=2)
    ids = np.take_along_axis(ids, order, axis=2)
    w = np.take_along_axis(w, order, axis=2)
    key = ((ids[..., 0] * 13 + ids[..., 1]) * 13 + ids[..., 2]) * (n + 1) ** 2 + w[..., 0] * (n + 1) + w[..., 1]
    _, first, inverse = np.unique(key.ravel(), return_index=True, return_inverse=True)
    inverse = inverse.reshape(20, -1)
    a, b, c = (corners[ico_faces[:, k]] for k in range(3))
    points = (
        a[:, None, :] * weights[None, :, 0:1]
        + b[:, None, :] * weights[None, :, 1:2]
        + c[:, None, :] * weights[None, :, 2:3]
    ) / n
    vertices = points.reshape(-1, 3)[first]
    vertices /= np.linalg.norm(vertices, axis=1, keepdims=True)
    up = i + j <= n - 1
    down = i + j <= n - 2
    tri_local = np.concatenate(
        [
            np.stack([local[i[up], j[up]], local[i[up] + 1, j[up]], local[i[up], j[up] + 1]], axis=1),
            np.stack(
                [local[i[down] + 1, j[down]], local[i[down] + 1, j[down] + 1], local[i[down], j[down] + 1]], axis=1
            ),
        ]
    )
    faces = inverse[:, tri_local].reshape(-1, 3)
    return vertices, faces


def icosphere(subdivisions: int = 16, radius: float = 1.0, center=(0.0, 0.0, 0.0)) -> AnalyticMesh:
    """Sphere from a regular icosahedron whose edges are split into ``subdivisions`` parts.

    As matGeom's ``subdivideMesh(createIcosahedron, n)`` projected on the sphere.

    Parameters
    ----------
    subdivisions : int, default: 16
        Parts each icosahedron edge is split into, >= 1.
    radius : float, default: 1.0
        > 0.
    center : sequence of 3 floats, default: (0, 0, 0)

    Returns
    -------
    AnalyticMesh
        Closed, outward; ``10 * subdivisions**2 + 2`` vertices (2562 for 16)
        and twice as many faces less 4. Exact curvature ``1 / radius``
        everywhere; directions NaN (every point is umbilic).

    Raises
    ------
    InvalidOptionError
        ``subdivisions`` not an integer >= 1, ``radius`` not a positive finite
        number, ``center`` not 3 finite numbers.
    """
    radius = check_positive_float(radius, "radius")
    unit, faces = _subdivided_sphere(subdivisions)
    vertices = unit * radius + _check_center(center)
    return _make(f"icosphere({subdivisions})", vertices, faces, 1 / radius, 1 / radius, np.nan, np.nan, unit)


def uv_sphere(n_longitude: int = 32, n_latitude: int = 16, radius: float = 1.0) -> AnalyticMesh:
    """Latitude-longitude sphere with single pole vertices (matGeom's sphereMesh, poles merged).

    Triangles at the poles, split quads elsewhere.

    Parameters
    ----------
    n_longitude : int, default: 32
        Vertices around each ring of latitude, >= 3.
    n_latitude : int, default: 16
        Bands from pole to pole, >= 2 (``n_latitude - 1`` rings).
    radius : float, default: 1.0
        > 0; centred at the origin, poles on the z axis.

    Returns
    -------
    AnalyticMesh
        Closed, outward; ``n_longitude * (n_latitude - 1) + 2`` vertices and
        ``2 * n_longitude * (n_latitude - 1)`` faces. Exact curvature
        ``1 / radius``; directions NaN.

    Raises
    ------
    InvalidOptionError
        A count below its minimum or not an integer, ``radius`` not a positive
        finite number.
    """
    n_longitude = check_int_option(n_longitude, "n_longitude", minimum=3)
    n_latitude = check_int_option(n_latitude, "n_latitude", minimum=2)
    radius = check_positive_float(radius, "radius")
    theta = np.pi * np.arange(1, n_latitude) / n_latitude  # colatitude of the rings
    phi = 2 * np.pi * np.arange(n_longitude) / n_longitude
    t, p = np.meshgrid(theta, phi, indexing="ij")
    ring = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)], axis=-1).reshape(-1, 3)
    unit = np.vstack([[0.0, 0.0, 1.0], ring, [0.0, 0.0, -1.0]])
    north, south = 0, unit.shape[0] - 1
    idx = 1 + np.arange((n_latitude - 1) * n_longitude).reshape(n_latitude - 1, n_longitude)
    nxt = np.roll(idx, -1, axis=1)
    quads = np.stack([idx[:-1], idx[1:], nxt[1:], nxt[:-1]], axis=-1).reshape(-1, 4)
    caps = np.concatenate(
        [
            np.stack([np.full(n_longitude, north), idx[0], nxt[0]], axis=1),
            np.stack([np.full(n_longitude, south), nxt[-1], idx[-1]], axis=1),
        ]
    )
    faces = np.concatenate([caps[:n_longitude], _quads_to_triangles(quads), caps[n_longitude:]])
    return _make(
        f"uv_sphere({n_longitude}x{n_latitude})", unit * radius, faces, 1 / radius, 1 / radius, np.nan, np.nan, unit
    )


def torus(
    major_radius: float = 30.0,
    minor_radius: float = 10.0,
    n_major: int = 60,
    n_minor: int = 60,
    *,
    jitter: float = 0.0,
    seed: int = 0,
) -> AnalyticMesh:
    """Torus around the z axis, laid out as matGeom's ``torusMesh``.

    Vertex ``i * n_minor + j`` sits at ring angle ``2 pi i / n_major`` and tube
    angle ``2 pi j / n_minor`` (0 on the outer equator). The quads
    ``(i, j), (i+1, j), (i+1, j+1), (i, j+1)`` are kept in ``quads`` and split as
    matGeom's ``triangulateFaces`` does. Defaults: matGeom's torusMesh (R 30,
    r 10, 60 x 60: 3600 vertices).

    Exact curvatures: ``1 / r`` along the tube circle (``k_max``), and
    ``cos(phi) / (R + r cos(phi))`` along the ring (``k_min``).

    Parameters
    ----------
    major_radius : float, default: 30.0
        ``R``, the radius of the centre circle of the tube.
    minor_radius : float, default: 10.0
        ``r``, the radius of the tube, ``0 < r < R``.
    n_major : int, default: 60
        Vertices around the ring, >= 3.
    n_minor : int, default: 60
        Vertices around the tube, >= 3.
    jitter : float, default: 0.0
        In ``[0, 0.5)``. Above 0, an irregular mesh of the same surface: both
        angles of every vertex move by a uniform random fraction (up to
        ``jitter``) of the grid step, and each quad is split along a random
        diagonal; the exact values are those of the moved points.
    seed : int, default: 0
        Seed of ``numpy.random.default_rng`` for ``jitter``.

    Returns
    -------
    AnalyticMesh
        Closed, outward, genus 1: ``n_major * n_minor`` vertices,
        ``2 * n_major * n_minor`` faces, ``quads`` of shape
        ``(n_major * n_minor, 4)``.

    Raises
    ------
    InvalidOptionError
        A radius not a positive finite number, ``minor_radius >= major_radius``,
        a count below 3, ``jitter`` outside ``[0, 0.5)``.
    """
    R, r = check_positive_float(major_radius, "major_radius"), check_positive_float(minor_radius, "minor_radius")
    if r >= R:
        raise InvalidOptionError(f"`minor_radius` must be below `major_radius` (a ring torus); got {r!r} >= {R!r}")
    n_major, n_minor = check_int_option(n_major, "n_major", minimum=3), check_int_option(n_minor, "n_minor", minimum=3)
    theta = 2 * np.pi * np.arange(n_major) / n_major
    phi = 2 * np.pi * np.arange(n_minor) / n_minor
    grid = [a.ravel() for a in np.meshgrid(theta, phi, indexing="ij")]
    (t, p), rng, jittered = _jittered(grid, (2 * np.pi / n_major, 2 * np.pi / n_minor), (None, None), jitter, seed)
    normals = np.stack([np.cos(p) * np.cos(t), np.cos(p) * np.sin(t), np.sin(p)], axis=1)
    vertices = np.stack([(R + r * np.cos(p)) * np.cos(t), (R + r * np.cos(p)) * np.sin(t), r * np.sin(p)], axis=1)
    tube_direction = np.stack([-np.sin(p) * np.cos(t), -np.sin(p) * np.sin(t), np.cos(p)], axis=1)
    ring_direction = np.stack([-np.sin(t), np.cos(t), np.zeros_like(t)], axis=1)
    idx = np.arange(n_major * n_minor).reshape(n_major, n_minor)
    i_next = np.roll(idx, -1, axis=0)
    quads = np.stack([idx, i_next, np.roll(i_next, -1, axis=1), np.roll(idx, -1, axis=1)], axis=-1).reshape(-1, 4)
    k_ring = np.cos(p) / (R + r * np.cos(p))
    exact = (k_ring, 1 / r, ring_direction, tube_direction, normals)
    return _make(f"torus(R={R:g}, r={r:g}){jittered}", vertices, _quads_to_triangles(quads, rng), *exact, quads=quads)


def ellipsoid(semi_axes=(3.0, 2.0, 1.0), subdivisions: int = 12) -> AnalyticMesh:
    """Unit icosphere scaled by ``semi_axes`` (matGeom reference ``ellipsoid_321``).

    The exact values are those of ``sum(x_k**2 / a_k**2) = 1`` at each vertex
    (vertices lie on it exactly), from the eigenpairs of the projected Hessian.

    Parameters
    ----------
    semi_axes : sequence of 3 floats, default: (3, 2, 1)
        ``a_k`` along x, y, z; > 0.
    subdivisions : int, default: 12
        As for :func:`icosphere`.

    Returns
    -------
    AnalyticMesh
        Closed, outward; ``10 * subdivisions**2 + 2`` vertices. Directions NaN
        where ``k_min == k_max`` (umbilics; to 1e-9 relative).

    Raises
    ------
    InvalidOptionError
        ``semi_axes`` not 3 positive finite numbers, ``subdivisions`` not an integer >= 1.
    """
    a = _check_lengths(semi_axes, "semi_axes", 3)
    unit, faces = _subdivided_sphere(subdivisions)
    vertices = unit * a
    return _make(f"ellipsoid{tuple(a.tolist())}", vertices, faces, *_ellipsoid_exact(vertices, a))


def cylinder(
    radius: float = 1.0,
    height: float = 2.0,
    n_around: int = 32,
    n_along: int = 16,
    *,
    jitter: float = 0.0,
    seed: int = 0,
) -> AnalyticMesh:
    """Open cylinder around the z axis (two boundary rings), split quads.

    Exact curvatures: ``k_max = 1 / radius`` around, ``k_min = 0`` along the axis.

    Parameters
    ----------
    radius : float, default: 1.0
        > 0.
    height : float, default: 2.0
        > 0; the cylinder spans ``z`` in ``[-height / 2, height / 2]``.
    n_around : int, default: 32
        Vertices around each ring, >= 3.
    n_along : int, default: 16
        Bands along the axis, >= 1 (``n_along + 1`` rings).
    jitter, seed
        As for :func:`torus` (the boundary rings stay flat).

    Returns
    -------
    AnalyticMesh
        Outward normals; ``(n_along + 1) * n_around`` vertices,
        ``2 * n_around * n_along`` faces and their ``quads``.

    Raises
    ------
    InvalidOptionError
        A length not a positive finite number, a count below its minimum,
        ``jitter`` outside ``[0, 0.5)``.
    """
    radius, height = check_positive_float(radius, "radius"), check_positive_float(height, "height")
    n_around, n_along = (
        check_int_option(n_around, "n_around", minimum=3),
        check_int_option(n_along, "n_along", minimum=1),
    )
    phi = 2 * np.pi * np.arange(n_around) / n_around
    z = np.linspace(-height / 2, height / 2, n_along + 1)
    zz, pp = (a.ravel() for a in np.meshgrid(z, phi, indexing="ij"))
    steps, bounds = (2 * np.pi / n_around, height / n_along), (None, height / 2)  # the boundary rings stay flat
    (pp, zz), rng, jittered = _jittered([pp, zz], steps, bounds, jitter, seed)
    normals = np.stack([np.cos(pp), np.sin(pp), np.zeros_like(pp)], axis=1)
    vertices = normals * radius + np.stack([0 * zz, 0 * zz, zz], axis=1)
    around = np.stack([-np.sin(pp), np.cos(pp), np.zeros_like(pp)], axis=1)
    axis = np.broadcast_to([0.0, 0.0, 1.0], vertices.shape)
    idx = np.arange(vertices.shape[0]).reshape(n_along + 1, n_around)
    nxt = np.roll(idx, -1, axis=1)
    quads = np.stack([idx[:-1], nxt[:-1], nxt[1:], idx[1:]], axis=-1).reshape(-1, 4)
    exact = (0.0, 1 / radius, axis, around, normals)
    return _make(f"cylinder(r={radius:g}){jittered}", vertices, _quads_to_triangles(quads, rng), *exact, quads=quads)


def saddle(half_width: float = 1.0, spacing: float = 0.025, *, jitter: float = 0.0, seed: int = 0) -> AnalyticMesh:
    """Open height field ``z = x**2 - y**2`` on a square grid over ``[-w, w]^2``, normals up.

    At the centre the exact curvatures are ``-2`` (along x: the surface bends
    towards its upward normal) and ``+2`` (along y); elsewhere those of the
    height field at the vertex. Each grid square is split along the same
    diagonal.

    Parameters
    ----------
    half_width : float, default: 1.0
        ``w`` > 0.
    spacing : float, default: 0.025
        The grid step, rounded so that ``round(2 w / spacing) + 1`` points span
        each side; below ``4 w``.
    jitter, seed
        As for :func:`torus` (boundary vertices move along the boundary only).

    Returns
    -------
    AnalyticMesh
        Open (one boundary loop), normals up; ``n**2`` vertices with
        ``n = round(2 w / spacing) + 1``, and the grid's ``quads``.

    Raises
    ------
    InvalidOptionError
        ``half_width`` or ``spacing`` not a positive finite number, ``spacing``
        of ``4 w`` or more, ``jitter`` outside ``[0, 0.5)``.
    """
    half_width, spacing = check_positive_float(half_width, "half_width"), check_positive_float(spacing, "spacing")
    n = int(round(2 * half_width / spacing)) + 1
    if n < 2:
        raise InvalidOptionError(f"`spacing` must be below 4 times `half_width` (one grid square); got {spacing!r}")
    x = np.linspace(-half_width, half_width, n)
    yy, xx = (a.ravel() for a in np.meshgrid(x, x, indexing="ij"))
    step = x[1] - x[0] if n > 1 else 0.0
    (xx, yy), rng, jittered = _jittered([xx, yy], (step, step), (half_width, half_width), jitter, seed)
    vertices = np.stack([xx, yy, xx**2 - yy**2], axis=1)
    gradient = np.stack([-2 * xx, 2 * yy, np.ones_like(xx)], axis=1)  # of F = z - x^2 + y^2
    hessian = np.zeros((vertices.shape[0], 6))
    hessian[:, 0], hessian[:, 1] = -2.0, 2.0
    k_min, k_max, dir_min, dir_max, normals = _implicit(vertices, gradient, hessian)
    idx = np.arange(n * n).reshape(n, n)  # idx[row = y, column = x]
    quads = np.stack([idx[:-1, :-1], idx[:-1, 1:], idx[1:, 1:], idx[1:, :-1]], axis=-1).reshape(-1, 4)
    exact = (k_min, k_max, dir_min, dir_max, normals)
    return _make(
        f"saddle(spacing={spacing:g}){jittered}", vertices, _quads_to_triangles(quads, rng), *exact, quads=quads
    )


def _random_unit_sphere(n_vertices: int, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """Uniform random points on the unit sphere and their Delaunay triangulation (convex hull), outward."""
    from scipy.spatial import ConvexHull

    n = check_int_option(n_vertices, "n_vertices", minimum=4)
    rng = np.random.default_rng(seed)
    points = rng.normal(size=(n, 3))
    points /= np.linalg.norm(points, axis=1, keepdims=True)
    faces = ConvexHull(points).simplices.astype(np.int64)
    a, b, c = (points[faces[:, k]] for k in range(3))
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a + b + c) < 0
    faces[inward] = faces[inward][:, ::-1]
    return points, faces


def random_sphere(n_vertices: int = 2562, radius: float = 1.0, *, seed: int = 0) -> AnalyticMesh:
    """Sphere through ``n_vertices`` uniform random points: an irregular Delaunay mesh.

    The points are drawn with ``numpy.random.default_rng(seed)`` and triangulated
    by their convex hull (the Delaunay triangulation on the sphere), faces wound
    outward. Valences and angles vary freely (slivers included), the test that
    1-ring estimators fail.

    Parameters
    ----------
    n_vertices : int, default: 2562
        >= 4.
    radius : float, default: 1.0
        > 0; centred at the origin.
    seed : int, default: 0

    Returns
    -------
    AnalyticMesh
        Closed, outward; ``n_vertices`` vertices and ``2 * n_vertices - 4``
        faces. Exact curvature ``1 / radius``; directions NaN.

    Raises
    ------
    InvalidOptionError
        ``n_vertices`` not an integer >= 4, ``radius`` not a positive finite number.
    """
    radius = check_positive_float(radius, "radius")
    unit, faces = _random_unit_sphere(n_vertices, seed)
    return _make(
        f"random_sphere({n_vertices}, seed {seed})", unit * radius, faces, 1 / radius, 1 / radius, np.nan, np.nan, unit
    )


def random_ellipsoid(semi_axes=(3.0, 2.0, 1.0), n_vertices: int = 2562, *, seed: int = 0) -> AnalyticMesh:
    """:func:`random_sphere` (unit radius) scaled by ``semi_axes``: an irregular ellipsoid mesh.

    Parameters
    ----------
    semi_axes : sequence of 3 floats, default: (3, 2, 1)
        As for :func:`ellipsoid`.
    n_vertices : int, default: 2562
        >= 4.
    seed : int, default: 0

    Returns
    -------
    AnalyticMesh
        Closed, outward; exact values as for :func:`ellipsoid`.

    Raises
    ------
    InvalidOptionError
        ``semi_axes`` not 3 positive finite numbers, ``n_vertices`` not an integer >= 4.
    """
    a = _check_lengths(semi_axes, "semi_axes", 3)
    unit, faces = _random_unit_sphere(n_vertices, seed)
    vertices = unit * a
    return _make(f"random_ellipsoid{tuple(a.tolist())}", vertices, faces, *_ellipsoid_exact(vertices, a))


def hemisphere(subdivisions: int = 16, radius: float = 1.0, *, irregular: bool = False, seed: int = 0) -> AnalyticMesh:
    """Open upper half (z > 0) of :func:`icosphere` (or of :func:`random_sphere` with ``irregular=True``).

    The faces whose centroid lies above the equator are kept and the vertices
    re-indexed: one boundary loop near ``z = 0``.

    Parameters
    ----------
    subdivisions : int, default: 16
        As for :func:`icosphere`; with ``irregular=True`` the sphere has the
        same number of points, ``10 * subdivisions**2 + 2``.
    radius : float, default: 1.0
        > 0.
    irregular : bool, default: False
        Cut :func:`random_sphere` instead of :func:`icosphere`.
    seed : int, default: 0
        Seed of :func:`random_sphere`.

    Returns
    -------
    AnalyticMesh
        Open, outward. Exact curvature ``1 / radius``; directions NaN.

    Raises
    ------
    InvalidOptionError
        As :func:`icosphere` and :func:`random_sphere`.
    """
    if irregular:
        whole = random_sphere(
            10 * check_int_option(subdivisions, "subdivisions", minimum=1) ** 2 + 2, radius, seed=seed
        )
    else:
        whole = icosphere(subdivisions, radius)
    keep = whole.vertices[whole.faces].mean(axis=1)[:, 2] > 0
    used, faces = np.unique(whole.faces[keep], return_inverse=True)
    exact = (1 / radius, 1 / radius, np.nan, np.nan, whole.normals[used])
    return _make(f"hemisphere({whole.name})", whole.vertices[used], faces.reshape(-1, 3), *exact)


def with_normal_noise(mesh: AnalyticMesh, level: float, *, seed: int = 0) -> AnalyticMesh:
    """The mesh with every vertex moved along its exact normal by uniform noise.

    Each vertex moves by ``t * n`` with ``t`` uniform in ``[-a, a]``,
    ``a = level * mean edge length`` (``level`` 0.1 and 0.3 in the accuracy
    benchmark), drawn with ``numpy.random.default_rng(seed)``.

    Parameters
    ----------
    mesh : AnalyticMesh
    level : float
        >= 0, the amplitude as a fraction of the mean edge length.
    seed : int, default: 0

    Returns
    -------
    AnalyticMesh
        A new mesh, the same faces; the exact curvatures, directions and
        normals stay those of the unperturbed surface at the original points:
        what an estimator should recover.

    Raises
    ------
    InvalidMeshError
        ``mesh`` not an :class:`AnalyticMesh`.
    InvalidOptionError
        ``level`` not a finite number >= 0.
    """
    if not isinstance(mesh, AnalyticMesh):
        raise InvalidMeshError(
            f"`mesh` must be an AnalyticMesh (a shape of meshcurv.shapes); got {type(mesh).__name__}"
        )
    real = isinstance(level, (int, float, np.integer, np.floating)) and not isinstance(level, bool)
    if not (real and np.isfinite(level) and level >= 0):
        raise InvalidOptionError(f"`level` must be a number >= 0 (a fraction of the mean edge length); got {level!r}")
    edges = MeshTopology.from_faces(mesh.faces, mesh.vertices.shape[0]).edges
    amplitude = level * mean_edge_length(mesh.vertices, edges)
    t = np.random.default_rng(seed).uniform(-amplitude, amplitude, size=(mesh.vertices.shape[0],))
    moved = {**_analytic_fields(mesh), "vertices": mesh.vertices + t[:, None] * mesh.normals}
    return AnalyticMesh(**{**moved, "name": f"{mesh.name} + noise {level:g}h"})


# -- voxelised solids: marching-cubes meshes of binary images -------------------------


@dataclass(frozen=True, eq=False)
class VoxelMesh(AnalyticMesh):
    """A marching-cubes mesh of a voxelised analytic solid, with the exact curvatures.

    The fields of :class:`AnalyticMesh` hold the exact values at each vertex's
    closest point on the analytic surface, oriented **outward** (a convex solid
    is positive), whereas ``faces`` keep marching cubes' own winding, which is
    **inward**: the estimate of a method that honours the winding literally
    has the opposite sign of ``mean`` and of the principal curvatures.

    Attributes
    ----------
    name, vertices, faces, k_min, k_max, dir_min, dir_max, normals, quads
        As for :class:`AnalyticMesh` (``quads`` None).
    closest_points : ndarray of shape (V, 3)
        The closest point on the analytic surface to each vertex, where the
        exact values are taken.
    center : ndarray of shape (3,)
        The centre of the solid, in the vertices' coordinates.
    spacing : tuple of 3 floats
        The voxel size along the image axes 0, 1, 2.
    """

    closest_points: np.ndarray | None = None
    center: np.ndarray | None = None
    spacing: tuple | None = None


def _check_center(center) -> np.ndarray:
    try:
        values = np.asarray(center, dtype=float)
    except (TypeError, ValueError):
        values = None
    if values is None or values.shape != (3,) or not np.isfinite(values).all():
        raise InvalidOptionError(f"`center` must be 3 finite numbers; got {center!r}")
    return values


def _check_lengths(values, name: str, count: int) -> np.ndarray:
    out = np.atleast_1d(np.asarray(values, dtype=float))
    if out.shape != (count,) or not (np.isfinite(out).all() and (out > 0).all()):
        raise InvalidOptionError(f"`{name}` must be {count} positive number(s); got {values!r}")
    return out


def _marching_cubes(inside, extent: np.ndarray, spacing: np.ndarray, seed: int, name: str):
    """Voxelise the solid ``inside(points - center)`` and run marching cubes on it.

    The grid spans ``extent`` (half-widths along the axes) plus two voxels on
    each side; the centre sits at a random sub-voxel offset drawn with
    ``numpy.random.default_rng(seed)``. Returns ``vertices, faces, center``.
    """
    message = f"shapes.{name} needs scikit-image: pip install 'meshcurv[volume]'"
    marching_cubes = optional_module("skimage.measure", message).marching_cubes
    counts = np.ceil(2 * extent / spacing).astype(int) + 5
    if np.prod(counts.astype(float)) > 2e8:
        raise InvalidOptionError(
            f"shapes.{name}: the voxel grid would have {' x '.join(map(str, counts))} voxels; use a larger `spacing`"
        )
    offset = np.random.default_rng(seed).random(3)
    center = ((counts - 1) / 2 + offset - 0.5) * spacing
    axes = [np.arange(n) * s - c for n, s, c in zip(counts, spacing, center)]
    mask = inside(*np.meshgrid(*axes, indexing="ij", sparse=True))
    vertices, faces, _, _ = marching_cubes(mask.astype(float), 0.5, spacing=tuple(spacing))
    return vertices.astype(float), faces.astype(np.int64), center


def _voxel_mesh(name, vertices, faces, center, spacing, closest, k_min, k_max, dir_min, dir_max, normals):
    base = _analytic_fields(_make(name, vertices, faces, k_min, k_max, dir_min, dir_max, normals))
    return VoxelMesh(**base, closest_points=closest, center=center, spacing=tuple(spacing.tolist()))


def _spacing_label(spacing: np.ndarray) -> str:
    return "x".join(f"{s:g}" for s in spacing)


def voxel_sphere(radius: float = 10.0, spacing=(1.0, 1.0, 1.0), *, seed: int = 0) -> VoxelMesh:
    """Marching-cubes mesh of a voxelised ball, as a segmentation pipeline makes it.

    The ball of ``radius`` (physical units) is voxelised on a grid of voxel size
    ``spacing`` along the image axes 0, 1, 2 (scikit-image's ``(plane, row,
    column)``, often called z, y, x): a voxel is inside when its centre is. Its
    centre sits at a random sub-voxel offset (``numpy.random.default_rng(seed)``)
    so that the solid is not aligned with the grid. The mesh is exactly what
    ``skimage.measure.marching_cubes(mask.astype(float), 0.5, spacing=spacing)``
    returns: vertex coordinate ``k`` is the position along image axis ``k``
    (index times ``spacing[k]``, origin at voxel 0), and the faces are wound
    inward, as marching cubes winds them.

    Parameters
    ----------
    radius : float, default: 10.0
        > 0, in physical units (those of ``spacing``).
    spacing : sequence of 3 floats, default: (1, 1, 1)
        Voxel size along image axes 0, 1, 2.
    seed : int, default: 0
        Seed of the sub-voxel offset of the centre.

    Returns
    -------
    VoxelMesh
        Exact curvature ``1 / radius`` (outward) at each vertex's closest
        point, ``center + radius * (v - center) / |v - center|``.

    Raises
    ------
    ImportError
        Without scikit-image (``pip install 'meshcurv[volume]'``).
    """
    r = float(_check_lengths(radius, "radius", 1)[0])
    s = checked_spacing(spacing)
    vertices, faces, center = _marching_cubes(
        lambda x, y, z: x * x + y * y + z * z <= r * r, np.full(3, r), s, seed, "voxel_sphere"
    )
    offset = vertices - center
    normals = offset / np.linalg.norm(offset, axis=1, keepdims=True)
    name = f"voxel_sphere(r={r:g}, voxel {_spacing_label(s)})"
    exact = (1 / r, 1 / r, np.nan, np.nan, normals)
    return _voxel_mesh(name, vertices, faces, center, s, center + r * normals, *exact)


def ellipsoid_closest_points(points, semi_axes, *, iterations: int = 60) -> np.ndarray:
    """Closest points on the ellipsoid ``sum(x_k**2 / a_k**2) = 1`` (centred, axis-aligned).

    The closest point to ``y`` is ``x_k = a_k**2 y_k / (a_k**2 + t)`` where ``t``
    is the largest root of ``f(t) = sum((a_k y_k / (a_k**2 + t))**2) - 1``. ``f``
    is convex and decreasing on ``t > -min(a_k**2)``, so Newton's method started
    left of the root, at ``t = max_k(a_k |y_k| - a_k**2)`` (where one term alone
    makes ``f >= 0``), converges monotonically from below; all points are solved
    together. A point on a principal plane of the smallest axis inside the
    ellipsoid, far from its surface, has no such start and is not supported.

    Parameters
    ----------
    points : array_like of shape (N, 3)
    semi_axes : sequence of 3 positive floats
    iterations : int, default: 60
        At most this many Newton steps (stops when every step is below
        ``1e-14`` of the axes' squared scale).

    Returns
    -------
    ndarray of shape (N, 3)
    """
    y = np.asarray(points, dtype=float)
    a = _check_lengths(semi_axes, "semi_axes", 3)
    a2 = a**2
    ay2 = a2 * y * y
    floor = -a2.min()
    t = np.maximum((a * np.abs(y) - a2).max(axis=1), floor + 1e-12 * a2.max())
    for _ in range(check_int_option(iterations, "iterations", minimum=1)):
        d = a2 + t[:, None]
        f = (ay2 / d**2).sum(axis=1) - 1
        slope = -2 * (ay2 / d**3).sum(axis=1)
        step = np.divide(f, slope, out=np.zeros_like(f), where=slope < 0)
        t = t - step
        if np.abs(step).max(initial=0.0) <= 1e-14 * a2.max():
            break
    return a2 * y / (a2 + t[:, None])


def voxel_ellipsoid(semi_axes=(10.0, 7.0, 5.0), spacing=(1.0, 1.0, 1.0), *, seed: int = 0) -> VoxelMesh:
    """Marching-cubes mesh of a voxelised solid ellipsoid.

    ``semi_axes[k]`` is along image axis ``k``; grid, centre offset, vertex
    coordinates and (inward) winding as in :func:`voxel_sphere`.

    Parameters
    ----------
    semi_axes : sequence of 3 floats, default: (10, 7, 5)
        > 0, in physical units.
    spacing, seed
        As for :func:`voxel_sphere`: voxel size along image axes 0, 1, 2
        (default 1, 1, 1) and seed of the centre's offset (default 0).

    Returns
    -------
    VoxelMesh
        Exact curvatures (outward) at each vertex's closest point on the
        ellipsoid (:func:`ellipsoid_closest_points`, a vectorised Newton solve).

    Raises
    ------
    InvalidOptionError
        A length or ``spacing`` not positive finite numbers, or a grid
        of more than 2e8 voxels.
    MissingDependencyError
        Without scikit-image (``pip install 'meshcurv[volume]'``).
    """
    a = _check_lengths(semi_axes, "semi_axes", 3)
    s = checked_spacing(spacing)
    inv2 = 1.0 / a**2
    vertices, faces, center = _marching_cubes(
        lambda x, y, z: x * x * inv2[0] + y * y * inv2[1] + z * z * inv2[2] <= 1, a, s, seed, "voxel_ellipsoid"
    )
    local = ellipsoid_closest_points(vertices - center, a)
    name = f"voxel_ellipsoid{tuple(a.tolist())}, voxel {_spacing_label(s)}"
    return _voxel_mesh(name, vertices, faces, center, s, center + local, *_ellipsoid_exact(local, a))


def voxel_torus(
    major_radius: float = 12.0, minor_radius: float = 4.0, spacing=(1.0, 1.0, 1.0), *, seed: int = 0
) -> VoxelMesh:
    """Marching-cubes mesh of a voxelised solid torus whose axis is image axis 0.

    Grid, centre offset, vertex coordinates and (inward) winding as in
    :func:`voxel_sphere`. The closest point of a vertex is on the tube circle
    around the nearest point of the centre circle; there the exact curvatures
    (outward) are ``1 / r`` around the tube (``k_max``) and
    ``cos(phi) / (R + r cos(phi))`` along the ring, ``phi`` the angle from the
    outer equator.

    Parameters
    ----------
    major_radius : float, default: 12.0
        ``R``, in physical units.
    minor_radius : float, default: 4.0
        ``r``, ``0 < r < R``.
    spacing, seed
        As for :func:`voxel_sphere`.

    Returns
    -------
    VoxelMesh
        Closed, genus 1, faces wound inward, exact values outward.

    Raises
    ------
    InvalidOptionError
        A length or ``spacing`` not positive finite numbers,
        ``minor_radius >= major_radius``, or a grid of more than 2e8 voxels.
    MissingDependencyError
        Without scikit-image (``pip install 'meshcurv[volume]'``).
    """
    R = float(_check_lengths(major_radius, "major_radius", 1)[0])
    r = float(_check_lengths(minor_radius, "minor_radius", 1)[0])
    if r >= R:
        raise InvalidOptionError(f"`minor_radius` must be below `major_radius`; got {r!r} >= {R!r}")
    s = checked_spacing(spacing)

    def inside(x, y, z):
        return x * x + (np.sqrt(y * y + z * z) - R) ** 2 <= r * r

    vertices, faces, center = _marching_cubes(inside, np.array([r, R + r, R + r]), s, seed, "voxel_torus")
    p = vertices - center
    rho = np.hypot(p[:, 1], p[:, 2])
    radial = np.zeros_like(p)
    radial[:, 1:] = p[:, 1:] / rho[:, None]
    tube = p - R * radial
    normals = tube / np.linalg.norm(tube, axis=1, keepdims=True)
    cos_phi = np.sum(normals * radial, axis=1)
    ring_direction = np.stack([np.zeros_like(rho), -radial[:, 2], radial[:, 1]], axis=1)
    tube_direction = np.cross(normals, ring_direction)
    name = f"voxel_torus(R={R:g}, r={r:g}, voxel {_spacing_label(s)})"
    exact = (cos_phi / (R + r * cos_phi), 1 / r, ring_direction, tube_direction, normals)
    return _voxel_mesh(name, vertices, faces, center, s, center + R * radial + r * normals, *exact)
