"""Pictures: resolution and size that change the output, colour maps, fixed limits, labels that fit,
the up axis chosen from the mesh, and the user's matplotlib backend left alone."""

import subprocess
import sys
import textwrap

import numpy as np
import pytest

import meshcurv
from meshcurv.errors import InvalidOptionError
from meshcurv.plotting import choose_up, plot_field, save_figure

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
    ],
)
def test_errors(options, message):
    with pytest.raises(InvalidOptionError, match=message):
        plot_field(TORUS.vertices, TORUS.faces, TORUS.mean, pixels=40, **options)


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
