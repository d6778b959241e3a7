"""The result of a curvature computation."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from types import MappingProxyType
from typing import TYPE_CHECKING, Any, Mapping

import numpy as np

if TYPE_CHECKING:
    from .diagnosis import MeshDiagnosis

__all__ = ["CurvatureResult", "INVALID_REASONS"]

#: What ``CurvatureResult.invalid_reason`` codes mean: code ``c`` is ``INVALID_REASONS[c]``. A vertex
#: gets the first code that applies, in this order.
INVALID_REASONS = (
    "valid",
    "unreferenced vertex (in no face)",
    "on a non-manifold edge (3+ faces)",
    "bow-tie vertex (fans of faces meeting at a point)",
    "on an edge between inconsistently oriented faces",
    "corner of a zero-area face",
    "on a boundary edge (this method needs a closed neighbourhood)",
    "estimate undefined (too few neighbours in the ball, a failed fit, or a non-finite value)",
)


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
    """

    k_min: np.ndarray
    k_max: np.ndarray
    dir_min: np.ndarray
    dir_max: np.ndarray
    normals: np.ndarray
    valid: np.ndarray
    method: str
    parameters: Mapping[str, Any] = field(default_factory=dict)
    diagnosis: "MeshDiagnosis | None" = None
    invalid_reason: np.ndarray | None = None

    def __post_init__(self):
        for name in _ARRAY_FIELDS:
            value = getattr(self, name)
            if isinstance(value, np.ndarray) and not value.flags.writeable and _keepable(value, name):
                continue  # read-only and owning its data: taken as it is, not copied (see _of_arrays)
            array = np.array(value, dtype=bool if name == "valid" else np.float64, copy=True)
            array.flags.writeable = False
            object.__setattr__(self, name, array)
        object.__setattr__(self, "parameters", MappingProxyType(dict(self.parameters)))
        if self.invalid_reason is not None:
            object.__setattr__(self, "invalid_reason", _readonly(np.array(self.invalid_reason, dtype=np.int8)))

    def invalid_counts(self) -> dict[str, int]:
        """How many vertices are invalid for each reason (:data:`INVALID_REASONS`), largest first.

        Empty when every vertex is valid; ``{"unknown": n}`` when the result
        carries no ``invalid_reason``.
        """
        if self.invalid_reason is None:
            n_invalid = int((~self.valid).sum())
            return {"unknown": n_invalid} if n_invalid else {}
        counts = np.bincount(self.invalid_reason, minlength=len(INVALID_REASONS))
        order = np.argsort(-counts[1:], kind="stable") + 1
        return {INVALID_REASONS[c]: int(counts[c]) for c in order if counts[c]}

    @classmethod
    def _of_arrays(cls, **fields) -> "CurvatureResult":
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
        Flipping the faces negates it. NaN where the surface is flat
        (``curvedness == 0``) or the estimate is invalid.

        J. J. Koenderink and A. J. van Doorn (1992). Surface shape and curvature
        scales. Image and Vision Computing 10(8), 557-564.
        https://doi.org/10.1016/0262-8856(92)90076-F
        """
        with np.errstate(invalid="ignore"):
            index = (2 / np.pi) * np.arctan2(self.k_max + self.k_min, self.k_max - self.k_min)
        return _readonly(np.where(self.curvedness > 0, index, np.nan))

    @cached_property
    def curvedness(self) -> np.ndarray:
        """(V,) curvedness ``sqrt((k_min**2 + k_max**2) / 2)`` (Koenderink and van Doorn 1992), in 1/length."""
        return _readonly(np.sqrt((self.k_min**2 + self.k_max**2) / 2))

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


_ARRAY_FIELDS = ("k_min", "k_max", "dir_min", "dir_max", "normals", "valid")


def _keepable(array: np.ndarray, name: str) -> bool:
    dtype = np.bool_ if name == "valid" else np.float64
    return array.dtype == dtype and array.flags.owndata and array.flags.c_contiguous


def _readonly(array: np.ndarray) -> np.ndarray:
    array.flags.writeable = False
    return array
