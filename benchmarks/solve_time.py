"""CPU time of the normal fits' written-out 10 x 10 solve alone, per solve (issue 31).

The default's normal fits solve one 10 x 10 system per vertex (``meshcurv._kernels.jets._solve_10``); callgrind
counts its instructions, but its time is mostly their latency (square roots and divisions one after the other),
which only a clock shows. This script builds random moment sets like those of a clean mesh's balls (``--points``
points in the unit disk, weights ``(1 - r^2)^2``, cubic heights), solves them all in one compiled loop, and prints
the CPU nanoseconds per solve (the best and the median of ``--repeats`` passes). From the repository::

    python benchmarks/solve_time.py --sets 200000
"""

from __future__ import annotations

import argparse
import time

import numba as nb
import numpy as np

from meshcurv._kernels import jets as kernel_jets

EXPONENTS = [(total - k, k) for total in range(4) for k in range(total + 1)]


def moment_sets(n_sets: int, n_points: int, seed: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """(N, 7, 7) moments ``sum w u^i v^k`` and (N, 10) right-hand sides ``sum w h u^i v^k`` of random balls."""
    rng = np.random.default_rng(seed)
    angle = rng.uniform(0.0, 2.0 * np.pi, (n_sets, n_points))
    radius = np.sqrt(rng.uniform(0.0, 1.0, (n_sets, n_points)))
    u, v = radius * np.cos(angle), radius * np.sin(angle)
    height = 0.3 * u * u + 0.1 * v * v + 0.05 * u**3
    weight = np.maximum(1.0 - (u * u + v * v + height * height), 0.0) ** 2
    moments = np.zeros((n_sets, 7, 7))
    for i in range(7):
        for k in range(7 - i):
            moments[:, i, k] = np.sum(weight * u**i * v**k, axis=1)
    right = np.stack([np.sum(weight * height * u**i * v**k, axis=1) for i, k in EXPONENTS], axis=1)
    return moments, right


@nb.njit
def _solve_all(moments, right, out, min_spread):
    """Solve every set with ``_solve_10``; its 6 coefficients to ``out``; the number solved."""
    solved = 0
    solution = np.zeros(10)
    for s in range(moments.shape[0]):
        if kernel_jets._solve_10(moments[s], right[s], solution, min_spread):
            solved += 1
            for r in range(6):
                out[s, r] = solution[r]
    return solved


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sets", type=int, default=200_000, help="moment sets (one solve each)")
    parser.add_argument("--points", type=int, default=33, help="points per ball (33: the default's at 1M)")
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args(argv)
    moments, right = moment_sets(args.sets, args.points)
    out = np.zeros((args.sets, 6))
    _solve_all(moments[:10], right[:10], out[:10], 1e-7)  # compile
    times = []
    for _ in range(args.repeats):
        start = time.process_time()
        solved = _solve_all(moments, right, out, 1e-7)
        times.append(time.process_time() - start)
    best, median = min(times) / args.sets * 1e9, float(np.median(times)) / args.sets * 1e9
    print(f"{solved} of {args.sets} sets solved; CPU ns per solve: best {best:.1f}, median {median:.1f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
