"""The result of a curvature computation."""

from __future__ import annotations

import dataclasses
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

from . import _adapters
from ._validation import check_choice
from .defects import INVALID_REASONS
from .errors import InvalidOptionError

if TYPE_CHECKING:
    from .diagnosis import MeshDiagnosis

__all__ = ["CurvatureResult", "INVALID_REASONS"]


@dataclass(frozen=True, eq=False)
class CurvatureResult:
    """Per-vertex curvatures of a triangle mesh.

    All arrays are read-only float64 (``valid`` is bool) with one row per vertex.

    Conventions (pinned by the tests):

    - ``k_max >= k_min`` algebraically at every valid vertex;
    - ``mean = (k_min + k_max) / 2`` and ``gaussian = k_min * k_max``;
    - curvatures are positive where the surface bends away from its normal:
      a sphere of radius ``r`` with outward-wound faces gives ``+1/r``;
      reversing every face flips the signs of ``k_min``, ``k_max``, ``mean`` and
      ``normals`` and keeps ``gaussian``;
    - ``dir_min`` and ``dir_max`` are unit vectors, orthogonal to each other and
      to the normal, defined up to sign (arbitrary where ``k_min == k_max``);
    - where ``valid`` is False the estimate is undefined and the curvature
      fields are NaN (the one exception is ``method="matgeom"``, which keeps
      matGeom's own numbers wherever matGeom computes them, its zeros at
      unreferenced vertices included, and marks ``valid=False`` where they
      are not an estimate).

    Attributes
    ----------
    k_min, k_max : ndarray of shape (V,)
        Principal curvatures, in 1/length (dimensionless for ``method="matgeom"``).
    dir_min, dir_max : ndarray of shape (V, 3)
        Principal directions of ``k_min`` and ``k_max`` (NaN for methods without
        directions).
    normals : ndarray of shape (V, 3)
        Unit vertex normals, oriented by the face winding (matGeom's unoriented
        ``N`` for ``method="matgeom"``).
    valid : ndarray of shape (V,), bool
        Where the estimate is defined.
    method : str
        The estimator that produced the result.
    parameters : mapping
        The options the estimator used (defaults filled in).
    diagnosis : MeshDiagnosis or None
        What :func:`meshcurv.diagnose` found in the mesh the curvatures were
        computed on (after welding and ``orient=``), with the number of faces
        ``orient=`` reversed; None when the result was built directly.
    invalid_reason : ndarray of shape (V,), int8, or None
        Why each vertex is invalid: an index into :data:`INVALID_REASONS`
        (0 where ``valid``); set by :func:`meshcurv.principal_curvatures`,
        None when the result was built directly.
    radius : ndarray of shape (V,), or None
        The radius of the ball each vertex's estimate was measured over, in the
        units of the vertices (methods over balls: ``icc``, ``quadric``,
        ``normal_cycle_ball``, point clouds); None for the other methods.
    vertex_areas : ndarray of shape (V,)
        Barycentric vertex areas (a third of each incident face), in length^2;
        they sum to the area of the mesh. Where a welded vertex has several
        rows, the first holds the area and the others 0. NaN when the result
        has no mesh (point clouds, results built directly).

    Notes
    -----
    Integrals over the surface (:meth:`integral`) are sums of per-vertex
    shares (:meth:`vertex_integrals`) computed from the mesh the curvatures
    were computed on (kept by :func:`meshcurv.principal_curvatures`) and the
    result's normals, not from the pointwise fields times an area: see
    :mod:`meshcurv.integrals`.

    :meth:`to_pyvista`, :meth:`to_trimesh` and :meth:`to_dataframe` put the
    per-vertex fields onto a ``pyvista.PolyData``, a ``trimesh.Trimesh`` or a
    ``pandas.DataFrame`` (none of these libraries is needed otherwise).
    """

    k_min: np.ndarray
    k_max: np.ndarray
    dir_min: np.ndarray
    dir_max: np.ndarray
    normals: np.ndarray
    valid: np.ndarray
    method: str
    parameters: Mapping[str, Any] = field(default_factory=dict)
    diagnosis: MeshDiagnosis | None = None
    invalid_reason: np.ndarray | None = None
    radius: np.ndarray | None = None
    _surface: Surface | None = field(default=None, repr=False)

    def __post_init__(self):
        for name in _ARRAY_FIELDS:
            value = getattr(self, name)
            if isinstance(value, np.ndarray) and not value.flags.writeable and _keepable(value, name):
                continue  # read-only and owning its data: taken as it is, not copied (see _of_arrays)
            array = np.array(value, dtype=bool if name == "valid" else np.float64, copy=True)
            array.flags.writeable = False
            object.__setattr__(self, name, array)
        object.__setattr__(self, "parameters", MappingProxyType(dict(self.parameters)))
        for name, dtype in (("invalid_reason", np.int8), ("radius", np.float64)):
            value = getattr(self, name)
            if value is None or (isinstance(value, np.ndarray) and not value.flags.writeable and _kept(value, dtype)):
                continue  # read-only and owning its data: taken as it is (each replace() copied it, issue 31)
            object.__setattr__(self, name, _readonly(np.array(value, dtype=dtype)))

    def __reduce__(self):
        # the parameters' MappingProxyType does not pickle: rebuilt from a dict
        fields = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        fields["parameters"] = dict(self.parameters)
        return (_rebuild, (type(self), fields))

    def invalid_counts(self) -> dict[str, int]:
        """How many vertices are invalid for each reason (:data:`INVALID_REASONS`), largest first.

        Returns
        -------
        dict of str to int
            Reason phrase -> number of vertices, only reasons with at least
            one vertex, in decreasing count (ties in the order of
            :data:`INVALID_REASONS`). Empty when every vertex is valid;
            ``{"unknown": n}`` when the result carries no ``invalid_reason``.
        """
        if self.invalid_reason is None:
            n_invalid = int((~self.valid).sum())
            return {"unknown": n_invalid} if n_invalid else {}
        counts = np.bincount(self.invalid_reason, minlength=len(INVALID_REASONS))
        order = np.argsort(-counts[1:], kind="stable") + 1
        return {INVALID_REASONS[c]: int(counts[c]) for c in order if counts[c]}

    @classmethod
    def _of_arrays(cls, **fields) -> CurvatureResult:
        """A result that takes the estimator's own arrays without copying them.

        The arrays are made read-only here and kept by :meth:`__post_init__`
        (float64, or bool for ``valid``, C-contiguous, owning their data);
        others are copied as by the constructor. Only for arrays that nobody
        else holds.
        """
        for name in _ARRAY_FIELDS:
            value = fields[name]
            if isinstance(value, np.ndarray) and _keepable(value, name):
                value.flags.writeable = False
        return cls(**fields)

    @property
    def n_vertices(self) -> int:
        """The number of vertices (rows of every per-vertex field)."""
        return int(self.k_min.shape[0])

    @cached_property
    def mean(self) -> np.ndarray:
        """(V,) mean curvature ``(k_min + k_max) / 2``."""
        return _readonly((self.k_min + self.k_max) / 2)

    @cached_property
    def gaussian(self) -> np.ndarray:
        """(V,) Gaussian curvature ``k_min * k_max``."""
        return _readonly(self.k_min * self.k_max)

    @cached_property
    def shape_index(self) -> np.ndarray:
        """(V,) shape index of Koenderink and van Doorn (1992), in [-1, 1].

        ``S = (2 / pi) * arctan((k_max + k_min) / (k_max - k_min))``, computed as
        ``arctan2`` so that umbilics give +-1. With meshcurv's signs (convex
        outward = positive curvature): +1 a cap (sphere seen from outside),
        +1/2 a ridge (cylinder), 0 a symmetric saddle, -1/2 a rut, -1 a cup.
        Flipping the faces negates it. NaN where the estimate is invalid and
        where the surface is flat: its curvedness times the scale of the
        estimate (``radius``, or the square root of the vertex's area on a mesh
        without one) below :data:`FLAT_CURVEDNESS`, where the curvatures are the
        round-off of their sums and their ratio any number (the flat sides of a
        voxel blob: 1e-14 of 1/h, whose shape index took any value in [-1, 1]
        and moved a label's shape-index columns under a change of spacing).
        Without a scale (a result built directly), flat is ``curvedness == 0``.

        J. J. Koenderink and A. J. van Doorn (1992). Surface shape and curvature
        scales. Image and Vision Computing 10(8), 557-564.
        https://doi.org/10.1016/0262-8856(92)90076-F
        """
        if self.radius is not None:
            scale = self.radius
        elif self._surface is not None:
            scale = np.sqrt(self.vertex_areas)
        else:
            scale = None
        return _readonly(shape_index(self.k_min, self.k_max, scale))

    @cached_property
    def curvedness(self) -> np.ndarray:
        """(V,) curvedness ``sqrt((k_min**2 + k_max**2) / 2)`` (Koenderink and van Doorn 1992), in 1/length."""
        return _readonly(np.sqrt((self.k_min**2 + self.k_max**2) / 2))

    @cached_property
    def vertex_areas(self) -> np.ndarray:
        """(V,) barycentric vertex areas, in length^2 (NaN when the result has no mesh)."""
        if self._surface is None:
            return _readonly(np.full(self.n_vertices, np.nan))
        return self.vertex_integrals("area")

    def vertex_integrals(self, field: str) -> np.ndarray:
        """(V,) the share of each vertex in :meth:`integral` ``(field)``; they add up over any region.

        Parameters
        ----------
        field : {'area', 'mean', 'gaussian', 'willmore'}
            See :meth:`integral`.

        Returns
        -------
        ndarray of shape (V,), read-only
            Where a welded vertex has several rows, the first holds its share
            and the others 0.

        Raises
        ------
        InvalidOptionError
            Unknown ``field``, or a result with no mesh (point clouds, results built directly).
        """
        from . import integrals  # on use: kept out of `import meshcurv` (its _LAZY names)

        check_choice(field, "field", integrals.INTEGRALS)
        cache = self.__dict__.setdefault("_vertex_integrals", {})
        if field in cache:
            return cache[field]
        if self._surface is None:
            raise InvalidOptionError(
                f"integrals need the triangles of a mesh; this {self.method!r} result has none (a point "
                "cloud's, or one built directly): compute it with meshcurv.principal_curvatures on a mesh, "
                "or use meshcurv.integrals.vertex_integrals(vertices, faces, field, normals=...)"
            )
        cache[field] = _readonly(self._surface.shares(field, self))
        return cache[field]

    def integral(self, field: str, *, where=None) -> float:
        """The integral of ``field`` over the surface (or over the vertices in ``where``).

        Parameters
        ----------
        field : {'area', 'mean', 'gaussian', 'willmore'}
            - ``'area'``: the area of the mesh (sum of :attr:`vertex_areas`);
            - ``'mean'``: total mean curvature ``int H dA`` (``4 pi R`` on a
              sphere of radius ``R``), from the corrected curvature measure
              ``mu_1 / 2`` of each face with the result's normals;
            - ``'gaussian'``: total Gaussian curvature ``int K dA``, the signed
              area of the spherical image of each face under the result's
              normals: ``2 pi chi`` on a closed mesh (Gauss-Bonnet), whatever
              the method;
            - ``'willmore'``: Willmore energy ``int H^2 dA`` (``4 pi`` on a
              sphere), the pointwise ``mean**2`` times :attr:`vertex_areas`.

            ``'mean'`` and ``'gaussian'`` are defined on every face: they take
            the area-weighted face normals at invalid vertices, where the
            result's normal points away from the faces (cosine <= 0), and for
            ``method='matgeom'`` (unoriented normals).
        where : array_like of shape (V,), bool, optional
            Integrate over these vertices only (each stands for a third of
            its incident faces), e.g. ``result.valid`` for the Willmore
            energy of a mesh with invalid vertices.

        Returns
        -------
        float
            NaN for ``'willmore'`` when a vertex integrated over is invalid.

        Raises
        ------
        InvalidOptionError
            Unknown ``field``, a ``where`` of the wrong shape, or a result
            with no mesh (point clouds, results built directly).

        Examples
        --------
        >>> import numpy as np, meshcurv
        >>> sphere = meshcurv.shapes.icosphere(subdivisions=8, radius=2.0)
        >>> r = meshcurv.principal_curvatures(sphere.vertices, sphere.faces)
        >>> print(f"{r.integral('gaussian') / np.pi:.4f}")  # 2 pi chi, chi = 2
        4.0000
        >>> print(f"{r.integral('willmore') / (4 * np.pi):.2f}")  # 4 pi on any sphere
        1.00
        """
        shares = self.vertex_integrals(field)
        return float(np.sum(shares if where is None else shares[_where_mask(where, self.n_vertices)]))

    def to_pyvista(self, mesh=None, *, fields=None):
        """A ``pyvista.PolyData`` of the mesh with the result's fields as ``point_data``.

        Parameters
        ----------
        mesh : pyvista.PolyData, other mesh object, or (vertices, faces), optional
            The mesh the result was computed on, one vertex per row of the
            result; a ``PolyData`` is copied (never changed). By default the
            mesh the result keeps (when nothing was welded).
        fields : sequence of str, optional
            Names of :data:`meshcurv.io.fields.FIELDS` (default all).

        Returns
        -------
        pyvista.PolyData
            (V,) scalars and (V, 3) vectors as ``point_data``, ``valid`` as uint8.

        Raises
        ------
        MissingDependencyError
            PyVista is not installed.
        InvalidMeshError
            The mesh has another number of vertices than the result has rows,
            or none was given and the result keeps none.
        """
        return _adapters.to_pyvista(self, mesh, fields=fields)

    def to_trimesh(self, mesh=None, *, fields=None):
        """A ``trimesh.Trimesh`` of the mesh with the result's fields in ``vertex_attributes``.

        Parameters
        ----------
        mesh : trimesh.Trimesh, other mesh object, or (vertices, faces), optional
            As for :meth:`to_pyvista`; a ``Trimesh`` is copied, others are
            built with ``process=False`` (vertices kept in their order) and
            their polygons fan-triangulated.
        fields : sequence of str, optional
            As for :meth:`to_pyvista`.

        Returns
        -------
        trimesh.Trimesh

        Raises
        ------
        MissingDependencyError
            trimesh is not installed.
        InvalidMeshError
            As for :meth:`to_pyvista`.
        """
        return _adapters.to_trimesh(self, mesh, fields=fields)

    def to_dataframe(self, *, fields=None):
        """A ``pandas.DataFrame`` of the per-vertex fields, one row per vertex.

        Parameters
        ----------
        fields : sequence of str, optional
            Names of :data:`meshcurv.io.fields.FIELDS` (default all).

        Returns
        -------
        pandas.DataFrame
            V rows; the scalar fields by name, vectors as ``<name>_x``,
            ``<name>_y``, ``<name>_z``, ``valid`` as bool, and ``vertex_area``
            (:attr:`vertex_areas`) when ``fields`` is not given.

        Raises
        ------
        MissingDependencyError
            pandas is not installed.
        """
        return _adapters.to_dataframe(self, fields=fields)

    def as_matgeom(self) -> tuple[np.ndarray, ...]:
        """The seven outputs of matGeom's ``meshCurvatures``, in its order.

        Returns
        -------
        C1, C2, U1, U2, H, K, N
            ``k_min, k_max, dir_min, dir_max, mean, gaussian, normals``.
            With ``method="matgeom"`` they are matGeom's own numbers.
        """
        return (self.k_min, self.k_max, self.dir_min, self.dir_max, self.mean, self.gaussian, self.normals)

    def __repr__(self) -> str:
        n_valid = int(self.valid.sum())
        return (
            f"CurvatureResult(method={self.method!r}, n_vertices={self.n_vertices}, "
            f"valid={n_valid}, parameters={dict(self.parameters)})"
        )


