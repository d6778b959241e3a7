"""The curvature estimators, one module per algorithm, behind one registry."""

from __future__ import annotations

from dataclasses import dataclass
from collections.abc import Callable

from . import icc, matgeom, meyer, normal_cycle, normal_cycle_ball, quadric, rusinkiewicz

__all__ = ["Estimator", "ESTIMATORS", "DEFAULT_METHOD"]

#: The method of :func:`meshcurv.principal_curvatures`, the CLI and batch runs when none is given: the
#: lowest error on irregular and noisy meshes of the accuracy benchmark (see the README).
DEFAULT_METHOD = "icc"


@dataclass(frozen=True)
class Estimator:
    """A registered curvature estimator.

    Attributes
    ----------
    name : str
        The ``method=`` name.
    function : callable
        ``function(mesh, *, stages, **options) -> (CurvatureResult, problems)``, ``mesh`` a
        :class:`meshcurv._prepared.PreparedMesh` (checked once; the estimator trusts it).
    options : dict
        The options it takes, with their defaults (``radius=None``: the mesh's
        default, :func:`meshcurv.radius.edge_radius`).
    summary : str
        One line for ``meshcurv methods``.
    stages : tuple of str
        The stages it reports, in order.
    radius_warning_edges : float or None
        A ``radius`` given below this many median edge lengths is named in the
        call's warning (:func:`meshcurv.radius.small_radius_note`); None
        for the methods without a radius.
    multiscale : callable or None
        ``multiscale(mesh, *, radii, stages) -> [(CurvatureResult, problems), ...]`` at
        increasing radii in one pass (:func:`meshcurv.multiscale_curvatures`); None: one
        call of ``function`` per radius.
    boundary : bool
        Whether its boundary vertices can be valid (a boundary is not a defect
        for it: :data:`meshcurv.defects.BOUNDARY`).
    fragments : bool
        Whether the vertices of a part with no interior vertex (isolated faces,
        strips) can be valid: its fits take Euclidean neighbours, the other
        parts' too (:data:`meshcurv.defects.FRAGMENT`).
    """

    name: str
    function: Callable
    options: dict
    summary: str
    stages: tuple
    radius_warning_edges: float | None = None
    boundary: bool = False
    fragments: bool = False
    multiscale: Callable | None = None


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
        boundary=True,
    ),
    "icc": Estimator(
        name="icc",
        function=icc.estimate,
        multiscale=icc.estimate_multiscale,
        options={"radius": None},
        summary="interpolated corrected curvature measures over a ball, normals from jets (Lachaud et al. 2020), in 1/length",
        stages=icc.STAGES,
        radius_warning_edges=icc.RADIUS_WARNING_EDGES,
        boundary=True,
    ),
    "quadric": Estimator(
        name="quadric",
        function=quadric.estimate,
        options={"radius": None},
        summary="weighted degree-4 jet fit over a ball, normal re-estimated (Cazals & Pouget 2005; Panozzo et al. 2010)",
        stages=quadric.STAGES,
        radius_warning_edges=quadric.RADIUS_WARNING_EDGES,
        boundary=True,
        fragments=True,
    ),
    "rusinkiewicz": Estimator(
        name="rusinkiewicz",
        function=rusinkiewicz.estimate,
        options={},
        summary="per-face curvature tensors from normal differences, Voronoi-weighted (Rusinkiewicz 2004)",
        stages=rusinkiewicz.STAGES,
        boundary=True,
    ),
    "normal_cycle_ball": Estimator(
        name="normal_cycle_ball",
        function=normal_cycle_ball.estimate,
        options={"radius": None},
        summary="normal-cycle tensor over a ball (Cohen-Steiner & Morvan 2003), in 1/length",
        stages=normal_cycle_ball.STAGES,
        radius_warning_edges=normal_cycle_ball.RADIUS_WARNING_EDGES,
        boundary=True,
    ),
    "meyer": Estimator(
        name="meyer",
        function=meyer.estimate,
        options={},
        summary="cotangent mean and angle-defect Gaussian curvature (Meyer et al. 2003), no directions",
        stages=meyer.STAGES,
    ),
}
