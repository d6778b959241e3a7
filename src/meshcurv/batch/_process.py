"""The task of a batch: one mesh file read, its curvatures computed and written, its summary row."""

from __future__ import annotations

import contextlib
import json
import logging
import os
import pathlib
import time
import warnings
from typing import Any

import numpy as np

from ..curvature import principal_curvatures
from ..estimators import DEFAULT_METHOD
from ..integrals import weighted_statistics
from ..io import is_point_cloud, read_mesh, read_points, write_curvatures, write_point_curvatures
from ..io._files import atomic_output
from ..pointcloud import POINT_CLOUD_METHODS, point_cloud_curvatures
from ._inputs import _identity, _refuse_input
from ._records import _attempt_path, _previous_attempt, _record_failure, _time_limit, _write_record, fingerprint

logger = logging.getLogger(__name__)

#: The per-vertex fields summarised in each row (attributes of :class:`~meshcurv.CurvatureResult`).
SUMMARY_FIELDS = ("k_min", "k_max", "mean", "gaussian", "shape_index", "curvedness")

#: The per-vertex statistics of each summarised field, over the valid vertices with a finite value
#: (each vertex counts once: they depend on the sampling density), as ``<field>_<statistic>``.
STATISTICS = ("mean", "median", "p5", "p95")

#: The area-weighted statistics of each summarised field (each vertex counts by its vertex area,
#: :attr:`meshcurv.CurvatureResult.vertex_areas`), as ``<field>_area_<statistic>``; NaN for point clouds.
AREA_STATISTICS = ("mean", "median", "p5", "p95")

#: The integrals over the surface (:meth:`meshcurv.CurvatureResult.integral`): column -> field.
#: ``willmore`` is over the valid vertices. NaN for point clouds.
INTEGRAL_COLUMNS = {"total_mean": "mean", "total_gaussian": "gaussian", "willmore": "willmore"}


def _statistics(result) -> dict:
    row = {}
    for name in SUMMARY_FIELDS:
        values = np.asarray(getattr(result, name))[result.valid]
        values = values[np.isfinite(values)]
        if values.size:
            p5, median, p95 = np.percentile(values, [5, 50, 95])
            figures = {"mean": values.mean(), "median": median, "p5": p5, "p95": p95}
        else:
            figures = dict.fromkeys(STATISTICS, np.nan)
        row.update({f"{name}_{statistic}": float(figures[statistic]) for statistic in STATISTICS})
    if result._surface is None:  # a point cloud: no areas
        row.update({f"{name}_area_{statistic}": np.nan for name in SUMMARY_FIELDS for statistic in AREA_STATISTICS})
        row.update(dict.fromkeys(INTEGRAL_COLUMNS, np.nan))
        return row

    areas = np.where(result.valid, result.vertex_areas, 0.0)
    for name in SUMMARY_FIELDS:
        figures = weighted_statistics(getattr(result, name), areas)
        row.update({f"{name}_area_{statistic}": figures[statistic] for statistic in AREA_STATISTICS})
    for column, field in INTEGRAL_COLUMNS.items():
        row[column] = result.integral(field, where=result.valid if field == "willmore" else None)
    return row


