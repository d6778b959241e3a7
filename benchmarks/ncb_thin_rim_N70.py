"""normal_cycle_ball at the voxel default on thin rims: a shell of balls that reaches round a part thinner than its
balls (issue 29, N70).

At the voxel default the estimator sums a shell of balls (``normal_cycle_ball.VOXEL_SHELL``), widened on coarse
voxels to about 2.4 voxels (``_voxel_shell``). Round the rim of a thin ellipsoid (``voxel_ellipsoid((8, 8, 2))``: its
radius of curvature half a voxel) the balls hold both faces of the part, and the tensor, the mean of the shape
operator over them, reads about half the rim's curvature: ``k_max`` 0.58-0.75 for 1.45-1.71 at 24 valid vertices,
H within 0.3 of the largest ``|k|``. ``_voxel_round_balls`` makes such vertices undefined (reason ``REACH``) where the
mean of the normals over the outer ball is short (``VOXEL_REACH_MEAN_NORMAL``).

For each clean voxel shape (exact ``k_min``, ``k_max`` at each vertex's closest point on the analytic surface) this
prints, for the shell with no reach check (``none``, ``VOXEL_REACH_MEAN_NORMAL = -inf``) and the default (``mean``)
in the same run on the same mesh: the vertices, the valid ones, those of them whose ``k_min``, ``k_max`` or H is off
by more than half the shape's largest ``|k|`` (``lies``), those among them where the outer ball's radius times the
read largest ``|k|`` exceeds ``ROUND_CANDIDATE`` (``rim``: the class a reaching ball makes; the others read a torus or
a pole flat, another cause) and the call's CPU seconds; then the totals of each set.

``VOXEL_REACH_MEAN_NORMAL`` and the use of ``ROUND_CANDIDATE`` were chosen on the ``tuned`` shapes; the ``held out``
ones were not looked at until then.

``--readings`` (N71): the default against the reading before N71 (``N70``: the tensor in the tangent plane of the
vertex's own normal, over the staircase's area) in the same run on the same mesh: the vertices left lying by the
staircase's normals and area (a pole of a coarse axis, the saddles of tori). N71's readings (the shell's mean normal,
the surface's area, ``normal_cycle_ball._shell_normals`` and ``_voxel_surface_areas``, whose
``VOXEL_AREA_INFLATION`` was chosen on the ``tuned`` shapes) are the default rows (``N71``).

Run: ``python benchmarks/ncb_thin_rim_N70.py`` (``--quick``: the first four shapes of each set; ``--readings``: N70's
reading against N71's).
"""

from __future__ import annotations

import argparse
import contextlib
import time
import warnings
from unittest import mock

import numpy as np

import meshcurv
from meshcurv import shapes as S
from meshcurv.estimators import normal_cycle_ball

TUNED = [
    ("voxel_ellipsoid(8, 8, 2, seed 2)", lambda: S.voxel_ellipsoid((8.0, 8.0, 2.0), seed=2)),
    ("voxel_ellipsoid(10, 10, 2.5, seed 1)", lambda: S.voxel_ellipsoid((10.0, 10.0, 2.5), seed=1)),
    ("voxel_ellipsoid(14, 3, 3, seed 3)", lambda: S.voxel_ellipsoid((14.0, 3.0, 3.0), seed=3)),
    ("voxel_ellipsoid(10, 7, 5)", lambda: S.voxel_ellipsoid((10.0, 7.0, 5.0))),
    ("voxel_ellipsoid(12, 6, 4, 1 x 1 x 2, seed 4)", lambda: S.voxel_ellipsoid((12.0, 6.0, 4.0), (1, 1, 2), seed=4)),
    ("voxel_torus(12, 4, 1 x 1 x 1.5, seed 3)", lambda: S.voxel_torus(12.0, 4.0, (1.0, 1.0, 1.5), seed=3)),
    ("voxel_torus(12, 4, 1 x 1 x 2, seed 1)", lambda: S.voxel_torus(12.0, 4.0, (1.0, 1.0, 2.0), seed=1)),
    ("voxel_torus(10, 4, 1 x 2 x 2, seed 2)", lambda: S.voxel_torus(10.0, 4.0, (1.0, 2.0, 2.0), seed=2)),
    ("voxel_torus(10, 3.5, seed 4)", lambda: S.voxel_torus(10.0, 3.5, seed=4)),
    ("voxel_torus(12, 4)", lambda: S.voxel_torus(12.0, 4.0)),
    ("voxel_sphere(3, 0.5 x 0.2 x 0.2, seed 6)", lambda: S.voxel_sphere(3.0, (0.5, 0.2, 0.2), seed=6)),
    ("voxel_sphere(6)", lambda: S.voxel_sphere(6.0)),
    ("voxel_sphere(10)", lambda: S.voxel_sphere(10.0)),
    ("voxel_sphere(10, 1 x 1 x 2, seed 3)", lambda: S.voxel_sphere(10.0, (1.0, 1.0, 2.0), seed=3)),
]
HELD_OUT = [
    ("voxel_ellipsoid(9, 9, 2.2, seed 5)", lambda: S.voxel_ellipsoid((9.0, 9.0, 2.2), seed=5)),
    ("voxel_ellipsoid(12, 12, 3, seed 4)", lambda: S.voxel_ellipsoid((12.0, 12.0, 3.0), seed=4)),
    ("voxel_ellipsoid(16, 3.5, 3.5, seed 6)", lambda: S.voxel_ellipsoid((16.0, 3.5, 3.5), seed=6)),
    ("voxel_ellipsoid(10, 6, 1.8, seed 8)", lambda: S.voxel_ellipsoid((10.0, 6.0, 1.8), seed=8)),
    (
        "voxel_ellipsoid(12, 12, 4, 1 x 1 x 1.5, seed 9)",
        lambda: S.voxel_ellipsoid((12.0, 12.0, 4.0), (1.0, 1.0, 1.5), seed=9),
    ),
    ("voxel_ellipsoid(15, 10, 6, seed 7)", lambda: S.voxel_ellipsoid((15.0, 10.0, 6.0), seed=7)),
    ("voxel_torus(14, 5, 1 x 1 x 2.5, seed 10)", lambda: S.voxel_torus(14.0, 5.0, (1.0, 1.0, 2.5), seed=10)),
    ("voxel_torus(12, 4, 1 x 1.5 x 2.5, seed 11)", lambda: S.voxel_torus(12.0, 4.0, (1.0, 1.5, 2.5), seed=11)),
    ("voxel_torus(8, 2.5, seed 5)", lambda: S.voxel_torus(8.0, 2.5, seed=5)),
    ("voxel_torus(16, 6, 1 x 1 x 2, seed 1)", lambda: S.voxel_torus(16.0, 6.0, (1.0, 1.0, 2.0), seed=1)),
    ("voxel_sphere(4, 0.5 x 0.25 x 0.25, seed 2)", lambda: S.voxel_sphere(4.0, (0.5, 0.25, 0.25), seed=2)),
    ("voxel_sphere(12, seed 3)", lambda: S.voxel_sphere(12.0, seed=3)),
    ("voxel_sphere(9, 1 x 1 x 2.5, seed 1)", lambda: S.voxel_sphere(9.0, (1.0, 1.0, 2.5), seed=1)),
    ("voxel_sphere(17, seed 5)", lambda: S.voxel_sphere(17.0, seed=5)),
]


