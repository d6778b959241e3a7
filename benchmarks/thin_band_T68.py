"""icc's default on thin analytic parts, clean: valid vertices off the exact H, of the wrong sign, undefined (issue 29).

A part thinner than icc's balls (the rim of a flat ellipsoid) puts its other side in the balls of the normal fits
(three measure radii) and, nearer the rim, of the sums. Each row: an analytic mesh of ``meshcurv.shapes`` (its
vertices lie on the surface, so the exact curvatures are those at the vertices), ``principal_curvatures`` at its
default; the error of H over the largest exact ``|k|`` at each vertex, over the valid vertices; ``off``: above 0.5;
``wrong sign``: valid vertices whose H has the other sign than the exact H; ``REACH``: vertices undefined because
their ball reaches round the surface. ``tuned`` marks the shapes the constants were chosen on (T68); the rest were
not looked at before the constants were fixed.

A second table (T70) runs the thin shapes at given radii (``radius=`` 0.12, 0.25, 0.35: 0.6, 1.4 and 2 default radii of
the ellipsoid (3, 3, 0.15) s16), where balls that stop short of the rim read the curvature growing towards it; its
``tuned`` marks the shapes the check of the wider ball (``meshcurv.estimators.icc.THIN_WIDER``) was chosen on.

Run from the repository root (a source tree with ``PYTHONPATH=<tree>/src`` to compare two commits)::

    python benchmarks/thin_band_T68.py [numba|numpy] [--radii]
"""

from __future__ import annotations

import sys
import time
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes
from meshcurv._backend import use_backend
from meshcurv.defects import REACH

CASES = (
    ("ellipsoid (3, 3, 0.15) s10", True, lambda: shapes.ellipsoid((3.0, 3.0, 0.15), 10)),
    ("ellipsoid (3, 3, 0.15) s16", True, lambda: shapes.ellipsoid((3.0, 3.0, 0.15), 16)),
    ("ellipsoid (3, 3, 0.15) s24", True, lambda: shapes.ellipsoid((3.0, 3.0, 0.15), 24)),
    ("ellipsoid (3, 3, 0.3) s16", True, lambda: shapes.ellipsoid((3.0, 3.0, 0.3), 16)),
    ("ellipsoid (3, 2, 0.1) s20", True, lambda: shapes.ellipsoid((3.0, 2.0, 0.1), 20)),
    ("ellipsoid (3, 3, 0.05) s24", True, lambda: shapes.ellipsoid((3.0, 3.0, 0.05), 24)),
    ("torus (3, 0.1) 96 x 8", True, lambda: shapes.torus(3.0, 0.1, 96, 8)),
    ("torus (3, 0.15) 192 x 12", True, lambda: shapes.torus(3.0, 0.15, 192, 12)),
    ("icosahedron", True, lambda: shapes.icosphere(1)),
    ("torus (3, 1) 12 x 6", True, lambda: shapes.torus(3.0, 1.0, 12, 6)),
    ("ellipsoid (3, 1.5, 0.2) s20", False, lambda: shapes.ellipsoid((3.0, 1.5, 0.2), 20)),
    ("ellipsoid (4, 3, 0.12) s24", False, lambda: shapes.ellipsoid((4.0, 3.0, 0.12), 24)),
    ("ellipsoid (1, 1, 0.08) s20", False, lambda: shapes.ellipsoid((1.0, 1.0, 0.08), 20)),
    ("torus (2, 0.08) 128 x 8", False, lambda: shapes.torus(2.0, 0.08, 128, 8)),
    ("torus (3, 0.3) 96 x 12", False, lambda: shapes.torus(3.0, 0.3, 96, 12)),
    ("ellipsoid (3, 2, 1) s16", False, lambda: shapes.ellipsoid((3.0, 2.0, 1.0), 16)),
    ("ellipsoid (3, 2, 1) s32", False, lambda: shapes.ellipsoid((3.0, 2.0, 1.0), 32)),
    ("ellipsoid (2, 2, 0.5) s16", False, lambda: shapes.ellipsoid((2.0, 2.0, 0.5), 16)),
    ("icosphere(8)", False, lambda: shapes.icosphere(8)),
    ("torus (3, 1) 64 x 32", False, lambda: shapes.torus(3.0, 1.0, 64, 32)),
)


#: The thin shapes of the given radii's table (T70), with whether the wider ball's check was tuned on them.
THIN_CASES = (
    ("ellipsoid (3, 3, 0.15) s16", True, CASES[1][2]),
    ("ellipsoid (3, 2, 0.1) s20", True, CASES[4][2]),
    ("ellipsoid (3, 3, 0.05) s24", True, CASES[5][2]),
    ("ellipsoid (3, 1.5, 0.2) s20", False, CASES[10][2]),
    ("ellipsoid (4, 3, 0.12) s24", False, CASES[11][2]),
    ("ellipsoid (1, 1, 0.08) s20", False, CASES[12][2]),
    ("torus (2, 0.08) 128 x 8", False, CASES[13][2]),
    ("torus (3, 0.1) 96 x 8", False, CASES[6][2]),
)
RADII = (0.12, 0.25, 0.35)


def main(backend: str, radii: bool = False) -> None:
    print(f"meshcurv {meshcurv.__version__}, backend {backend}\n")
    given = " radius |" if radii else ""
    print(f"| shape | tuned | V |{given} valid | off | wrong sign | REACH | H error median / p95 | CPU s |")
    print(f"|---|---|---|{'---|' if radii else ''}---|---|---|---|---|---|")
    rows = (
        [(name, tuned, make, radius) for name, tuned, make in THIN_CASES for radius in RADII]
        if radii
        else [(name, tuned, make, None) for name, tuned, make in CASES]
    )
    for name, tuned, make, radius in rows:
        mesh = make()
        start = time.process_time()
        with use_backend(backend), warnings.catch_warnings():
            warnings.simplefilter("ignore")
            given = {} if radius is None else {"radius": radius}
            result = meshcurv.principal_curvatures(mesh.vertices, mesh.faces, **given)
        cpu = time.process_time() - start
        largest = np.maximum(np.abs(mesh.k_min), np.abs(mesh.k_max))
        H = (result.k_min + result.k_max) / 2
        error = np.abs(H - mesh.mean) / largest
        valid = result.valid
        signed = np.abs(mesh.mean) > 1e-9 * largest
        wrong = valid & signed & (np.sign(H) != np.sign(mesh.mean))
        reach = 0 if result.invalid_reason is None else int(np.sum(result.invalid_reason == REACH))
        cells = (
            f"{100 * np.median(error[valid]):.3g}% / {100 * np.percentile(error[valid], 95):.3g}%"
            if valid.any()
            else "-"
        )
        print(
            f"| {name} | {'yes' if tuned else 'no'} | {valid.size} |{'' if radius is None else f' {radius} |'} "
            f"{int(valid.sum())} | "
            f"{int(np.sum(valid & (error > 0.5)))} | {int(wrong.sum())} | {reach} | {cells} | {cpu:.2f} |",
            flush=True,
        )


if __name__ == "__main__":
    arguments = [argument for argument in sys.argv[1:] if argument != "--radii"]
    main(arguments[0] if arguments else "numba", radii="--radii" in sys.argv[1:])
