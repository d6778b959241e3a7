"""The jets' written-out solves of 10 and 6 terms against the general loop and the NumPy twin (issue 31).

``_kernels.jets._solve_10`` and ``_solve_6`` are emitted as LLVM instructions (``_solve_steps``); the fits of
degree 4 and more use the loop of ``_cholesky_inline``, and the NumPy backend ``jets._cholesky_solve``. The three
do the same operations in the same order, so they must agree to the bit, in their solutions and in their
decisions (a pivot not above ``PIVOT_FLOOR`` times its diagonal entry, points not spread: ``MIN_SPREAD``), on
random moment sets: balls of 5 to 40 points in the unit disk, some weights zero, some balls on a line or on two
lines (no quadric determined). The solution itself is checked against exact polynomials.
"""

from __future__ import annotations

from math import comb

import numpy as np
import pytest

nb = pytest.importorskip("numba")

from meshcurv import jets  # noqa: E402
from meshcurv._kernels import jets as kernel_jets  # noqa: E402

EXPONENTS = [(total - k, k) for total in range(4) for k in range(total + 1)]


def moment_sets(n_sets, seed):
    """(N, 7, 7) moments ``sum w u^i v^k`` (``i + k <= 6``) and (N, 10) right-hand sides ``sum w h u^i v^k`` of
    random balls, their heights ``h`` a cubic with random coefficients plus noise."""
    rng = np.random.default_rng(seed)
    moments = np.zeros((n_sets, 7, 7))
    right = np.zeros((n_sets, 10))
    for n in range(n_sets):
        size = rng.integers(5, 41)
        angle = rng.uniform(0.0, 2.0 * np.pi, size)
        radius = np.sqrt(rng.uniform(0.0, 1.0, size))
        u, v = radius * np.cos(angle), radius * np.sin(angle)
        kind = n % 10
        if kind == 0:  # on a line: no quadric, no linear fit either
            v = 0.5 * u
        elif kind == 1:  # on two lines: no quadric
            v = np.where(rng.random(size) < 0.5, 0.0, 0.3)
        weight = np.maximum(1.0 - (u * u + v * v), 0.0) ** 2
        weight[rng.random(size) < 0.02] = 0.0
        coefficients = rng.normal(0.0, 1.0, 10)
        height = sum(c * u**i * v**k for c, (i, k) in zip(coefficients, EXPONENTS))
        height = height + rng.normal(0.0, 0.01, size)
        for i in range(7):
            for k in range(7 - i):
                moments[n, i, k] = np.sum(weight * u**i * v**k)
        for r, (i, k) in enumerate(EXPONENTS):
            right[n, r] = np.sum(weight * height * u**i * v**k)
    return moments, right


@nb.njit
def _written_out(moments, right, m, min_spread):
    """The solves of :func:`meshcurv._kernels.jets._solve_10` (``m`` 10) or ``_solve_6`` (6) of each set."""
    n = moments.shape[0]
    solutions = np.full((n, 6), np.nan)
    solution = np.zeros(10)
    for s in range(n):
        if m == 10:
            ok = kernel_jets._solve_10(moments[s], right[s], solution, min_spread)
        else:
            ok = kernel_jets._solve_6(moments[s], right[s], solution, min_spread)
        if ok:
            solutions[s] = solution[:6]
    return solutions


@nb.njit
def _loop_solves(moments, right, m, min_spread, inverse_binomials, exponents):
    """The same solves by the loop of ``_cholesky_inline`` (``_cholesky_solve``, callable from compiled code
    only), the matrix read as the compiled fits of degree 4 and more read it."""
    n = moments.shape[0]
    solutions = np.full((n, 6), np.nan)
    matrix = np.zeros((m, m))
    low = np.zeros((m, m))
    solution = np.zeros(m)
    for s in range(n):
        for r in range(m):
            for c in range(r + 1):
                matrix[r, c] = moments[s, exponents[r, 0] + exponents[c, 0], exponents[r, 1] + exponents[c, 1]]
            solution[r] = right[s, r]
        if kernel_jets._cholesky_solve(matrix, solution, low, m, min_spread, inverse_binomials, moments[s, 0, 0]):
            solutions[s] = solution[:6]
    return solutions


def _loop(moments, right, m, min_spread):
    inverse_binomials = np.array([1.0 / comb(i + k, i) for i, k in EXPONENTS[:m]])
    return _loop_solves(moments, right, m, min_spread, inverse_binomials, np.array(EXPONENTS[:m]))


def _numpy(moments, right, m, min_spread):
    """The NumPy backend's solves (``jets._cholesky_solve``) of the full symmetric matrices."""
    matrix = np.zeros((moments.shape[0], m, m))
    for r, (i, k) in enumerate(EXPONENTS[:m]):
        for c, (p, q) in enumerate(EXPONENTS[:m]):
            matrix[:, r, c] = moments[:, i + p, k + q]
    inverse_binomials = np.array([1.0 / comb(i + k, i) for i, k in EXPONENTS[:m]])
    solutions, ok = jets._cholesky_solve(matrix, right[:, :m].copy(), inverse_binomials, moments[:, 0, 0], min_spread)
    return np.where(ok[:, None], solutions[:, :6], np.nan)


@pytest.mark.parametrize("m", [10, 6])
@pytest.mark.parametrize("min_spread", [jets.MIN_SPREAD, 1e-3])
def test_the_written_out_solve_is_the_loop_and_the_numpy_twin(m, min_spread):
    moments, right = moment_sets(3000, seed=m)
    written = _written_out(moments, right, m, min_spread)
    loop = _loop(moments, right, m, min_spread)
    numpy = _numpy(moments, right, m, min_spread)
    np.testing.assert_array_equal(written, loop)
    np.testing.assert_array_equal(written, numpy)
    kept = ~np.isnan(written[:, 0])
    # both decisions taken on these sets: balls on one or two lines refused, others kept
    assert not kept[0::10].any()
    if m == 10:
        assert not kept[1::10].any()
    assert kept.any()
    if min_spread == jets.MIN_SPREAD:
        assert kept.mean() > 0.5


def test_the_solve_recovers_an_exact_cubic():
    """Heights that are a cubic of the tangent coordinates, on 30 spread points: the fit is that cubic (its
    constant, linear and quadratic coefficients), to the round-off of a well-conditioned system."""
    rng = np.random.default_rng(3)
    angle = rng.uniform(0.0, 2.0 * np.pi, 30)
    radius = np.sqrt(rng.uniform(0.05, 1.0, 30))
    u, v = radius * np.cos(angle), radius * np.sin(angle)
    weight = np.maximum(1.0 - (u * u + v * v), 0.0) ** 2
    coefficients = np.array([0.1, -0.2, 0.3, 0.5, -0.25, 0.75, 0.2, -0.1, 0.05, 0.3])
    height = sum(c * u**i * v**k for c, (i, k) in zip(coefficients, EXPONENTS))
    moments = np.zeros((1, 7, 7))
    right = np.zeros((1, 10))
    for i in range(7):
        for k in range(7 - i):
            moments[0, i, k] = np.sum(weight * u**i * v**k)
    for r, (i, k) in enumerate(EXPONENTS):
        right[0, r] = np.sum(weight * height * u**i * v**k)
    found = _written_out(moments, right, 10, jets.MIN_SPREAD)[0]
    np.testing.assert_allclose(found, coefficients[:6], rtol=0, atol=1e-10)
