"""Cost of the pose-free extent (radius.rigid_extent: the smallest enclosing ball) against the bounding box's
diagonal it replaced, at 1M points (issue 29, fuzz_api 512/16).

``python benchmarks/enclosing_ball_X26.py [--points N] [--repeats R]``: CPU milliseconds (the least of R runs, paired
in each run) for a noisy unit sphere, a torus, a uniform box and a Gaussian blob.
"""

import argparse
import time

import numpy as np

from meshcurv.radius import rigid_extent


def clouds(n, rng):
    unit = rng.normal(size=(n, 3))
    unit /= np.linalg.norm(unit, axis=1, keepdims=True)
    t, p = rng.uniform(0.0, 2.0 * np.pi, (2, n))
    torus = np.column_stack([(3.0 + np.cos(p)) * np.cos(t), (3.0 + np.cos(p)) * np.sin(t), np.sin(p)])
    return {
        "noisy sphere": unit * (1.0 + 0.003 * rng.normal(size=(n, 1))),
        "torus": torus,
        "box 3 x 2 x 1": rng.random((n, 3)) * [3.0, 2.0, 1.0],
        "gaussian blob": rng.normal(size=(n, 3)),
    }


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1_000_000)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    print("| cloud | rigid_extent (ms) | box diagonal (ms) | extent / diagonal |")
    print("|---|--:|--:|--:|")
    for name, points in clouds(args.points, np.random.default_rng(0)).items():
        ball, box = [], []
        for _ in range(args.repeats):
            start = time.process_time()
            size = rigid_extent(points)
            ball.append(time.process_time() - start)
            start = time.process_time()
            diagonal = float(np.linalg.norm(points.max(axis=0) - points.min(axis=0)))
            box.append(time.process_time() - start)
        print(f"| {name} | {1e3 * min(ball):.0f} | {1e3 * min(box):.0f} | {size / diagonal:.3f} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
