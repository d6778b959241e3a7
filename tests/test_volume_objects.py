"""``meshcurv volume``'s one VTP file of all objects (``<name>_objects.vtp``), and the VTP pieces it is made of.

Oracles: two balls of known radius and centre, so that each point's label is
known from which centre it is near; the file read back must hold, per label,
the mesh the table describes (its vertex and face counts, its triangle area
``area_mesh`` and its corrected area ``area`` as the sum of the ``vertex_area``
field, both of them within 3% of 4 pi R^2).
"""

import numpy as np
import pytest

from meshcurv.errors import MeshFileError
from meshcurv.io._vtp import PieceWriter, read_vtp, read_vtp_cell_data, read_vtp_point_data, write_vtp

pytest.importorskip("skimage")
pandas = pytest.importorskip("pandas")
click_testing = pytest.importorskip("click.testing")

SPACING = (1.0, 0.5, 0.5)
CENTRES = {3: (7.7, 6.8, 6.6), 8: (8.2, 7.1, 19.3)}
RADIUS = 5.5


def run_volume(args):
    from meshcurv.cli._common import Session
    from meshcurv.cli._volume import volume

    session = Session()
    with session:
        return click_testing.CliRunner().invoke(volume, [str(arg) for arg in args], obj=session)


def two_balls():
    shape = (16, 28, 52)
    grid = np.meshgrid(*[np.arange(n) * s for n, s in zip(shape, SPACING)], indexing="ij", sparse=True)
    image = np.zeros(shape, dtype=np.uint16)
    for label, centre in CENTRES.items():
        image[sum((axis - c) ** 2 for axis, c in zip(grid, centre)) <= RADIUS**2] = label
    return image


def _write_two_pieces(path):
    """Two surfaces (a triangle, labelled 1; a square, labelled 2) written as two pieces of one VTP file."""
    first = (np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0.0]]), np.array([[0, 1, 2]]))
    second = (np.array([[0, 0, 1], [1, 0, 1], [0, 1, 1], [1, 1, 1.0]]), np.array([[0, 1, 2], [1, 3, 2]]))
    with open(path, "wb") as handle, PieceWriter(handle) as writer:
        for number, (vertices, faces) in enumerate((first, second), start=1):
            writer.add(
                vertices,
                faces,
                {
                    "label": np.full(len(vertices), number, dtype=np.uint64),
                    "normals": np.tile([0, 0, 1.0], (len(vertices), 1)),
                },
                {"label": np.full(len(faces), number, dtype=np.uint64)},
            )
    return first, second


def test_pieces_round_trip_as_one_surface(tmp_path):
    first, second = _write_two_pieces(tmp_path / "two.vtp")
    vertices, faces = read_vtp(tmp_path / "two.vtp")
    assert np.array_equal(vertices, np.concatenate([first[0], second[0]]))
    assert np.array_equal(faces, [[0, 1, 2], [3, 4, 5], [4, 6, 5]])
    points, cells = read_vtp_point_data(tmp_path / "two.vtp"), read_vtp_cell_data(tmp_path / "two.vtp")
    assert points["label"].tolist() == [1, 1, 1, 2, 2, 2, 2] and points["normals"].shape == (7, 3)
    assert cells["label"].tolist() == [1, 2, 2]
    # one piece, written whole: as before
    write_vtp(tmp_path / "one.vtp", *second, {"mean": np.arange(4.0)}, {"label": np.array([5, 6])})
    assert np.array_equal(read_vtp(tmp_path / "one.vtp")[1], second[1])
    assert read_vtp_cell_data(tmp_path / "one.vtp")["label"].tolist() == [5, 6]


def test_pieces_with_different_arrays_are_refused(tmp_path):
    with open(tmp_path / "odd.vtp", "wb") as handle, PieceWriter(handle) as writer:
        writer.add(np.eye(3), np.array([[0, 1, 2]]), {"a": np.zeros(3)})
        writer.add(np.eye(3), np.array([[0, 1, 2]]), {"b": np.zeros(3)})
    with pytest.raises(MeshFileError, match="odd.vtp: the pieces of the file do not carry the same PointData arrays"):
        read_vtp_point_data(tmp_path / "odd.vtp")


