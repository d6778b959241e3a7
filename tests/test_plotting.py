"""Pictures: resolution and size that change the output, colour maps, fixed limits, labels that fit,
the up axis chosen from the mesh, and the user's matplotlib backend left alone."""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import meshcurv
from meshcurv.errors import InvalidMeshError, InvalidOptionError, MeshFileError
from meshcurv.plotting import VIEWS, _camera, _point_spacing, _Raster, choose_up, plot_field, save_figure

matplotlib = pytest.importorskip("matplotlib")

TORUS = meshcurv.shapes.torus(n_major=24, n_minor=12)


def png_size(path):
    """(width, height) from the PNG's IHDR chunk."""
    data = path.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    return int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")


@pytest.mark.slow
def test_dpi_sets_the_size_of_the_picture(tmp_path):
    sizes = {}
    for dpi in (50, 100, 200):
        fig = plot_field(TORUS.vertices, TORUS.faces, TORUS.mean, view=["iso", "top"], dpi=dpi)
        sizes[dpi] = png_size(save_figure(fig, tmp_path / f"{dpi}.png"))
    # two views: (2 x 3.3 + 1.2) x 4.2 inches
    for dpi, (width, height) in sizes.items():
        assert (width, height) == (round(7.8 * dpi), round(4.2 * dpi))
    # save_figure's dpi overrides the figure's
    fig = plot_field(TORUS.vertices, TORUS.faces, TORUS.mean, view="iso", dpi=100)
    assert png_size(save_figure(fig, tmp_path / "override.png", dpi=40)) == (round(4.5 * 40), round(4.2 * 40))


@pytest.mark.slow  # 3.5 s: pictures at several resolutions
def test_the_view_images_follow_the_resolution():
    small = plot_field(TORUS.vertices, TORUS.faces, TORUS.mean, view="iso", dpi=50)
    large = plot_field(TORUS.vertices, TORUS.faces, TORUS.mean, view="iso", dpi=200)
    # the image of a view is twice its panel's side in the picture: 2 x 3.3 x dpi along its longer side
    assert max(small.axes[0].images[0].get_array().shape[:2]) == 2 * 165
    assert max(large.axes[0].images[0].get_array().shape[:2]) == 2 * 660
    given = plot_field(TORUS.vertices, TORUS.faces, TORUS.mean, view="iso", pixels=123)
    assert max(given.axes[0].images[0].get_array().shape[:2]) == 123


def test_fixed_limits_and_colour_map():
    fig = plot_field(TORUS.vertices, TORUS.faces, TORUS.gaussian, limits=(-0.002, 0.004), cmap="magma")
    bar = fig.axes[-1]
    assert bar.get_ylim() == pytest.approx((-0.002, 0.004))
    assert bar.get_ylabel().endswith("colour limits -0.002 to 0.004 (fixed)")
    image = np.asarray(fig.axes[0].images[0].get_array())
    shown = image[..., :3].reshape(-1, 3)
    shown = shown[shown.sum(axis=1) > 0.05][::25]
    # every shaded colour is a magma colour darkened by the light: its direction in RGB is on the map's curve
    colours = matplotlib.colormaps["magma"](np.linspace(0, 1, 256))[:, :3]
    unit = colours / np.linalg.norm(colours, axis=1, keepdims=True).clip(1e-9)
    seen = shown / np.linalg.norm(shown, axis=1, keepdims=True)
    assert np.median((seen @ unit.T).max(axis=1)) > 0.999
    viridis = matplotlib.colormaps["viridis"](np.linspace(0, 1, 256))[:, :3]
    viridis /= np.linalg.norm(viridis, axis=1, keepdims=True)
    assert np.median((seen @ viridis.T).max(axis=1)) < np.median((seen @ unit.T).max(axis=1))


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"cmap": "no-such-map"}, "unknown colour map 'no-such-map'; choose a name of matplotlib.colormaps"),
        ({"limits": (1.0, -1.0)}, r"`limits` must be finite with low < high; got \(1.0, -1.0\)"),
        ({"limits": (0.0, np.inf)}, "`limits` must be finite with low < high"),
        ({"limits": "wide"}, "`limits` must be"),
        ({"dpi": 5}, "`dpi` must be an integer between 10 and 1200; got 5"),
        # checked as the viewer checks them, not numpy's ValueError nor a silent swap
        ({"percentiles": (2, 101)}, r"`percentiles` must satisfy 0 <= low < high <= 100; got \(2, 101\)"),
        ({"percentiles": (98, 2)}, "`percentiles` must satisfy 0 <= low < high <= 100"),
        ({"percentiles": (2,)}, r"`percentiles` must be two numbers \(low, high\); got \(2,\)"),
        # were an AttributeError deep in matplotlib, and numpy's ValueError
        ({"cmap": 5}, "`cmap` must be a name of matplotlib.colormaps or a Colormap; got 5"),
        ({"label": 5}, "`label` must be a string; got int"),
        ({"title": ["a"]}, "`title` must be a string; got list"),
    ],
)
def test_errors(options, message):
    with pytest.raises(InvalidOptionError, match=message):
        plot_field(TORUS.vertices, TORUS.faces, TORUS.mean, pixels=40, **options)


