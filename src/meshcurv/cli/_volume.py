"""``meshcurv volume``: per-object curvature tables of a 3D label image (:mod:`meshcurv.volume`)."""

from __future__ import annotations

import contextlib
import pathlib
import warnings

import click
import numpy as np

from ..io import write_curvatures
from ..io._files import atomic_output, check_output
from ..io._vtp import PieceWriter
from ..io.fields import FIELDS, curvature_fields
from ..plotting import _pyplot, plot_field, save_figure
from ._common import (
    PATH,
    POSITIVE,
    SCALAR_FIELDS,
    ProgressBar,
    choice,
    common_options,
    current_session,
    method_option,
    output_dir_option,
    overwrite_option,
    report_failures,
    workers_option,
)

__all__ = ["volume", "LabelBar", "MESH_FORMATS"]

#: Formats of the per-label mesh files (those of :data:`meshcurv.io.FORMATS` that hold per-vertex fields).
MESH_FORMATS = ("ply", "vtp", "vtu", "vtk", "npz", "csv")


class LabelBar(ProgressBar):
    """Progress over the labels: ``[####....] 12/50 labels, label 17 ok``.

    Redrawn in place on a terminal; otherwise one line per label.
    """

    def __call__(self, done: int, total: int, label: int, status: str) -> None:
        if self.stream is None:
            return
        self._shown = True
        self._draw(done, total, f"labels, label {label} {status}")


def _stem(path: pathlib.Path) -> str:
    name = path.name
    for double in (".nii.gz", ".ome.zarr"):
        if name.lower().endswith(double):
            return name[: -len(double)]
    return path.stem


def _label_list(ctx, param, value):
    if value is None:
        return None
    try:
        labels = [int(part) for part in value.split(",") if part.strip()]
    except ValueError:
        raise click.BadParameter(f"labels are whole numbers separated by commas; got {value!r}") from None
    if not labels or min(labels) < 1:
        raise click.BadParameter(f"labels are whole numbers >= 1 separated by commas; got {value!r}")
    return labels


