"""The public entry point: :func:`principal_curvatures`."""

from __future__ import annotations

import dataclasses
import warnings
from collections.abc import Sequence

import numpy as np

from ._prepared import prepare_mesh
from ._validation import check_choice, check_positive_float
from .diagnosis import mesh_diagnosis, quality_message
from .errors import InvalidOptionError, MeshQualityWarning
from .estimators import DEFAULT_METHOD, ESTIMATORS
from .estimators._support import ProgressCallback, Stages
from .estimators.icc import voxel_pilot
from .radius import (
    VoxelReading,
    _checked_radii,
    _notes_by_radius,
    _small_radius_note,
    _voxel_surface_grid,
    _voxel_surface_radius,
)
from .result import CurvatureResult
from .smoothing import check_smoothing_steps

__all__ = ["principal_curvatures", "multiscale_curvatures", "METHODS"]

#: The names accepted by ``method=``.
METHODS = tuple(ESTIMATORS)

#: The methods that measure over a ring of faces, with no length scale: on a voxel surface (marching cubes)
#: they read the staircase of the voxels as curvature, and the call's warning says so (issue 29: on a voxel
#: sphere of radius 4 voxels, ``rusinkiewicz`` had 114 of 255 valid vertices off by more than half the
#: curvature, ``quadric`` at the voxel default radius 192; the median H errors on the voxel spheres,
#: ellipsoids and tori of ``benchmarks/accuracy_voxel.md``: ``normal_cycle`` 26-100%, ``rusinkiewicz``
#: 100-434%, ``meyer`` 100-1130%, ``quadric`` 29-227%, against 0.5-25% for ``icc``). ``matgeom`` is left
#: out: its values are matGeom's, dimensionless.
RING_METHODS = ("normal_cycle", "rusinkiewicz", "meyer")