@dataclass(frozen=True, eq=False)
class Surface:
    """The mesh a result was computed on, for its integrals (private to meshcurv).

    ``vertices`` (W, 3) and ``faces`` (F, 3) after welding and orientation;
    ``index`` (V,) the row of ``vertices`` of each row of the result (None
    when nothing was welded). Read-only views, never the caller's arrays.
    """

    vertices: np.ndarray
    faces: np.ndarray
    index: np.ndarray | None = None

    def __post_init__(self):
        for name in ("vertices", "faces", "index"):
            value = getattr(self, name)
            if value is not None:
                view = value.view()
                view.flags.writeable = False
                object.__setattr__(self, name, view)

    @cached_property
    def rows(self) -> slice | np.ndarray:
        """The rows of a result on the caller's vertices that stand for the rows of ``vertices``: (W,) the
        first row of each welded vertex, ``slice(None)`` when nothing was welded."""
        if self.index is None:
            return slice(None)
        first = np.full(self.vertices.shape[0], self.index.shape[0], dtype=np.int64)
        np.minimum.at(first, self.index, np.arange(self.index.shape[0]))
        return first

    def shares(self, field: str, result: CurvatureResult) -> np.ndarray:
        """(V,) per-row shares of ``field`` (see :func:`meshcurv.integrals.vertex_integrals`): a welded
        vertex's share on its first row, 0 on the rows of its copies."""
        rows = self.rows
        normals = (
            None if result.method == "matgeom" else np.where(result.valid[rows, None], result.normals[rows], np.nan)
        )
        pointwise = result.mean[rows] if field == "willmore" else None
        from .integrals import vertex_integrals  # on use, as in CurvatureResult.vertex_integrals

        shares = vertex_integrals(self.vertices, self.faces, field, normals=normals, pointwise=pointwise)
        if self.index is None:
            return shares
        out = np.zeros(result.n_vertices, dtype=np.float64)
        out[rows] = shares
        return out


