"""Exceptions and warnings raised by meshcurv.

Every error about user input subclasses :class:`ValueError`, so ``except
ValueError`` catches them all; the subclasses say which kind of input was wrong.
Warnings subclass :class:`MeshcurvWarning` so they can be filtered together.
"""

import sys
import types

__all__ = [
    "InvalidMeshError",
    "InvalidOptionError",
    "MeshFileError",
    "MissingDependencyError",
    "MeshcurvWarning",
    "MeshQualityWarning",
    "TriangulationWarning",
]


class InvalidMeshError(ValueError):
    """The vertices or faces given cannot describe a mesh (shape, dtype, values)."""


class InvalidOptionError(ValueError):
    """An option (method, smoothing steps, radius, ...) has an unusable value."""


class MeshFileError(ValueError):
    """A mesh file cannot be read or written (missing, unreadable, unknown format)."""


class MissingDependencyError(ImportError):
    """An optional dependency needed by the requested feature is not installed."""


def optional_module(name: str, message: str) -> types.ModuleType:
    """The optional dependency ``name`` imported, or a :class:`MissingDependencyError` saying ``message``."""
    try:
        __import__(name)
    except ImportError as exc:
        raise MissingDependencyError(message) from exc
    return sys.modules[name]


class MeshcurvWarning(UserWarning):
    """Base class of the warnings meshcurv issues."""


class MeshQualityWarning(MeshcurvWarning):
    """The mesh has defects (boundary, non-manifold edges, degenerate faces, ...).

    The computation went on with a defined result; the affected vertices are
    marked ``valid=False`` where the estimate is undefined.
    """


class TriangulationWarning(MeshcurvWarning):
    """Polygonal faces were fan-triangulated before the computation."""
