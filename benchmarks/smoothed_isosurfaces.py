"""The default call on isosurfaces of smoothed masks: ``python benchmarks/smoothed_isosurfaces.py``.

The held-out ``smoothed`` family of ``benchmarks/scale_families.py`` (marching cubes at 0.5 of binary
masks blurred by a Gaussian of sigma voxels, the biology pipeline): the surface kind found, the default
radius and the median ``|H - H_exact| / max|k|`` against the analytic surface, for the default call and
for ``radius="adaptive"``. Needs scikit-image.
"""

from __future__ import annotations

import os
import sys
import warnings

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import meshcurv  # noqa: E402
import scale_families  # noqa: E402


def main():
    warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
    print("| mesh | vertices | surface | default radius | median H error | adaptive |")
    print("|---|--:|---|--:|--:|--:|")
    for case in scale_families.smoothed_cases():
        scale = np.maximum(np.abs(case.k_min), np.abs(case.k_max))
        errors = []
        for radius in (None, "adaptive"):
            r = meshcurv.principal_curvatures(case.vertices, case.faces, radius=radius)
            errors.append(np.nanmedian(np.abs(r.mean - case.mean) / scale))
            if radius is None:
                default = r
        radius = np.atleast_1d(default.parameters["radius"])[0]
        print(
            f"| {case.name} | {case.vertices.shape[0]:,} | {default.parameters.get('surface')} | {radius:.3g} | "
            f"{100 * errors[0]:.2f}% | {100 * errors[1]:.2f}% |"
        )


if __name__ == "__main__":
    main()