#: A vertex is flat where its curvedness times the scale of its estimate is below this: a radius of curvature
#: a billion times the ball's, which no estimate in double precision tells from a plane (:func:`shape_index`).
FLAT_CURVEDNESS = 1e-9


def shape_index(k_min, k_max, scale=None) -> np.ndarray:
    """(V,) the shape index of principal curvatures ``k_min, k_max`` (V,), NaN where flat or NaN.

    Flat: the curvedness times ``scale`` (V,), the length over which each vertex was measured, below
    :data:`FLAT_CURVEDNESS` (or where it is 0 exactly, wherever the scale is not a positive finite number,
    and everywhere when ``scale`` is None). One definition for :attr:`CurvatureResult.shape_index` and the
    statistics' columns (:mod:`meshcurv.statistics`, :func:`meshcurv.label_curvatures`).
    """
    k_min, k_max = np.asarray(k_min, dtype=np.float64), np.asarray(k_max, dtype=np.float64)
    curvedness = np.sqrt((k_min**2 + k_max**2) / 2)
    floor = np.zeros_like(curvedness)
    if scale is not None:
        scale = np.broadcast_to(np.asarray(scale, dtype=np.float64), curvedness.shape)
        usable = np.isfinite(scale) & (scale > 0)
        np.divide(FLAT_CURVEDNESS, scale, out=floor, where=usable)
    with np.errstate(invalid="ignore"):
        index = (2 / np.pi) * np.arctan2(k_max + k_min, k_max - k_min)
        return np.where((curvedness > floor) & (curvedness > 0), index, np.nan)


