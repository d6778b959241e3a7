"""The public entry point: :func:`principal_curvatures`."""

from __future__ import annotations

import dataclasses
import warnings
from typing import Any

import numpy as np

from ._adapters import mesh_arrays
from ._locality import local_topology
from ._validation import as_vertices, check_choice, check_int_option, check_positive_float, trusting
from .diagnosis import diagnose, quality_message
from .errors import InvalidOptionError, MeshQualityWarning
from .estimators import DEFAULT_METHOD, ESTIMATORS
from .estimators._common import ProgressCallback, Stages
from .estimators.icc import voxel_pilot
from .geometry import degenerate_faces
from .orient import ORIENT_CHOICES, oriented_topology
from .radius import small_radius_note, voxel_surface_radius
from .result import INVALID_REASONS, CurvatureResult, Surface
from .topology import MeshTopology
from .weld import drop_double_sided, weld_vertices

__all__ = ["principal_curvatures", "METHODS"]

#: The names accepted by ``method=``.
METHODS = tuple(ESTIMATORS)


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
    radius : float, optional
        Radius of the Euclidean ball around each vertex over which ``'icc'``,
        ``'quadric'`` and ``'normal_cycle_ball'`` gather the mesh, in the units of
        ``vertices`` (the same meaning for all three; ``'icc'`` fits its normals
        over three times this radius). Default: for ``'icc'``, one mean edge
        length on a clean mesh, growing with the noise measured on the mesh
        (:func:`meshcurv.radius.noise_radius`; the value used and the
        noise level are in ``result.parameters``); for the others 2.5 mean edge
        lengths (:func:`meshcurv.radius.edge_radius`). Pass the same
        value for meshes of one object at different resolutions to get the
        same estimate. Refused by the other methods.
    orient : {'auto', 'outward', 'consistent', 'keep'}, default: 'auto'
        Face orientation before the computation (:func:`meshcurv.orient.orient_faces`):
        ``'outward'`` reverses the fewest faces that make each patch (faces
        joined by manifold edges) consistently oriented, and turns every closed
        patch outward (positive volume), so that a convex solid gets positive
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
        the warning.
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
    if not isinstance(method, str) or method not in ESTIMATORS:
        check_choice(method, "method", METHODS)  # raises: not a registered method
    estimator = ESTIMATORS[method]
    given = {"smoothing_steps": smoothing_steps, "radius": radius}
    options = dict(estimator.options)
    for name, value in given.items():
        if value is None:
            continue
        if name not in estimator.options:
            raise InvalidOptionError(f"method {method!r} does not take the option `{name}`")
        options[name] = value
    if "smoothing_steps" in options:
        options["smoothing_steps"] = check_int_option(options["smoothing_steps"], "smoothing_steps")
    if options.get("radius") is not None:
        options["radius"] = check_positive_float(options["radius"], "radius")

    if faces is None:
        vertices, faces = mesh_arrays(vertices)
    callers = as_vertices(vertices)
    points, topology, local = local_topology(callers, faces, stacklevel=3)  # a scattered order made local
    check_choice(orient, "orient", ORIENT_CHOICES)
    if orient == "auto":
        orient = "keep" if method == "matgeom" else "outward"
    if weld is None:
        weld = method != "matgeom"
    elif not isinstance(weld, (bool, np.bool_)):
        raise InvalidOptionError(f"`weld` must be True or False; got {weld!r}")
    welding = weld_vertices(points, topology) if weld else None
    if welding is not None and welding.n_welded:
        points, topology = welding.vertices, welding.topology
    one_sided = drop_double_sided(points, topology)  # a double-sided mesh: its faces of one winding
    topology = one_sided.topology
    topology, n_flipped = oriented_topology(points, topology, orient)
    with trusting(points, topology.faces, topology.edges):  # checked: the helpers below need not check again
        found: dict = {}
        if "radius" in options and options["radius"] is None:
            voxel = voxel_surface_radius(points, topology, voxel_pilot(points, topology))  # a voxel surface: one default for every ball method
            if voxel is not None:
                options["radius"], found = voxel
        result, problems = estimator.function(
            points, topology, stages=Stages(estimator.stages, progress), **options
        )
        if radius is not None and estimator.radius_warning_edges is not None:  # given, not a default
            note = small_radius_note(result.parameters["radius"], points, topology, estimator.radius_warning_edges)
            problems = [*problems, note] if note else problems
        diagnosis = diagnose(points, topology, n_flipped_faces=n_flipped)
        reasons = invalid_reasons(points, topology, result.valid, boundary_valid=result.method in _BOUNDARY_METHODS)
    parameters = {**result.parameters, **found, "orient": orient,
                  "n_welded_vertices": welding.n_welded if welding is not None else 0,
                  "n_double_sided_faces": one_sided.n_dropped}
    # the rows of the computed result (welded vertices, in the local order) of each of the caller's vertices
    welded = welding if welding is not None and welding.n_welded else None
    index = None if welded is None else welded.index
    if local is not None:
        index = local.index if welded is None else welded.index[local.index]
    if local is not None and welded is None:  # the mesh the caller gave, its faces oriented (and one-sided)
        surface = Surface(callers, np.take(local.order, topology.faces) if one_sided.n_dropped
                          else local.original_faces(topology.faces))
    else:
        surface = Surface(points, topology.faces, index)
    result = dataclasses.replace(result, diagnosis=diagnosis, invalid_reason=reasons, parameters=parameters,
                                 _surface=surface)
    if index is not None:
        result = _expanded(result, index)
    if n_flipped:
        problems = list(problems) + [_flip_reason(diagnosis, orient)]
    message = quality_message(method, problems, dataclasses.replace(diagnosis, n_flipped_faces=0))
    prepared = _preparation_notes(welded, one_sided.n_dropped)
    if prepared:  # before what the estimator and the diagnosis found (which they may not name otherwise)
        message = f"{method}: " + "; ".join(prepared + ([message[len(method) + 2:]] if message else []))
    if message:
        counts = result.invalid_counts()
        if counts:
            message += "; invalid vertices by reason: " + ", ".join(f"{n} {why}" for why, n in counts.items())
        warnings.warn(message, MeshQualityWarning, stacklevel=2)
    return result