def test_values_that_are_not_numbers():  # was numpy's ValueError
    with pytest.raises(InvalidOptionError, match="`values` must be numbers, one per vertex; got a list of others"):
        plot_field(TORUS.vertices, TORUS.faces, ["a"] * len(TORUS.vertices), pixels=40)


def test_the_colour_bar_label_fits_in_the_picture():
    long = "shape_index: " + meshcurv.io.fields.FIELDS["shape_index"]
    values = np.linspace(-1, 1, TORUS.vertices.shape[0])
    for views in (["iso"], ["front", "left", "back"]):
        fig = plot_field(TORUS.vertices, TORUS.faces, values, view=views, label=long, pixels=60)
        fig.canvas.draw()
        label = fig.axes[-1].yaxis.label.get_window_extent()
        picture = fig.bbox
        assert picture.x0 <= label.x0 and label.x1 <= picture.x1, views
        assert picture.y0 <= label.y0 and label.y1 <= picture.y1, views
        assert "percentiles 2-98, centred on 0" in fig.axes[-1].get_ylabel()


def test_up_axis_is_chosen_from_the_extent():
    box = np.array([[0, 0, 0], [1, 2, 3], [1, 0, 0], [0, 2, 0]], dtype=float)  # 3 / 2 along z / y: z up
    assert choose_up(box)[0] == "z"
    assert choose_up(box[:, [0, 2, 1]])[0] == "y"  # 2 / 3: y up
    assert choose_up(np.array([[0, 0, 0], [1, 1, 1.1]]))[0] == "y"  # 1.1: below the 1.2 ratio
    with pytest.raises(InvalidMeshError, match=r"`vertices` must have shape \(V, 3\); got \(4, 2\)"):
        choose_up(box[:, :2])  # was numpy's IndexError
    # a tall column along z, drawn front on: taller than wide in the picture
    column = meshcurv.shapes.cylinder(radius=1.0, height=6.0)  # axis along z
    fig = plot_field(column.vertices, column.faces, column.mean, view="front", pixels=100)
    height, width = fig.axes[0].images[0].get_array().shape[:2]
    assert height > 2 * width
    fig = plot_field(column.vertices, column.faces, column.mean, view="front", pixels=100, up="y")
    height, width = fig.axes[0].images[0].get_array().shape[:2]
    assert abs(height - width) <= 2  # y up: seen along its axis, a disc


def test_the_backend_and_pyplot_are_left_alone(tmp_path):
    """In a fresh process: a backend chosen by the user stays, and pyplot is never imported."""
    script = textwrap.dedent(f"""
        import sys
        import matplotlib
        matplotlib.use("svg")
        import meshcurv
        from meshcurv.plotting import plot_field, save_figure
        t = meshcurv.shapes.torus(n_major=12, n_minor=8)
        save_figure(plot_field(t.vertices, t.faces, t.mean, pixels=40), {str(tmp_path / "p.png")!r})
        print(matplotlib.get_backend(), "matplotlib.pyplot" in sys.modules)
    """)
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.split() == ["svg", "False"]
    assert png_size(tmp_path / "p.png")[0] > 0


def test_a_pyplot_figure_is_closed_by_save_figure(tmp_path):
    plt = pytest.importorskip("matplotlib.pyplot")
    fig, ax = plt.subplots()
    plot_field(TORUS.vertices, TORUS.faces, TORUS.mean, ax=ax, pixels=40)
    assert plt.fignum_exists(fig.number)
    save_figure(fig, tmp_path / "ax.png")
    assert not plt.fignum_exists(fig.number)


