"""The ``meshcurv`` group (click) and its commands; ``batch``, ``volume`` and ``view`` come from their modules.

Run them through :func:`meshcurv.cli.main`.
"""

from __future__ import annotations

import importlib.metadata
import operator
import pathlib
import platform
import re
import textwrap

import click
import numpy as np

from .. import __version__
from .._backend import backend_name
from .._validation import as_faces
from ..demo import run_demo
from ..diagnosis import diagnose
from ..errors import MeshFileError
from ..estimators import ESTIMATORS
from ..integrals import weighted_statistics
from ..io import (
    FORMATS,
    POINT_EXTENSIONS,
    is_point_cloud,
    read_mesh,
    read_points,
    write_curvatures,
    write_point_curvatures,
)
from ..io._files import check_output
from ..io.fields import FIELDS, VIEWERS, curvature_fields
from ..result import parameter_text
from ..plotting import _EXTRA_INCHES, _PANEL_INCHES, MAX_DPI, VIEWS, _pyplot, choose_up, plot_field, save_figure
from ..topology import MeshTopology
from ._batch import batch
from ._common import (
    PATH,
    SCALAR_FIELDS,
    Session,
    _default_method,
    choice,
    common_options,
    current_session,
    estimated,
    low_high,
    mesh_argument,
    method_options,
    output_file,
    overwrite_option,
    path_option,
    percentiles_option,
    up_option,
)
from ._view import view
from ._volume import volume

__all__ = ["meshcurv", "Session"]


def _fields(ctx, param, value):
    if value is None:
        return None
    names = [name.strip() for name in value.split(",") if name.strip()]
    unknown = [name for name in names if name not in FIELDS]
    if unknown or not names:
        raise click.BadParameter(
            f"unknown field {unknown[0] if unknown else value!r}; choose from {', '.join(FIELDS)} (separated by commas)"
        )
    return names


def _check_output(path: pathlib.Path, *, overwrite: bool, source, cloud: bool) -> None:
    """Refuse an output ``compute`` cannot write for this input, naming exactly those it can write."""
    suffix = path.suffix.lower()
    accepted = output_extensions(cloud=cloud)
    known = ", ".join(accepted)
    what = "a point cloud's" if cloud else "a mesh's"
    if suffix not in accepted and (cloud or suffix not in FORMATS):
        shown = repr(path.suffix) if path.suffix else "(none)"
        raise MeshFileError(f"{path}: unknown output extension {shown}; {what} fields are written to {known}")
    check_output(path, overwrite=overwrite, source=source)
    if suffix not in accepted:  # a mesh format without per-vertex fields (OBJ, STL, OFF)
        raise MeshFileError(
            f"{path}: {FORMATS[suffix].name} files cannot hold per-vertex fields; write {what} fields to {known}"
        )


def output_extensions(*, cloud: bool) -> tuple:
    """The extensions ``meshcurv compute -o`` writes: those of a point cloud's fields, or of a mesh's."""
    if cloud:
        return POINT_EXTENSIONS
    return tuple(extension for extension, fmt in FORMATS.items() if fmt.fields != "none")


def version_text() -> str:
    """``meshcurv --version``: the version, the backend the computations use, numba's and Python's versions."""
    try:
        numba = importlib.metadata.version("numba")
    except importlib.metadata.PackageNotFoundError:
        numba = "not installed"
    return f"meshcurv {__version__} (backend {backend_name()}, numba {numba}, Python {platform.python_version()})"


def _print_version(ctx, param, value):
    if value and not ctx.resilient_parsing:
        click.echo(version_text())
        ctx.exit()