def principal_curvatures(
    vertices,
    faces=None,
    *,
    method: str = DEFAULT_METHOD,
    smoothing_steps: int | None = None,
    radius: float | None = None,
    orient: str = "auto",
    weld: bool | None = None,
    progress: ProgressCallback | None = None,
) -> CurvatureResult:
    """Principal curvatures, their directions, and the normal at every vertex.

    Parameters
    ----------
    vertices : array_like of shape (V, 3), or a mesh object
        Vertex coordinates (any real dtype; computed in float64). Or, with
        ``faces`` left out, a mesh object of trimesh (``Trimesh``), PyVista
        (``PolyData``), meshio (``Mesh``) or Open3D (``TriangleMesh``), whose
        vertices and faces are taken (none of these libraries is needed
        otherwise).
    faces : array_like of shape (F, 3) or (F, k), list of index lists, or MeshTopology
        0-based vertex indices. Polygons (k > 3, or lists of varying length) are
        fan-triangulated as matGeom's ``triangulateFaces`` does, with a
        :class:`~meshcurv.errors.TriangulationWarning`. A :class:`MeshTopology`
        built once with :meth:`MeshTopology.from_faces` skips the topology step
        (unless the vertices come in a scattered order: a large mesh whose
        neighbours are far apart in index order is computed with its vertices
        in their Morton order and its topology built for it, then its results
        put back in the caller's order: the same numbers, several times
        faster on a shuffled mesh; ``benchmarks/order.md``).
    method : {'icc', 'normal_cycle', 'matgeom', 'quadric', 'rusinkiewicz', 'normal_cycle_ball', 'meyer'}, default: 'icc'
        - ``'icc'`` (default): interpolated corrected curvature measures over a
          ball (Lachaud et al. 2020) of normals from fitted degree-3 jets; takes
          ``radius`` (default from the mesh's measured noise); boundary vertices
          are kept. The lowest error of all methods and peers on every irregular
          and noisy surface of the accuracy benchmark (see the README); about
          2.5-3 times the time of ``'normal_cycle'`` (README, Speed).
        - ``'normal_cycle'``: the normal-cycle tensor of Cohen-Steiner and Morvan
          over barycentric cells, in 1/length, correct on open meshes; fast
          (a million vertices in a few seconds, topology included), exact to second
          order on regular meshes, less accurate on irregular or noisy ones.
        - ``'matgeom'``: matGeom's ``meshCurvatures`` reproduced number for
          number (dimensionless values; see the README).
        - ``'quadric'``: weighted degree-4 jet fit over a ball with normal
          re-estimation (Cazals and Pouget 2005; Panozzo et al. 2010); takes
          ``radius``. Accurate on clean (noise-free) meshes, regular or not;
          not for noisy ones.
        - ``'rusinkiewicz'``: per-face tensors from normal differences averaged
          with Voronoi weights (Rusinkiewicz 2004).
        - ``'normal_cycle_ball'``: the normal-cycle tensor over a ball; takes
          ``radius``.
        - ``'meyer'``: cotangent mean and angle-defect Gaussian curvature (Meyer
          et al. 2003); no directions (``dir_min``, ``dir_max`` NaN), boundary
          vertices invalid.
    smoothing_steps : int, default: 3
        Passes of the 1-ring mean over the tensor field (0 = none); only
        ``'normal_cycle'`` and ``'matgeom'``.
    radius : float or 'adaptive', optional
        Radius of the Euclidean ball around each vertex over which ``'icc'``,
        ``'quadric'`` and ``'normal_cycle_ball'`` gather the mesh, in the units of
        ``vertices`` (the same meaning for all three; ``'icc'`` fits its normals
        over three times this radius). Default: for ``'icc'``, one mean edge
        length on a clean mesh, growing with the noise measured on the mesh
        (:func:`meshcurv.radius.noise_radius`; the value used and the
        noise level are in ``result.parameters``); for the others 2.5 mean edge
        lengths (:func:`meshcurv.radius.edge_radius`). Pass the same
        value for meshes of one object at different resolutions to get the
        same estimate. Refused by the other methods. ``'adaptive'`` (``'icc'``
        only): each vertex at its own scale, the radius of a ladder from the
        default upwards where its estimate changes least
        (:func:`meshcurv.radius.stable_scales`; ``result.radius`` holds it):
        more accurate than the default on every family of
        ``benchmarks/scale.md``, at 1.4 to 4 times its time.
    orient : {'auto', 'outward', 'consistent', 'keep'}, default: 'auto'
        Face orientation before the computation (:func:`meshcurv.orient.orient_faces`):
        ``'outward'`` reverses the fewest faces that make each patch (faces
        joined by manifold edges) consistently oriented, and turns every closed
        patch outward (positive volume), and every nearly closed one (small
        holes: its volume with the holes filled; a hemisphere or a saddle keeps
        its majority), so that a convex solid gets positive
        curvature however its faces were wound (marching cubes winds them
        inward); ``'consistent'`` does the same but keeps the majority
        orientation of closed patches too; ``'keep'`` uses the faces as given
        (vertices on inconsistently oriented edges are then ``valid=False``,
        and an inward-wound sphere gets negative curvature). ``'auto'``:
        ``'keep'`` for ``method='matgeom'`` (matGeom's numbers), ``'outward'``
        for every other method. The number of faces reversed is
        ``result.diagnosis.n_flipped_faces`` and is given, with the reason, in
        the warning.
    weld : bool, optional
        Merge coincident vertices on boundary edges before the computation
        (:func:`meshcurv.weld.weld_vertices`: triangle soups such as STL files,
        meshes split at texture or normal seams), within ``1e-5`` times the
        median edge length. The result still has one row per input vertex: the
        copies of a welded vertex get the same values. Default: True for every
        method but ``'matgeom'`` (matGeom's numbers); the number of vertices
        welded is ``result.parameters["n_welded_vertices"]`` and is given in
        the warning. A closed part stored twice, its vertices coincident
        (:func:`meshcurv.weld.drop_closed_copies`), is measured once, its
        copy's vertices getting the same values
        (``result.parameters["n_copy_vertices"]``, in the warning).
    progress : callable, optional
        Called as ``progress(stage, index, total)`` when each stage starts (matGeom's
        ShowProgress, per stage). Stage messages also go to the ``meshcurv``
        logger at INFO level (matGeom's Verbose).

    Returns
    -------
    CurvatureResult
        ``k_min, k_max, dir_min, dir_max, normals, valid`` and the derived
        ``mean`` and ``gaussian``; ``as_matgeom()`` gives matGeom's seven outputs;
        ``vertex_areas`` and ``integral(field)`` (area, total mean and Gaussian
        curvature, Willmore energy) from the mesh it keeps (read-only views,
        computed on first use).

    Raises
    ------
    InvalidMeshError
        Vertices or faces of the wrong shape or dtype, NaN or infinite
        coordinates, empty mesh, negative, out-of-range or 1-based indices.
    InvalidOptionError
        Unknown method, or an option value it cannot use.

    Warns
    -----
    MeshQualityWarning
        Once per call, when the mesh has boundaries, non-manifold or
        inconsistently oriented edges, zero-area faces or unreferenced vertices,
        when vertices were welded, the faces of a second side dropped or faces
        reversed, with the counts; the affected vertices have ``valid=False``
        and ``result.invalid_reason`` says why for each.

    Notes
    -----
    A double-sided mesh (every face stored twice, with opposite windings, as
    renderers without back faces want) is computed on one side, for every
    method: after welding, the faces that repeat another face's corners with
    the opposite winding are dropped (:func:`meshcurv.weld.drop_double_sided`;
    the side kept is the outward one of closed parts), their number is
    ``result.parameters["n_double_sided_faces"]`` and is given in the warning.
    The side kept is then welded as if it had been given alone (its seams and
    cracks are boundaries only once the other side is gone), and a second side
    stored with vertices of its own (at the same points) is found too: the
    result is the one side's, each copy of a vertex with its twin's values.
    Without this every edge would have four faces (every vertex NaN) and the
    integrals would count the surface twice.

    Examples
    --------
    A sphere of radius 2 has curvature 1/2 everywhere:

    >>> import numpy as np, meshcurv
    >>> sphere = meshcurv.shapes.icosphere(subdivisions=16, radius=2.0)
    >>> r = meshcurv.principal_curvatures(sphere.vertices, sphere.faces)
    >>> print(f"{np.median(r.k_min):.2f} {np.median(r.k_max):.2f}")
    0.50 0.50

    matGeom's seven outputs, its numbers:

    >>> C1, C2, U1, U2, H, K, N = meshcurv.principal_curvatures(
    ...     sphere.vertices, sphere.faces, method="matgeom").as_matgeom()
    >>> print(f"{np.mean(C1):.4f}")  # dimensionless, not 1/2: see the README
    0.0215
    """
    estimator, options, _ = _checked_options(method, smoothing_steps=smoothing_steps, radius=radius)
    orient, weld = _resolved(method, orient, weld)
    result, message = _computed(vertices, faces, estimator, options, orient, weld, progress, radius)
    if message:
        warnings.warn(message, MeshQualityWarning, stacklevel=2)
    return result


