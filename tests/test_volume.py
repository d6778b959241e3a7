"""meshcurv.volume (label images to per-label curvature tables), its image readers and ``meshcurv volume``.

Oracles: closed-form solids voxelised analytically (a voxel is inside when its
centre is), whose area, volume, integral of H and Gauss-Bonnet total (4 pi
per closed genus-0 surface) are known exactly.

Tolerances: the balls here have radii of 8-10 voxels (so that each label takes
well under a second). Binary marching cubes on them overestimates area by
8-19% (the staircase); the corrected area of the fitted normals is within 1%
at these sizes (1.1% at radius 6), the divergence-theorem volume within 1.5%
(the half-voxel rounding of the mask, relative 1.5 h / R), H within 1% and the
total Gaussian curvature within 1.2%. The tests allow 3% (area, H) and 2%
(volume, total K): the targets of issue 17.
"""

import numpy as np
import pytest

pytest.importorskip("skimage")
pandas = pytest.importorskip("pandas")

from meshcurv.errors import (  # noqa: E402
    InvalidMeshError,
    InvalidOptionError,
    MeshcurvWarning,
    MeshFileError,
    MeshQualityWarning,
)
from meshcurv.volume import COLUMNS, label_curvatures, label_surfaces  # noqa: E402

UNIT = (1.0, 1.0, 1.0)  # the voxel size of the tests (a call without spacing warns)

REQUIRED = (
    "label",
    "n_vertices",
    "area",
    "volume",
    "equivalent_radius",
    "mean_weighted",
    "mean_median",
    "mean_p5",
    "mean_p95",
    "gaussian_weighted",
    "k_min_weighted",
    "k_max_weighted",
    "shape_index_weighted",
    "curvedness_weighted",
    "total_mean",
    "total_gaussian",
    "willmore",
    "euler_characteristic",
    "touches_border",
    "n_invalid",
    "status",
    "error",
)


def solid(shape, spacing, center, semi_axes, rotation=None):
    """Boolean image of the solid ellipsoid ``|R^T (p - center) / semi_axes| <= 1``, physical units."""
    axes = np.meshgrid(*[np.arange(n) * s - c for n, s, c in zip(shape, spacing, center)], indexing="ij", sparse=True)
    turn = np.eye(3) if rotation is None else rotation
    body = [sum(turn[k, j] * axes[k] for k in range(3)) for j in range(3)]
    return sum((body[j] / semi_axes[j]) ** 2 for j in range(3)) <= 1


def ellipsoid_integrals(a, b, c, n=600):
    """(area, int H dA) of an ellipsoid by the midpoint rule over its parametrisation (converges fast)."""
    t = (np.arange(n) + 0.5) * np.pi / n
    p = (np.arange(2 * n) + 0.5) * np.pi / n
    t, p = np.meshgrid(t, p, indexing="ij")
    x, y, z = a * np.sin(t) * np.cos(p), b * np.sin(t) * np.sin(p), c * np.cos(t)
    element = (
        np.sin(t)
        * np.sqrt(
            (b * c * np.sin(t) * np.cos(p)) ** 2 + (a * c * np.sin(t) * np.sin(p)) ** 2 + (a * b * np.cos(t)) ** 2
        )
        * (np.pi / n) ** 2
    )
    g2 = (x / a**2) ** 2 + (y / b**2) ** 2 + (z / c**2) ** 2
    mean = (a * a + b * b + c * c - x * x - y * y - z * z) / (2 * (a * b * c) ** 2 * g2**1.5)
    return element.sum(), (mean * element).sum()


def test_ellipsoid_integrals_are_exact_on_a_sphere():
    area, integral = ellipsoid_integrals(5.0, 5.0, 5.0)
    assert area == pytest.approx(4 * np.pi * 25, rel=1e-5)
    assert integral == pytest.approx(4 * np.pi * 5, rel=1e-5)


def relative(value, truth):
    return abs(value / truth - 1)