#: Methods whose boundary vertices are valid (the others leave them undefined).
_BOUNDARY_METHODS = frozenset({"icc", "quadric", "normal_cycle_ball", "rusinkiewicz", "matgeom"})


def invalid_reasons(vertices: np.ndarray, topology: MeshTopology, valid: np.ndarray, *,
                    boundary_valid: bool) -> np.ndarray:
    """(V,) int8 codes of :data:`~meshcurv.result.INVALID_REASONS`: why each invalid vertex is.

    Each invalid vertex gets the first reason that applies to it, in the
    order of :data:`~meshcurv.result.INVALID_REASONS`; an invalid vertex
    with no defect of the mesh gets the last one (the estimate itself was
    undefined). 0 where ``valid``.
    """
    reasons = np.zeros(valid.shape[0], dtype=np.int8)
    invalid = ~valid
    if not invalid.any():
        return reasons
    degenerate = degenerate_faces(vertices, topology)
    corners = np.zeros(valid.shape[0], dtype=bool)
    corners[topology.faces[degenerate].ravel()] = True
    bowties = topology.bowtie_vertices & ~topology.edge_vertices(topology.nonmanifold_edges)
    boundary = np.zeros_like(valid) if boundary_valid else topology.boundary_vertices
    classes = [~topology.referenced_vertices, topology.edge_vertices(topology.nonmanifold_edges), bowties,
               topology.edge_vertices(topology.inconsistent_edges), corners, boundary]
    for code, members in enumerate(classes, start=1):
        reasons[invalid & members & (reasons == 0)] = code
    reasons[invalid & (reasons == 0)] = len(INVALID_REASONS) - 1
    return reasons


def _preparation_notes(welded, n_dropped: int) -> list[str]:
    """What was done to the mesh before the computation: vertices welded, the faces of a second side dropped."""
    notes = []
    if welded is not None:
        notes.append(f"welded {welded.n_welded} coincident vertices (a triangle soup or split seams) "
                     "before the computation; copies share their values")
    if n_dropped:
        notes.append(f"dropped {n_dropped} faces that repeat another face's corners with the opposite winding "
                     "(a double-sided mesh): computed on one side (result.parameters['n_double_sided_faces'])")
    return notes


def _flip_reason(diagnosis, orient: str) -> str:
    n = diagnosis.n_flipped_faces
    if orient == "consistent" or diagnosis.n_faces == 0 or n < diagnosis.n_faces:
        why = "to orient every patch consistently" + (" and outward" if orient == "outward" else "")
    else:
        why = "the mesh was wound inward (negative volume; marching cubes winds its faces so)"
    return f"orient={orient!r} reversed {n} of {diagnosis.n_faces} faces before the computation: {why}"


def _expanded(result: CurvatureResult, index: np.ndarray) -> CurvatureResult:
    """The result of a welded or reordered mesh on the input's vertices: row ``i`` is the computed row ``index[i]``."""
    # np.take: several times faster than indexing the rows of an (N, 3) array
    fields: dict[str, Any] = {name: np.take(getattr(result, name), index, axis=0)
                              for name in ("k_min", "k_max", "dir_min", "dir_max", "normals", "valid", "invalid_reason")}
    return dataclasses.replace(result, **fields)
