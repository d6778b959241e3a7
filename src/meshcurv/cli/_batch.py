"""``meshcurv batch``: the command over :func:`meshcurv.batch.run`."""

from __future__ import annotations

import click

from ..batch import DEFAULT_TIMEOUT, OUTPUT_FORMATS, run
from ._common import (
    ProgressBar,
    choice,
    common_options,
    current_session,
    method_options,
    output_dir_option,
    overwrite_option,
    report_failures,
    workers_option,
)

__all__ = ["batch", "BatchBar"]


class BatchBar(ProgressBar):
    """Progress over the meshes of a batch: ``[####....] 12/200 meshes, 1 failed``.

    Redrawn in place on a terminal; otherwise one line per percent at most.
    """

    def __call__(self, done: int, total: int, failed: int) -> None:
        if self.stream is None:
            return
        step = (done * 100 // total if total else 100, failed)
        if not self.tty and step == self._shown:
            return
        self._shown = step
        self._draw(done, total, f"meshes, {failed} failed")


@click.command("batch")
@click.argument("inputs", nargs=-1, required=True)
@output_dir_option("Folder of the results and of summary.parquet / summary.csv (created if needed).")
@method_options
@choice(("--format", "output_format"), OUTPUT_FORMATS, "ply", "Format of the result files.")
@workers_option("Worker processes of the local cluster (default: one per core).")
@click.option(
    "--scheduler",
    metavar="ADDRESS",
    default=None,
    help="Run on an existing Dask cluster, e.g. tcp://host:8786, instead of a local one.",
)
@overwrite_option("Compute again the meshes whose results exist.")
@click.option(
    "--timeout",
    type=click.FloatRange(min=0, max=1e9),
    default=DEFAULT_TIMEOUT,
    show_default=True,
    metavar="SECONDS",
    help="Time limit of one mesh; a mesh over it fails as timed out (its worker is restarted). 0: no limit.",
)
@click.option(
    "--retry-failed",
    is_flag=True,
    help="Compute again the meshes that failed in an earlier run (by default their recorded "
    "failure is reported; a changed input is always computed again).",
)
@common_options
def batch(
    inputs,
    out_dir,
    output_format,
    workers,
    scheduler,
    overwrite,
    timeout,
    retry_failed,
    **estimate,
):
    """Curvatures of many meshes on Dask: INPUTS are files, folders and glob patterns.

    \b
    meshcurv batch scans/ -o results/                    a local cluster, one worker per core
    meshcurv batch 'scans/**/*.ply' -o results/ --workers 4
    meshcurv batch scans/ -o results/ --scheduler tcp://host:8786

    Writes one result file per mesh to OUTDIR and a summary, one row per mesh,
    to OUTDIR/summary.parquet and OUTDIR/summary.csv. A second run skips the
    meshes whose results exist and whose input is unchanged (size, mtime,
    content hash), and reports the recorded failures without trying them
    again (--retry-failed tries them; --overwrite computes everything again).
    OUTDIR must be apart from the inputs: an input inside it (by any name:
    links, aliases) is refused, and no result ever replaces an input.
    A mesh that runs longer than --timeout fails as timed out. Inputs and
    OUTDIR must be on storage that every worker sees under the same paths.
    Exits with 1 when a mesh failed (the summary has its error).
    """
    if workers is not None and scheduler is not None:
        raise click.UsageError(
            "--workers sizes the local cluster; leave it out with --scheduler (the cluster's own workers are used)"
        )
    session = current_session()
    with session.bar(BatchBar) as bar:
        summary = run(
            list(inputs),
            out_dir,
            **estimate,
            output_format=output_format,
            workers=workers,
            scheduler=scheduler,
            overwrite=overwrite,
            timeout=timeout or None,
            retry_failed=retry_failed,
            progress=bar,
        )
    counts = summary["status"].value_counts()
    failures = summary[summary["status"] == "failed"]
    session.info(
        f"{len(summary)} meshes: {counts.get('computed', 0)} computed, {counts.get('skipped', 0)} skipped "
        f"(done before), {len(failures)} failed; summary in {out_dir / 'summary.parquet'} and "
        f"{out_dir / 'summary.csv'}"
    )
    not_written = summary.attrs.get("not_written")
    if failures.empty and not not_written:
        return 0
    report_failures(failures["path"], failures["error"], "the summary")
    if not failures.empty and not retry_failed:
        session.info(
            "meshes that failed before are reported, not tried again, until their file changes "
            "(--retry-failed tries them)"
        )
    if not failures.empty:
        click.echo(f"meshcurv: error: {len(failures)} of {len(summary)} meshes failed", err=True)
    if not_written:
        click.echo(f"meshcurv: error: {not_written}", err=True)
    return 1