def test_sphere_area_volume_curvature_and_gauss_bonnet():
    radius = 9.0
    image = solid((24, 24, 24), (1, 1, 1), (11.7, 12.2, 11.4), (radius,) * 3).astype(np.uint8)
    table, surfaces = label_curvatures(image, spacing=UNIT, return_meshes=True)
    assert set(REQUIRED) <= set(table.columns) and list(table.columns) == list(COLUMNS)
    row = table.iloc[0]
    assert row.status == "ok" and row.label == 1 and not row.touches_border and row.n_invalid == 0
    assert row.surface == "voxel"  # the default radius recognised the voxel grid
    assert relative(row.area, 4 * np.pi * radius**2) < 0.03
    assert relative(row.area_mesh, 4 * np.pi * radius**2) > 0.05  # the staircase bias the corrected area removes
    assert relative(row.volume, 4 / 3 * np.pi * radius**3) < 0.02
    assert relative(row.equivalent_radius, radius) < 0.01
    assert relative(row.mean_weighted, 1 / radius) < 0.03  # positive: outward
    assert relative(row.gaussian_weighted, 1 / radius**2) < 0.06
    assert relative(row.total_gaussian, 4 * np.pi) < 0.02
    assert relative(row.total_mean, 4 * np.pi * radius) < 0.03
    assert relative(row.willmore, 4 * np.pi) < 0.06
    assert row.euler_characteristic == 2
    assert row.mean_p5 <= row.mean_median <= row.mean_p95
    assert row.shape_index_fraction_cap > 0.9 and row.n_voxels == image.sum()
    surface = surfaces[1]
    x0, x1, x2 = (surface.vertices[surface.faces[:, k]] for k in range(3))
    assert np.einsum("ij,ij->i", x0, np.cross(x1, x2)).sum() > 0  # faces wound outward
    assert surface.vertex_areas.sum() == pytest.approx(row.area, rel=1e-9)


def test_rotated_ellipsoid_with_anisotropic_voxels():
    semi_axes = np.array([10.0, 7.0, 6.0])
    spacing = (1.0, 0.5, 0.5)
    rotation = np.array([[0.8, 0.6, 0.0], [-0.6, 0.8, 0.0], [0.0, 0.0, 1.0]]) @ np.array(
        [[1.0, 0.0, 0.0], [0.0, 0.6, -0.8], [0.0, 0.8, 0.6]]
    )
    image = solid((26, 52, 52), spacing, (12.6, 12.9, 13.1), semi_axes, rotation)
    row = label_curvatures(image, spacing=spacing).iloc[0]
    area, integral = ellipsoid_integrals(*semi_axes)
    assert row.status == "ok" and row.surface == "voxel"
    assert relative(row.area, area) < 0.03
    assert relative(row.volume, 4 / 3 * np.pi * semi_axes.prod()) < 0.02
    assert relative(row.mean_weighted, integral / area) < 0.03
    assert relative(row.total_gaussian, 4 * np.pi) < 0.02


def test_anisotropic_spacing_gives_the_physical_answers_of_isotropic():
    center, radius = np.array([11.3, 11.8, 12.2]), 9.0
    iso = label_curvatures(solid((24, 24, 24), (1, 1, 1), center, (radius,) * 3), spacing=UNIT).iloc[0]
    aniso = label_curvatures(solid((24, 48, 48), (1, 0.5, 0.5), center, (radius,) * 3), spacing=(1, 0.5, 0.5)).iloc[0]
    for column in ("area", "volume", "mean_weighted", "total_gaussian"):
        assert relative(aniso[column], iso[column]) < 0.03, column
    assert relative(aniso.centroid_1, iso.centroid_1) < 0.01  # physical coordinates, not voxel indices
    assert aniso.n_vertices > 2 * iso.n_vertices


