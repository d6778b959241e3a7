"""The normal-cycle curvature tensor (Cohen-Steiner and Morvan 2003), in true units.

For a region ``A(v)`` around vertex ``v``,

.. math::

    T(v) = \\frac{1}{|A(v)|} \\sum_{e} \\beta(e)\\, |e \\cap A(v)|\\, \\bar e \\bar e^T

where ``beta(e)`` is the signed angle between the normals of the two faces of
edge ``e`` (positive where the surface bends away from the normals) and ``ē`` the
unit edge vector. Here ``A(v)`` is the barycentric cell of ``v`` (a third of each
incident face), which contains half of every edge at ``v`` and no other edge, so
the sum runs over the edges at ``v`` with half their length. The numerator is an
integral (the anisotropic curvature measure of the cell) and the denominator an
area, so ``T`` is in 1/length.

``smoothing_steps`` passes of matGeom's 1-ring mean are applied to the measure
and to the area alike before the division: the result is the same formula over
the larger region those passes cover (a 1-ring mean of the measures, divided by
the 1-ring mean of the areas).

The eigenvector of ``T`` with eigenvalue ``k`` lies along the curvature
direction of the *other* principal curvature (an edge bends the surface across
itself); the tensor is restricted to the plane orthogonal to the vertex normal
(area-weighted mean of the face normals) and its 2x2 eigen-problem solved in
closed form. The mean of the two curvatures is half the trace of the full 3x3
tensor (the normal cycle's mean-curvature measure, independent of any frame),
their difference comes from the tangent restriction.

Boundary edges have no dihedral angle: the cells of boundary vertices miss
part of their measure, so boundary vertices are ``valid=False`` (NaN) and do not
enter the smoothing of their neighbours. The same holds for vertices on
non-manifold or inconsistently oriented edges and for vertices of zero-area faces.

On a voxel surface (marching cubes, vertices on a voxel grid) the cells'
measures are the staircase's: dihedral angles of about 90 degrees of both
signs, up to eight times the curvature at a single vertex, which only the
smoothing's whole region averages out. A region that lost the cells of invalid
vertices (a hole, a rim, a zero-area face within ``smoothing_steps`` rings)
averages a part of the staircase: its vertex is ``valid=False`` (a voxel
surface: the mesh, or the faces around its valid vertices, on a voxel grid; issue 29: a
voxel sphere of radius 4 voxels with 20% of its faces removed had 12-17 of
86-91 valid vertices off the intact sphere's H by more than half of its
largest curvature, each with its own star intact and so its own cell
unchanged: with ``smoothing_steps=0`` none moved). On other meshes the cells
vary smoothly and a cut region reads the same curvature: nothing changes there.

On a voxel surface, a smoothing too short to average the staircase out
(:func:`voxel_steps_needed`: ``(1.2 sqrt(h R) / e)^2`` steps, 15 on a voxel
sphere of radius 10 voxels) leaves every vertex ``valid=False`` (estimate
undefined), with a warning naming the steps needed, ``icc`` and
``normal_cycle_ball``: at the default 3 steps the median error of H was 26% to
100% on the marching-cubes meshes of ``benchmarks/accuracy_voxel.md`` and 17% to
63% of the vertices off by more than half of the curvature, every one of them
valid (issue 29: never a valid wrong number).

References
----------
D. Cohen-Steiner and J.-M. Morvan (2003). Restricted Delaunay triangulations and
normal cycle. Proc. 19th ACM Symposium on Computational Geometry, 312-321.
https://doi.org/10.1145/777792.777839

P. Alliez, D. Cohen-Steiner, O. Devillers, B. Levy, M. Desbrun (2003).
Anisotropic polygonal remeshing. ACM Trans. Graph. 22(3), 485-493.
https://doi.org/10.1145/882262.882296
"""

from __future__ import annotations

import numpy as np