def process_mesh(
    source,
    output,
    record,
    *,
    method: str = DEFAULT_METHOD,
    smoothing_steps: int | None = None,
    radius: float | None = None,
    orient: str | None = None,
    timeout: float | None = None,
    run_id: str | None = None,
) -> dict:
    """Compute the curvatures of one mesh file, write the result and its record, return its summary row.

    The task :func:`run` sends to the workers; it never raises for a bad mesh.
    The result file is written under a temporary name; the record is written
    before the result is renamed into place, so a result that exists always
    has its record. An older result at ``output`` is replaced; ``output``
    is never the input file itself (checked before the rename).

    Parameters
    ----------
    source : str or os.PathLike
        The mesh file (any format :func:`meshcurv.read_mesh` reads).
    output : str or os.PathLike
        The result file; its extension picks the format (one of
        :data:`OUTPUT_FORMATS`). Its folder is created if needed.
    record : str or os.PathLike
        The JSON file that keeps the row and the input's :func:`fingerprint`,
        for later runs; a failure is recorded too.
    method, smoothing_steps, radius, orient
        As in :func:`meshcurv.principal_curvatures`.
    timeout : float, optional
        The time limit in seconds. Enforced only in a Dask worker that has a
        nanny (the local cluster's, ``dask worker``'s): past it, the worker
        process is ended, and the next attempt of the task (``run_id`` given)
        reports the mesh as timed out.
    run_id : str, optional
        The batch run: with it, the mesh being computed is noted beside its
        record, so that an attempt after its worker died knows it (see
        :data:`MAX_WORKER_DEATHS`).

    Returns
    -------
    dict
        The summary row (the keys of :data:`COLUMNS` but ``path``), with
        ``status`` ``'computed'``, or ``'failed'`` and the ``error`` (its type
        and message) when the mesh could not be read, computed or written,
        took longer than ``timeout`` or killed its workers.
    """
    start = time.perf_counter()
    source, output, record = pathlib.Path(source), pathlib.Path(output), pathlib.Path(record)
    given = {"smoothing_steps": smoothing_steps, "radius": radius, "orient": orient}
    options: dict[str, Any] = {name: value for name, value in given.items() if value is not None}
    stored_options = {"method": method, **options}
    row = {"status": "computed", "error": "", "warnings": "", "method": method, "output": os.fspath(output)}
    attempt = _attempt_path(record)
    deaths, error = _previous_attempt(attempt, run_id, timeout)
    facts = None
    with contextlib.suppress(OSError):  # read_mesh says what is wrong with it
        facts = fingerprint(source)
    failure = (source, record, method, stored_options, facts, timeout)
    if error is not None:
        row = _failed(*failure, error, timeout if error.startswith("TimeoutError") else np.nan)
        attempt.unlink(missing_ok=True)
        return row
    try:
        if run_id is not None:
            deadline = time.time() + timeout if timeout is not None else None
            # a plain write, no temporary nor sync (cost: benchmarks/docstring_figures.md): a note cut short reads
            # as no note
            attempt.parent.mkdir(parents=True, exist_ok=True)
            attempt.write_text(json.dumps({"run": run_id, "deaths": deaths, "deadline": deadline}))
        with _time_limit(timeout), warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            if is_point_cloud(source):  # a file without faces: the point-cloud estimators, their default
                vertices, normals = read_points(source)
                faces = None
                cloud_method = method if method in POINT_CLOUD_METHODS else None
                result = point_cloud_curvatures(
                    vertices, normals=normals, radius=options.get("radius"), method=cloud_method
                )
                row["method"] = result.method
            else:
                vertices, faces = read_mesh(source)
                result = principal_curvatures(vertices, faces, method=method, **options)
        facts_of = result.diagnosis
        if facts_of is None:  # a point cloud
            row.update(n_vertices=vertices.shape[0], n_faces=0, area=np.nan, volume=np.nan)
        else:
            names = ("n_vertices", "n_faces", "area", "euler_characteristic", "n_components", "n_boundary_loops")
            row.update({name: getattr(facts_of, name) for name in names})
            row["volume"] = np.nan if facts_of.volume is None else facts_of.volume
        row.update(
            n_invalid=int((~result.valid).sum()),
            warnings="; ".join(dict.fromkeys(str(warning.message) for warning in caught)),
        )
        row.update(_statistics(result))
        output.parent.mkdir(parents=True, exist_ok=True)
        with atomic_output(output) as temporary:
            if faces is None:
                write_point_curvatures(temporary, vertices, result, overwrite=True, source=source)
            else:
                write_curvatures(temporary, vertices, faces, result, overwrite=True, source=source)
            inputs = {_identity(source): source}
            _refuse_input(output, inputs)  # the output folder may have become an alias of the input's
            _refuse_input(record, inputs)
            output.unlink(missing_ok=True)  # an older result must not outlive a newer record
            row["seconds"] = time.perf_counter() - start
            _write_record(record, {"row": row, "options": stored_options, "input": facts})
    except Exception as exc:  # one bad mesh never sinks the batch: its row says what went wrong
        row = _failed(*failure, f"{type(exc).__name__}: {exc}", time.perf_counter() - start)
    attempt.unlink(missing_ok=True)
    return row


def _failed(source, record, method, stored_options, facts, timeout, error: str, seconds: float | None) -> dict:
    """The row of a mesh that failed with ``error``, recorded."""
    row = {"status": "failed", "error": error, "warnings": "", "method": method, "output": "", "seconds": seconds}
    logger.info("%s failed: %s", source, error)
    _record_failure(record, row, stored_options, facts, timeout)
    return row


def process_meshes(sources, outputs, records, **options) -> list[dict]:
    """:func:`process_mesh` on several meshes in turn (one Dask task); their rows, in order.

    Parameters
    ----------
    sources, outputs, records : sequence of str or os.PathLike
        The ``source``, ``output`` and ``record`` of each mesh, in the same
        order (of the same length).
    **options
        The options of :func:`process_mesh` (``method``, ``timeout``, ...),
        the same for every mesh.

    Returns
    -------
    list of dict
        The summary row of each mesh (:func:`process_mesh`), in order.
    """
    return [
        process_mesh(source, output, record, **options)
        for source, output, record in zip(sources, outputs, records, strict=True)
    ]
