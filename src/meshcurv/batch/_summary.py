"""The summary table of a batch: its columns, built from the rows, written as Parquet and CSV."""

from __future__ import annotations

import logging
import os
import pathlib

from ..io._files import atomic_output
from ._inputs import _SUMMARY_NAME, _Job
from ._process import AREA_STATISTICS, INTEGRAL_COLUMNS, STATISTICS, SUMMARY_FIELDS

logger = logging.getLogger(__name__)

#: The columns of the summary, in order, with their pandas dtypes.
COLUMNS = {
    "path": "str",
    "status": "str",
    "n_vertices": "Int64",
    "n_faces": "Int64",
    "area": "float64",
    "volume": "float64",
    "euler_characteristic": "Int64",
    "n_components": "Int64",
    "n_boundary_loops": "Int64",
    **{f"{field}_{statistic}": "float64" for field in SUMMARY_FIELDS for statistic in STATISTICS},
    **{f"{field}_area_{statistic}": "float64" for field in SUMMARY_FIELDS for statistic in AREA_STATISTICS},
    **dict.fromkeys(INTEGRAL_COLUMNS, "float64"),
    "n_invalid": "Int64",
    "seconds": "float64",
    "error": "str",
    "warnings": "str",
    "method": "str",
    "output": "str",
}

#: Columns added since the first records: a record without them is computed again.
_ADDED_COLUMNS = (
    *(f"{field}_area_{statistic}" for field in SUMMARY_FIELDS for statistic in AREA_STATISTICS),
    *INTEGRAL_COLUMNS,
)


def _summary(pandas, jobs: list[_Job], rows: dict[int, dict]):
    records = [{**rows[index], "path": os.fspath(job.path)} for index, job in enumerate(jobs)]
    frame = pandas.DataFrame.from_records(records, columns=list(COLUMNS))
    for name, dtype in COLUMNS.items():
        if dtype == "str":
            frame[name] = frame[name].fillna("").astype(str)
        else:
            frame[name] = frame[name].astype(dtype)
    return frame


def _write_summary(summary, out_dir: pathlib.Path) -> None:
    for suffix in (".parquet", ".csv"):
        path = out_dir / f"{_SUMMARY_NAME}{suffix}"
        with atomic_output(path) as temporary:
            if suffix == ".parquet":
                summary.to_parquet(temporary, index=False)
            else:
                summary.to_csv(temporary, index=False)
        logger.info("wrote %s", path)