# ----------------------------------------------------------------------------------------------------
# meshcurv.plotting: the z-buffer rasteriser against exact answers, the figure, and the errors.


pytest.importorskip("matplotlib")


def square(z, half):
    vertices = np.array([[-half, -half, z], [half, -half, z], [half, half, z], [-half, half, z]], dtype=float)
    return vertices, np.array([[0, 1, 2], [0, 2, 3]])


def test_the_nearer_surface_hides_the_farther_one():
    far_vertices, far_faces = square(0.0, 2.0)
    near_vertices, near_faces = square(1.0, 1.0)
    vertices = np.vstack([near_vertices, far_vertices])  # drawn first, and still in front
    faces = np.vstack([near_faces, far_faces + 4])
    raster = _Raster(vertices, faces, _camera(*VIEWS["top"]), pixels=101)
    middle = raster.face[raster.height // 2, raster.width // 2]
    corner = raster.face[3, 3]
    assert middle in (0, 1) and corner in (2, 3)
    from_below = _Raster(vertices, faces, _camera(*VIEWS["bottom"]), pixels=101)
    assert from_below.face[from_below.height // 2, from_below.width // 2] in (2, 3)


def test_interpolated_values_are_exact_for_a_linear_field():
    vertices, faces = square(0.0, 1.0)
    raster = _Raster(vertices, faces, _camera(*VIEWS["top"]), pixels=64)
    field = raster.interpolate(faces, vertices[:, 0])  # the x coordinate
    covered = raster.face >= 0
    assert covered.mean() > 0.9  # the square fills the image but for the margin
    # top view with z up: screen right is +x; pixel centres sit at (column + 0.5) / scale + offset
    centres = (np.arange(raster.width) + 0.5) / raster.scale + raster.offset[0]
    expected = np.broadcast_to(centres, field.shape)
    np.testing.assert_allclose(field[covered], expected[covered], atol=1e-12)
    assert np.isnan(field[~covered]).all()


def test_a_sphere_covers_a_disc_of_its_radius():
    sphere = meshcurv.shapes.icosphere(subdivisions=8, radius=2.0)
    raster = _Raster(sphere.vertices, sphere.faces, _camera(*VIEWS["iso"]), pixels=200)
    covered_area = (raster.face >= 0).sum() / raster.scale**2
    assert covered_area == pytest.approx(np.pi * 4.0, rel=0.02)  # inscribed polyhedron: slightly less


def test_camera_is_a_rotation_and_front_looks_from_minus_y():
    for elevation, azimuth in VIEWS.values():
        camera = _camera(elevation, azimuth)
        np.testing.assert_allclose(camera @ camera.T, np.eye(3), atol=1e-12)
        assert np.linalg.det(camera) == pytest.approx(1.0)
    np.testing.assert_allclose(_camera(*VIEWS["front"])[2], [0, -1, 0], atol=1e-12)


def test_plot_field_several_views_colour_bar_and_legend():
    torus = meshcurv.shapes.torus(n_major=24, n_minor=12)
    fig = plot_field(
        torus.vertices,
        torus.faces,
        torus.gaussian,
        view=["iso", "top", (10, 20)],
        label="K",
        directions={"k_max": torus.dir_max, "k_min": torus.dir_min},
        pixels=120,
        title="t",
    )
    assert len(fig.axes) == 4  # three views and the colour bar
    bar = fig.axes[-1]
    low, high = bar.get_ylim()
    assert low == pytest.approx(-high)  # signed: centred on zero
    assert "percentiles 2-98, centred on 0" in bar.get_ylabel()
    assert [text.get_text() for text in fig.legends[0].get_texts()] == ["k_max direction", "k_min direction"]
    assert [ax.get_title() for ax in fig.axes[:2]] == ["iso", "top"]
    strokes = fig.axes[0].collections
    assert len(strokes) == 2 and len(strokes[0].get_segments()) > 50


def test_plot_field_unsigned_into_given_axes_and_quads():
    import matplotlib.pyplot as plt

    torus = meshcurv.shapes.torus(n_major=12, n_minor=8)
    fig, ax = plt.subplots()
    with pytest.warns(meshcurv.TriangulationWarning):
        out = plot_field(
            torus.vertices,
            torus.quads,
            np.abs(torus.gaussian) + 1,
            ax=ax,
            view="front",
            directions=torus.dir_max,
            pixels=60,
            percentiles=(0, 100),
        )
    assert out is fig
    assert "centred" not in fig.axes[-1].get_ylabel()
    assert fig.axes[-1].get_ylim()[0] > 0
    plt.close(fig)


def test_save_figure_is_atomic_and_refuses_to_overwrite(tmp_path):
    torus = meshcurv.shapes.torus(n_major=12, n_minor=8)
    path = save_figure(plot_field(torus.vertices, torus.faces, torus.mean, pixels=40), tmp_path / "t.png")
    assert path.read_bytes()[:4] == b"\x89PNG" and [p.name for p in tmp_path.iterdir()] == ["t.png"]
    with pytest.raises(MeshFileError, match=r"t\.png: already exists"):
        save_figure(plot_field(torus.vertices, torus.faces, torus.mean, pixels=40), path)


@pytest.mark.parametrize(
    ("options", "message"),
    [
        ({"values": np.zeros(5)}, r"`values` must have shape \(96,\), one per vertex; got \(5,\)"),
        ({"directions": np.zeros((5, 3))}, r"`directions` arrays must have shape \(96, 3\); got \(5, 3\)"),
        (
            {"directions": {"a": np.zeros((96, 3)), "b": np.zeros((96, 3)), "c": np.zeros((96, 3))}},
            "`directions` takes at most two fields; got 3",
        ),
        ({"view": "sideways"}, "unknown view 'sideways'; choose one of iso, front"),
        ({"view": [(1, 2, 3)]}, r"a view is a name or \(elevation, azimuth\) in degrees"),
        ({"view": []}, "`view` is empty"),
        ({"view": ["iso", "top"], "ax": "given"}, "`ax` takes one view; got 2"),
        ({"pixels": 8}, "`pixels` must be an integer between 16 and 8192; got 8"),
        ({"pixels": 100_000}, "`pixels` must be an integer between 16 and 8192"),
        ({"up": "w"}, "`up` must be one of 'z', 'y', 'x'; got 'w'"),
    ],
)
def test_plot_field_errors(options, message):
    import matplotlib.pyplot as plt

    torus = meshcurv.shapes.torus(n_major=12, n_minor=8)
    options = dict(options)
    values = options.pop("values", torus.mean)
    if options.get("ax") == "given":
        options["ax"] = plt.subplots()[1]
    with pytest.raises(InvalidOptionError, match=message):
        plot_field(torus.vertices, torus.faces, values, pixels=options.pop("pixels", 40), **options)
    plt.close("all")


# --- point clouds: discs of each point's spacing, the nearest point per pixel ------------------------


def grid_points(z, half, n):
    u = np.linspace(-half, half, n)
    x, y = np.meshgrid(u, u)
    return np.column_stack([x.ravel(), y.ravel(), np.full(x.size, z)])


def test_the_nearer_points_hide_the_farther_ones():
    near, far = grid_points(1.0, 1.0, 41), grid_points(0.0, 2.0, 81)  # equal spacing 0.05
    points = np.vstack([far, near])  # the far ones first: order must not matter
    spacing = _point_spacing(points)
    raster = _Raster.of_points(points, _camera(*VIEWS["top"]), pixels=201, spacing=spacing)
    middle = raster.face[raster.height // 2, raster.width // 2]
    assert middle >= len(far)  # a point of the near square
    assert 0 <= raster.face[5, 5] < len(far)  # the corner: only the far square is there
    from_below = _Raster.of_points(points, _camera(*VIEWS["bottom"]), pixels=201, spacing=spacing)
    assert 0 <= from_below.face[from_below.height // 2, from_below.width // 2] < len(far)


def test_a_sampled_sphere_covers_a_disc_of_its_radius_without_holes():
    rng = np.random.default_rng(5)
    points = rng.normal(size=(20000, 3))
    points *= 2.0 / np.linalg.norm(points, axis=1, keepdims=True)  # random: clusters and holes
    raster = _Raster.of_points(points, _camera(*VIEWS["iso"]), pixels=200, spacing=_point_spacing(points))
    covered = raster.face >= 0
    # the discs reach past the outline by about one spacing: a disc of radius 2 + spacing at most
    spacing = np.sqrt(4 * np.pi * 4.0 / len(points))
    area = covered.sum() / raster.scale**2
    assert np.pi * 2.0**2 * 0.99 < area < np.pi * (2.0 + 2 * spacing) ** 2
    # no hole inside the outline: every pixel within 0.9 R of the centre is covered
    rows, columns = np.indices(covered.shape)
    x = (columns + 0.5) / raster.scale + raster.offset[0]
    y = (rows + 0.5) / raster.scale + raster.offset[1]
    assert covered[np.hypot(x, y) < 1.8].all()


def test_plot_field_of_a_point_cloud_is_shaded_by_the_given_normals():
    rng = np.random.default_rng(6)
    points = rng.normal(size=(3000, 3))
    points /= np.linalg.norm(points, axis=1, keepdims=True)
    fig = plot_field(points, None, points[:, 2], normals=points, view=["iso", "top"], label="z")
    assert len(fig.axes) == 3
    with pytest.raises(InvalidOptionError, match="normals"):
        plot_field(points, None, points[:, 2], normals=points[:10])


# --- what principal_curvatures takes: mesh objects, a MeshTopology, objects of points ------------------


def image_of(*mesh, values, **options):
    """The RGBA image of one view of ``plot_field(*mesh, values)``."""
    fig = plot_field(*mesh, values, view="iso", pixels=80, **options)
    return fig.axes[0].images[0].get_array()


def torus_object(library: str):
    """The small torus as a mesh object of ``library`` (the test skipped when it is not installed)."""
    module = pytest.importorskip(library.split()[0])
    if library == "trimesh":
        return module.Trimesh(TORUS.vertices, TORUS.faces, process=False)
    if library == "meshio":
        return module.Mesh(TORUS.vertices, [("triangle", TORUS.faces)])
    polydata = module.PolyData.from_regular_faces(TORUS.vertices, TORUS.faces)
    return polydata.cast_to_unstructured_grid() if library == "pyvista grid" else polydata


@pytest.mark.parametrize("library", ["trimesh", "pyvista", "pyvista grid", "meshio"])
def test_plot_field_of_a_mesh_object_is_the_picture_of_its_arrays(library):
    mesh = torus_object(library)
    expected = image_of(TORUS.vertices, TORUS.faces, values=TORUS.mean)
    np.testing.assert_array_equal(image_of(mesh, None, values=TORUS.mean), expected)
    # principal_curvatures takes the same object alone and gives one row per vertex, as drawn
    assert meshcurv.principal_curvatures(mesh).n_vertices == len(TORUS.vertices)


def test_plot_field_takes_a_topology_and_empty_faces_as_points():
    topology = meshcurv.MeshTopology.from_faces(TORUS.faces)
    expected = image_of(TORUS.vertices, TORUS.faces, values=TORUS.mean)
    np.testing.assert_array_equal(image_of(TORUS.vertices, topology, values=TORUS.mean), expected)
    points = image_of(TORUS.vertices, None, values=TORUS.mean)
    np.testing.assert_array_equal(image_of(TORUS.vertices, np.zeros((0, 3), dtype=int), values=TORUS.mean), points)


def test_plot_field_of_a_pyvista_point_cloud_is_the_picture_of_its_points():
    pyvista = pytest.importorskip("pyvista")
    expected = image_of(TORUS.vertices, None, values=TORUS.mean)
    for cloud in (pyvista.PolyData(TORUS.vertices), pyvista.PointSet(TORUS.vertices)):
        np.testing.assert_array_equal(image_of(cloud, None, values=TORUS.mean), expected)


@pytest.mark.parametrize(
    "vertices",
    [object(), "torus.obj", np.zeros((4, 2))],
    ids=["object", "string", "array of 2 columns"],
)
def test_plot_field_refuses_what_principal_curvatures_refuses(vertices):
    faces = None if not isinstance(vertices, np.ndarray) else [[0, 1, 2]]
    with pytest.raises(InvalidMeshError) as call:
        meshcurv.principal_curvatures(vertices, faces)
    with pytest.raises(InvalidMeshError) as drawn:
        plot_field(vertices, faces, np.zeros(4))
    assert str(drawn.value) == str(call.value)


def test_plot_field_refuses_a_volume_mesh_as_principal_curvatures_does():
    pyvista = pytest.importorskip("pyvista")
    grid = pyvista.UnstructuredGrid({pyvista.CellType.TETRA: np.array([[0, 1, 2, 3]])}, np.eye(4)[:, :3])
    with pytest.raises(InvalidMeshError, match="cells that are not surface polygons") as call:
        meshcurv.principal_curvatures(grid)
    with pytest.raises(InvalidMeshError) as drawn:
        plot_field(grid, None, np.zeros(4))
    assert str(drawn.value) == str(call.value)
