"""The bias of ``method="jets"`` against the size of its ball, on a unit sphere (issue 29).

``python benchmarks/pointcloud_jet_bias.py``: for clouds of 400 and 2,000 points on the unit sphere (H = 1), clean
or under noise along the normal (uniform, in spacings ``sqrt(4 pi / N)``), jets over given radii from 0.4 to 1.6:
the share of valid points, the median and largest |H - 1| of the valid ones, and the median ``radius |H|`` of the
estimates over the given radius (the turn that :data:`meshcurv._pointcloud_estimators.JET_MEAN_TURN` bounds, over
the radius of each fit). A ball of radius 1.6 holds the far side of the sphere and its fits shrink to one side
(:func:`meshcurv._pointcloud_estimators.one_sided_fits`: balls of 1.13, turning by about 1.4 rad).
"""

import argparse
import warnings

import numpy as np

from meshcurv.pointcloud import point_cloud_curvatures

RADII = (0.4, 0.6, 0.8, 1.0, 1.2, 1.4, 1.6)
CLOUDS = ((400, 0.0), (400, 0.1), (2000, 0.0), (2000, 0.2))


def sphere(n: int, noise: float, seed: int = 1) -> np.ndarray:
    """``n`` points of the unit sphere moved along the normal by uniform noise of ``noise`` spacings."""
    rng = np.random.default_rng(seed)
    u = rng.normal(size=(n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    return u * (1.0 + rng.uniform(-noise, noise, (n, 1)) * np.sqrt(4 * np.pi / n))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.parse_args(argv)
    print("| points | noise (spacings) | radius | valid | median \\|H - 1\\| | largest | median radius \\|H\\| |")
    print("|--:|--:|--:|--:|--:|--:|--:|")
    for n, noise in CLOUDS:
        points = sphere(n, noise)
        for radius in RADII:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                r = point_cloud_curvatures(points, radius=radius, method="jets")
            valid = r.valid
            if not valid.any():
                print(f"| {n} | {noise:g} | {radius:g} | 0 | - | - | - |")
                continue
            error = np.abs(r.mean[valid] - 1.0)
            turn = radius * np.abs(r.mean[valid])
            print(
                f"| {n} | {noise:g} | {radius:g} | {valid.mean():.3f} | {np.median(error):.3f} | {error.max():.3f} "
                f"| {np.median(turn):.2f} |",
                flush=True,
            )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