def _staircase_reading():
    """The reading before N71: the vertex's own normal and the staircase's area (patches of ``normal_cycle_ball``)."""
    stack = contextlib.ExitStack()
    stack.enter_context(mock.patch.object(normal_cycle_ball, "_shell_normals", lambda sums, normals: normals))
    stack.enter_context(mock.patch.object(normal_cycle_ball, "_voxel_surface_areas", lambda areas, *rest: areas))
    return stack


def measure(mesh, threshold, *, staircase=False):
    """``(valid, lies, rim lies, CPU s)`` of ``normal_cycle_ball`` at its default with ``VOXEL_REACH_MEAN_NORMAL =
    threshold`` (None: the default); ``staircase``: with the reading before N71 (:func:`_staircase_reading`)."""
    value = normal_cycle_ball.VOXEL_REACH_MEAN_NORMAL if threshold is None else threshold
    reading = _staircase_reading() if staircase else contextlib.nullcontext()
    with reading, mock.patch.object(normal_cycle_ball, "VOXEL_REACH_MEAN_NORMAL", value), warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the mesh's winding and the vertices refused, said in each call
        start = time.process_time()
        result = meshcurv.principal_curvatures(mesh.vertices, mesh.faces, method="normal_cycle_ball")
        cpu = time.process_time() - start
    largest = float(np.nanmax(np.abs(np.concatenate([mesh.k_min, mesh.k_max]))))
    valid = result.valid
    errors = np.fmax(np.abs(result.k_min - mesh.k_min), np.abs(result.k_max - mesh.k_max))
    errors = np.fmax(errors, np.abs(result.mean - mesh.mean)) / largest
    lies = valid & (errors > 0.5)
    # the outer shell ball's radius (the shell of the call's own default) times the read largest |k|
    radius = np.asarray(result.radius, dtype=np.float64)
    spacing = result.parameters.get("voxel_spacing")
    step = float(np.max(spacing)) if spacing is not None else np.nan
    outer = max(normal_cycle_ball._voxel_shell(float(np.nanmax(radius)), step)) * radius
    with np.errstate(invalid="ignore"):
        rim = lies & (outer * np.fmax(np.abs(result.k_min), np.abs(result.k_max)) > normal_cycle_ball.ROUND_CANDIDATE)
    return int(valid.sum()), int(lies.sum()), int(rim.sum()), cpu


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the first four shapes of each set")
    parser.add_argument("--readings", action="store_true", help="N70's reading (staircase normal, area) against N71's")
    options = parser.parse_args(argv)
    # rows: (label, threshold, staircase reading)
    rows = (
        [("N70", None, True), ("N71", None, False)]
        if options.readings
        else [("none", -np.inf, False), ("mean", None, False)]
    )
    print(f"{'shape':48s} {'set':8s} {'check':5s} {'V':>6s} {'valid':>6s} {'lies':>5s} {'rim':>5s} {'CPU s':>6s}")
    for kind, cases in (("tuned", TUNED), ("held out", HELD_OUT)):
        totals = {label: np.zeros(3, dtype=int) for label, _, _ in rows}
        for name, make in cases[:4] if options.quick else cases:
            mesh = make()
            for label, threshold, staircase in rows:  # paired: same mesh, same minute
                valid, lies, rim, cpu = measure(mesh, threshold, staircase=staircase)
                totals[label] += (valid, lies, rim)
                print(
                    f"{name:48s} {kind:8s} {label:5s} {len(mesh.vertices):6d} {valid:6d} {lies:5d} {rim:5d} {cpu:6.2f}",
                    flush=True,
                )
        for label, (valid, lies, rim) in totals.items():
            print(f"{'total':48s} {kind:8s} {label:5s} {'':6s} {valid:6d} {lies:5d} {rim:5d}")


if __name__ == "__main__":
    main()