@click.group(context_settings={"help_option_names": ["-h", "--help"]})
@click.option(
    "--version",
    is_flag=True,
    expose_value=False,
    is_eager=True,
    callback=_print_version,
    help="Show the version, the backend (numba or numpy) and numba's version, and exit.",
)
@common_options
def meshcurv():
    """Curvature of triangle meshes: principal curvatures and directions, mean and Gaussian curvature.

    \b
    meshcurv info mesh.obj                 what the mesh is
    meshcurv compute mesh.obj              summary table of the curvatures
    meshcurv compute mesh.obj -o out.vtp   per-vertex fields for ParaView and PyVista
    meshcurv compute mesh.obj -o out.ply   ... for MeshLab (--quality), meshio, trimesh
    meshcurv compute mesh.obj -o out.csv   ... for pandas and spreadsheets
    meshcurv plot mesh.obj --field mean    a picture
    meshcurv volume cells.tif -o out/      per-object table of a label image
    meshcurv view mesh.obj                 an interactive 3D page (HTML, works offline)
    meshcurv methods                       the estimators and their options
    """


def _viewers_epilog() -> str:
    """The file to write for each reader (:data:`meshcurv.io.fields.VIEWERS`), for ``compute --help``."""
    lines = ["\b", "Which file for which reader (what it keeps of the fields):"]
    for reader, (extensions, keeps) in VIEWERS.items():
        lines.append(f"  {reader}: {', '.join(extensions)}")
        lines.extend(
            textwrap.wrap(keeps, width=78, initial_indent="      ", subsequent_indent="      ", break_on_hyphens=False)
        )
    return "\n".join(lines)


@meshcurv.command(epilog=_viewers_epilog())
@mesh_argument
@path_option(
    ("-o", "--output"),
    "Write the fields to .vtp (ParaView, PyVista), .ply (MeshLab: one field as quality; meshio, "
    "trimesh), .vtu/.vtk, .csv (pandas) or .npz (NumPy); see below. A point cloud's fields go to "
    ".ply, .xyz, .txt, .pts, .csv, .pcd, .las or .laz. Default: print a summary.",
)
@method_options
@click.option(
    "--fields",
    callback=_fields,
    default=None,
    metavar="NAME,...",
    help=f"Fields to write or summarise (default: all): {', '.join(FIELDS)}.",
)
@choice("--quality", SCALAR_FIELDS, "mean", "Field copied as `quality`, the vertex property MeshLab colours by.")
@click.option("--ascii", "ascii_", is_flag=True, help="ASCII rather than binary PLY, STL or VTK.")
@overwrite_option("Replace an existing output file.")
@common_options
def compute(mesh, output, fields, quality, ascii_, overwrite, **estimate):
    """Compute the curvatures of MESH (a mesh or a point cloud); write them with -o, or print a summary table.

    A point cloud is a file without faces: .xyz, .txt, .pts, .csv (rows of
    x y z, maybe a header line and more columns), .pcd, .las, .laz, or a .ply
    without faces.
    """
    session = current_session()
    if output is not None:
        _check_output(output, overwrite=overwrite, source=mesh, cloud=is_point_cloud(mesh))
    with estimated(mesh, session, "write" if output is not None else "summary", **estimate) as got:
        settings = {"fields": fields, "quality": quality, "overwrite": overwrite, "source": mesh, "binary": not ascii_}
        if output is not None and got.cloud:
            write_point_curvatures(output, got.vertices, got.result, **settings)
        elif output is not None:
            write_curvatures(output, got.vertices, got.faces, got.result, **settings)
    if output is None:
        click.echo(_summary(mesh, got.vertices, 0 if got.cloud else len(got.faces), got.result, fields))
        return
    written = fields or list(FIELDS)
    hint = (
        " (ParaView and PyVista read only the normals of a PLY file: write .vtp for them)"
        if output.suffix.lower() == ".ply" and not got.cloud
        else ""
    )
    session.info(
        f"wrote {output}: {len(got.vertices)} {'points' if got.cloud else 'vertices'}, fields "
        f"{', '.join(written)} (quality = {quality}){hint}"
    )