from .._tensors import outer6, principal_from_shape_operator
from .._backend import kernel_threads, numba_kernels
from .._geometry import DEGENERATE_AREA_RATIO, edge_dihedral_angles, median_edge_length
from ..smoothing import STEPS_PER_CALL, _smooth_vertex_field
from .._prepared import PreparedMesh
from ..radius import VoxelReading, _ring_max, _voxel_surface_grid
from ._ring_noise import welded_grid, welded_staircase_note, noisy_rings, noisy_rings_note
from ._support import Stages, finish
from .normal_cycle_ball import edge_area_densities, edge_readings, few_elements, few_elements_note

#: On a voxel surface the smoothing must reach ``VOXEL_RING_GAIN sqrt(h R)`` (:func:`voxel_steps_needed`).
VOXEL_RING_GAIN = 1.2

#: The noise gain of the edges' dihedral angles summed over a ring (:func:`~meshcurv.estimators._ring_noise.noisy_rings`):
#: H moves by about ``NOISE_GAIN sigma / l^2`` for vertices scattered by ``sigma`` along the normal without
#: smoothing, less over the smoothing's rings (``pooled_steps`` there; measured on welded soups of icospheres).
NOISE_GAIN = 2.0

STAGES = ("compute adjacencies", "compute edge tensors", "average vertex tensors", "retrieve curvatures")


