"""Triangle strips in VTK files (.vtp ``<Strips>``, legacy ``TRIANGLE_STRIPS``): read as VTK makes their triangles.

A .vtp file of strips (what ``PolyData.strip()`` saves) was refused as having "no polygons", and the strips of a
file holding polygons too were dropped without a word: a surface with holes, measured as if whole.
"""

import pathlib

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.topology import strip_triangles

# five points of the plane: a quad, a triangle beside it, and a strip over the quad (fuzz_readers.md, round 14)
POINTS = "0 0 0 1 0 0 1 1 0 0 1 0 2 0 0"


def _vtp(tmp_path: pathlib.Path, polys: tuple[str, str] | None, strips: tuple[str, str] | None) -> pathlib.Path:
    cells = ""
    for tag, arrays in (("Polys", polys), ("Strips", strips)):
        if arrays is not None:
            cells += (
                f'<{tag}><DataArray type="Int64" Name="connectivity" format="ascii">{arrays[0]}</DataArray>'
                f'<DataArray type="Int64" Name="offsets" format="ascii">{arrays[1]}</DataArray></{tag}>'
            )
    path = tmp_path / "strips.vtp"
    path.write_text(
        '<VTKFile type="PolyData"><PolyData><Piece NumberOfPoints="5"><Points>'
        f'<DataArray type="Float64" NumberOfComponents="3" format="ascii">{POINTS}</DataArray></Points>'
        f"{cells}</Piece></PolyData></VTKFile>"
    )
    return path


def _faces(faces) -> list[list[int]]:
    return [list(map(int, face)) for face in faces]


def test_a_vtp_file_of_strips_alone_is_read_as_their_triangles(tmp_path):
    # the strip 0 1 3 2 makes (0, 1, 3) and, wound the other way round, (3, 1, 2): both counter-clockwise seen from +z
    _, faces = meshcurv.read_mesh(_vtp(tmp_path, None, ("0 1 3 2", "4")))
    assert _faces(faces) == [[0, 1, 3], [3, 1, 2]]


def test_strips_beside_polygons_are_kept_after_them(tmp_path):
    # as the legacy reader does (tests/test_io.py): the polygons, then the strips' triangles
    _, faces = meshcurv.read_mesh(_vtp(tmp_path, ("0 1 2 3 1 4 2", "4 7"), ("0 1 3 2", "4")))
    assert _faces(faces) == [[0, 1, 2, 3], [1, 4, 2], [0, 1, 3], [3, 1, 2]]


def test_bad_strips_are_mesh_file_errors(tmp_path):
    with pytest.raises(meshcurv.errors.MeshFileError, match=r"strips\.vtp: the triangle strip offsets do not"):
        meshcurv.read_mesh(_vtp(tmp_path, None, ("0 1 3 2", "5")))
    with pytest.raises(meshcurv.errors.MeshFileError, match=r"strips\.vtp: the PolyData has no points or no polyg"):
        meshcurv.read_mesh(_vtp(tmp_path, None, ("", "")))


def test_the_joins_of_strips_are_no_faces():
    # repeated points join two strips in one (0 1 2 and 3 4 5 through 2 2 3 3): the triangles between have no area;
    # the last is the strip's sixth, wound the other way round
    triangles = strip_triangles(np.array([0, 1, 2, 2, 3, 3, 4, 5]), np.array([8]))
    assert triangles.tolist() == [[0, 1, 2], [4, 3, 5]]
    # strips of fewer than three points hold no triangle; none at all is no error
    assert strip_triangles(np.array([0, 1, 2, 3, 4]), np.array([2, 5])).tolist() == [[2, 3, 4]]
    assert strip_triangles(np.zeros(0), np.zeros(0)).shape == (0, 3)


@pytest.mark.parametrize("extension", [".vtp", ".vtk"])
@pytest.mark.parametrize("binary", [False, True])
def test_a_stripped_sphere_read_back_is_the_sphere(tmp_path, extension, binary):
    # VTK is the reference: our triangles are the ones pyvista's triangulate() makes of the strips, wound alike;
    # measured, the sphere of radius 1 is what the polygons give
    pv = pytest.importorskip("pyvista")
    sphere = shapes.icosphere(subdivisions=3)
    flat = np.c_[np.full(sphere.faces.shape[0], 3), sphere.faces].ravel()
    stripped = pv.PolyData(sphere.vertices, flat).strip()
    assert stripped.n_strips > 0 and np.asarray(stripped.faces).size == 0
    path = tmp_path / f"sphere{extension}"
    stripped.save(path, binary=binary)
    vertices, faces = meshcurv.read_mesh(path)
    reference = np.asarray(stripped.triangulate().faces).reshape(-1, 4)[:, 1:]

    def rolled(triangles):  # each triangle from its smallest corner, its winding kept
        triangles = np.asarray(triangles)
        start = triangles.argmin(axis=1)
        return {tuple(np.roll(t, -s)) for t, s in zip(triangles.tolist(), start)}

    assert len(faces) == len(reference) == sphere.faces.shape[0]
    assert rolled(faces) == rolled(reference) == rolled(sphere.faces)
    result = meshcurv.principal_curvatures(vertices, faces)
    assert np.median(np.abs(result.mean[result.valid] - 1.0)) < 0.05
