"""meshcurv._masks: probability maps to labels (threshold), float label images, smoothed masks; and their
options in :func:`meshcurv.volume.label_curvatures` and ``meshcurv volume``.

Oracles: images built so that their components are known (blobs apart, voxels
touching a blob only at an edge or a corner), and balls voxelised analytically
(a voxel is inside when its centre is) whose area 4 pi R^2 and volume
4/3 pi R^3 are known. Blurring shrinks a ball by about sigma^2 / R (see
meshcurv._masks), 0.5% of R for the radii and sigmas here, so area and volume
move by about 1% and 1.5%; with the staircase's half-voxel rounding, 3% is
the tolerance (issue 34's target).
"""

import numpy as np
import pytest

from meshcurv import _masks
from meshcurv.errors import InvalidMeshError, InvalidOptionError, MeshcurvWarning

skimage_measure = pytest.importorskip("skimage.measure")


def ball(shape, spacing, center, radius):
    grid = np.meshgrid(*[np.arange(n) * s - c for n, s, c in zip(shape, spacing, center)], indexing="ij", sparse=True)
    return sum(axis**2 for axis in grid) <= radius**2


def mesh_area_volume(vertices, faces):
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
    volume = np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0
    return area, volume


def test_threshold_splits_six_connected_components():
    image = np.zeros((12, 12, 12), dtype=np.float32)
    image[1:4, 1:4, 1:4] = 0.9
    image[6:10, 6:10, 6:10] = 0.7
    image[4, 4, 4] = 0.8  # touches the first blob only at a corner: an object of its own
    image[5, 1, 1] = 0.4  # below the threshold
    labels = _masks.labels_from_image(image, 0.5, caller="test", stacklevel=1)
    assert labels.dtype == np.int32 and labels.shape == image.shape
    assert sorted(np.unique(labels).tolist()) == [0, 1, 2, 3]
    assert len(np.unique(labels[1:4, 1:4, 1:4])) == 1 and labels[4, 4, 4] not in (0, labels[1, 1, 1])
    assert labels[5, 1, 1] == 0
    # an integer probability map (0-255) with a threshold is thresholded too
    assert np.array_equal(
        _masks.labels_from_image((image * 255).astype(np.uint8), 127, caller="test", stacklevel=1) > 0, labels > 0
    )


def test_nan_voxels_are_background_with_one_warning():
    image = np.zeros((5, 5, 5))
    image[1:3, 1:3, 1:3] = 1.0
    image[4, 4, :] = np.nan
    with pytest.warns(MeshcurvWarning, match="test: 5 voxels of the image are NaN; they are taken as background"):
        labels = _masks.labels_from_image(image, 0.5, caller="test", stacklevel=1)
    assert labels.max() == 1 and labels[4, 4, 0] == 0


def test_float_images_need_a_threshold():
    image = np.zeros((4, 4, 4), dtype=np.float32)
    image[1:3, 1:3, 1:3] = 3.0
    with pytest.raises(
        InvalidMeshError,
        match=r"an integer label image or a boolean mask; got dtype float32: for a "
        r"probability map pass threshold=T \(--threshold T\).*cast them",
    ):
        _masks.labels_from_image(image, None, caller="test", stacklevel=1)
    integers = np.ones((2, 2, 2), dtype=np.int16)
    assert _masks.labels_from_image(integers, None, caller="test", stacklevel=1) is integers
    with pytest.raises(InvalidMeshError, match="with `threshold` must be an image of real numbers"):
        _masks.labels_from_image(np.ones((2, 2, 2), dtype=complex), 0.5, caller="test", stacklevel=1)


@pytest.mark.parametrize(
    "value, message",
    [
        ("1", "`threshold` must be a finite number"),
        (np.nan, "`threshold` must be a finite number"),
        (True, "`threshold` must be a finite number"),
    ],
)
def test_threshold_option_errors(value, message):
    with pytest.raises(InvalidOptionError, match=message):
        _masks.check_threshold(value)


@pytest.mark.parametrize("value", [0.0, -1.0, np.inf, "a"])
def test_smooth_option_errors(value):
    with pytest.raises(InvalidOptionError, match="smooth"):
        _masks.check_smooth(value)