def test_hollow_ball_wall_faces_into_the_cavity():
    outer, inner = 10.0, 6.0
    center = (12.4, 12.1, 11.8)
    shell = solid((25, 25, 25), (1, 1, 1), center, (outer,) * 3) & ~solid((25, 25, 25), (1, 1, 1), center, (inner,) * 3)
    row = label_curvatures(shell, spacing=UNIT).iloc[0]
    assert row.euler_characteristic == 4  # two closed surfaces
    assert relative(row.volume, 4 / 3 * np.pi * (outer**3 - inner**3)) < 0.02
    assert relative(row.total_gaussian, 8 * np.pi) < 0.03
    # int H dA: +4 pi R on the outside, -4 pi r on the cavity's wall (it bends towards its normal)
    assert relative(row.total_mean, 4 * np.pi * (outer - inner)) < 0.06


def test_two_labels_touching_each_other():
    ball = solid((24, 24, 24), (1, 1, 1), (11.6, 11.9, 12.3), (9.0,) * 3)
    image = np.zeros(ball.shape, dtype=np.int32)
    image[ball] = 7
    image[ball & (np.arange(24)[None, None, :] >= 12)] = 3  # the right half: another label, touching
    table = label_curvatures(image, spacing=UNIT)
    assert list(table.label) == [3, 7]
    assert (table.status == "ok").all() and not table.touches_border.any()
    assert list(table.n_voxels) == [(image == 3).sum(), (image == 7).sum()]
    assert relative(table.volume.sum(), 4 / 3 * np.pi * 9.0**3) < 0.02
    assert (table.euler_characteristic == 2).all()
    assert (table.mean_weighted > 0).all()


def test_label_cut_by_the_border_is_flagged_and_its_cap_left_out():
    radius = 12.0
    image = solid((20, 30, 30), (1, 1, 1), (4.0, 14.2, 13.9), (radius,) * 3)  # cut by the plane z = -0.5
    table, surfaces = label_curvatures(image, spacing=UNIT, return_meshes=True)
    row, surface = table.iloc[0], surfaces[1]
    assert row.touches_border and row.status == "ok"
    assert 0 < row.n_used < row.n_vertices
    low = -0.5  # the image's outer face along axis 0
    # no vertex within the reach of the normal fits (3 radii) of the cap in the statistics
    assert surface.vertices[surface.used, 0].min() - low >= 3 * row.radius
    assert relative(row.mean_weighted, 1 / radius) < 0.03  # the cap (H = 0) would pull it down
    # the area of the part inside (a zone of height R + 4.5): more in tests/test_volume_border.py
    assert relative(row.area, 2 * np.pi * radius * (radius + 4.5)) < 0.03


def test_empty_and_tiny_labels_get_a_row_with_the_reason():
    image = solid((24, 24, 24), (1, 1, 1), (11.6, 11.9, 12.3), (8.0,) * 3).astype(np.uint16)
    image[1, 1, 1] = 2  # one voxel
    with pytest.warns(MeshQualityWarning, match="2 of 3 labels have no curvature"):
        table = label_curvatures(image, spacing=UNIT, labels_to_use=[1, 2, 5])
    status = dict(zip(table.label, table.status))
    assert status == {1: "ok", 2: "too_small", 5: "empty"}
    errors = dict(zip(table.label, table.error))
    assert "has no voxel" in errors[5] and "too small" in errors[2] and errors[1] == ""
    assert np.isnan(table.set_index("label").loc[5, "area"])


def test_one_failing_label_does_not_sink_the_others(monkeypatch):
    import meshcurv.volume as volume

    image = np.zeros((30, 30, 30), dtype=np.uint8)
    image[solid(image.shape, (1, 1, 1), (8.2, 8.1, 8.4), (6.0,) * 3)] = 1
    image[solid(image.shape, (1, 1, 1), (21.3, 20.8, 21.1), (6.0,) * 3)] = 2
    original = volume.principal_curvatures

    def failing(vertices, faces, **options):
        if vertices[:, 0].mean() > 15:
            raise ValueError("a fault in the estimator")
        return original(vertices, faces, **options)

    monkeypatch.setattr(volume, "principal_curvatures", failing)
    with pytest.warns(MeshQualityWarning, match="1 failed"):
        table = label_curvatures(image, spacing=UNIT)
    assert list(table.status) == ["ok", "failed"]
    assert table.error[1] == "ValueError: a fault in the estimator"


