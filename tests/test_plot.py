"""meshcurv.plotting: the z-buffer rasteriser against exact answers, the figure, and the errors."""

import numpy as np
import pytest

import meshcurv
from meshcurv.errors import InvalidOptionError, MeshFileError
from meshcurv.plotting import VIEWS, _camera, _point_spacing, _Raster, plot_field, save_figure

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
