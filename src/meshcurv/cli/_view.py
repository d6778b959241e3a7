"""``meshcurv view``: an interactive page of a mesh's curvatures (:func:`meshcurv.viewer.write_html`)."""

from __future__ import annotations

import click

from ..io._files import check_input
from ..viewer import VIEWER_FIELDS, write_html
from ._common import choice, common_options, current_session, estimated, mesh_argument, method_options
from ._common import output_file, overwrite_option, path_option, percentiles_option, radii_option, up_option

__all__ = ["view"]


@click.command("view")
@mesh_argument
@path_option(("-o", "--output"), "The page to write (default: MESH-NAME.html in the current folder).")
@choice(("-f", "--field"), VIEWER_FIELDS, "mean", "The field shown first (the page has a menu of all of them).")
@method_options
@radii_option(
    "Several ball radii in mesh units (icc, quadric, normal_cycle_ball, or a point cloud's method): the page "
    "gets a menu of the scales (`meshcurv.multiscale_curvatures`, `multiscale_point_cloud_curvatures`)."
)
@up_option(
    "The axis drawn upwards at first; auto: z when the mesh is clearly taller along z than "
    "along y, else y (most OBJ and PLY files)."
)
@percentiles_option("Default colour limits as percentiles of each field (symmetric for signed fields).")
@click.option(
    "--directions",
    "max_directions",
    type=click.IntRange(min=0, max=10**7),
    default=20000,
    show_default=True,
    help="Principal directions at most at this many vertices, evenly spread.",
)
@click.option(
    "--unit",
    "length_unit",
    default=None,
    metavar="UNIT",
    help="The unit of the coordinates (mm, um, ...) for the colour bar: 1/UNIT.",
)
@click.option("--title", default=None, help="The page's heading (default: the file name).")
@overwrite_option("Replace an existing page.")
@common_options
def view(
    mesh,
    output,
    field,
    up,
    percentiles,
    max_directions,
    length_unit,
    title,
    overwrite,
    radii,
    **estimate,
):
    """Write MESH (a mesh or a point cloud) and its curvatures as one interactive HTML page.

    \b
    meshcurv view bunny.ply                  bunny.html, open it in a browser
    meshcurv view scan.obj -o scan.html --field gaussian --unit mm
    meshcurv view cloud.xyz --radius 0.5     points, curvatures of the cloud
    meshcurv view cell.ply --radii 0.5,1,2   three scales, a menu picks one

    The page needs no network and no installation (WebGL2 in any current
    browser): drag to rotate, right drag to pan, the wheel zooms; a menu
    picks the field, boxes set the colour limits, the value under the
    cursor is shown, principal directions on demand. Grey: vertices
    without an estimate.
    """
    session = current_session()
    page = "the page is an HTML file (.html)"
    output = output_file(output, f"{mesh.stem}.html", (".html", ".htm"), page, overwrite=overwrite, source=mesh)
    check_input(mesh)
    with estimated(mesh, session, "page", radii=radii, **estimate) as got:
        vertices, result = got.vertices, got.result
        faces = None if got.topology is None else got.topology.faces
        write_html(
            output,
            vertices,
            faces,
            result,
            field=field,
            title=title or mesh.name,
            up=None if up == "auto" else up,
            percentiles=percentiles,
            max_directions=max_directions,
            length_unit=length_unit,
            overwrite=overwrite,
            source=mesh,
        )
    size = output.stat().st_size / 1e6
    session.info(
        f"wrote {output} ({size:.1f} MB, {len(vertices)} {'points' if faces is None else 'vertices'}); "
        "open it in a browser"
    )
