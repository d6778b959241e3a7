"""Compiled twins of :mod:`meshcurv.jets`: weighted jets fitted over Euclidean or surface-connected balls."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import cast

import numba as nb
import numpy as np
from llvmlite import ir  # type: ignore[import-untyped]
from numba.core import cgutils, types
from numba.extending import intrinsic, overload

from ._common import (
    _JIT,
    _JIT_INNER,
    _JIT_INNER_REASSOC,
    _TINY,
    _UNSIGNED,
    _JitOptions,
    _tangent_frame,
    run_chunks,
    run_slots,
    threaded,
)
from .geometry import _unadvised_array
from .neighborhoods import _ball_members, _connected_members, _vertex_spans, pool_grid
from .tensors import _tangent_eigen


#: ``jets.PIVOT_FLOOR``: the smallest pivot for which the factorization goes on.
_PIVOT_FLOOR = 1e-12

#: The options of :func:`_fit_one` and of the functions it calls: compiled without numba's reference counts
#: (``_nrt``): they allocate nothing, and each of their array arguments was otherwise counted up and down once per
#: fit (two atomic operations each, some 50 per vertex of the inlined fit: a third of the normal fits' CPU on a 1M
#: icosphere, issue 31). Their callers allocate, and keep the counts.
_JIT_LEAF: _JitOptions = cast(_JitOptions, {**_JIT_INNER, "_nrt": False})
_JIT_LEAF_REASSOC: _JitOptions = cast(_JitOptions, {**_JIT_INNER_REASSOC, "_nrt": False})
_JIT_LEAF_OVERLOAD: _JitOptions = cast(_JitOptions, {**_JIT, "_nrt": False})


@nb.njit(inline="always", **_JIT)
def _cholesky_inline(a, b, low, m, min_spread, inverse_binomials, total):
    """Solve ``a[:m, :m] x = b[:m]`` in place of ``b``; False if a pivot is not above ``_PIVOT_FLOOR`` times its
    diagonal entry or the points are not spread.

    ``a`` is the symmetric normal matrix (only its lower triangle is read; it is overwritten with the factor's
    entries times their pivots). The factorization is ``a = L D L^T``, ``L`` unit lower triangular: no square
    roots, no scaling (issue 31: the square roots and divisions of Cholesky's factor of the matrix scaled to a
    unit diagonal were most of the solve's time, one after the other). Pivot ``d_k`` must be above
    ``_PIVOT_FLOOR max(a_kk, tiny)`` (the pivot of the scaled matrix above ``_PIVOT_FLOOR``). The points are
    spread where ``total sum_j (a^-1)_jj / C(i_j + k_j, i_j) < 1 / min_spread`` (``jets.MIN_SPREAD``; ``total``:
    the sum of the weights, ``(i_j, k_j)`` the exponents, ``inverse_binomials`` the ``1 / C``,
    :func:`_jet_scratch`), ``(a^-1)_jj = sum_i (L^-1)_ij^2 / d_i``; the solution ``L^-T D^-1 L^-1 b`` is taken
    from the same columns of ``L^-1`` (no substitutions). The same operations in the same order as
    ``jets._cholesky_solve`` and :func:`_solve_steps`. ``low`` is scratch: ``L`` below its diagonal, ``1 / d_k``
    on it, and in row ``j`` above it column ``j`` of ``L^-1``, negated.
    """
    for k in range(m):
        d = a[k, k]
        for j in range(k):
            d -= a[k, j] * low[k, j]
        floor = a[k, k]
        floor = _TINY if _TINY > floor else floor  # max(a_kk, tiny)
        if not d > floor * _PIVOT_FLOOR:
            return False
        inverse = 1.0 / d
        low[k, k] = inverse
        for i in range(k + 1, m):
            s = a[i, k]
            for j in range(k):
                s -= a[i, j] * low[k, j]
            a[i, k] = s  # read no more: the factor's entry times pivot k
            low[i, k] = s * inverse
    trace = 0.0
    for j in range(m):  # column j of the unit factor's inverse below its diagonal, negated, in row j
        norm = low[j, j]
        for i in range(j + 1, m):
            s = low[i, j]
            for k in range(j + 1, i):
                s -= low[i, k] * low[j, k]
            low[j, i] = s
            norm += s * s * low[i, i]
        trace += norm * inverse_binomials[j]
    if not trace * total * min_spread < 1.0:
        return False
    for i in range(m - 1, -1, -1):  # D^-1 L^-1 b (each row reads the rows of b above it, not yet replaced)
        s = b[i]
        for j in range(i):
            s -= low[j, i] * b[j]
        b[i] = s * low[i, i]
    for j in range(m):  # L^-T (each row reads the rows of b below it, not yet replaced)
        s = b[j]
        for i in range(j + 1, m):
            s -= low[j, i] * b[i]
        b[j] = s
    return True


@nb.njit(**_JIT_LEAF)
def _cholesky_solve(a, b, low, m, min_spread, inverse_binomials, total):
    """:func:`_cholesky_inline` of any size ``m``."""
    return _cholesky_inline(a, b, low, m, min_spread, inverse_binomials, total)


def _solve_steps(m, steps):
    """:func:`_fit_one`'s solve of the first ``m`` (10 or 6) exponents of ``jets._exponents(3)``, written out as
    calls on ``steps`` (:class:`_IRSteps`: one LLVM instruction each).

    The loops of :func:`_smaller_solve` (the lower triangle of the normal matrix read from ``moments``) and of
    :func:`_cholesky_inline` (the ``L D L^T`` factor, the spread from the columns of ``L^-1``, the solution from
    the same columns) unrolled, each quantity a value of its own: the same operations in the same order (the same
    numbers, the same decisions: False where a pivot is not above :data:`_PIVOT_FLOOR` times its diagonal entry or
    the points are not spread), with no loads and stores of scratch arrays between them and no index arithmetic
    (issue 31: the loops' 10 x 10 solve took about a quarter of the normal fits' instructions). Written as LLVM
    instructions, not as generated Python: numba types and lowers some 1,500 scalar operations in about 2 s of
    CPU, LLVM takes 0.2 s. Stores the 6 coefficients (constant, linear, quadratic: the last 4 rows of ``L^-T``
    are not formed) to ``solution[:6]`` when it succeeds.
    """
    exponents = [(total - k, k) for total in range(4) for k in range(total + 1)][:m]
    loaded = {}

    def moment(i, k):
        if (i, k) not in loaded:
            loaded[i, k] = steps.moment(i, k)
        return loaded[i, k]

    one = steps.constant(1.0)
    a = [[moment(i + p, k + q) for p, q in exponents[: r + 1]] for r, (i, k) in enumerate(exponents)]
    low = [[None] * m for _ in range(m)]  # the unit factor below its diagonal
    unscaled = [[None] * m for _ in range(m)]  # low[i][k] times pivot k
    inverse = [None] * m  # 1 / each pivot
    for k in range(m):
        d = a[k][k]
        for j in range(k):
            d = steps.sub(d, steps.mul(unscaled[k][j], low[k][j]))
        steps.require_above(d, steps.mul(steps.at_least_tiny(a[k][k]), steps.constant(_PIVOT_FLOOR)))
        inverse[k] = steps.div(one, d)
        for i in range(k + 1, m):
            s = a[i][k]
            for j in range(k):
                s = steps.sub(s, steps.mul(unscaled[i][j], low[k][j]))
            unscaled[i][k] = s
            low[i][k] = steps.mul(s, inverse[k])
    trace = steps.constant(0.0)  # column j of the unit factor's inverse below its diagonal (negated), its norm
    columns = [[None] * m for _ in range(m)]
    for j, (i, k) in enumerate(exponents):
        column = columns[j]
        norm = inverse[j]
        for row in range(j + 1, m):
            s = low[row][j]
            for c in range(j + 1, row):
                s = steps.sub(s, steps.mul(low[row][c], column[c]))
            column[row] = s
            norm = steps.add(norm, steps.mul(steps.mul(s, s), inverse[row]))
        trace = steps.add(trace, steps.mul(norm, steps.constant(1.0 / math.comb(i + k, i))))
    steps.require_below(steps.mul(steps.mul(trace, moment(0, 0)), steps.min_spread), 1.0)
    right = [steps.right(i) for i in range(m)]
    z = [None] * m
    for i in range(m):
        s = right[i]
        for j in range(i):
            s = steps.sub(s, steps.mul(columns[j][i], right[j]))
        z[i] = steps.mul(s, inverse[i])
    for j in range(6):
        s = z[j]
        for i in range(j + 1, m):
            s = steps.sub(s, steps.mul(columns[j][i], z[i]))
        steps.store(j, s)


class _IRSteps:
    """The operations of :func:`_solve_steps` as LLVM instructions in ``builder`` (no fast-math flags: IEEE, as
    numba compiles them in :func:`_cholesky_inline`), on the arrays ``moments, right, solution`` and the float
    ``min_spread`` of the intrinsic's ``args``; a failed requirement branches to the block ``fail``."""

    def __init__(self, context, builder, signature, args, fail):
        self.context, self.builder, self.fail = context, builder, fail
        self.arrays = [
            (kind, context.make_array(kind)(context, builder, value))
            for kind, value in zip(signature.args[:3], args[:3])
        ]
        self.min_spread = args[3]
        double = ir.DoubleType()
        self.sqrt_function = builder.module.declare_intrinsic("llvm.sqrt", [double])

    def _load(self, which, indices):
        kind, array = self.arrays[which]
        index = [self.context.get_constant(types.intp, i) for i in indices]
        return cgutils.get_item_pointer(self.context, self.builder, kind, array, index)

    def constant(self, value):
        return ir.Constant(ir.DoubleType(), value)

    def moment(self, i, k):
        return self.builder.load(self._load(0, (i, k)))

    def right(self, i):
        return self.builder.load(self._load(1, (i,)))

    def store(self, r, value):
        self.builder.store(value, self._load(2, (r,)))

    def mul(self, x, y):
        return self.builder.fmul(x, y)

    def add(self, x, y):
        return self.builder.fadd(x, y)

    def sub(self, x, y):
        return self.builder.fsub(x, y)

    def div(self, x, y):
        return self.builder.fdiv(x, y)

    def neg(self, x):
        return self.builder.fneg(x)

    def sqrt(self, x):
        return self.builder.call(self.sqrt_function, [x])

    def at_least_tiny(self, x):  # _TINY if _TINY > x else x
        tiny = self.constant(_TINY)
        return self.builder.select(self.builder.fcmp_ordered(">", tiny, x), tiny, x)

    def _require(self, condition):
        go_on = self.builder.append_basic_block("go_on")
        self.builder.cbranch(condition, go_on, self.fail)
        self.builder.position_at_end(go_on)

    def require_above(self, x, floor):  # not x > floor: fail (NaN fails)
        self._require(self.builder.fcmp_ordered(">", x, floor))

    def require_below(self, x, ceiling):  # not x < ceiling: fail
        self._require(self.builder.fcmp_ordered("<", x, self.constant(ceiling)))


def _solve_intrinsic(m):
    """``solve(moments, right, solution, min_spread) -> bool`` in compiled code: :func:`_solve_steps` of ``m``
    terms, True where it succeeds."""

    def typer(typingctx, moments, right, solution, min_spread):
        def codegen(context, builder, signature, args):
            fail = builder.append_basic_block("fail")
            steps = _IRSteps(context, builder, signature, args, fail)
            _solve_steps(m, steps)
            done = builder.append_basic_block("done")
            success = builder.block
            builder.branch(done)
            builder.position_at_end(fail)
            builder.branch(done)
            builder.position_at_end(done)
            result = builder.phi(ir.IntType(1))
            result.add_incoming(ir.Constant(ir.IntType(1), 1), success)
            result.add_incoming(ir.Constant(ir.IntType(1), 0), fail)
            return result

        return types.boolean(moments, right, solution, types.float64), codegen

    typer.__name__ = f"_solve_{m}"
    return cast(Callable[[np.ndarray, np.ndarray, np.ndarray, float], bool], intrinsic(typer))


#: The solves of the cubic jets (10 terms) and of the quadratic ones (6) a cubic fit falls back to.
_solve_10 = _solve_intrinsic(10)
_solve_6 = _solve_intrinsic(6)


def _smaller_solve(general, degree, count, moments, right, solution, min_spread, scratch):
    """:func:`_fit_one`'s solve: the fit of the highest degree ``<= degree`` with at least as many points
    (``count``) as terms whose solve succeeds; its 6 coefficients (constant, linear, quadratic; in the
    monomials' units) to ``solution[:6]``; False if none.

    ``moments`` and ``right`` are those of :func:`_jet_moments`. Fits of 10 and 6 terms are solved by
    :func:`_solve_10` and :func:`_solve_6`; where ``general`` is not None (degree 4 or more), the larger ones by
    :func:`_cholesky_solve` in ``scratch = (exponents, matrix, low, inverse_binomials)`` (:func:`_jet_scratch`).

    Compiled only (:func:`_smaller_solve_typed`).
    """
    raise NotImplementedError("compiled only: called from the compiled jet fits")


@overload(_smaller_solve, jit_options=_JIT_LEAF_OVERLOAD)  # type: ignore[arg-type]  # numba's stub types a TypedDict
def _smaller_solve_typed(general, degree, count, moments, right, solution, min_spread, scratch):
    if isinstance(general, types.NoneType):

        def fixed(general, degree, count, moments, right, solution, min_spread, scratch):
            if degree >= 3 and count >= 10 and _solve_10(moments, right, solution, min_spread):
                return True
            return degree >= 2 and count >= 6 and _solve_6(moments, right, solution, min_spread)

        return fixed

    def any_size(general, degree, count, moments, right, solution, min_spread, scratch):
        exponents, matrix, low, inverse_binomials = scratch
        for d in range(degree, 1, -1):
            m = (d + 1) * (d + 2) // 2
            if count < m:
                continue
            if m == 10:
                if _solve_10(moments, right, solution, min_spread):
                    return True
                continue
            if m == 6:
                return _solve_6(moments, right, solution, min_spread)
            for r in range(m):  # the lower triangle: all the factorization reads
                for c in range(r + 1):
                    matrix[r, c] = moments[
                        _UNSIGNED(exponents[r, 0] + exponents[c, 0]), _UNSIGNED(exponents[r, 1] + exponents[c, 1])
                    ]
                solution[r] = right[r]
            if _cholesky_solve(matrix, solution, low, m, min_spread, inverse_binomials, moments[0, 0]):
                return True
        return False

    return any_size


@threaded
def fit_jets(
    vertices,
    normals,
    radii,
    degree,
    iterations,
    exponents,
    min_spread,
    centres,
    n_chunks,
    pool,
    facing,
    check_facing,
    away_fraction,
    settled,
    areas,
    larger=0.0,
    agreement=-2.0,
):
    """``jets.fit_jets``: weighted jets over the balls of ``radii``, frame re-estimated from each fit.

    Fits the jets of the vertices ``centres`` (the other rows of the outputs
    stay NaN), vertex ``v`` over the ball of radius ``radii[v]`` ((V,): one per
    vertex) or ``radii[0]`` ((1,): one for all; the grid's cells are as wide as
    the largest). Only the vertices ``pool`` (int64 ids) enter the balls. With
    ``check_facing``, a fit whose ball holds more than ``away_fraction`` of its
    points (of non-zero weight) with a ``facing`` normal opposite to the centre's
    (``n_j . n_v < 0``; NaN normals are not counted) is not a height function over
    the tangent plane and is left NaN. Returns ``(coefficients (V, 6), t1, t2,
    n, counts, away)``, ``away`` the share of points facing away (NaN
    unless checked); the neighbours of each vertex are found on a grid of cells
    (:func:`_grid`). A fit whose slope ``c10^2 + c01^2`` is below ``settled``
    ends the iterations of its vertex (0: ``iterations`` fits everywhere).
    ``areas`` (V,): each point's weight is also its area (empty: none).

    The fits run in ``n_chunks`` ranges of the centres (:func:`_grid_chunk`)
    on threads (:func:`~meshcurv._kernels._common.run_chunks`). With ``larger``
    > 0, the fits over balls of that radius too (:func:`fit_jet_pairs`). With ``agreement`` above -1 (and
    ``check_facing``), the points whose ``facing`` normal has a cosine below it with the centre's weigh 0.
    """
    points, ids, grid, centres = _grid_centres(vertices, pool, radii, centres)
    # read-only views, as jets._connected_fits passes its arrays to fit_jets_connected: one compiled _fit_one
    # for both paths (a writable array among them made numba compile it a second time: 0.7 s, issue 31)
    vertices, points, normals, facing, areas = (
        _read_only(array) for array in (vertices, points, normals, facing, areas)
    )
    outputs = _jet_outputs.py_func(vertices.shape[0])  # NumPy's: one compiled function fewer to load
    wider = _jet_outputs.py_func(vertices.shape[0] if larger > 0 else 1)  # (one row unused without larger)
    limits = np.array([away_fraction, settled, agreement])
    facing = facing[: facing.shape[0] if check_facing else 0]
    run_chunks(
        _grid_chunk,
        centres.shape[0],
        n_chunks,
        vertices,
        points,
        normals,
        radii,
        degree,
        iterations,
        exponents,
        min_spread,
        centres,
        grid,
        ids,
        facing,
        limits,
        areas,
        *outputs,
        float(larger),
        wider,
        _general(degree),
    )
    return outputs + wider if larger > 0 else outputs


def _read_only(array: np.ndarray) -> np.ndarray:
    """A read-only view of ``array`` (no copy)."""
    view = array.view()
    view.flags.writeable = False
    return view


@threaded
def fit_jet_pairs(vertices, normals, radii, larger, *options):
    """``jets.fit_jets(larger=)``: the fits of :func:`fit_jets` over balls of ``radii[0]`` and of ``larger``
    (one radius each, ``larger > radii[0]``) at the same centres, from one walk of the grid per centre.

    ``options``: the arguments of :func:`fit_jets` after ``radii``. The grid is that of :func:`fit_jets` over
    ``radii[0]`` (cells of that side); each centre's ball of ``larger`` is walked once, over the cells it
    reaches (:func:`~meshcurv._kernels.neighborhoods._ball_members`), and the ball of ``radii[0]`` is the subsequence
    of its members within that radius: the same points in the same order as :func:`fit_jets` finds them (the
    cells of the smaller walk, in the same column-major order, are a sub-block of the larger one's), so the
    fits over ``radii[0]`` are those of :func:`fit_jets` to the bit. The fits over ``larger`` sum the same
    points in another order than :func:`fit_jets` over a grid of cells of side ``larger`` (within rounding of
    them). Returns the six outputs of :func:`fit_jets` over ``radii[0]``, then the six over ``larger``.
    """
    return fit_jets(vertices, normals, radii, *options, float(larger))


@nb.njit(**_JIT)
def _grid_centres(vertices, pool, radii, centres):
    """``(points, ids, grid, centres)`` of :func:`fit_jets`: the pool's grid (``pool_grid``) and the centres
    in grid order (consecutive balls share cells: cache), the centres outside the pool last."""
    n = vertices.shape[0]
    n_pool = pool.shape[0]
    widest = radii[0]  # radii.max() (NaN if any is), without compiling numba's max
    for k in range(1, radii.shape[0]):
        widest = radii[k] if radii[k] > widest or radii[k] != radii[k] else widest
    points, ids, grid = pool_grid(vertices, pool, widest)
    chosen = np.empty(n, np.bool_)  # False (without numba's np.zeros and its fill: issue 31)
    for k in range(n):
        chosen[k] = False
    chosen[centres] = True
    sorted_centres = np.empty(centres.shape[0], np.int64)
    m = 0
    for k in range(n_pool):
        if chosen[ids[k]]:
            sorted_centres[m] = ids[k]
            chosen[ids[k]] = False
            m += 1
    for k in range(centres.shape[0]):
        if chosen[centres[k]]:
            sorted_centres[m] = centres[k]
            chosen[centres[k]] = False
            m += 1
    return points, ids, grid, sorted_centres[:m]


@nb.njit(**_JIT)
def _grid_chunk(
    lo,
    hi,
    vertices,
    points,
    normals,
    radii,
    degree,
    iterations,
    exponents,
    min_spread,
    centres,
    grid,
    ids,
    facing,
    limits,
    areas,
    coefficients,
    t1s,
    t2s,
    ns,
    counts,
    away,
    larger,
    wider,
    general,
):
    """The fits of ``centres[lo:hi]`` of :func:`fit_jets`, written to their rows of the outputs; with ``larger``
    > 0, those over balls of that radius too, to the outputs ``wider`` (:func:`fit_jet_pairs`): one walk of the
    larger ball, the smaller one its members within the radius. One call site of :func:`_fit_one`."""
    per_vertex = radii.shape[0] > 1
    members = np.empty(64, np.int64)
    inner = np.empty(64, np.int64)  # the smaller ball of a pair
    outer = np.empty(64, np.int64)  # the larger one
    outer_size = 0
    smaller = (coefficients, t1s, t2s, ns, counts, away)
    work, moments, right, matrix, low, inverse_binomials, solution = _jet_scratch(degree, exponents.shape[0])
    steps = 2 if larger > 0 else 1  # fits per centre
    for step in range(lo * steps, hi * steps):
        v = centres[step // steps]
        radius = radii[v if per_vertex else 0]
        coefficients, t1s, t2s, ns, counts, away = smaller
        if steps == 1:
            members, size = _ball_members(points, grid, vertices[v, 0], vertices[v, 1], vertices[v, 2], radius, members)
        elif step % 2 == 0:  # the walk of the larger ball, its members within the radius the smaller one
            outer, outer_size = _ball_members(
                points, grid, vertices[v, 0], vertices[v, 1], vertices[v, 2], larger, outer
            )
            if inner.shape[0] < outer_size:
                inner = np.empty(outer.shape[0], np.int64)
            members, size = inner, _nested_members(points, vertices[v], radius, outer, outer_size, inner)
        else:
            radius, members, size = larger, outer, outer_size
            coefficients, t1s, t2s, ns, counts, away = wider
        work = _grown_work(work, size)
        _fit_one(
            vertices,
            points,
            normals,
            radius,
            degree,
            iterations,
            exponents,
            min_spread,
            v,
            v,
            members,
            size,
            work,
            moments,
            right,
            matrix,
            low,
            inverse_binomials,
            solution,
            coefficients,
            t1s,
            t2s,
            ns,
            counts,
            ids,
            facing,
            limits,
            away,
            areas,
            general,
        )


@nb.njit(**_JIT_INNER)
def _nested_members(points, centre, radius, outer, outer_size, members):
    """The members of ``outer[:outer_size]`` within ``radius`` of ``centre``, in their order, written to
    ``members`` (at least ``outer_size`` long); their count. Squared distances as
    :func:`~meshcurv._kernels.neighborhoods._ball_members` forms them: the same points it finds."""
    cutoff2 = radius * radius
    count = 0
    for a in range(outer_size):  # branch-free: every candidate written, the inside ones kept
        j = outer[a]
        dx = points[j, 0] - centre[0]
        dy = points[j, 1] - centre[1]
        dz = points[j, 2] - centre[2]
        members[count] = j
        count += dx * dx + dy * dy + dz * dz <= cutoff2
    return count


def _general(degree: int) -> bool | None:
    """The ``general`` argument of the chunks (:func:`_jet_moments`): None for fits of degree 3 or less."""
    return None if degree <= 3 else True


#: Rows of a jet fit's scratch before the powers of u and v: the offsets x, y, z, the weight, weight * height.
_JET_ROWS = 5


@nb.njit(**_JIT)
def _jet_outputs(rows):
    """The outputs of the jet fits, ``coefficients (rows, 6), t1, t2, n (rows, 3), counts, away``: NaN, counts 0."""
    return (
        np.full((rows, 6), np.nan),
        np.full((rows, 3), np.nan),
        np.full((rows, 3), np.nan),
        np.full((rows, 3), np.nan),
        np.zeros(rows),
        np.full(rows, np.nan),
    )


@nb.njit(inline="always", **_JIT)
def _grown_work(work, size):
    """``work`` of :func:`_jet_scratch`, or a new one twice as wide when a ball of ``size`` points does not fit:
    grown by the callers of :func:`_fit_one` (``_grid_chunk``, ``_connected_chunk``, ``icc._nested_fits_chunk``),
    as the fit allocates nothing (:data:`~._common._JIT_LEAF`). Inlined: a call per vertex would count the
    array's references up and down."""
    if size > work.shape[1]:
        return np.empty((work.shape[0], 2 * size))
    return work


@nb.njit(inline="always", **_JIT)
def _jet_scratch(degree, n_terms):
    """The buffers of :func:`_fit_one` (once per chunk of vertices, not per vertex):
    ``work, moments, right, matrix, low, inverse_binomials, solution``. The moments and the
    right-hand side hold at least those of degree 3, which :func:`_cubic_jet_moments`
    writes for every fit of degree 3 or less. ``inverse_binomials`` holds
    ``1 / C(i + k, i)`` for each exponent ``(i, k)`` (by total degree, as
    ``jets._exponents``): the weights of :func:`_cholesky_solve`'s spread.

    Inlined: its arrays are then allocated by its callers' own instances of ``np.empty``, which numba compiles
    once per set of the caller's options (issue 31)."""
    work = np.empty((_JET_ROWS + 3 * (2 * degree + 1) + degree + 1, 64))
    order = 2 * (3 if 3 > degree else degree) + 1  # max(degree, 3) (numba compiles max once per caller's options)
    inverse_binomials = np.empty(n_terms)
    t = 0
    for total in range(degree + 1):
        for k in range(total + 1):
            binomial = 1
            for step in range(total - k):  # C(total, i), i = total - k, in integers
                binomial = binomial * (total - step) // (step + 1)
            inverse_binomials[t] = 1.0 / binomial
            t += 1
    return (
        work,
        np.empty((order, order)),
        np.empty(10 if 10 > n_terms else n_terms),
        np.empty((n_terms, n_terms)),
        np.empty((n_terms, n_terms)),
        inverse_binomials,
        np.empty(n_terms),
    )


@nb.njit(**_JIT_LEAF_REASSOC)
def _dot(a, b, size):
    """``sum_i a[i] b[i]`` over the first ``size`` entries, reassociated (vectorized)."""
    total = 0.0
    for i in range(size):
        total += a[i] * b[i]
    return total


@nb.njit(**_JIT_LEAF_REASSOC)
def _cubic_jet_moments(ox, oy, oz, weight, size, ax, ay, az, bx, by, bz, nx, ny, nz, moments, right):
    """:func:`_fit_one`'s moments of a degree-3 fit, summed member by member in scalars.

    ``moments[i, k] = sum w u^i v^k`` (``i + k <= 6``) and ``right[t] = sum w h
    u^i v^k`` for the ten exponents ``(i, k)`` of ``jets._exponents(3)``
    (by total degree), where ``u, v, h`` are the coordinates of the offsets
    ``ox, oy, oz`` along ``a, b, n`` and ``w`` the weights: the sums of the
    rows of powers of :func:`_fit_one`, in one pass over the members with no
    per-member scratch (the products are formed alike, ``(w u^i) v^k``; the sums
    are reassociated).
    """
    m00 = m10 = m01 = m20 = m11 = m02 = m30 = m21 = m12 = m03 = 0.0
    m40 = m31 = m22 = m13 = m04 = m50 = m41 = m32 = m23 = m14 = m05 = 0.0
    m60 = m51 = m42 = m33 = m24 = m15 = m06 = 0.0
    r00 = r10 = r01 = r20 = r11 = r02 = r30 = r21 = r12 = r03 = 0.0
    for a in range(size):
        x, y, z, w = ox[a], oy[a], oz[a], weight[a]
        u = x * ax + y * ay + z * az
        v = x * bx + y * by + z * bz
        lift = w * (x * nx + y * ny + z * nz)
        u2 = u * u
        u3 = u2 * u
        u4 = u3 * u
        u5 = u4 * u
        u6 = u5 * u
        v2 = v * v
        v3 = v2 * v
        v4 = v3 * v
        v5 = v4 * v
        v6 = v5 * v
        w1, w2, w3, w4, w5, w6 = w * u, w * u2, w * u3, w * u4, w * u5, w * u6
        m00 += w
        m01 += w * v
        m02 += w * v2
        m03 += w * v3
        m04 += w * v4
        m05 += w * v5
        m06 += w * v6
        m10 += w1
        m11 += w1 * v
        m12 += w1 * v2
        m13 += w1 * v3
        m14 += w1 * v4
        m15 += w1 * v5
        m20 += w2
        m21 += w2 * v
        m22 += w2 * v2
        m23 += w2 * v3
        m24 += w2 * v4
        m30 += w3
        m31 += w3 * v
        m32 += w3 * v2
        m33 += w3 * v3
        m40 += w4
        m41 += w4 * v
        m42 += w4 * v2
        m50 += w5
        m51 += w5 * v
        m60 += w6
        l1, l2, l3 = lift * u, lift * u2, lift * u3
        r00 += lift
        r10 += l1
        r01 += lift * v
        r20 += l2
        r11 += l1 * v
        r02 += lift * v2
        r30 += l3
        r21 += l2 * v
        r12 += l1 * v2
        r03 += lift * v3
    moments[0, 0], moments[0, 1], moments[0, 2], moments[0, 3] = m00, m01, m02, m03
    moments[0, 4], moments[0, 5], moments[0, 6] = m04, m05, m06
    moments[1, 0], moments[1, 1], moments[1, 2] = m10, m11, m12
    moments[1, 3], moments[1, 4], moments[1, 5] = m13, m14, m15
    moments[2, 0], moments[2, 1], moments[2, 2], moments[2, 3], moments[2, 4] = m20, m21, m22, m23, m24
    moments[3, 0], moments[3, 1], moments[3, 2], moments[3, 3] = m30, m31, m32, m33
    moments[4, 0], moments[4, 1], moments[4, 2] = m40, m41, m42
    moments[5, 0], moments[5, 1] = m50, m51
    moments[6, 0] = m60
    right[0], right[1], right[2], right[3], right[4] = r00, r10, r01, r20, r11
    right[5], right[6], right[7], right[8], right[9] = r02, r30, r21, r12, r03


@nb.njit(**_JIT_LEAF)
def _general_jet_moments(work, size, degree, exponents, ax, ay, az, bx, by, bz, nx, ny, nz, moments, right):
    """:func:`_fit_one`'s moments of a fit of degree 4 or more, from the rows of ``work`` (:func:`_jet_scratch`).

    The offsets and weights are in its first rows; the powers of ``u`` and
    ``v``, the weight times each power of ``u`` and the weighted height times
    each power of ``u`` are written to the rows after them, then each moment
    is one dot product of two rows (:func:`_dot`). A function of its own, not
    inlined: the default fits (degrees 2 and 3, :func:`_cubic_jet_moments`)
    do not compile it into their loop.
    """
    top = 2 * degree
    ox, oy, oz, weight, lift = work[0], work[1], work[2], work[3], work[4]
    pu = work[_JET_ROWS : _JET_ROWS + top + 1]
    pv = work[_JET_ROWS + top + 1 : _JET_ROWS + 2 * (top + 1)]
    wu = work[_JET_ROWS + 2 * (top + 1) : _JET_ROWS + 3 * (top + 1)]
    lu = work[_JET_ROWS + 3 * (top + 1) :]
    for a in range(size):
        pu[0, a] = 1.0
        pv[0, a] = 1.0
        pu[1, a] = ox[a] * ax + oy[a] * ay + oz[a] * az
        pv[1, a] = ox[a] * bx + oy[a] * by + oz[a] * bz
        lift[a] = weight[a] * (ox[a] * nx + oy[a] * ny + oz[a] * nz)
    for p in range(2, top + 1):  # power by power over all members (no chain of products per member)
        for a in range(size):
            pu[p, a] = pu[p - 1, a] * pu[1, a]
            pv[p, a] = pv[p - 1, a] * pv[1, a]
    for p in range(top + 1):  # the weight (and weighted height) times each power of u, once
        for a in range(size):
            wu[p, a] = weight[a] * pu[p, a]
    for p in range(degree + 1):
        for a in range(size):
            lu[p, a] = lift[a] * pu[p, a]
    for total in range(top + 1):
        for k in range(total + 1):
            moments[total - k, k] = _dot(wu[total - k], pv[k], size)
    for t in range(exponents.shape[0]):
        right[t] = _dot(lu[exponents[t, 0]], pv[exponents[t, 1]], size)


def _jet_moments(general, work, size, degree, exponents, ax, ay, az, bx, by, bz, nx, ny, nz, moments, right):
    """:func:`_fit_one`'s moments: :func:`_cubic_jet_moments` up to degree 3, else :func:`_general_jet_moments`.

    Compiled only (:func:`_jet_moments_typed`). ``general`` is None where every fit has degree 3 or less (what
    the callers pass then), True otherwise: with None, the compiled fit holds no code of the general
    moments (0.5 s of CPU less to compile the default's fits on a cold cache).
    """
    raise NotImplementedError("compiled only: called from the compiled jet fits")


@overload(_jet_moments, jit_options=_JIT_LEAF_OVERLOAD)  # type: ignore[arg-type]  # numba's stub types a TypedDict
def _jet_moments_typed(general, work, size, degree, exponents, ax, ay, az, bx, by, bz, nx, ny, nz, moments, right):
    if isinstance(general, types.NoneType):

        def cubic(general, work, size, degree, exponents, ax, ay, az, bx, by, bz, nx, ny, nz, moments, right):
            _cubic_jet_moments(
                work[0], work[1], work[2], work[3], size, ax, ay, az, bx, by, bz, nx, ny, nz, moments, right
            )

        return cubic

    def either(general, work, size, degree, exponents, ax, ay, az, bx, by, bz, nx, ny, nz, moments, right):
        if degree <= 3:  # the normal and noise fits: moments summed member by member (degree 2 reads a subset)
            _cubic_jet_moments(
                work[0], work[1], work[2], work[3], size, ax, ay, az, bx, by, bz, nx, ny, nz, moments, right
            )
        else:
            _general_jet_moments(work, size, degree, exponents, ax, ay, az, bx, by, bz, nx, ny, nz, moments, right)

    return either


@nb.njit(**_JIT_LEAF)
def _fit_one(
    vertices,
    points,
    normals,
    radius,
    degree,
    iterations,
    exponents,
    min_spread,
    v,
    row,
    members,
    size,
    work,
    moments,
    right,
    matrix,
    low,
    inverse_binomials,
    solution,
    coefficients,
    t1s,
    t2s,
    ns,
    counts,
    ids,
    facing,
    limits,
    away_out,
    areas,
    general,
):
    """One vertex of :func:`fit_jets` in the caller's buffers (``work`` holds at least ``size`` columns: the
    caller grows it).

    A call per vertex, compiled without reference counts (:data:`_JIT_LEAF`): inlined into its callers, as it was,
    each of its thirty arguments was counted up and down per vertex all the same (numba's pruning of the counts
    misses them across the fit's loops), and a call counting them cost a quarter of the normal fits' time. The
    scalar options come in ``limits = (away_fraction, settled[, agreement])``, and the facing check is
    on when ``facing`` has rows (an empty ``facing``: no check). With an ``agreement`` above -1 and
    ``facing`` rows, a point whose ``facing`` normal has a cosine below it with the centre's weighs 0
    (the same-side fits of ``jets.fit_jets(agreement=)``).

    The ball's points are ``points[members[:size]]`` (vertex ``ids[members[a]]``);
    the fit is written to row ``row`` of the outputs. ``work`` holds one column per ball member: its offset from the centre in
    units of the radius, its weight, its weighted height, the powers
    ``u^0..u^2d`` and ``v^0..v^2d`` of its tangent coordinates and the products
    of the weight with ``u^0..u^2d`` and of the weighted height with ``u^0..u^d``
    (:func:`_jet_scratch`), so that each moment of the normal equations is one
    vectorized dot product of two rows (the products are those of the three
    factors in their order: the same numbers). A fit of degree 3 or less sums
    its moments member by member instead (:func:`_cubic_jet_moments`, the same
    products; no per-member rows; degree 2 reads the moments up to order 4).
    A fit whose slope ``c10^2 + c01^2`` is below ``settled``
    ends the iterations (its frame and coefficients are kept). ``general``:
    None when ``degree <= 3`` (:func:`_jet_moments`).

    With ``areas`` (V,) not empty, each point's weight is its kernel weight
    times its area (the fit approximates the surface integral: a part sampled
    100 times more densely does not outweigh its neighbour).
    """
    away_fraction, settled = limits[0], limits[1]
    check_facing = facing.shape[0] > 0
    # the same-side selection (limits[2], the cosine bound; callers with two limits select nothing)
    agreement = limits[2] if limits.shape[0] > 2 else -2.0
    select = check_facing and agreement > -1.0
    sx = sy = sz = 0.0
    if select:
        sx, sy, sz = facing[v, 0], facing[v, 1], facing[v, 2]
    ox, oy, oz, weight = work[0], work[1], work[2], work[3]
    inverse = 1.0 / radius
    cx, cy, cz = vertices[v, 0], vertices[v, 1], vertices[v, 2]  # read once (the stores below may alias)
    count = 0.0
    weighted = areas.shape[0] > 0
    for slot in range(_UNSIGNED(size)):  # unsigned indices: no code for negative ones
        member = _UNSIGNED(members[slot])
        x = (points[member, 0] - cx) * inverse
        y = (points[member, 1] - cy) * inverse
        z = (points[member, 2] - cz) * inverse
        ox[slot], oy[slot], oz[slot] = x, y, z
        w = 1.0 - (x * x + y * y + z * z)
        w = 0.0 if 0.0 > w else w  # max(w, 0.0)
        w = w * w
        if weighted:
            w = w * areas[ids[member]]
        if select:  # a point facing another way than the centre is no part of its fit
            k = ids[member]
            if sx * facing[k, 0] + sy * facing[k, 1] + sz * facing[k, 2] < agreement:
                w = 0.0
        weight[slot] = w
        count += w > 0
    counts[row] = count
    graph = True
    if check_facing:  # the ball must not hold the other side of the surface (a height function over the plane)
        fx, fy, fz = facing[v, 0], facing[v, 1], facing[v, 2]
        total = 0.0
        away = 0.0
        for a in range(size):
            if not weight[a] > 0:
                continue
            k = ids[members[a]]
            total += 1.0
            if fx * facing[k, 0] + fy * facing[k, 1] + fz * facing[k, 2] < 1e-9:  # jets.AWAY_DOT
                away += 1.0
        away_out[row] = away / total if total > 0 else 0.0
        graph = not away > away_fraction * total
    nx, ny, nz = normals[v, 0], normals[v, 1], normals[v, 2]
    ax, ay, az, bx, by, bz = _tangent_frame(nx, ny, nz)
    fitted = False
    for step in range(iterations):
        _jet_moments(general, work, size, degree, exponents, ax, ay, az, bx, by, bz, nx, ny, nz, moments, right)
        fitted = _smaller_solve(
            general, degree, count, moments, right, solution, min_spread, (exponents, matrix, low, inverse_binomials)
        )
        if step + 1 < iterations and fitted:
            p, q = solution[1], solution[2]
            if p * p + q * q < settled:
                break  # the fit's normal is within the frame's: another fit in its frame would change little
            tx = nx - p * ax - q * bx
            ty = ny - p * ay - q * by
            tz = nz - p * az - q * bz
            norm = math.sqrt(tx * tx + ty * ty + tz * tz)
            tx, ty, tz = tx / norm, ty / norm, tz / norm
            if math.isfinite(tx) and math.isfinite(ty) and math.isfinite(tz):
                nx, ny, nz = tx, ty, tz
                ax, ay, az, bx, by, bz = _tangent_frame(nx, ny, nz)
    if fitted and graph:
        for r in range(6):
            coefficients[row, r] = solution[r]
    t1s[row, 0], t1s[row, 1], t1s[row, 2] = ax, ay, az
    t2s[row, 0], t2s[row, 1], t2s[row, 2] = bx, by, bz
    ns[row, 0], ns[row, 1], ns[row, 2] = nx, ny, nz


@threaded
def fit_jets_connected(
    vertices,
    normals,
    radii,
    degree,
    iterations,
    exponents,
    min_spread,
    centres,
    n_chunks,
    allowed,
    indptr,
    indices,
    facing,
    check_facing,
    away_fraction,
    normals_only,
    settled,
    areas,
    agreement=-2.0,
):
    """:func:`fit_jets` over the surface-connected piece of each ball (:func:`_connected_members`).

    The ball of ``centres[i]`` has the radius ``radii[i]`` ((M,): one per
    centre) or ``radii[0]`` ((1,): one for all).

    The same fits, outputs and checks as :func:`fit_jets`, with the points of
    each ball found breadth-first over the mesh's edges (``indptr, indices``,
    CSR) instead of on a grid: no search structure over all the points is
    built, so a fit at a few centres costs only their balls. Only ``allowed``
    (V,) vertices enter the balls. ``n_chunks``: the threads at most, three (V,) int64 arrays each.
    The outputs have one row per centre, in the order of ``centres`` (a fit at
    a few centres of a large mesh writes no row for the others).
    With ``normals_only``, returns ``(fitted, ...)``: the (M, 3) unit normals of
    the fitted jets, ``(n - c10 t1 - c01 t2) / sqrt(1 + c10^2 + c01^2)`` as
    ``jets.jet_normals`` computes them (NaN where no fit), and one-row
    placeholders for the other outputs (136 bytes per centre never written).
    A fit whose slope ``c10^2 + c01^2`` is below ``settled`` ends the
    iterations of its vertex (its normal is within ``atan(sqrt(settled))`` of
    the frame's normal); with 0, every vertex has ``iterations`` fits.
    ``areas``, ``agreement``: as :func:`fit_jets`. The fits run in ranges of the centres (:func:`_connected_chunk`),
    :data:`_RANGES_PER_SLOT` per thread, on threads (:func:`~meshcurv._kernels._common.run_slots`), each with
    the walk's scratch of its thread (the stamps are the centres' rows: one fill for all its ranges).
    """
    n = vertices.shape[0]
    m = centres.shape[0]
    # read-only views, as fit_jets passes them: one compiled _fit_one whatever the callers' flags (issue 31)
    vertices, normals, facing, areas = (_read_only(array) for array in (vertices, normals, facing, areas))
    outputs = _jet_outputs.py_func(1 if normals_only else m)  # NumPy's: one compiled function fewer to load
    # every row written by its centre's fit (NaN where none): no NaN fill of (M, 3) beforehand; no huge pages
    fitted = _unadvised_array((m, 3), np.float64) if normals_only else np.full((1, 3), np.nan)
    limits = np.array([away_fraction, settled, agreement])
    facing = facing[: facing.shape[0] if check_facing else 0]
    slots = max(1, min(int(n_chunks), m))
    # each thread's walk scratch: the stamps (filled with -1 by the thread on its first range), members, queue;
    # int64: in int32 the walk compared each stamp to its centre's int64 position after a widening load (+6% of
    # the fits' instructions, callgrind, icosphere(32); no CPU seconds gained at 1M)
    scratch = _unadvised_array((3, slots, n), np.int64)  # no huge pages (geometry._unadvised_array)
    filled = np.zeros(slots, np.bool_)
    run_slots(
        _connected_chunk,
        m,
        _RANGES_PER_SLOT * slots,
        slots,
        scratch,
        filled,
        vertices,
        normals,
        radii,
        degree,
        iterations,
        exponents,
        min_spread,
        centres,
        allowed,
        indptr,
        indices,
        # the vertex of each point: read by the facing check and the area weights only (8 MB at 1M otherwise)
        np.arange(n) if facing.shape[0] > 0 or areas.shape[0] > 0 else np.empty(0, np.int64),
        facing,
        limits,
        normals_only,
        areas,
        *outputs,
        fitted,
        _general(degree),
        _vertex_spans(vertices, indptr, indices),
    )
    return (fitted, *outputs[1:]) if normals_only else outputs


#: :func:`fit_jets_connected` cuts its centres into this many ranges per thread (:func:`~._common.run_slots`): a
#: thread that finishes its share early takes ranges of the others.
_RANGES_PER_SLOT = 8


@nb.njit(**_JIT)
def _connected_chunk(
    lo,
    hi,
    slot,
    scratch,
    filled,
    vertices,
    normals,
    radii,
    degree,
    iterations,
    exponents,
    min_spread,
    centres,
    allowed,
    indptr,
    indices,
    ids,
    facing,
    limits,
    normals_only,
    areas,
    coefficients,
    t1s,
    t2s,
    ns,
    counts,
    away,
    fitted,
    general,
    spans,
):
    """The fits of ``centres[lo:hi]`` of :func:`fit_jets_connected`, written to their rows of the outputs
    (of ``fitted`` with ``normals_only``), with row ``slot`` of the (3, slots, V) ``scratch`` (the stamps of
    the walk, its members, its queue), the stamps filled with -1 on the slot's first range (``filled``);
    ``spans``: each vertex's longest edge, which the walk skips far vertices with
    (:func:`~meshcurv._kernels.neighborhoods._vertex_spans`)."""
    per_centre = radii.shape[0] > 1
    mark, members, queue = scratch[0, slot], scratch[1, slot], scratch[2, slot]
    if not filled[slot]:  # -1: np.full compiles two more functions (issue 31)
        for k in range(mark.shape[0]):
            mark[k] = -1
        filled[slot] = True
    work, moments, right, matrix, low, inverse_binomials, solution = _jet_scratch(degree, exponents.shape[0])
    # one row of each output, written by every fit (c and one_away set below): unpacked once, not per vertex; no
    # call of _jet_outputs (its NaN fills compile 0.3-0.5 s of CPU more than these)
    c, a, b, nn = np.empty((1, 6)), np.empty((1, 3)), np.empty((1, 3)), np.empty((1, 3))
    one_count, one_away = np.empty(1), np.empty(1)
    # the fit's row: an int64 as _grid_chunk's (a literal 0 made numba compile _fit_one a second time)
    only_row = np.int64(0)
    for i in range(lo, hi):
        v = centres[i]
        radius = radii[i if per_centre else 0]
        size = _connected_members(vertices, indptr, indices, allowed, v, radius, mark, i, members, queue, spans)
        # the fit into one row, then copied (one call site)
        c[0, :] = np.nan  # a failed fit leaves the row as it finds it
        one_away[0] = np.nan  # written only when the facing is checked
        work = _grown_work(work, size)
        _fit_one(
            vertices,
            vertices,
            normals,
            radius,
            degree,
            iterations,
            exponents,
            min_spread,
            v,
            only_row,
            members,
            size,
            work,
            moments,
            right,
            matrix,
            low,
            inverse_binomials,
            solution,
            c,
            a,
            b,
            nn,
            one_count,
            ids,
            facing,
            limits,
            one_away,
            areas,
            general,
        )
        if not normals_only:
            for k in range(6):
                coefficients[i, k] = c[0, k]
            for k in range(3):
                t1s[i, k], t2s[i, k], ns[i, k] = a[0, k], b[0, k], nn[0, k]
            counts[i], away[i] = one_count[0], one_away[0]
            continue
        p, q = c[0, 1], c[0, 2]
        width = np.sqrt(1 + p * p + q * q)
        for k in range(3):
            fitted[i, k] = (nn[0, k] - p * a[0, k] - q * b[0, k]) / width


@threaded
def jet_curvatures(coefficients, frame, radii, normals):
    """``jets.jet_curvatures``: the principal curvatures, directions and normals of fitted jets.

    Row by row on threads (:func:`~meshcurv._kernels._common.run_chunks`): the shape operator of
    ``jets.shape_operators`` (its 2 x 2 and 3 x 2 products written out as sums of two products in the
    order of the matrix products; NumPy's ``matmul`` may round differently, so the results agree to
    a few ulps, not to the bit), divided by ``radii``, then restricted to the fitted normal's tangent
    plane as ``tensors.principal_from_shape_operator`` does (:func:`~meshcurv._kernels.tensors._tangent_eigen`).
    Returns ``(k_min, k_max, dir_min, dir_max, normals)``: NaN (and the given ``normals``) where a
    coefficient or the fitted normal is not finite.
    """
    t1, t2, n = (np.ascontiguousarray(part, dtype=np.float64) for part in frame)
    coefficients = np.ascontiguousarray(coefficients, dtype=np.float64)
    rows = coefficients.shape[0]
    outputs = (np.empty(rows), np.empty(rows), np.empty((rows, 3)), np.empty((rows, 3)), np.empty((rows, 3)))
    run_chunks(
        _curvatures_chunk,
        rows,
        8 * nb.get_num_threads(),
        coefficients,
        t1,
        t2,
        n,
        np.ascontiguousarray(radii, dtype=np.float64),
        np.ascontiguousarray(normals, dtype=np.float64),
        *outputs,
    )
    return outputs


def _fma_intrinsic(typingctx, x, y, z):
    """``x * y + z`` rounded once (LLVM's ``llvm.fma.f64``; a library call where the processor has no such
    instruction): how the matrix products of NumPy's ``matmul`` (its BLAS) add their second term."""
    signature = types.float64(types.float64, types.float64, types.float64)

    def codegen(context, builder, sig, args):
        double = ir.DoubleType()
        function = builder.module.declare_intrinsic("llvm.fma", [double], ir.FunctionType(double, [double] * 3))
        return builder.call(function, args)

    return signature, codegen


#: ``_fma(x, y, z)`` in compiled code (:func:`_fma_intrinsic`).
_fma = cast(Callable[[float, float, float], float], intrinsic(_fma_intrinsic))


@nb.njit(**_JIT)
def _curvatures_chunk(lo, hi, coefficients, t1, t2, n, radii, normals, k_min, k_max, dir_min, dir_max, out_normals):
    """Rows ``lo:hi`` of :func:`jet_curvatures`."""
    for i in range(lo, hi):
        p, q = coefficients[i, 1], coefficients[i, 2]
        width = math.sqrt(1 + p * p + q * q)
        fx = (n[i, 0] - p * t1[i, 0] - q * t2[i, 0]) / width
        fy = (n[i, 1] - p * t1[i, 1] - q * t2[i, 1]) / width
        fz = (n[i, 2] - p * t1[i, 2] - q * t2[i, 2]) / width
        ok = math.isfinite(fx) and math.isfinite(fy) and math.isfinite(fz)
        for k in range(6):
            ok = ok and math.isfinite(coefficients[i, k])
        if not ok:
            k_min[i] = k_max[i] = np.nan
            for k in range(3):
                dir_min[i, k] = dir_max[i, k] = np.nan
                out_normals[i, k] = normals[i, k]
            continue
        # the first fundamental form's inverse and the second (meshcurv's sign), as jets.shape_operators
        f0, f1, f2 = 1 + p * p, p * q, 1 + q * q
        s0 = -(2 * coefficients[i, 3]) / width
        s1 = -coefficients[i, 4] / width
        s2 = -(2 * coefficients[i, 5]) / width
        det = f0 * f2 - f1**2
        i00, i01, i11 = f2 / det, -f1 / det, f0 / det
        # (inverse @ second) @ inverse, then (jacobian @ middle) @ jacobian^T, each entry of a product
        # rounded as NumPy's matmul rounds it here (a0 b0, then a1 b1 added by a fused multiply-add)
        a00 = _fma(i01, s1, i00 * s0)
        a01 = _fma(i01, s2, i00 * s1)
        a10 = _fma(i11, s1, i01 * s0)
        a11 = _fma(i11, s2, i01 * s1)
        m00 = _fma(a01, i01, a00 * i00)
        m01 = _fma(a01, i11, a00 * i01)
        m10 = _fma(a11, i01, a10 * i00)
        m11 = _fma(a11, i11, a10 * i01)
        # the jacobian's columns t1 + p n and t2 + q n
        ux, uy, uz = t1[i, 0] + p * n[i, 0], t1[i, 1] + p * n[i, 1], t1[i, 2] + p * n[i, 2]
        vx, vy, vz = t2[i, 0] + q * n[i, 0], t2[i, 1] + q * n[i, 1], t2[i, 2] + q * n[i, 2]
        lx0, lx1 = _fma(vx, m10, ux * m00), _fma(vx, m11, ux * m01)
        ly0, ly1 = _fma(vy, m10, uy * m00), _fma(vy, m11, uy * m01)
        lz0, lz1 = _fma(vz, m10, uz * m00), _fma(vz, m11, uz * m01)
        radius = radii[i]
        lo_k, hi_k, d0, d1, d2, d3, d4, d5 = _tangent_eigen(
            _fma(lx1, vx, lx0 * ux) / radius,
            _fma(ly1, vy, ly0 * uy) / radius,
            _fma(lz1, vz, lz0 * uz) / radius,
            _fma(lx1, vy, lx0 * uy) / radius,
            _fma(lx1, vz, lx0 * uz) / radius,
            _fma(ly1, vz, ly0 * uz) / radius,
            fx,
            fy,
            fz,
            False,
            False,
        )
        k_min[i], k_max[i] = lo_k, hi_k
        dir_min[i, 0], dir_min[i, 1], dir_min[i, 2] = d0, d1, d2
        dir_max[i, 0], dir_max[i, 1], dir_max[i, 2] = d3, d4, d5
        out_normals[i, 0], out_normals[i, 1], out_normals[i, 2] = fx, fy, fz
