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
    grid = np.meshgrid(*[np.arange(n) * s - c for n, s, c in zip(shape, spacing, center)], indexing="ij",
                       sparse=True)
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
    assert np.array_equal(_masks.labels_from_image((image * 255).astype(np.uint8), 127, caller="test",
                                                   stacklevel=1) > 0, labels > 0)


def test_nan_voxels_are_background_with_one_warning():
    image = np.zeros((5, 5, 5))
    image[1:3, 1:3, 1:3] = 1.0
    image[4, 4, :] = np.nan
    with pytest.warns(MeshcurvWarning, match="test: 5 voxels of the image are NaN; they are taken as background"):
        labels = _masks.labels_from_image(image, 0.5, caller="test", stacklevel=1)
    assert labels.max() == 1 and labels[4, 4, 0] == 0


def test_float_images_without_threshold():
    image = np.zeros((4, 4, 4), dtype=np.float32)
    image[1:3, 1:3, 1:3] = 300.0
    with pytest.warns(MeshcurvWarning, match=r"stored as float32; its values are whole numbers \(0 to 300\), read as "
                                             r"labels \(uint16\)"):
        labels = _masks.labels_from_image(image, None, caller="test", stacklevel=1)
    assert labels.dtype == np.uint16 and labels.max() == 300
    integers = np.ones((2, 2, 2), dtype=np.int16)
    assert _masks.labels_from_image(integers, None, caller="test", stacklevel=1) is integers
    for values, what in ((0.5, "fractional values"), (-1.0, "negative values"), (np.inf, "non-finite values"),
                         (2.0**60, "values beyond 2")):
        bad = image.astype(np.float64)
        bad[0, 0, 0] = values
        with pytest.raises(InvalidMeshError, match=rf"a float image \(float64\) with {what}.*pass threshold=T "
                                                   r"\(--threshold T\)"):
            _masks.labels_from_image(bad, None, caller="test", stacklevel=1)
    with pytest.raises(InvalidMeshError, match="with `threshold` must be an image of real numbers"):
        _masks.labels_from_image(np.ones((2, 2, 2), dtype=complex), 0.5, caller="test", stacklevel=1)


@pytest.mark.parametrize("value, message", [("1", "`threshold` must be a finite number"),
                                            (np.nan, "`threshold` must be a finite number"),
                                            (True, "`threshold` must be a finite number")])
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
        mask, origin, starts, stops, shape, spacing, sigma, skimage_measure.marching_cubes)
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
    index, faces, _, _, touching = _masks.smoothed_surface(mask, origin, starts, stops, shape, spacing, sigma,
                                                           skimage_measure.marching_cubes)
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
