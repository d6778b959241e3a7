"""Time of meshcurv.multiscale_curvatures against the single calls: ``python benchmarks/multiscale.py``.

Three radii ``h, 2h, 4h`` (``h`` the mean edge length) on icospheres, icc:
the multi-scale call against the largest radius alone and against three
separate calls (issue 30's target: at most 1.3 times the largest alone). Each
figure is the median of ``--repeats`` rounds after a warm-up round (numba's
compilation not counted); in each round the calls run one after the other, so
that the ratios compare calls made under the same load; wall and CPU seconds,
the ratios of CPU time (the machine is shared). ``--stages`` adds the CPU
seconds of each stage (the ``progress`` callback) of the largest radius alone
and of the multi-scale call. The multi-scale call fits the normals of the
radii from one walk per vertex (:func:`meshcurv.jets.nested_jet_normals`);
the row "fits per radius" runs it with one ``fitted_normals`` call per radius
instead (the call before aae8001; the results are checked equal to round-off).

    python benchmarks/multiscale.py --sizes 100k,1M --repeats 5 --stages
"""

from __future__ import annotations

import argparse
import contextlib
import os
import time
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes
from meshcurv.estimators import icc

SIZES = {"10k": 32, "100k": 100, "1M": 316}  # icosphere subdivisions: 10 n^2 + 2 vertices


@contextlib.contextmanager
def _per_radius_fits():
    """Within the block, ``icc.estimate_multiscale`` fits the normals of each radius on its own walk (one
    ``fitted_normals`` call per radius, as before it took them from ``nested_jet_normals``)."""
    nested = icc.nested_jet_normals
    icc.nested_jet_normals = lambda *args, **options: []  # no fits given: fitted_normals fits each radius
    try:
        yield
    finally:
        icc.nested_jet_normals = nested


def _call(function, stages_out=None):
    """(wall s, CPU s) of ``function(progress)``; the CPU seconds by stage added to ``stages_out``."""
    marks = []

    def progress(stage, index, total):
        marks.append((stage, time.process_time()))

    wall, cpu = time.perf_counter(), time.process_time()
    function(progress)
    end = time.process_time()
    if stages_out is not None:
        for (stage, at), (_, after) in zip(marks, marks[1:] + [("", end)]):
            stages_out[stage] = stages_out.get(stage, 0.0) + after - at
    return time.perf_counter() - wall, end - cpu


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="100k")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--stages", action="store_true", help="the CPU seconds of each stage")
    args = parser.parse_args(argv)
    warnings.simplefilter("ignore", meshcurv.MeshQualityWarning)
    print(
        f"meshcurv {meshcurv.__version__}, {os.cpu_count()} cores, load {os.getloadavg()[0]:.1f}; "
        f"median of {args.repeats} rounds, wall s (CPU s); ratios of CPU time\n"
    )
    header = "| vertices | icc at 4h alone | 3 calls h, 2h, 4h | multiscale h, 2h, 4h | multiscale / 4h alone |"
    rows, splits = [header, "|--:|--:|--:|--:|--:|"], []
    for size in args.sizes.split(","):
        sphere = shapes.icosphere(SIZES[size])
        v, f = sphere.vertices, sphere.faces
        h = meshcurv.geometry.mean_edge_length(v, meshcurv.MeshTopology.from_faces(f).edges)
        radii = [h, 2 * h, 4 * h]
        check = [r.mean for r in meshcurv.multiscale_curvatures(v, f, radii)]
        with _per_radius_fits():
            for got, expected in zip(meshcurv.multiscale_curvatures(v, f, radii), check):
                np.testing.assert_allclose(got.mean, expected, rtol=0, atol=1e-9 * np.abs(expected).max())
        calls = {
            "alone": lambda p: meshcurv.principal_curvatures(v, f, radius=4 * h, progress=p),
            "separate": lambda p: [meshcurv.principal_curvatures(v, f, radius=r, progress=p) for r in radii],
            "multi": lambda p: meshcurv.multiscale_curvatures(v, f, radii, progress=p),
            "per radius": lambda p: meshcurv.multiscale_curvatures(v, f, radii, progress=p),
        }
        times = {name: [] for name in calls}
        stages = {name: {} for name in calls}
        for round_ in range(args.repeats + 1):  # round 0 warms up
            for name, call in calls.items():
                with _per_radius_fits() if name == "per radius" else contextlib.nullcontext():
                    measured = _call(call, stages[name] if round_ else None)
                if round_:
                    times[name].append(measured)
        wall = {name: float(np.median([t[0] for t in ts])) for name, ts in times.items()}
        cpu = {name: float(np.median([t[1] for t in ts])) for name, ts in times.items()}
        ratio = {name: float(np.median([m[1] / a[1] for m, a in zip(times[name], times["alone"])])) for name in calls}
        rows.append(
            f"| {v.shape[0]:,} | {wall['alone']:.3f} ({cpu['alone']:.2f}) | {wall['separate']:.3f} "
            f"({cpu['separate']:.2f}) | {wall['multi']:.3f} ({cpu['multi']:.2f}) | {ratio['multi']:.2f}x |"
        )
        rows.append(
            f"| {v.shape[0]:,}, fits per radius | | | {wall['per radius']:.3f} ({cpu['per radius']:.2f}) "
            f"| {ratio['per radius']:.2f}x |"
        )
        for name in ("alone", "multi", "per radius"):
            split = ", ".join(f"{k} {s / args.repeats:.2f}" for k, s in stages[name].items())
            splits.append(f"- {v.shape[0]:,}, {name}: {split}")
    print("\n".join(rows))
    if args.stages:
        print("\nCPU s by stage (mean of the rounds):\n" + "\n".join(splits))


if __name__ == "__main__":
    main()