def estimate(mesh: PreparedMesh, *, smoothing_steps: int, stages: Stages):
    """Normal-cycle tensor in true units. Returns ``(result, problems)``."""
    vertices, topology = mesh.vertices, mesh.topology
    kernels = numba_kernels("normal_cycle")
    if kernels is not None:
        return _estimate_compiled(kernels, mesh, smoothing_steps, stages)
    stages.start("compute adjacencies")
    n_vertices = vertices.shape[0]
    faces = topology.faces
    cross, degenerate, defects = mesh.cross, mesh.degenerate, mesh.defects()
    double_areas = np.linalg.norm(cross, axis=1)

    stages.start("compute edge tensors")
    usable = topology.interior_edges & ~degenerate[np.maximum(topology.edge_faces, 0)].any(axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit_normals = cross / double_areas[:, None]
    beta, lengths, unit = edge_dihedral_angles(vertices, topology, unit_normals, usable)
    edge_measures = outer6(unit, 0.5 * beta * lengths)
    ends = topology.edges.T.ravel()
    measures = np.stack(
        [np.bincount(ends, weights=np.tile(edge_measures[:, k], 2), minlength=n_vertices) for k in range(6)],
        axis=1,
    )
    face_area_thirds = np.where(degenerate, 0.0, double_areas / 6.0)
    areas = np.bincount(faces.ravel(), weights=np.repeat(face_area_thirds, 3), minlength=n_vertices)
    normals = mesh.vertex_normals

    stages.start("average vertex tensors")
    valid = ~defects.invalid_vertices
    weights = valid.astype(np.float64)
    pooled = _smooth_vertex_field(
        np.column_stack([measures * weights[:, None], areas * weights]), topology, smoothing_steps
    )
    with np.errstate(invalid="ignore", divide="ignore"):
        tensors = pooled[:, :6] / pooled[:, 6:7]

    stages.start("retrieve curvatures")
    valid &= np.isfinite(normals).all(axis=1) & (pooled[:, 6] > 0)
    k_min, k_max, dir_min, dir_max = principal_from_shape_operator(
        np.where(valid[:, None], tensors, 0.0),
        np.where(valid[:, None], normals, [0.0, 0.0, 1.0]),
        rotate=True,
        mean_from_trace=True,
    )
    curvatures = (k_min, k_max, dir_min, dir_max)
    return _finished(mesh, defects, valid, smoothing_steps, stages.voxel, normals, *curvatures)


def _finished(mesh: PreparedMesh, defects, valid: np.ndarray, smoothing_steps: int, reading: VoxelReading, *fields):
    """:func:`finish` of the result, but on a voxel surface without the vertices whose smoothing region (the
    vertices within ``smoothing_steps`` edges) holds an invalid vertex, and elsewhere without those whose region
    lost cells and reads too few of them (:func:`_few_cells`), with the warning's phrases for them.

    The smoothing sums the cells of the valid vertices only; on a voxel staircase a region without some of its
    cells reads a part of the staircase, not the surface (the module's Notes). The grid is read once
    (:func:`meshcurv.radius._voxel_surface_grid`, the mesh's own kept by ``reading`` for the call's warning);
    ``fields``: the normals and the curvatures.
    """
    invalid, note, few_note = defects.invalid_vertices, "", ""
    grid = _voxel_surface_grid(mesh, invalid=invalid, reading=reading) if valid.any() else None
    needed = _steps_on_grid(mesh, grid)
    if smoothing_steps < needed:
        note = (
            f"{int(valid.sum())} vertices of this voxel surface are NaN (estimate undefined): normal_cycle measures "
            f"over rings of faces and its smoothing ({smoothing_steps} rings) is too short to average the voxels' "
            f"staircase out (median |H| errors of 26-100% at the default 3); use the default method 'icc' or "
            f"'normal_cycle_ball', whose balls are scaled to the voxels, or smoothing_steps={needed} or more"
        )
        valid = np.zeros_like(valid)
    elif smoothing_steps > 0 and invalid.any() and grid is not None:
        cut = valid & (_ring_max(mesh.topology.neighbour_lists, smoothing_steps, invalid.astype(np.float64)) > 0)
        if cut.any():
            valid = valid & ~cut
            note = (
                f"{int(cut.sum())} vertices of this voxel surface are NaN (estimate undefined): their smoothing "
                f"region ({smoothing_steps} rings) holds a boundary or a defect, and a part of the staircase does "
                f"not average out"
            )
    normals, k_min, k_max, dir_min, dir_max = fields
    if smoothing_steps > 0 and invalid.any() and grid is None and valid.any():
        few = _few_cells(mesh, invalid, valid, smoothing_steps, (k_min, k_max, dir_min, dir_max))
        valid = valid & ~few
        few_note = few_elements_note(int(few.sum()), f"smoothing region ({smoothing_steps} rings)", "cells")
    welded: tuple[str, ...] = ()
    if grid is None and valid.any() and smoothing_steps < _steps_on_grid(mesh, welded_grid(mesh, valid)):
        welded = (welded_staircase_note(int(valid.sum())),)  # the staircase welded back across cracks
        valid = np.zeros_like(valid)
    noisy = noisy_rings(mesh, valid, NOISE_GAIN, pooled_steps=smoothing_steps)
    valid = valid & ~noisy
    parameters = {"smoothing_steps": smoothing_steps}
    extra = (note, few_note, *welded, noisy_rings_note(int(noisy.sum())))
    return finish("normal_cycle", parameters, valid, normals, k_min, k_max, dir_min, dir_max, defects, extra=extra)


def _few_cells(mesh: PreparedMesh, invalid, valid, steps: int, fields) -> np.ndarray:
    """(V,) bool: :func:`~meshcurv.estimators.normal_cycle_ball.few_elements` of the ``valid`` vertices whose
    smoothing region (``steps`` rings) holds an ``invalid`` vertex. A cell is the mean of its edges' readings
    ``H_e`` weighted by their areas ``a_e`` (a cell's measure is half of its edges' ``beta l / 2``, its area half
    of their ``a_e``), so the region's H is the mean of the edges' readings weighted by ``a_e (s_a + s_b)``, ``s``
    the row of the ``steps`` passes of the 1-ring mean over the cells of valid vertices. ``fields``: ``(k_min,
    k_max, ...)``."""
    import scipy.sparse as sp  # imported on use: keeps `import meshcurv` fast

    topology = mesh.topology
    cut = valid & (_ring_max(topology.neighbour_lists, steps, invalid.astype(np.float64)) > 0)
    if not cut.any():
        return cut
    beta, density, usable = _edge_readings(mesh)
    indptr, indices = topology.neighbour_lists
    n = valid.shape[0]
    degrees = np.diff(indptr)
    rows = np.concatenate([np.repeat(np.arange(n), degrees), np.arange(n)])
    ring = sp.csr_matrix((1.0 / (degrees[rows] + 1.0), (rows, np.concatenate([indices, np.arange(n)]))), shape=(n, n))
    centres = np.flatnonzero(cut)
    region = sp.csr_matrix((np.ones(centres.size), (np.arange(centres.size), centres)), shape=(centres.size, n))
    for _ in range(steps):
        region = region @ ring
    edges = np.flatnonzero(usable | (density > 0))
    ends = topology.edges[edges]
    every = edge_readings(beta, density, usable)
    readings = every[edges]
    read = np.isfinite(readings)
    held = np.where(read, readings, 0.0)
    edge_areas = density[edges] * _edge_lengths(mesh)[edges]
    sums = []
    # the cells the smoothing sums (those of the vertices free of defects), and all of them (an intact region's)
    for kept in ((usable[edges, None] & ~invalid[ends]).astype(np.float64), np.ones(ends.shape)):
        incidence = sp.csr_matrix(
            (kept.ravel(), (ends.ravel(), np.repeat(np.arange(edges.size), 2))), shape=(n, edges.size)
        )
        weights = (region @ incidence).tocsr()
        sums.append([weights @ edge_areas, weights.multiply(weights) @ (edge_areas * edge_areas)])
    whole = weights @ np.column_stack([edge_areas * read, edge_areas * held, edge_areas * held * held])
    shares, intact_shares, variances = np.full(n, np.inf), np.full(n, np.inf), np.full(n, np.nan)
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        shares[centres] = sums[0][1] / (sums[0][0] * sums[0][0])
        intact_shares[centres] = sums[1][1] / (sums[1][0] * sums[1][0])
        variances[centres] = whole[:, 2] / whole[:, 0] - (whole[:, 1] / whole[:, 0]) ** 2
    return few_elements(valid, shares, intact_shares, variances, every, fields[:2])


def _edge_readings(mesh: PreparedMesh):
    """``(beta, density, usable)`` of the mesh's edges: their dihedral angles, area densities
    (:func:`~meshcurv.estimators.normal_cycle_ball.edge_area_densities`) and the edges with an angle."""
    topology, cross, degenerate = mesh.topology, mesh.cross, mesh.degenerate
    double_areas = np.linalg.norm(cross, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit_normals = cross / double_areas[:, None]
    usable = topology.interior_edges & ~degenerate[np.maximum(topology.edge_faces, 0)].any(axis=1)
    beta, lengths, _ = edge_dihedral_angles(mesh.vertices, topology, unit_normals, usable)
    density = edge_area_densities(topology, np.where(degenerate, 0.0, double_areas / 2), lengths)
    return beta, density, usable


def _edge_lengths(mesh: PreparedMesh) -> np.ndarray:
    ends = mesh.vertices[mesh.topology.edges]
    return np.linalg.norm(ends[:, 1] - ends[:, 0], axis=1)


def voxel_steps_needed(mesh: PreparedMesh, invalid: np.ndarray) -> int:
    """The smoothing steps that a voxel surface needs before its ring estimates mean anything (0 elsewhere).

    A marching-cubes staircase is noise of amplitude ``h`` (the voxel size) that a region of radius ``rho``
    averages down as ``h / rho``; icc's voxel rule puts the best radius at ``1.5 sqrt(h R)``
    (:func:`meshcurv.radius.voxel_radius`). ``s`` passes of the 1-ring mean spread a cell's measure over about
    ``sqrt(s)`` median edge lengths ``e`` (a diffusion), so ``s`` must reach ``(g sqrt(h R) / e)^2`` with ``g``
    :data:`VOXEL_RING_GAIN`, ``h`` the largest voxel size times its ratio to the smallest (coarse steps over
    fine treads) and ``R`` the radius of the sphere of the surface's bounding box (never less than the typical
    radius of curvature: the rule errs on the side of undefined). Measured (share of the valid vertices off the
    exact H by more than half of the largest ``|k|``, at 3 / 6 / 10 / 20 / 40 steps): ``voxel_sphere(10)`` 20 /
    2.2 / 0 / 0 / 0% (needed: 15), ``voxel_torus(12, 4)`` at 0.5 voxels 17 / 2.8 / 0.2 / 0 / 0% (needed: 39),
    ``voxel_sphere(20)`` in 4 x 1 x 1 voxels 63 / 34 / 17 / 5.3 / 0.9% (needed: 231).

    The grid is the mesh's, or that of its faces with a corner not ``invalid`` ((V,) bool; faces detached off the
    grid leave the rest on it: :func:`meshcurv.radius._voxel_surface_grid`).
    """
    return _steps_on_grid(mesh, _voxel_surface_grid(mesh, invalid=invalid))


def _steps_on_grid(mesh: PreparedMesh, found) -> int:
    """:func:`voxel_steps_needed` of the grid found (``(grid, used)`` of
    :func:`meshcurv.radius._voxel_surface_grid`, or None: 0)."""
    if found is None:
        return 0
    topology = mesh.topology
    grid, on_grid = found
    spacing = np.asarray(grid.spacing, dtype=np.float64)
    used = grid.along(mesh.vertices[on_grid])  # (the bounding box in the grid's axes: the same in every pose)
    edge = median_edge_length(mesh.vertices, topology.edges)
    if used.shape[0] == 0 or not edge > 0 or not np.all(spacing > 0):
        return 0
    h = float(spacing.max() * spacing.max() / spacing.min())
    size = 0.5 * float(np.linalg.norm(used.max(axis=0) - used.min(axis=0))) / np.sqrt(3.0)
    return int(np.ceil((VOXEL_RING_GAIN * np.sqrt(h * max(size, h)) / edge) ** 2))


def _estimate_compiled(kernels, mesh: PreparedMesh, smoothing_steps: int, stages: Stages):
    """The same with the compiled kernels: one pass for the sums, one kernel from sums to curvatures."""
    vertices, topology = mesh.vertices, mesh.topology
    stages.start("compute adjacencies")
    indptr, indices = topology.smoothing_lists(smoothing_steps)
    stages.start("compute edge tensors")
    sums, degenerate = kernels.normal_cycle_sums(
        vertices,
        topology.faces,
        topology.edges,
        topology.edge_faces,
        topology.edge_face_counts,
        topology._edge_forward_counts,
        mesh.length_scales,
        DEGENERATE_AREA_RATIO,
        kernel_threads(),
    )
    mesh.found_degenerate(degenerate)  # the same test as mesh.degenerate (the twin tests): not made twice
    defects = mesh.defects()
    stages.start("average vertex tensors")
    stages.start("retrieve curvatures")
    if smoothing_steps > STEPS_PER_CALL:
        # a long smoothing in interruptible calls (_smooth_vertex_field), the same passes the kernel makes
        sums = sums.copy()
        sums[defects.invalid_vertices, :7] = 0.0
        sums[:, :7] = _smooth_vertex_field(sums[:, :7], topology, smoothing_steps)
        smoothing_left = 0
    else:
        smoothing_left = smoothing_steps
    k_min, k_max, dir_min, dir_max, normals, valid = kernels.normal_cycle_finish(
        sums, defects.invalid_vertices, indptr, indices, smoothing_left
    )
    curvatures = (k_min, k_max, dir_min, dir_max)
    return _finished(mesh, defects, valid, smoothing_steps, stages.voxel, normals, *curvatures)
