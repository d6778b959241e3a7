"""The curvature estimators, one module per algorithm, behind one registry."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

from . import matgeom, normal_cycle

__all__ = ["Estimator", "ESTIMATORS"]


@dataclass(frozen=True)
class Estimator:
    """A registered curvature estimator.

    Attributes
    ----------
    name : str
        The ``method=`` name.
    function : callable
        ``function(vertices, topology, *, stages, **options) -> (CurvatureResult, problems)``.
    options : dict
        The options it takes, with their defaults.
    summary : str
        One line for ``meshcurv methods``.
    stages : tuple of str
        The stages it reports, in order.
    """

    name: str
    function: Callable
    options: dict
    summary: str
    stages: tuple


ESTIMATORS: dict[str, Estimator] = {
    "normal_cycle": Estimator(
        name="normal_cycle",
        function=normal_cycle.estimate,
        options={"smoothing_steps": 3},
        summary="normal-cycle tensor (Cohen-Steiner & Morvan 2003) over barycentric cells, in 1/length",
        stages=normal_cycle.STAGES,
    ),
    "matgeom": Estimator(
        name="matgeom",
        function=matgeom.estimate,
        options={"smoothing_steps": 3},
        summary="matGeom's meshCurvatures reproduced exactly (dimensionless values, compatibility mode)",
        stages=matgeom.STAGES,
    ),
}