def test_huge_label_values_keep_their_identity():
    ball = solid((16, 16, 16), (1, 1, 1), (7.6, 7.8, 7.3), (5.0,) * 3)
    image = np.where(ball, np.uint64(2**63 + 5), np.uint64(2**40))  # no background voxel at all
    image[0] = 0
    table = label_curvatures(image, spacing=UNIT, labels_to_use=[2**63 + 5])
    assert table.label.tolist() == [2**63 + 5] and table.status.tolist() == ["ok"]
    assert table.n_voxels[0] == ball.sum()


def test_no_label_gives_an_empty_table_with_one_warning():
    with pytest.warns(MeshcurvWarning, match=r"label_curvatures: the image holds no object: every voxel is 0") as seen:
        table = label_curvatures(np.zeros((8, 8, 8), dtype=np.uint8), spacing=UNIT)
    assert table.empty and list(table.columns) == list(COLUMNS)
    assert len(seen) == 1


def test_a_threshold_above_every_voxel_gives_an_empty_table_with_one_warning():
    probability = np.full((8, 8, 8), 0.3)
    probability[2:6, 2:6, 2:6] = 0.45
    with pytest.warns(MeshcurvWarning, match=r"no voxel is greater than threshold=0\.5; the table has no row") as seen:
        table = label_curvatures(probability, spacing=UNIT, threshold=0.5)
    assert table.empty and len(seen) == 1
    with pytest.warns(MeshcurvWarning, match=r"label_surfaces: the image holds no object"):
        total, rows = label_surfaces(probability, spacing=UNIT, threshold=0.5)
    assert total == 0 and list(rows) == []


def test_no_label_asked_for_is_an_empty_table_without_a_warning():
    image = np.zeros((8, 8, 8), dtype=np.uint8)
    image[2:6, 2:6, 2:6] = 1
    table = label_curvatures(image, spacing=UNIT, labels_to_use=[])  # the warnings are errors here
    assert table.empty


def test_boolean_mask_and_progress():
    mask = solid((20, 20, 20), (1, 1, 1), (9.6, 9.9, 10.2), (7.0,) * 3)
    calls = []
    table = label_curvatures(mask, spacing=UNIT, progress=lambda done, total, label: calls.append((done, total, label)))
    assert list(table.label) == [1] and calls == [(1, 1, 1)]


@pytest.mark.parametrize(
    "labels, message",
    [
        (np.zeros((5, 5, 5)), "integer label image or a boolean mask; got dtype float64"),
        (np.zeros((5, 5), dtype=int), "3D image .* got 2 dimensions"),
        (np.zeros((0, 5, 5), dtype=int), "empty"),
        (-np.ones((5, 5, 5), dtype=int), ">= 0"),
    ],
)
def test_image_errors(labels, message):
    with pytest.raises(InvalidMeshError, match=message):
        label_curvatures(labels)


@pytest.mark.parametrize(
    "options, message",
    [
        ({"spacing": (1, 0, 1)}, "positive and finite"),
        ({"spacing": (1, -0.5, 1)}, "positive and finite"),
        ({"spacing": (1, 1)}, "3 numbers"),
        ({"labels_to_use": [0]}, ">= 1"),
        ({"labels_to_use": [1.5]}, "integer labels"),
        ({"radius": -1.0}, "radius"),
        ({"method": "nope"}, "method"),
        ({"progress": 3}, "callable"),
    ],
)
def test_option_errors(options, message):
    image = np.zeros((20, 20, 20), dtype=np.uint8)
    image[5:15, 5:15, 5:15] = 1
    with pytest.raises(InvalidOptionError, match=message):
        label_curvatures(image, **{"spacing": UNIT, **options})


