"""Curvature of whole datasets: many mesh files at once, on a Dask cluster.

:func:`run` expands files, folders and glob patterns into a list of meshes,
computes the curvatures of each on a Dask cluster (a local one by default,
started and closed by the call, or an existing one given by its scheduler
address or a :class:`distributed.Client`), writes one result file per mesh
and returns a summary table, one row per mesh, that it also writes to
``OUT_DIR/summary.parquet`` and ``OUT_DIR/summary.csv``.

Paths travel to the workers, not arrays: each worker reads its own file and
writes its own result, so the inputs and ``OUT_DIR`` must be on storage that
the machine calling :func:`run` and every worker see under the same paths
(a local disk for a local cluster, a shared file system for a cluster).

Needs ``pip install 'meshcurv[batch]'`` (dask.distributed, pandas, pyarrow).

What is written (``OUT_DIR`` is created if needed):

- one result file per mesh, ``OUT_DIR/<name>.<output_format>``, holding the
  mesh and its curvature fields (:func:`meshcurv.io.write_curvatures`); inputs
  in several folders keep their folders below the deepest folder they share;
- a record per mesh in ``OUT_DIR/.meshcurv-batch/`` (its summary row, the
  options and the input's :func:`fingerprint`, in JSON), so that a later run
  can skip the mesh and still report it, and notice an input changed since;
  failures are recorded too (a later run reports them without trying again,
  unless asked); a damaged record is ignored (its mesh computed again);
- ``summary.parquet`` and ``summary.csv``, ordered by input path.

``OUT_DIR`` is kept apart from the inputs: an input in it (under any name:
links, ``..``, bind mounts) is refused or, matched by a folder or pattern,
left out, and no result or record is ever written over an input file. Each
mesh has a time limit (``timeout``, one hour by default), and a mesh whose
workers keep dying fails alone (see :func:`run`).

Every file is written under a temporary name and renamed when complete: a
result file that exists is complete, and a run that is interrupted or whose
worker dies leaves no partial file (see :func:`run`).
"""

# the names of meshcurv.batch before it became a package, all importable from here; the settings are
# read where they are defined (to change CHUNK_BYTES for a test, patch meshcurv.batch._run.CHUNK_BYTES)
from ._driver import MAX_WORKERS as MAX_WORKERS
from ._driver import NO_WORKER_SECONDS as NO_WORKER_SECONDS
from ._driver import WORKER_CONFIG as WORKER_CONFIG
from ._driver import WORKER_ENVIRONMENT as WORKER_ENVIRONMENT
from ._driver import NoWorkerError, local_cluster
from ._inputs import OUTPUT_FORMATS, RECORDS, expand_inputs
from ._process import AREA_STATISTICS as AREA_STATISTICS
from ._process import INTEGRAL_COLUMNS as INTEGRAL_COLUMNS
from ._process import STATISTICS as STATISTICS
from ._process import SUMMARY_FIELDS, process_mesh, process_meshes
from ._records import HASH_PART_BYTES as HASH_PART_BYTES
from ._records import HASH_WHOLE_BYTES as HASH_WHOLE_BYTES
from ._records import MAX_WORKER_DEATHS as MAX_WORKER_DEATHS
from ._records import fingerprint
from ._run import CHUNK_BYTES as CHUNK_BYTES
from ._run import CHUNKS_PER_WORKER as CHUNKS_PER_WORKER
from ._run import DEFAULT_TIMEOUT, run
from ._summary import COLUMNS

__all__ = [
    "run",
    "local_cluster",
    "process_mesh",
    "process_meshes",
    "expand_inputs",
    "fingerprint",
    "COLUMNS",
    "SUMMARY_FIELDS",
    "OUTPUT_FORMATS",
    "RECORDS",
    "DEFAULT_TIMEOUT",
    "NoWorkerError",
]
