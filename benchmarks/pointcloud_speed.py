"""Speed of meshcurv's point-cloud curvatures, stage by stage (issue 31: 1M points in <= 5 s wall).

Torus samples (R 3, r 1, uniform by area, as ``benchmarks/pointcloud.py``),
normals estimated, both methods, end to end. The stages are the log messages
of :mod:`meshcurv.pointcloud` and :mod:`meshcurv._pointcloud_estimators`
(INFO and DEBUG): a stage lasts from its message to the next one; repeated
messages (chunks) are summed. Wall seconds and CPU seconds of the process (all
threads); the load average of the machine at the end (other processes share
its cores: the wall time grows with the load, the CPU time much less).
No peer: Open3D (which estimates normals, not curvatures) is not installed.

Usage::

    python benchmarks/pointcloud_speed.py                   # 100k and 1M points
    python benchmarks/pointcloud_speed.py --sizes 100000    # one size
    python benchmarks/pointcloud_speed.py --repeat 1        # one run each (default: the median of 3)
"""

from __future__ import annotations

import argparse
import collections
import logging
import os
import sys
import time
import warnings
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

from pointcloud import sample  # noqa: E402

from meshcurv.pointcloud import POINT_CLOUD_METHODS, point_cloud_curvatures  # noqa: E402


class StageClock(logging.Handler):
    """The wall, process CPU and calling-thread CPU time between consecutive log messages of the point-cloud modules.

    The calling thread runs every serial part and its share of the parallel ones: its CPU time is the wall time
    the call would take on idle cores (what a shared machine's wall time no longer tells).
    """

    def __init__(self):
        super().__init__(level=logging.DEBUG)
        self.marks = []

    def emit(self, record):
        label = record.msg.replace("%d ", "").replace("%s ", "")
        self.marks.append((label, time.perf_counter(), time.process_time(), time.thread_time()))

    def stages(self, end):
        """Label -> (wall, process CPU, calling-thread CPU) seconds, up to the clocks' readings ``end``."""
        totals: dict = collections.OrderedDict()
        for (label, *start), (_, *stop) in zip(self.marks, [*self.marks[1:], ("end", *end)]):
            old = totals.get(label, (0.0, 0.0, 0.0))
            totals[label] = tuple(o + b - a for o, a, b in zip(old, start, stop))
        return totals


def timed(points, method=None):
    """``(result, (wall, cpu, thread), stages)`` of one ``point_cloud_curvatures`` call (its default method if None)."""
    clock = StageClock()
    loggers = [logging.getLogger(name) for name in ("meshcurv.pointcloud", "meshcurv._pointcloud_estimators")]
    for logger in loggers:
        logger.addHandler(clock)
        logger.setLevel(logging.DEBUG)
    options = {} if method is None else {"method": method}
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            start = (time.perf_counter(), time.process_time(), time.thread_time())
            result = point_cloud_curvatures(points, **options)
            end = (time.perf_counter(), time.process_time(), time.thread_time())
    finally:
        for logger in loggers:
            logger.removeHandler(clock)
    return result, tuple(b - a for a, b in zip(start, end)), clock.stages(end)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", type=int, nargs="+", default=[100_000, 1_000_000])
    parser.add_argument("--methods", nargs="+", default=list(POINT_CLOUD_METHODS))
    parser.add_argument("--repeat", type=int, default=3, help="runs per size and method (the median one shown)")
    args = parser.parse_args(argv)
    # compiled kernels loaded (or compiled) before any timing: a cloud above the grid search's size, with a near copy
    warm = sample("torus", 70_000)[0]
    warm[1] = warm[0] + 1e-9
    for method in args.methods:
        timed(warm, method)
    lines = ["| points | method | wall s | CPU s | valid | stages: wall s (CPU s) |", "|---|---|---|---|---|---|"]
    for n in args.sizes:
        points = sample("torus", n)[0]
        for method in args.methods:
            runs = sorted((timed(points, method) for _ in range(args.repeat)), key=lambda run: run[1][0])
            result, (wall, cpu, _), stages = runs[len(runs) // 2]  # the run of median wall time
            detail = "; ".join(
                f"{label.replace('point cloud: ', '')} {w:.2f} ({c:.2f})"
                for label, (w, c, _) in stages.items()
                if w >= 0.005
            )
            lines.append(f"| {n} | {method} | {wall:.2f} | {cpu:.2f} | {result.valid.mean():.4f} | {detail} |")
            print(lines[-1], flush=True)
    load = ", ".join(f"{x:.1f}" for x in os.getloadavg())
    print("\n".join(["", *lines, "", f"load average at the end: {load} ({os.cpu_count()} cores)"]))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