# ---- the readers ---------------------------------------------------------------------------------------------------


def small_labels():
    image = np.zeros((6, 7, 8), dtype=np.uint16)
    image[1:4, 2:5, 3:7] = 4
    return image


def test_read_npy_npz(tmp_path):
    from meshcurv.io._images import read_image

    image = small_labels()
    np.save(tmp_path / "a.npy", image)
    np.savez(tmp_path / "b.npz", labels=image, raw=image.astype(float))
    np.savez_compressed(tmp_path / "c.npz", image)
    for name in ("a.npy", "b.npz", "c.npz"):
        read = read_image(tmp_path / name)
        assert read.spacing is None and read.array.dtype == np.uint16 and np.array_equal(read.array, image)


def test_read_tiff_and_nifti_with_spacing(tmp_path):
    tifffile = pytest.importorskip("tifffile")
    nibabel = pytest.importorskip("nibabel")
    from meshcurv.io._images import read_image

    image = small_labels()
    tifffile.imwrite(
        tmp_path / "a.tif", image, imagej=True, resolution=(1 / 0.25, 1 / 0.3), metadata={"spacing": 2.0, "unit": "um"}
    )
    read = read_image(tmp_path / "a.tif")
    assert np.array_equal(read.array, image) and read.spacing == pytest.approx((2.0, 0.3, 0.25))
    # NIfTI holds (i, j, k) = (x, y, z): read back as (z, y, x), pixdim with it
    nifti = nibabel.Nifti1Image(image.transpose(2, 1, 0), np.diag([0.5, 0.75, 2.0, 1.0]))
    nibabel.save(nifti, tmp_path / "a.nii.gz")
    read = read_image(tmp_path / "a.nii.gz")
    assert np.array_equal(read.array, image) and read.spacing == pytest.approx((2.0, 0.75, 0.5))


def test_reader_errors_name_the_file(tmp_path):
    from meshcurv.io._images import read_image

    np.save(tmp_path / "a.npy", small_labels())
    (tmp_path / "cut.npy").write_bytes((tmp_path / "a.npy").read_bytes()[:200])
    with pytest.raises(MeshFileError, match="cut.npy: cannot be read as .npy"):
        read_image(tmp_path / "cut.npy")
    np.savez(tmp_path / "two.npz", first=small_labels(), second=small_labels())
    with pytest.raises(MeshFileError, match="two.npz: an archive of several arrays needs one named 'labels'"):
        read_image(tmp_path / "two.npz")
    np.save(tmp_path / "flat.npy", np.zeros((4, 5), dtype=np.uint8))
    with pytest.raises(MeshFileError, match=r"flat.npy: a 3D image .* shape \(4, 5\)"):
        read_image(tmp_path / "flat.npy")
    np.save(tmp_path / "objects.npy", np.empty((2, 2, 2), dtype=object), allow_pickle=True)
    with pytest.raises(MeshFileError, match="objects.npy: the array holds Python objects"):
        read_image(tmp_path / "objects.npy")
    (tmp_path / "a.png").write_bytes(b"\x89PNG....")
    with pytest.raises(MeshFileError, match="a.png: unknown image extension '.png'"):
        read_image(tmp_path / "a.png")
    (tmp_path / "bad.tif").write_bytes(b"II*\x00" + b"\xff" * 64)
    with pytest.raises(MeshFileError, match="bad.tif"):
        read_image(tmp_path / "bad.tif")
    with pytest.raises(MeshFileError, match="missing.nii: no such file"):
        read_image(tmp_path / "missing.nii")


def test_reader_refuses_huge_declared_sizes(tmp_path, monkeypatch):
    import meshcurv.io._images as images

    np.save(tmp_path / "a.npy", small_labels())
    monkeypatch.setattr(images, "MAX_IMAGE_BYTES", 100)
    with pytest.raises(MeshFileError, match="a.npy: the image declares shape"):
        images.read_image(tmp_path / "a.npy")


# ---- the command ---------------------------------------------------------------------------------------------------


