"""What the estimators share: stage reporting, NaN rows, and the assembly of their result."""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np

from ..defects import VertexDefects
from ..result import CurvatureResult

logger = logging.getLogger("meshcurv")

#: A progress callback: ``progress(stage, index, total)`` with 1-based ``index``.
ProgressCallback = Callable[[str, int, int], None]


class Stages:
    """Announce the stages of a computation on the ``meshcurv`` logger and to a callback.

    Parameters
    ----------
    names : sequence of str
        The stages, in order.
    progress : callable, optional
        Called as ``progress(stage, index, total)`` when each stage starts.
    """

    def __init__(self, names, progress: ProgressCallback | None = None):
        self.names = tuple(names)
        self.progress = progress

    def start(self, name: str) -> None:
        index = self.names.index(name) + 1
        logger.info("%s (%d/%d)", name, index, len(self.names))
        if self.progress is not None:
            self.progress(name, index, len(self.names))


def nan_where(invalid: np.ndarray, *arrays: np.ndarray) -> None:
    """Set the rows of ``arrays`` selected by ``invalid`` to NaN, in place."""
    for array in arrays:
        array[invalid] = np.nan


def finish(
    method: str,
    parameters: dict,
    valid: np.ndarray,
    normals: np.ndarray,
    k_min,
    k_max,
    dir_min,
    dir_max,
    defects: VertexDefects,
    extra: tuple[str, ...] = (),
    radius: np.ndarray | None = None,
):
    """NaN where invalid, the one result, and the problem list for the one warning.

    ``radius``: the (V,) radius of each vertex's ball (the methods over balls).
    """
    valid = valid & np.isfinite(k_min) & np.isfinite(k_max)
    nan_where(~valid, k_min, k_max, dir_min, dir_max)
    # the estimators' own arrays, taken without copies (88 bytes per vertex)
    result = CurvatureResult._of_arrays(
        k_min=k_min,
        k_max=k_max,
        dir_min=dir_min,
        dir_max=dir_max,
        normals=normals,
        valid=valid,
        method=method,
        parameters=parameters,
        radius=radius,
    )
    return result, problems(defects, valid, extra)


def problems(defects: VertexDefects, valid: np.ndarray, extra=()) -> list[str]:
    """The phrases of the call's warning: the defects the method met, its own notes, the vertices left NaN."""
    found = defects.messages() + [m for m in extra if m]
    n_invalid = int((~valid).sum())
    if n_invalid:
        found.append(f"{n_invalid} vertices are NaN with valid=False")
    return found