def test_cli_writes_one_vtp_of_all_objects_with_their_labels(tmp_path):
    np.save(tmp_path / "cells.npy", two_balls())
    out = tmp_path / "out"
    result = run_volume([tmp_path / "cells.npy", "-o", out, "--spacing", *SPACING, "--no-picture"])
    assert result.exit_code == 0, result.output
    assert f"surfaces in {out / 'cells_objects.vtp'}" in result.output
    table = pandas.read_csv(out / "cells_labels.csv").set_index("label")
    assert not table.touches_border.any()
    vertices, faces = read_vtp(out / "cells_objects.vtp")
    points = read_vtp_point_data(out / "cells_objects.vtp")
    cells = read_vtp_cell_data(out / "cells_objects.vtp")
    assert {"mean", "gaussian", "k_min", "k_max", "normals", "valid", "label", "used", "vertex_area"} <= set(points)
    assert len(vertices) == table.n_vertices.sum() and len(faces) == table.n_faces.sum()
    for label, centre in CENTRES.items():
        on = points["label"] == label
        distance = np.linalg.norm(vertices[on] - centre, axis=1)
        assert np.abs(distance - RADIUS).max() < 1.0, np.abs(distance - RADIUS).max()  # on its own ball
        assert on.sum() == table.n_vertices[label] and (cells["label"] == label).sum() == table.n_faces[label]
        assert np.all(points["label"][faces[cells["label"] == label]] == label)  # cells and points agree
        mine = faces[cells["label"] == label]
        a, b, c = (vertices[mine[:, k]] for k in range(3))
        triangle_area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum()
        assert triangle_area == pytest.approx(table.area_mesh[label], rel=1e-9)
        assert points["vertex_area"][on].sum() == pytest.approx(table.area[label], rel=1e-9)
        assert table.area[label] == pytest.approx(4 * np.pi * RADIUS**2, rel=0.03)
        # the mean curvature field of the file is that of a ball of radius R, where the vertex is used
        used = on & (points["used"] == 1)
        assert np.median(points["mean"][used]) == pytest.approx(1 / RADIUS, rel=0.03)
    again = run_volume([tmp_path / "cells.npy", "-o", out, "--spacing", *SPACING, "--no-picture"])
    assert isinstance(again.exception, MeshFileError) and "already exists" in str(again.exception)
    for name in ("cells_labels.csv", "cells_labels.parquet", "cells_objects.vtp"):
        (out / name).unlink(missing_ok=True)
    assert run_volume([tmp_path / "cells.npy", "-o", out, "--no-objects", "--no-picture"]).exit_code == 0
    assert not (out / "cells_objects.vtp").exists()


def test_cli_objects_file_of_an_image_without_surfaces_is_an_empty_dataset(tmp_path):
    image = np.zeros((6, 6, 6), dtype=np.uint8)
    image[2, 2, 2] = 1  # one voxel: too small for a surface
    np.save(tmp_path / "dot.npy", image)
    result = run_volume([tmp_path / "dot.npy", "-o", tmp_path, "--spacing", 1, 1, 1, "--no-picture"])
    assert result.exit_code == 0, result.output
    with pytest.raises(MeshFileError, match="dot_objects.vtp: the PolyData has no points or no polygons"):
        read_vtp(tmp_path / "dot_objects.vtp")
    assert read_vtp_point_data(tmp_path / "dot_objects.vtp") == {}


def test_vtk_reads_the_pieces_as_one_dataset(tmp_path):
    vtk = pytest.importorskip("vtk")
    from vtk.util.numpy_support import vtk_to_numpy

    first, second = _write_two_pieces(tmp_path / "two.vtp")
    reader = vtk.vtkXMLPolyDataReader()  # what ParaView opens a .vtp with
    reader.SetFileName(str(tmp_path / "two.vtp"))
    reader.Update()
    data = reader.GetOutput()
    assert (data.GetNumberOfPoints(), data.GetNumberOfCells()) == (7, 3)
    assert vtk_to_numpy(data.GetPointData().GetArray("label")).tolist() == [1, 1, 1, 2, 2, 2, 2]
    assert vtk_to_numpy(data.GetCellData().GetArray("label")).tolist() == [1, 2, 2]
    assert vtk_to_numpy(data.GetPolys().GetConnectivityArray()).tolist() == [0, 1, 2, 3, 4, 5, 4, 6, 5]
    assert data.GetPointData().GetNormals() is not None