def _summary(path, vertices, n_faces: int, result, fields) -> str:
    """The summary table of ``meshcurv compute``: per-vertex and area-weighted statistics, then the integrals."""
    parameters = parameter_text(result.parameters)
    size = f"{len(vertices)} vertices, {n_faces} faces" if n_faces else f"{len(vertices)} points"
    lines = [f"{path}: {size}; method {result.method}" + (f" ({parameters})" if parameters else "")]
    values = curvature_fields(result, fields=[f for f in (fields or SCALAR_FIELDS) if f in SCALAR_FIELDS], quality=None)
    columns = ["min", "p5", "p25", "median", "p75", "p95", "max", "mean"]
    lines.append("per vertex (each vertex counts once: depends on the sampling density)")
    lines.append(f"{'field':<12}" + "".join(f"{name:>11}" for name in columns))
    for name, field in values.items():
        finite = field[np.isfinite(field)]
        if finite.size == 0:
            lines.append(f"{name:<12}" + f"{'(no finite value)':>22}")
            continue
        row = [finite.min(), *np.percentile(finite, [5, 25, 50, 75, 95]), finite.max(), finite.mean()]
        lines.append(f"{name:<12}" + "".join(f"{value:>11.4g}" for value in row))
    if n_faces:
        weighted = ["p5", "p25", "median", "p75", "p95", "mean"]
        lines.append("area-weighted (each vertex counts by its area: a third of its faces)")
        lines.append(f"{'field':<12}" + "".join(f"{name:>11}" for name in weighted))
        areas = result.vertex_areas
        for name, field in values.items():
            figures = weighted_statistics(field, areas)
            lines.append(f"{name:<12}" + "".join(f"{figures[key]:>11.4g}" for key in weighted))
        lines.append(_integrals_line(result))
    n_invalid = int((~result.valid).sum())
    lines.append(f"invalid vertices (estimate undefined, fields NaN): {n_invalid} of {len(vertices)}")
    return "\n".join(lines)


def _integrals_line(result) -> str:
    """The integrals over the surface, one line (Gauss-Bonnet's 2 pi chi beside the total of K)."""
    chi = result.diagnosis.euler_characteristic if result.diagnosis is not None else None
    closed = result.diagnosis is not None and result.diagnosis.n_boundary_edges == 0
    gaussian = result.integral("gaussian")
    check = f" = {gaussian / np.pi:.4f} pi" + (f"; 2 pi chi = {2 * chi} pi" if closed and chi is not None else "")
    willmore = result.integral("willmore", where=result.valid)
    partial = "" if result.valid.all() else " over the valid vertices"
    return (
        f"integrals: area {result.integral('area'):.6g}, total mean curvature {result.integral('mean'):.6g}, "
        f"total Gaussian curvature {gaussian:.6g}{check}, Willmore energy{partial} {willmore:.6g}"
    )


def _views(ctx, param, values):
    views = []
    for value in values:
        if re.fullmatch(r"\s*-?\d+(\.\d*)?\s*,\s*-?\d+(\.\d*)?\s*", value):
            views.append(tuple(float(x) for x in value.split(",")))
            continue
        for name in filter(None, (part.strip() for part in value.split(","))):
            if name != "auto" and name not in VIEWS:
                raise click.BadParameter(
                    f"unknown view {name!r}; choose auto, {', '.join(VIEWS)}, or ELEVATION,AZIMUTH in degrees"
                )
            views.append(name)
    return views or ["auto"]


#: The resolution of ``meshcurv plot`` pictures when neither --dpi nor --pixels is given.
DEFAULT_DPI = 150


def _limits(ctx, param, value):
    return low_high(value, what="numbers", example="-5,5", need="finite LOW < HIGH", holds=operator.lt)