@click.command("volume")
@click.argument("image", type=PATH)
@output_dir_option("Folder of the table, pictures and meshes (created if needed).")
@click.option(
    "--spacing",
    nargs=3,
    type=POSITIVE,
    default=None,
    metavar="Z Y X",
    help="Voxel size along image axes 0, 1, 2 (default: from the file, else 1 1 1).",
)
@click.option(
    "--labels",
    "labels_to_use",
    callback=_label_list,
    default=None,
    metavar="N,...",
    help="Only these labels (default: every label in the image).",
)
@method_option(None, "Curvature estimator (default: icc, with a radius chosen for voxel surfaces).")
@click.option(
    "--radius",
    type=POSITIVE,
    default=None,
    help="Ball radius in physical units (default: per label, from its voxels and curvature).",
)
@click.option(
    "--threshold",
    type=float,
    default=None,
    metavar="T",
    help="IMAGE is a probability map: the voxels greater than T are the objects, split into connected "
    "components (voxels sharing a face); not for Zarr stores.",
)
@click.option(
    "--smooth",
    type=POSITIVE,
    default=None,
    metavar="SIGMA",
    help="Blur each object's mask with a Gaussian of this standard deviation, in the "
    "unit of the voxel size, before its surface is extracted (shrinks objects by "
    "about SIGMA^2/R).",
)
@click.option(
    "--meshes",
    "mesh_format",
    type=click.Choice(MESH_FORMATS),
    default=None,
    help="Also write one mesh file per label with its curvature fields, in this format.",
)
@click.option(
    "--objects/--no-objects",
    "objects",
    default=True,
    show_default=True,
    help="One VTP file of all objects' surfaces, OUTDIR/<name>_objects.vtp, with a 'label' per point "
    "and per cell beside the curvature fields (ParaView colours by object).",
)
@click.option(
    "--picture/--no-picture",
    default=True,
    show_default=True,
    help="A picture of all objects coloured by --field (needs matplotlib).",
)
@choice(("-f", "--field"), SCALAR_FIELDS, "mean", "The field of the picture.")
@workers_option(
    "Compute the labels on a local Dask cluster of this many processes (needs "
    "meshcurv[batch]; default: one label after the other in this process)."
)
@overwrite_option("Replace existing outputs.")
@common_options
def volume(
    image,
    out_dir,
    spacing,
    labels_to_use,
    method,
    radius,
    threshold,
    smooth,
    mesh_format,
    objects,
    picture,
    field,
    workers,
    overwrite,
):
    """Curvature of every object of a 3D label image: one table row per label.

    \b
    meshcurv volume cells.tif -o results/ --spacing 1 0.25 0.25
    meshcurv volume brain_labels.nii.gz -o results/        spacing from the header
    meshcurv volume mask.npy -o results/ --meshes vtp --field gaussian
    meshcurv volume cells.tif -o results/ --workers 2      labels on 2 processes
    meshcurv volume membranes.mrc -o results/              voxel size in Angstrom
    meshcurv volume cells.ome.zarr -o results/ --workers 2 read lazily, per object
    meshcurv volume probability.tif -o results/ --threshold 0.5 --smooth 0.5

    IMAGE is a TIFF stack, .npy, .npz (the array 'labels', or its only array),
    NIfTI (.nii, .nii.gz), MRC (.mrc, .rec, .map: the voxel size of its header,
    in Angstrom) or a Zarr / OME-Zarr folder (.zarr: read a chunk at a time,
    never whole; needs pip install 'meshcurv[volume]') of integer labels (0: background) or
    a binary mask, or with --threshold a probability map. Writes OUTDIR/<name>_labels.csv and .parquet (one row per label:
    area, volume, area-weighted and percentiles of H, K, principal
    curvatures, shape index and curvedness, total curvatures, Willmore
    energy, Euler characteristic, border flag, status), the surfaces of all
    objects in one VTK file OUTDIR/<name>_objects.vtp (per point: the
    curvature fields, 'label', 'used' (1 where the vertex is in the
    statistics), 'vertex_area'; per cell: 'label'), a picture
    OUTDIR/<name>_<field>.png, and with --meshes one file per label
    OUTDIR/<name>_label_<N>.<format>. Nothing is overwritten without
    --overwrite. Exits with 1 when a label failed (its row says why). With
    --workers N the labels are computed on N processes (a label whose
    process dies gets a failed row; the others are computed).
    """
    # on use: the label images' modules stay out of the command line's start (issue 31)
    from .. import volume as volume_module
    from ..io._images import read_image

    session = current_session()
    volume_module._pandas()
    if picture:
        _pyplot()  # fail before computing when matplotlib is missing
    stem = _stem(image)
    out_dir.mkdir(parents=True, exist_ok=True)
    tables = [out_dir / f"{stem}_labels.csv", out_dir / f"{stem}_labels.parquet"]
    picture_path = out_dir / f"{stem}_{field}.png"
    objects_path = out_dir / f"{stem}_objects.vtp"
    for path in tables + ([picture_path] if picture else []) + ([objects_path] if objects else []):
        check_output(path, overwrite=overwrite, source=image)
    if mesh_format is not None and not overwrite:  # refused before hours of computing, not at the label
        existing = sorted(out_dir.glob(f"{stem}_label_*.{mesh_format}"))
        if existing:
            check_output(existing[0], overwrite=False)
    parquet = _has_pyarrow()
    if not parquet:
        session.info("pyarrow is not installed: the table is written as CSV only (pip install pyarrow)")

    read = read_image(image)
    if spacing is None:
        spacing = read.spacing
        if spacing is None:
            spacing = (1.0, 1.0, 1.0)
            session.info(f"{image}: no voxel size in the file; using 1 1 1 (give --spacing Z Y X)")
        else:
            unit = f" {read.unit}" if read.unit else ""
            session.info(
                f"{image}: voxel size {' x '.join(f'{s:g}' for s in spacing)}{unit} (z y x) from the file"
                + (f"; lengths in the table in {read.unit}" if read.unit else "")
            )
    total, labels = volume_module.label_surfaces(
        read.array,
        spacing=spacing,
        labels_to_use=labels_to_use,
        method=method,
        radius=radius,
        threshold=threshold,
        smooth=smooth,
        keep_surfaces=mesh_format is not None or picture or objects,
        workers=workers,
    )
    bar = session.bar(LabelBar)
    rows: list[dict] = []
    drawn: list[tuple] = []
    with contextlib.ExitStack() as stack:
        writer = _objects_writer(stack, objects_path, overwrite) if objects else None
        for surface in _with_bar(labels, bar, total, rows):
            if surface is not None:
                if writer is not None:
                    writer.add(*_object_piece(surface))
                if mesh_format is not None:
                    mesh_path = out_dir / f"{stem}_label_{surface.label}.{mesh_format}"
                    mesh = (surface.vertices, surface.faces, surface.result)
                    write_curvatures(mesh_path, *mesh, overwrite=overwrite, source=image)
                if picture:
                    values = np.where(surface.used, getattr(surface.result, field), np.nan)
                    drawn.append((surface.vertices, surface.faces, values))
        if writer is not None and writer.n_pieces == 0:
            writer.add(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64), {})  # no surface: an empty dataset
    table = volume_module._table(rows)
    for path in tables:
        if path.suffix == ".parquet" and not parquet:
            continue
        with atomic_output(path, overwrite=overwrite) as temporary:
            if path.suffix == ".parquet":
                table.to_parquet(temporary, index=False)
            else:
                table.to_csv(temporary, index=False)
    problems = volume_module._problems(table)
    if problems:
        warnings.warn(problems, volume_module.MeshQualityWarning, stacklevel=1)
    if picture and drawn:
        _draw(drawn, picture_path, field=field, title=f"{image.name}: {len(drawn)} objects", overwrite=overwrite)
    counts = table["status"].value_counts()
    written = ", ".join(str(path) for path in tables if parquet or path.suffix != ".parquet")
    session.info(
        f"{len(table)} labels: "
        + ", ".join(f"{int(counts.get(s, 0))} {s}" for s in ("ok", "empty", "too_small", "failed"))
        + f"; table in {written}"
        + (f"; picture {picture_path}" if picture and drawn else "")
        + (f"; surfaces in {objects_path}" if objects else "")
    )
    failures = table[table["status"] == "failed"]
    if failures.empty:
        return 0
    report_failures([f"label {label}" for label in failures["label"]], failures["error"], "the table")
    click.echo(f"meshcurv: error: {len(failures)} of {len(table)} labels failed", err=True)
    return 1