def _rebuild(cls, fields):
    return cls(**fields)


def _where_mask(where, n_vertices: int) -> np.ndarray:
    """``where`` as a (V,) bool mask, all True when None; an InvalidOptionError when it is not one."""
    mask = np.ones(n_vertices, dtype=bool) if where is None else np.asarray(where)
    if mask.dtype != bool or mask.shape != (n_vertices,):
        raise InvalidOptionError(
            f"`where` must be a bool array of shape ({n_vertices},); got {mask.dtype} of shape {mask.shape}"
        )
    return mask


_ARRAY_FIELDS = ("k_min", "k_max", "dir_min", "dir_max", "normals", "valid")


def _keepable(array: np.ndarray, name: str) -> bool:
    return _kept(array, np.bool_ if name == "valid" else np.float64)


def _kept(array: np.ndarray, dtype) -> bool:
    # owning its data, or over a buffer a compiled kernel allocated for it (a numba MemInfo): kept without a
    # copy (what a copy costs: benchmarks/docstring_figures.md)
    sole = array.flags.owndata or type(array.base).__name__ == "_MemInfo"
    return array.dtype == dtype and sole and array.flags.c_contiguous


def _readonly(array: np.ndarray) -> np.ndarray:
    array.flags.writeable = False
    return array


def parameter_text(parameters) -> str:
    """``key=value, ...`` of a result's parameters for people: numbers to 4 significant digits."""

    def shown(value) -> str:
        if isinstance(value, (float, np.floating)):
            return f"{value:.4g}"
        if isinstance(value, (tuple, list)) and value and all(isinstance(v, (float, np.floating)) for v in value):
            return "(" + ", ".join(f"{v:.4g}" for v in value) + ")"
        return str(value)

    return ", ".join(f"{key}={shown(value)}" for key, value in parameters.items())