def test_smooth_padding_is_three_sigma_and_a_voxel_per_axis():
    assert _masks.smooth_padding(np.array([1.0, 0.5, 0.25]), 0.5).tolist() == [3, 4, 7]


def test_smoothed_ball_keeps_area_and_volume_with_anisotropic_voxels():
    spacing = np.array([1.0, 0.5, 0.5])
    radius, sigma = 8.0, 0.5
    shape = (22, 40, 40)
    image = ball(shape, spacing, (10.3, 9.8, 10.1), radius).astype(np.uint8)
    box = (slice(2, 20), slice(3, 37), slice(3, 37))  # holds the ball
    assert image[box].sum() == image.sum()
    mask, origin, starts, stops = _masks.smoothed_crop(image, 1, box, spacing, sigma)
    assert origin.tolist() == [0, 0, 0] and mask.shape == (22, 40, 40)  # 3 and 4 voxels added, clipped
    index, faces, n_voxels, centroid, touching = _masks.smoothed_surface(
        mask, origin, starts, stops, shape, spacing, sigma, skimage_measure.marching_cubes
    )
    assert n_voxels == image.sum() and not touching.any()
    assert centroid == pytest.approx([10.3, 9.8, 10.1], abs=0.05)
    area, volume = mesh_area_volume(index * spacing, faces)
    assert area == pytest.approx(4 * np.pi * radius**2, rel=0.03)
    assert volume == pytest.approx(4 / 3 * np.pi * radius**3, rel=0.03)  # outward faces: positive


def test_smoothed_ball_cut_by_the_border_is_closed_by_a_flat_cap():
    spacing = np.array([1.0, 1.0, 1.0])
    shape, radius, sigma = (12, 24, 24), 8.0, 0.5
    image = ball(shape, spacing, (0.0, 12.0, 12.0), radius).astype(np.uint8)  # half a ball on the face z = 0
    box = tuple(slice(int(a.min()), int(a.max()) + 1) for a in np.nonzero(image))
    mask, origin, starts, stops = _masks.smoothed_crop(image, 1, box, spacing, sigma)
    index, faces, _, _, touching = _masks.smoothed_surface(
        mask, origin, starts, stops, shape, spacing, sigma, skimage_measure.marching_cubes
    )
    assert touching.tolist() == [[True, False], [False, False], [False, False]]
    # the cap lies on the image's outer voxel face, as that of an unsmoothed mask (meshcurv.volume leaves it out)
    assert index[:, 0].min() == -0.5 and not ((index[:, 0] > -0.5) & (index[:, 0] < 0.0)).any()
    cap = (index[faces, 0] == -0.5).all(axis=1)
    a, b, c = (index[faces[cap, k]] for k in range(3))
    cap_area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
    area, volume = mesh_area_volume(index, faces)
    # inside the image: the hemisphere and the side of the half voxel between z = 0 and the cap at z = -0.5
    assert area - cap_area == pytest.approx(2 * np.pi * radius**2 + np.pi * radius, rel=0.05)
    assert volume == pytest.approx(2 / 3 * np.pi * radius**3 + 0.5 * np.pi * radius**2, rel=0.05)


# ---- through label_curvatures --------------------------------------------------------------------------------------

pandas = pytest.importorskip("pandas")


def test_label_curvatures_of_a_probability_map():
    from meshcurv.volume import label_curvatures

    spacing = (1.0, 0.5, 0.5)
    shape, width = (20, 36, 60), 7.0
    grid = np.meshgrid(*[np.arange(n) * s for n, s in zip(shape, spacing)], indexing="ij", sparse=True)
    centres = [(9.6, 8.7, 7.9), (10.2, 9.1, 21.3)]
    # two Gaussian blobs: p > 0.5 where r < width sqrt(ln 2), two balls of that radius
    probability = np.maximum(
        *[np.exp(-sum((axis - c) ** 2 for axis, c in zip(grid, centre)) / width**2) for centre in centres]
    ).astype(np.float32)
    radius = width * np.sqrt(np.log(2.0))
    table = label_curvatures(probability, spacing=spacing, threshold=0.5)
    assert table.label.tolist() == [1, 2] and (table.status == "ok").all()
    assert table.area.to_numpy() == pytest.approx(4 * np.pi * radius**2, rel=0.03)
    assert table.volume.to_numpy() == pytest.approx(4 / 3 * np.pi * radius**3, rel=0.03)
    assert table.centroid_2.to_numpy() == pytest.approx([7.9, 21.3], abs=0.1)
    with pytest.raises(InvalidMeshError, match="got dtype float32: for a probability map pass threshold=T"):
        label_curvatures(probability, spacing=spacing)
    with pytest.raises(InvalidOptionError, match="`threshold` must be a finite number"):
        label_curvatures(probability, spacing=spacing, threshold=float("nan"))