def _computed(vertices, faces, estimator, options: dict, orient: str, weld, progress, radius) -> tuple:
    """``(result, message)`` of :func:`principal_curvatures`, its options checked."""
    mesh = prepare_mesh(vertices, faces, orient=orient, weld=weld, stacklevel=4)
    found: dict = {}
    stages = Stages(estimator.stages, progress)  # stages.voxel: the mesh's voxel grid, read once for the call
    if "radius" in options and options["radius"] is None:
        # one default for every ball method (the pilot reads a turned grid in its axes: the reading)
        voxel = _voxel_surface_radius(mesh, voxel_pilot(mesh, reading=stages.voxel), stages.voxel)
        if voxel is not None:
            options["radius"], found = voxel
            stages.voxel_default = True
            vertex_scale = found.pop("vertex_scale", None)  # icc: each vertex at its own scale (issue 30)
            if estimator.name == "icc":
                options["vertex_scale"] = vertex_scale
    result, problems = estimator.function(mesh, stages=stages, **options)
    note = _staircase_note(mesh, estimator.name, found, result, stages.voxel)
    return _finished(
        mesh,
        estimator,
        result,
        [*problems, note] if note else problems,
        found,
        given_radius=radius is not None and not options.get("adaptive"),
    )


def _staircase_note(mesh, method: str, found: dict, result: CurvatureResult, reading: VoxelReading) -> str:
    """The warning's sentence for a method that reads the staircase of a voxel surface, else ''.

    The methods over a ring of faces (:data:`RING_METHODS`) on a mesh whose vertices lie on a voxel grid (read
    as for the default radius, :func:`meshcurv.radius.voxel_surface_radius`), and ``quadric`` at the default
    radius of a voxel surface (``found``: what that default was derived from), whose jets of degree 4 follow
    the staircase there. A ring method that left every vertex undefined there (``rusinkiewicz`` and ``meyer``
    always, ``normal_cycle`` below the smoothing the staircase needs) is said to have done so. ``reading``: the
    call's grid (:class:`meshcurv.radius.VoxelReading`), read by the estimator or now.
    """
    parameters = result.parameters
    if method == "quadric" and found.get("surface") == "voxel":
        return (
            f"this mesh is a voxel surface (marching cubes, voxel {_shown(found['voxel_spacing'])}): method "
            f"'quadric' fits jets of degree 4 that follow the staircase of the voxels at the default radius "
            f"{parameters['radius']:.4g}, so only the vertices whose fit agrees with one over a ball twice as wide "
            f"are kept ({int(result.valid.sum())} of {result.valid.size}); use the default method 'icc', which "
            f"measures over balls scaled to the voxels, or pass a larger `radius`"
        )
    if method not in RING_METHODS:
        return ""
    spacing = _voxel_spacing(mesh, reading)
    if spacing is None:
        return ""
    effect = (
        "so every vertex is left undefined"
        if not result.valid.any()
        else "many of its curvatures are off by a large share of the curvature itself"
    )
    return (
        f"this mesh is a voxel surface (marching cubes, voxel {_shown(spacing)}): method {method!r} measures over "
        f"a ring of faces, with no scale, and reads the staircase of the voxels as curvature ({effect}); use the "
        f"default method 'icc' or 'normal_cycle_ball', which measure over balls scaled to the voxels"
    )