@meshcurv.command()
@mesh_argument
@path_option(("-o", "--output"), "The PNG to write (default: MESH-NAME_FIELD.png in the current folder).")
@choice(("-f", "--field"), SCALAR_FIELDS, "mean", "The field that colours the mesh.")
@method_options
@click.option(
    "--view",
    "views",
    multiple=True,
    callback=_views,
    metavar="VIEW",
    help="auto (several views of a closed mesh, one of an open one), names separated by commas "
    "(iso, front, back, left, right, top, bottom, iso-back) or ELEVATION,AZIMUTH; repeatable.",
)
@up_option(
    "The axis drawn upwards; auto: z when the mesh is more than 1.2 times as tall along z as "
    "along y, else y (most OBJ and PLY files)."
)
@choice("--directions", ["none", "max", "min", "both"], "none", "Strokes along the principal directions.")
@percentiles_option("Colour limits as percentiles of the field (symmetric about 0 for a signed field).")
@click.option(
    "--limits",
    callback=_limits,
    default=None,
    metavar="LOW,HIGH",
    help="Fixed colour limits (e.g. -5,5), to compare pictures of several meshes; replaces --percentiles.",
)
@click.option(
    "--cmap",
    default=None,
    metavar="NAME",
    help="A matplotlib colour map (default: RdBu_r for signed limits, viridis otherwise).",
)
@click.option(
    "--dpi",
    type=click.IntRange(min=10, max=MAX_DPI),
    default=None,
    help="Resolution of the PNG (default 150): one view is 4.5 x 4.2 inches, n views (3.3 n + 1.2) x 4.2.",
)
@click.option(
    "--pixels",
    type=click.IntRange(min=100, max=20000),
    default=None,
    help="Width of the PNG in pixels (sets the resolution; instead of --dpi).",
)
@overwrite_option("Replace an existing picture.")
@common_options
def plot(
    mesh,
    output,
    field,
    views,
    up,
    directions,
    percentiles,
    limits,
    cmap,
    dpi,
    pixels,
    overwrite,
    **estimate,
):
    """Draw MESH coloured by a curvature field, with a colour bar."""
    _pyplot()  # fail early, before computing, when matplotlib is missing
    context = click.get_current_context()
    session = current_session(context)
    if dpi is not None and pixels is not None:
        raise click.UsageError("give --dpi or --pixels, not both")
    if limits is not None and context.get_parameter_source("percentiles") != click.core.ParameterSource.DEFAULT:
        raise click.UsageError("give --limits or --percentiles, not both")
    output = output_file(
        output, f"{mesh.stem}_{field}.png", (".png",), "the picture is a PNG", overwrite=overwrite, source=mesh
    )
    with estimated(mesh, session, "draw", **estimate) as got:
        vertices, result, cloud = got.vertices, got.result, got.cloud
        triangles = None if got.topology is None else got.topology.faces
        if "auto" in views:
            closed = got.topology is None or not got.topology.boundary_edges.any()
            auto = ["front", "left", "back"] if closed else ["iso"]
            views = [view for name in views for view in (auto if name == "auto" else [name])]
        chosen = ""
        if up == "auto":
            up, why = choose_up(vertices)
            chosen = f" (up axis {up}, chosen from the mesh: {why}; --up to choose)"
        if pixels is not None:
            dpi = pixels / (_PANEL_INCHES * len(views) + _EXTRA_INCHES)
            dpi = max(10, min(MAX_DPI, round(dpi)))
        strokes = {
            "max": {"k_max": result.dir_max},
            "min": {"k_min": result.dir_min},
            "both": {"k_max": result.dir_max, "k_min": result.dir_min},
        }.get(directions)
        values = curvature_fields(result, fields=[field], quality=None)[field]
        figure = plot_field(
            vertices,
            triangles,
            values,
            view=views,
            up=up,
            percentiles=percentiles,
            limits=limits,
            cmap=cmap,
            label=f"{field}: {FIELDS[field]}",
            directions=strokes,
            dpi=dpi if dpi is not None else DEFAULT_DPI,
            title=f"{mesh.name}, method {result.method}",
            normals=result.normals if cloud else None,
        )
        if pixels is not None:  # exactly the width asked: the size in inches follows the rounded dpi
            width, height = figure.get_size_inches()
            figure.set_size_inches(pixels / figure.dpi, height * pixels / figure.dpi / width)
        save_figure(figure, output, overwrite=overwrite)
    session.info(f"wrote {output}{chosen}")