def run_volume(args):
    """``meshcurv volume ARGS`` in-process (click's CliRunner, the group's Session as meshcurv.cli.main makes it)."""
    click_testing = pytest.importorskip("click.testing")
    from meshcurv.cli._common import Session
    from meshcurv.cli._volume import volume

    session = Session()
    with session:
        return click_testing.CliRunner().invoke(volume, [str(arg) for arg in args], obj=session)


@pytest.mark.slow  # matplotlib's import and the picture: several seconds
def test_cli_writes_csv_and_parquet_meshes_and_picture(tmp_path):
    pytest.importorskip("pyarrow")
    pytest.importorskip("matplotlib")
    image = np.zeros((20, 40, 40), dtype=np.uint16)
    image[solid(image.shape, (1, 0.5, 0.5), (9.7, 9.8, 10.1), (6.0,) * 3, None)] = 2
    image[3, 30, 30] = 9  # one voxel
    np.save(tmp_path / "cells.npy", image)
    out = tmp_path / "out"
    result = run_volume([tmp_path / "cells.npy", "-o", out, "--spacing", 1, 0.5, 0.5, "--meshes", "vtp", "--progress"])
    assert result.exit_code == 0, result.output
    assert "2/2 labels, label 9 too_small" in result.output
    csv = pandas.read_csv(out / "cells_labels.csv")
    parquet = pandas.read_parquet(out / "cells_labels.parquet")
    assert list(parquet.label) == [2, 9] and list(csv.status) == ["ok", "too_small"]
    assert parquet.area[0] == pytest.approx(4 * np.pi * 36, rel=0.03)
    assert csv.area[0] == pytest.approx(parquet.area[0], rel=1e-12)
    assert (out / "cells_label_2.vtp").is_file() and not (out / "cells_label_9.vtp").exists()
    assert (out / "cells_mean.png").stat().st_size > 0
    again = run_volume([tmp_path / "cells.npy", "-o", out, "--no-picture"])
    assert isinstance(again.exception, MeshFileError) and "already exists" in str(again.exception)
    (out / "cells_labels.csv").unlink()
    (out / "cells_labels.parquet").unlink()
    again = run_volume([tmp_path / "cells.npy", "-o", out, "--no-picture", "--no-objects", "--meshes", "vtp"])
    assert isinstance(again.exception, MeshFileError) and "cells_label_2.vtp: already exists" in str(again.exception)
    assert not (out / "cells_labels.csv").exists()  # refused before computing
    assert run_volume([tmp_path / "cells.npy", "-o", out, "--overwrite", "--no-picture"]).exit_code == 0


def test_cli_spacing_from_nifti_and_usage_errors(tmp_path):
    pytest.importorskip("pyarrow")
    nibabel = pytest.importorskip("nibabel")
    image = solid((20, 40, 40), (1, 0.5, 0.5), (9.7, 9.8, 10.1), (6.0,) * 3).astype(np.uint8)
    nibabel.save(nibabel.Nifti1Image(image.transpose(2, 1, 0), np.diag([0.5, 0.5, 1.0, 1.0])), tmp_path / "m.nii.gz")
    result = run_volume([tmp_path / "m.nii.gz", "-o", tmp_path, "--no-picture"])
    assert result.exit_code == 0, result.output
    assert "voxel size 1 x 0.5 x 0.5 (z y x) from the file" in result.output
    table = pandas.read_parquet(tmp_path / "m_labels.parquet")
    assert table.area[0] == pytest.approx(4 * np.pi * 36, rel=0.03)
    assert pandas.read_csv(tmp_path / "m_labels.csv").volume[0] == pytest.approx(table.volume[0], rel=1e-12)
    assert run_volume([tmp_path / "m.nii.gz", "-o", tmp_path / "x", "--spacing", 1, 0, 1]).exit_code == 2
    assert run_volume([tmp_path / "m.nii.gz", "-o", tmp_path / "x", "--labels", "0"]).exit_code == 2
