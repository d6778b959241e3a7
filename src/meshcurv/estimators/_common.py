"""What the estimators share: stage reporting and the result assembly."""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np

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