@meshcurv.command()
@mesh_argument
@common_options
def info(mesh):
    """What MESH is: sizes, topology, defects, bounding box, edge length (or, for a point cloud, its spacing)."""
    if is_point_cloud(mesh):
        click.echo(_cloud_info(mesh))
        return
    vertices, faces = read_mesh(mesh)
    n_polygons = len(faces)
    triangles = as_faces(faces, len(vertices))
    facts = diagnose(vertices, MeshTopology.from_faces(triangles, len(vertices))).as_dict()
    lines = [f"file                   {mesh} ({FORMATS[mesh.suffix.lower()].name}, {mesh.stat().st_size} bytes)"]
    if n_polygons != len(triangles):
        lines.append(f"{'polygons':<22} {n_polygons} (fan-triangulated into {len(triangles)} triangles)")
    for key, value in facts.items():
        name = key[2:] if key.startswith("n_") else key
        name = name.replace("_", " ")
        if key == "bounding_box":
            low, high = (np.asarray(corner, dtype=float) for corner in value)
            value = f"{_point(low)} to {_point(high)} (size {_point(high - low)})"
        elif isinstance(value, float):
            value = f"{value:.6g}"
        elif value is None:
            value = "-"
        lines.append(f"{name:<22} {value}")
    click.echo("\n".join(lines))


def _cloud_info(path: pathlib.Path) -> str:
    """``meshcurv info`` of a point cloud: points, normals, non-finite and repeated points, box, spacing."""
    from scipy.spatial import cKDTree

    points, normals = read_points(path)
    finite = np.isfinite(points).all(axis=1)
    distinct = np.unique(points[finite], axis=0)
    lines = [
        f"file                   {path} (point cloud, {path.stat().st_size} bytes)",
        f"points                 {len(points)}",
        f"normals                {'given' if normals is not None else 'none (estimated when computing)'}",
        f"non-finite points      {int((~finite).sum())}",
        f"repeated points        {int(finite.sum()) - len(distinct)} (exact copies of another point)",
    ]
    if len(distinct):
        low, high = distinct.min(axis=0), distinct.max(axis=0)
        lines.append(f"bounding box           {_point(low)} to {_point(high)} (size {_point(high - low)})")
    if len(distinct) > 1:
        spacing = np.median(cKDTree(distinct).query(distinct, k=2)[0][:, 1])
        lines.append(f"spacing                {spacing:.6g} (median distance to the nearest other point)")
    return "\n".join(lines)


def _point(values) -> str:
    return "(" + ", ".join(f"{value:.6g}" for value in values) + ")"


@meshcurv.command()
@common_options
def methods():
    """The curvature estimators, one line each, and their options."""
    default = _default_method()
    width = max(map(len, ESTIMATORS)) + 2
    lines = []
    for name, estimator in ESTIMATORS.items():
        marker = " (default)" if name == default else ""
        lines.append(f"{name:<{width}}{estimator.summary}{marker}")
        options = [
            f"--{option.replace('_', '-')} "
            + (f"(default {value})" if value is not None else "(default: from the mesh)")
            for option, value in estimator.options.items()
        ]
        lines.append(" " * width + "options: " + (", ".join(options) if options else "none"))
    click.echo("\n".join(lines))


@meshcurv.command()
@click.argument("output", type=PATH, default="torus_gaussian.png")
@overwrite_option("Replace an existing picture.")
@common_options
def demo(output, overwrite):
    """A torus (matGeom's torusMesh), its curvatures against the exact ones, a picture (OUTPUT)."""
    _pyplot()
    click.echo(run_demo(output, overwrite=overwrite))


meshcurv.add_command(batch)
meshcurv.add_command(volume)
meshcurv.add_command(view)
