"""normal_cycle_ball at the voxel default: one ball against a shell of balls (issue 29, M33), and the shell widened to
the terraces of coarse voxels (N68).

A staircase is flat on its plateaus; a single ball whose rim lies on a plateau reads the surface as flat
(``normal_cycle_ball.VOXEL_SHELL``). For each clean voxel shape this prints, for the single ball (``one``) and the
shell (``shell``, the default) in the same run: the share of valid vertices, the valid vertices whose H is off the
exact one by more than 0.3, 0.4 and 0.5 of the shape's largest ``|k|`` (0.5: the fuzzer's bar for a lie) and whose
``k_min`` or ``k_max`` is off by more than 0.5 of it, the median errors (same unit) and the call's CPU seconds.

The shell was tuned on the shapes marked ``tuned``; the others were held out.

``--anisotropic`` (N68): anisotropic voxels and coarse shapes, where the voxel default is capped at half the radius
of curvature and the shell of ``VOXEL_SHELL`` crosses less than one terrace round the coarse axis's poles; rows
``M33`` (the shell of ``VOXEL_SHELL``: ``VOXEL_SHELL_TERRACES = 0``) and ``terr`` (the default: the shell widened to
one terrace, ``normal_cycle_ball._voxel_shell``), paired on each mesh. ``VOXEL_SHELL_TERRACES`` was tuned on the
``tuned`` families (spacings 1 x 1 x 1.5, 1 x 1 x 2, 1 x 2 x 2, 0.5 x 0.2 x 0.2 and isotropic) and is reported on
the ``held out`` ones (1 x 1 x 2.5, 1 x 1 x 3, 1 x 1.5 x 2.5, 1 x 1.5 x 2, and the held-out shapes above).

Run: ``python benchmarks/ncb_plateaus_M33.py`` (``--quick``: the first three shapes of each kind; ``--anisotropic``:
the N68 families).
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes
from meshcurv.estimators import normal_cycle_ball

TUNED = [
    ("voxel_sphere(6)", lambda: shapes.voxel_sphere(6.0)),
    ("voxel_sphere(8)", lambda: shapes.voxel_sphere(8.0)),
    ("voxel_sphere(10)", lambda: shapes.voxel_sphere(10.0)),
    ("voxel_sphere(14)", lambda: shapes.voxel_sphere(14.0)),
    ("voxel_sphere(20)", lambda: shapes.voxel_sphere(20.0)),
    ("voxel_torus(12, 4)", lambda: shapes.voxel_torus(12.0, 4.0)),
    ("voxel_ellipsoid(10, 7, 5)", lambda: shapes.voxel_ellipsoid((10.0, 7.0, 5.0))),
]
HELD_OUT = [
    ("voxel_sphere(12, seed 3)", lambda: shapes.voxel_sphere(12.0, seed=3)),
    ("voxel_sphere(17, seed 5)", lambda: shapes.voxel_sphere(17.0, seed=5)),
    ("voxel_sphere(9, spacing 1 x 1 x 2.5)", lambda: shapes.voxel_sphere(9.0, (1.0, 1.0, 2.5), seed=1)),
    ("voxel_sphere(16, spacing 1 x 1.5 x 2)", lambda: shapes.voxel_sphere(16.0, (1.0, 1.5, 2.0), seed=2)),
    ("voxel_torus(10, 3.5, seed 4)", lambda: shapes.voxel_torus(10.0, 3.5, seed=4)),
    ("voxel_torus(16, 6, spacing 1 x 1 x 2)", lambda: shapes.voxel_torus(16.0, 6.0, (1.0, 1.0, 2.0), seed=1)),
    ("voxel_ellipsoid(8, 8, 2)", lambda: shapes.voxel_ellipsoid((8.0, 8.0, 2.0), seed=2)),
    ("voxel_ellipsoid(12, 6, 4, spacing 1 x 1 x 2)", lambda: shapes.voxel_ellipsoid((12.0, 6.0, 4.0), (1.0, 1.0, 2.0))),
    ("voxel_ellipsoid(15, 10, 6, seed 7)", lambda: shapes.voxel_ellipsoid((15.0, 10.0, 6.0), seed=7)),
]

S = shapes
ANISOTROPIC_TUNED = [
    ("voxel_sphere(12, 1 x 1 x 1.5)", lambda: S.voxel_sphere(12.0, (1.0, 1.0, 1.5), seed=2)),
    ("voxel_sphere(8, 1 x 1 x 2)", lambda: S.voxel_sphere(8.0, (1.0, 1.0, 2.0), seed=4)),
    ("voxel_sphere(10, 1 x 1 x 2)", lambda: S.voxel_sphere(10.0, (1.0, 1.0, 2.0), seed=3)),
    ("voxel_sphere(12, 1 x 2 x 2)", lambda: S.voxel_sphere(12.0, (1.0, 2.0, 2.0), seed=5)),
    ("voxel_sphere(3, 0.5 x 0.2 x 0.2)", lambda: S.voxel_sphere(3.0, (0.5, 0.2, 0.2), seed=6)),
    ("voxel_torus(12, 4, 1 x 1 x 1.5)", lambda: S.voxel_torus(12.0, 4.0, (1.0, 1.0, 1.5), seed=3)),
    ("voxel_torus(12, 4, 1 x 1 x 2)", lambda: S.voxel_torus(12.0, 4.0, (1.0, 1.0, 2.0), seed=1)),
    ("voxel_torus(10, 4, 1 x 2 x 2)", lambda: S.voxel_torus(10.0, 4.0, (1.0, 2.0, 2.0), seed=2)),
    ("voxel_torus(3, 1, 0.5 x 0.2 x 0.2)", lambda: S.voxel_torus(3.0, 1.0, (0.5, 0.2, 0.2), seed=3)),
    ("voxel_ellipsoid(10, 7, 5, 1 x 1 x 1.5)", lambda: S.voxel_ellipsoid((10.0, 7.0, 5.0), (1.0, 1.0, 1.5), seed=1)),
    ("voxel_ellipsoid(12, 8, 6, 1 x 2 x 2)", lambda: S.voxel_ellipsoid((12.0, 8.0, 6.0), (1.0, 2.0, 2.0), seed=2)),
    ("voxel_ellipsoid(12, 6, 4, 1 x 1 x 2)", lambda: S.voxel_ellipsoid((12.0, 6.0, 4.0), (1.0, 1.0, 2.0), seed=4)),
    (
        "voxel_ellipsoid(3, 2, 1.5, 0.5 x 0.2 x 0.2)",
        lambda: S.voxel_ellipsoid((3.0, 2.0, 1.5), (0.5, 0.2, 0.2), seed=5),
    ),
    *TUNED,
]
ANISOTROPIC_HELD_OUT = [
    ("voxel_sphere(9, 1 x 1 x 2.5)", lambda: S.voxel_sphere(9.0, (1.0, 1.0, 2.5), seed=1)),
    ("voxel_sphere(10, 1 x 1 x 3)", lambda: S.voxel_sphere(10.0, (1.0, 1.0, 3.0), seed=7)),
    ("voxel_sphere(14, 1 x 1 x 3)", lambda: S.voxel_sphere(14.0, (1.0, 1.0, 3.0), seed=8)),
    ("voxel_sphere(11, 1 x 1.5 x 2.5)", lambda: S.voxel_sphere(11.0, (1.0, 1.5, 2.5), seed=9)),
    ("voxel_torus(14, 5, 1 x 1 x 2.5)", lambda: S.voxel_torus(14.0, 5.0, (1.0, 1.0, 2.5), seed=10)),
    ("voxel_torus(12, 4, 1 x 1.5 x 2.5)", lambda: S.voxel_torus(12.0, 4.0, (1.0, 1.5, 2.5), seed=11)),
    ("voxel_ellipsoid(12, 8, 5, 1 x 1 x 3)", lambda: S.voxel_ellipsoid((12.0, 8.0, 5.0), (1.0, 1.0, 3.0), seed=12)),
    *[case for case in HELD_OUT if "spacing 1 x 1 x 2.5" not in case[0]],
]


def measure(mesh, shell, terraces=None):
    """The row's figures of ``normal_cycle_ball`` at the default radius with ``VOXEL_SHELL = shell`` (and
    ``VOXEL_SHELL_TERRACES = terraces``, unless None)."""
    saved = normal_cycle_ball.VOXEL_SHELL, normal_cycle_ball.VOXEL_SHELL_TERRACES
    normal_cycle_ball.VOXEL_SHELL = shell
    if terraces is not None:
        normal_cycle_ball.VOXEL_SHELL_TERRACES = terraces
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            start = time.process_time()
            result = meshcurv.principal_curvatures(mesh.vertices, mesh.faces, method="normal_cycle_ball")
            cpu = time.process_time() - start
    finally:
        normal_cycle_ball.VOXEL_SHELL, normal_cycle_ball.VOXEL_SHELL_TERRACES = saved
    largest = float(np.nanmax(np.abs(np.concatenate([mesh.k_min, mesh.k_max]))))
    valid = result.valid
    h_error = np.abs(result.mean - mesh.mean)[valid] / largest
    k_error = np.fmax(np.abs(result.k_min - mesh.k_min), np.abs(result.k_max - mesh.k_max))[valid] / largest
    return (
        valid.mean(),
        *(int((h_error > bar).sum()) for bar in (0.3, 0.4, 0.5)),
        int((k_error > 0.5).sum()),
        float(np.median(h_error)) if h_error.size else np.nan,
        float(np.median(k_error)) if k_error.size else np.nan,
        cpu,
    )


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the first three shapes of each kind")
    parser.add_argument("--anisotropic", action="store_true", help="the N68 families: the shell widened to terraces")
    options = parser.parse_args(argv)
    header = f"{'shape':46s} {'set':8s} {'ball':5s} {'V':>6s} {'valid':>6s} {'H>0.3':>6s} {'H>0.4':>6s} {'H>0.5':>6s}"
    print(header + f" {'k>0.5':>6s} {'med H':>6s} {'med k':>6s} {'CPU s':>6s}")
    shell = normal_cycle_ball.VOXEL_SHELL
    if options.anisotropic:
        kinds = (("tuned", ANISOTROPIC_TUNED), ("held out", ANISOTROPIC_HELD_OUT))
        rows = (("M33", shell, 0.0), ("terr", shell, None))
    else:
        kinds = (("tuned", TUNED), ("held out", HELD_OUT))
        rows = (("one", (1.0,), None), ("shell", shell, None))
    for kind, cases in kinds:
        for name, make in cases[:3] if options.quick else cases:
            mesh = make()
            # paired: the rows alternate on the same mesh in the same minute
            for label, balls, terraces in rows:
                share, *counts, h_median, k_median, cpu = measure(mesh, balls, terraces)
                print(
                    f"{name:46s} {kind:8s} {label:5s} {len(mesh.vertices):6d} {share:6.3f} "
                    + " ".join(f"{c:6d}" for c in counts)
                    + f" {h_median:6.3f} {k_median:6.3f} {cpu:6.2f}",
                    flush=True,
                )


if __name__ == "__main__":
    main()