def _voxel_spacing(mesh, reading: VoxelReading) -> tuple | None:
    """The voxel size of a mesh whose vertices (but the needle vertices) lie on a voxel grid, else None.

    The grid is read as for the default radius of a voxel surface (:func:`meshcurv.radius._voxel_surface_grid`,
    the mesh's own), without its pilot pass.
    """
    found = _voxel_surface_grid(mesh, reading=reading)
    return None if found is None else tuple(float(x) for x in found[0].spacing)


def _shown(spacing) -> str:
    """A voxel size as the warning gives it: ``1`` or ``2 x 1 x 1``."""
    values = [f"{x:.4g}" for x in spacing]
    return values[0] if len(set(values)) == 1 else " x ".join(values)


def multiscale_curvatures(
    vertices,
    faces=None,
    radii: Sequence[float] | np.ndarray = (),
    *,
    method: str = DEFAULT_METHOD,
    orient: str = "auto",
    weld: bool | None = None,
    progress: ProgressCallback | None = None,
) -> list[CurvatureResult]:
    """Curvatures at several scales: one :class:`CurvatureResult` per radius, in one pass.

    Each result equals ``principal_curvatures(vertices, faces, method=method,
    radius=r)`` (to round-off); the mesh is checked and prepared once, and
    ``'icc'`` sums the balls of every radius in one walk of the largest
    (:func:`meshcurv.estimators.icc.estimate_multiscale`): three radii ``h``,
    ``2 h``, ``4 h`` cost about 1.5 times ``4 h`` alone, three separate calls
    1.6 to 1.7 times (``benchmarks/multiscale.md``). How the curvature of a surface changes
    with the scale it is measured at tells noise (large changes at small
    radii) from shape.

    Parameters
    ----------
    vertices, faces
        As for :func:`principal_curvatures`.
    radii : sequence of float
        The ball radii, in the units of the vertices (positive; any order).
    method : {'icc', 'quadric', 'normal_cycle_ball'}, default: 'icc'
        A method over balls.
    orient, weld, progress
        As for :func:`principal_curvatures`.

    Returns
    -------
    list of CurvatureResult
        One per radius, in the order of ``radii``; ``result.radius`` holds it.

    Raises
    ------
    InvalidMeshError
        As :func:`principal_curvatures`.
    InvalidOptionError
        No radius, a radius that is not a positive finite number, or a method
        without a ball.

    Warns
    -----
    MeshQualityWarning
        Once per call, as :func:`principal_curvatures` (the notes of each radius
        that differ are named with it).

    Examples
    --------
    >>> import numpy as np, meshcurv
    >>> sphere = meshcurv.shapes.icosphere(subdivisions=16, radius=2.0)
    >>> fine, coarse = meshcurv.multiscale_curvatures(sphere.vertices, sphere.faces, [0.2, 0.4])
    >>> print(f"{np.median(fine.mean):.3f} {np.median(coarse.mean):.3f} {coarse.radius[0]}")
    0.500 0.500 0.4
    """
    estimator, options, _ = _checked_options(method)
    if "radius" not in estimator.options:
        raise InvalidOptionError(
            f"method {method!r} measures no ball; multiscale_curvatures takes one of "
            + ", ".join(repr(name) for name, e in ESTIMATORS.items() if "radius" in e.options)
        )
    radii = _checked_radii(radii)
    orient, weld = _resolved(method, orient, weld)
    finished = _computed_at(vertices, faces, estimator, options, orient, weld, progress, radii)
    order = np.argsort(radii, kind="stable")
    results: list = [None] * len(radii)
    for rank, index in enumerate(order):
        results[index] = finished[rank][0]
    message = _notes_by_radius({radii[i]: finished[rank][1] for rank, i in enumerate(order)})
    if message:
        warnings.warn(message, MeshQualityWarning, stacklevel=2)
    return results