def test_label_curvatures_of_smoothed_masks_with_anisotropic_voxels():
    from meshcurv.volume import label_curvatures

    spacing = np.array([1.0, 0.5, 0.5])
    radius, sigma = 8.0, 0.5
    image = ball((22, 40, 40), spacing, (10.3, 9.8, 10.1), radius).astype(np.uint8)
    table = label_curvatures(image, spacing=spacing, smooth=sigma)
    row = table.iloc[0]
    assert row.status == "ok" and not row.touches_border
    assert row.area == pytest.approx(4 * np.pi * radius**2, rel=0.03)
    assert row.volume == pytest.approx(4 / 3 * np.pi * radius**3, rel=0.03)
    assert row.mean_weighted == pytest.approx(1 / radius, rel=0.03)
    assert row.total_gaussian == pytest.approx(4 * np.pi, rel=0.02)  # Gauss-Bonnet on the closed surface
    assert row.n_voxels == image.sum()
    with pytest.raises(InvalidOptionError, match="smooth"):
        label_curvatures(image, spacing=spacing, smooth=-1.0)


def test_smoothed_label_cut_by_the_border_leaves_its_cap_out():
    from meshcurv.volume import label_curvatures

    spacing = np.array([1.0, 0.5, 0.5])
    radius = 8.0
    image = ball((12, 40, 40), spacing, (0.0, 9.8, 10.1), radius).astype(np.uint8)  # half a ball on z = 0
    row = label_curvatures(image, spacing=spacing, smooth=0.5).iloc[0]
    assert row.status == "ok" and row.touches_border
    # the hemisphere and the side of the half voxel (0.5) down to the cap
    assert row.area == pytest.approx(2 * np.pi * radius**2 + 2 * np.pi * radius * 0.5, rel=0.03)
    # as unsmoothed: a hemisphere of a few ball radii keeps no surface beyond the estimator's reach of the cap
    assert np.isnan(row.mean_weighted) and "curvature columns NaN: the label is cut by the image border" in row.warnings


def test_cli_threshold_and_smooth(tmp_path):
    click_testing = pytest.importorskip("click.testing")
    from meshcurv.cli._common import Session
    from meshcurv.cli._volume import volume

    spacing = (1.0, 0.5, 0.5)
    shape, width = (20, 36, 36), 9.0
    grid = np.meshgrid(*[np.arange(n) * s for n, s in zip(shape, spacing)], indexing="ij", sparse=True)
    probability = np.exp(-sum((axis - c) ** 2 for axis, c in zip(grid, (9.6, 8.7, 8.9))) / width**2)
    np.save(tmp_path / "p.npy", probability.astype(np.float32))
    radius = width * np.sqrt(np.log(2.0))  # 7.5

    def run(*args):
        session = Session()
        with session:
            return click_testing.CliRunner().invoke(
                volume,
                [
                    str(tmp_path / "p.npy"),
                    "-o",
                    str(tmp_path / "out"),
                    "--spacing",
                    *map(str, spacing),
                    "--no-picture",
                    "--overwrite",
                    *args,
                ],
                obj=session,
            )

    result = run("--threshold", "0.5", "--smooth", "0.5")
    assert result.exit_code == 0, result.output
    row = pandas.read_csv(tmp_path / "out" / "p_labels.csv").iloc[0]
    assert row.area == pytest.approx(4 * np.pi * radius**2, rel=0.03)
    assert row.volume == pytest.approx(4 / 3 * np.pi * radius**3, rel=0.03)
    refused = run()
    assert isinstance(refused.exception, InvalidMeshError)
    assert "pass threshold=T (--threshold T)" in str(refused.exception)
    assert run("--threshold", "0.5", "--smooth", "0").exit_code == 2  # click refuses sigma 0
