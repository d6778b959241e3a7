"""The result of a curvature computation."""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property
from types import MappingProxyType
from typing import Any, Mapping

import numpy as np

__all__ = ["CurvatureResult"]


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
      matGeom's own zeros at unreferenced vertices).

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
    """

    k_min: np.ndarray
    k_max: np.ndarray
    dir_min: np.ndarray
    dir_max: np.ndarray
    normals: np.ndarray
    valid: np.ndarray
    method: str
    parameters: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self):
        for name in ("k_min", "k_max", "dir_min", "dir_max", "normals", "valid"):
            value = getattr(self, name)
            dtype = bool if name == "valid" else np.float64
            array = np.array(value, dtype=dtype, copy=True)
            array.flags.writeable = False
            object.__setattr__(self, name, array)
        object.__setattr__(self, "parameters", MappingProxyType(dict(self.parameters)))

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


def _readonly(array: np.ndarray) -> np.ndarray:
    array.flags.writeable = False
    return array