def _computed_at(vertices, faces, estimator, options: dict, orient: str, weld, progress, radii: list) -> list:
    """``(result, message)`` of :func:`multiscale_curvatures` at each radius, in increasing order."""
    mesh = prepare_mesh(vertices, faces, orient=orient, weld=weld, stacklevel=4)
    order = np.argsort(radii, kind="stable")
    stages = Stages(estimator.stages, progress)
    if estimator.multiscale is not None:
        computed = estimator.multiscale(mesh, radii=[radii[i] for i in order], stages=stages)
    else:
        computed = [estimator.function(mesh, stages=stages, **{**options, "radius": radii[i]}) for i in order]
    return [_finished(mesh, estimator, result, problems, {}, given_radius=True) for result, problems in computed]


def _checked_options(method, **given) -> tuple:
    """``(estimator, options, recorded)``: the registered method, its options with the given ones checked.

    ``options`` are what the estimator takes (every option, its defaults
    filled in, ``'adaptive'`` turned into ``radius=None, adaptive=True``);
    ``recorded`` is the computation as a batch records it: the method and the
    given options that differ from the defaults (``'adaptive'`` as given), so
    that ``smoothing_steps=3`` and nothing record the same.
    """
    if not isinstance(method, str) or method not in ESTIMATORS:
        check_choice(method, "method", METHODS)  # raises: not a registered method
    estimator = ESTIMATORS[method]
    options = dict(estimator.options)
    for name, value in given.items():
        if value is None:
            continue
        if name not in estimator.options:
            raise InvalidOptionError(f"method {method!r} does not take the option `{name}`")
        options[name] = value
    if given.get("smoothing_steps") is not None:  # the registry's default is an int in range
        options["smoothing_steps"] = check_smoothing_steps(options["smoothing_steps"])  # the estimators trust it
    if isinstance(options.get("radius"), str) and options["radius"] == "adaptive" and estimator.name == "icc":
        options["radius"], options["adaptive"] = None, True  # from the default radius upwards, per vertex
    elif options.get("radius") is not None:
        options["radius"] = check_positive_float(options["radius"], "radius")
    recorded = {"method": method}
    for name, value in given.items():
        if value is not None and options[name] != estimator.options[name]:
            recorded[name] = options[name]
    if options.get("adaptive"):
        recorded["radius"] = "adaptive"
    return estimator, options, recorded