def _with_bar(labels, bar, total: int, rows: list):
    """Yield the surface of each ``(row, surface)`` of ``labels`` once ``row`` is in ``rows``; the bar drawn after each."""
    with bar:
        for row, surface in labels:
            rows.append(row)
            yield surface
            bar(len(rows), total, row["label"], row["status"])


def _objects_writer(stack: contextlib.ExitStack, path: pathlib.Path, overwrite: bool):
    """A :class:`~meshcurv.io._vtp.PieceWriter` onto ``path``, published when ``stack`` closes without error."""
    temporary = stack.enter_context(atomic_output(path, overwrite=overwrite))
    handle = stack.enter_context(open(temporary, "wb"))
    return stack.enter_context(PieceWriter(handle))


def _object_piece(surface):
    """``(vertices, faces, point_data, cell_data)`` of one object in the objects' VTP file."""
    n_vertices, n_faces = surface.vertices.shape[0], surface.faces.shape[0]
    point_data = {
        **curvature_fields(surface.result),
        "label": np.full(n_vertices, surface.label, dtype=np.uint64),
        "used": np.asarray(surface.used, dtype=np.uint8),
        "vertex_area": np.asarray(surface.vertex_areas, dtype=np.float64),
    }
    return surface.vertices, surface.faces, point_data, {"label": np.full(n_faces, surface.label, dtype=np.uint64)}


def _has_pyarrow() -> bool:
    try:
        import pyarrow  # noqa: F401
    except ImportError:
        return False
    return True


def _draw(drawn, path: pathlib.Path, *, field: str, title: str, overwrite: bool) -> None:
    """All objects in one mesh, coloured by ``field`` (NaN, grey, where a vertex is not in the statistics)."""
    offsets = np.cumsum([0] + [len(vertices) for vertices, _, _ in drawn[:-1]])
    vertices = np.concatenate([vertices for vertices, _, _ in drawn])
    faces = np.concatenate([faces + offset for (_, faces, _), offset in zip(drawn, offsets)])
    values = np.concatenate([values for _, _, values in drawn])
    # image axis 0 (z) upwards
    figure = plot_field(
        vertices, faces, values, view=["iso", "top"], up="x", label=f"{field}: {FIELDS[field]}", title=title
    )
    save_figure(figure, path, overwrite=overwrite)