def _resolved(method: str, orient, weld) -> tuple:
    """``orient`` and ``weld`` with their defaults for ``method`` (matGeom's numbers: the mesh as given)."""
    if isinstance(orient, str) and orient == "auto":  # anything else is checked by prepare_mesh
        orient = "keep" if method == "matgeom" else "outward"
    if weld is None:
        weld = method != "matgeom"
    return orient, weld


def _finished(mesh, estimator, result: CurvatureResult, problems: list, found: dict, *, given_radius: bool):
    """``(result, message)``: the result on the caller's vertices, and the text of the call's one warning."""
    points, topology = mesh.vertices, mesh.topology
    if given_radius and estimator.radius_warning_edges is not None:  # given, not a default
        note = _small_radius_note(result.parameters["radius"], points, topology, estimator.radius_warning_edges)
        problems = [*problems, note] if note else problems
    diagnosis = mesh_diagnosis(
        points, topology, mesh.n_flipped, mesh.length_scales, n_needle_vertices=int(mesh.needles.sum())
    )
    defects = mesh.defects(boundary=estimator.boundary, fragments=estimator.fragments)
    reasons = defects.reasons(result.valid, result.invalid_reason)  # the estimator's codes: its limits
    parameters = {
        **result.parameters,
        **found,
        "orient": mesh.orient,
        "n_welded_vertices": mesh.n_welded,
        "n_copy_vertices": mesh.n_copies,
        "n_double_sided_faces": mesh.n_double_sided,
    }
    result = mesh.expand(
        dataclasses.replace(
            result, diagnosis=diagnosis, invalid_reason=reasons, parameters=parameters, _surface=mesh.surface
        )
    )
    if mesh.n_flipped:
        problems = list(problems) + [_flip_reason(diagnosis, mesh.orient)]
    message = quality_message(
        estimator.name, problems, dataclasses.replace(diagnosis, n_flipped_faces=0), notes=mesh.notes()
    )
    if message:
        counts = result.invalid_counts()
        if counts:
            message += "; invalid vertices by reason: " + ", ".join(f"{n} {why}" for why, n in counts.items())
    return result, message


def _flip_reason(diagnosis, orient: str) -> str:
    n = diagnosis.n_flipped_faces
    if orient == "consistent" or diagnosis.n_faces == 0 or n < diagnosis.n_faces:
        why = "to orient every patch consistently" + (" and outward" if orient == "outward" else "")
    else:
        why = "the mesh was wound inward (negative volume; marching cubes winds its faces so)"
    return f"orient={orient!r} reversed {n} of {diagnosis.n_faces} faces before the computation: {why}"
