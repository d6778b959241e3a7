"""``diagnose`` counts the needle vertices (issue 29: ``diagnose()`` and ``meshcurv info`` did not report them)."""

from __future__ import annotations

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv.diagnosis import NEEDLE_PHRASE, mesh_diagnosis
from meshcurv.geometry import vertex_length_scales
from meshcurv.topology import MeshTopology


def test_a_clean_mesh_has_no_needle():
    sphere = shapes.icosphere(6)
    found = meshcurv.diagnose(sphere.vertices, sphere.faces)
    assert found.n_needle_vertices == 0 and found.is_clean and found.problems() == []


@pytest.mark.parametrize("distance", [30.0, 1e10])
def test_a_spike_is_counted_with_the_defects_phrase(distance):
    sphere = shapes.icosphere(6)
    vertices = sphere.vertices.copy()
    vertices[5] *= distance
    found = meshcurv.diagnose(vertices, sphere.faces)
    assert found.n_needle_vertices == 1 and not found.is_clean
    assert found.problems() == [f"1 {NEEDLE_PHRASE}"]
    assert found.as_dict()["n_needle_vertices"] == 1
    assert "needle vertices" in NEEDLE_PHRASE


def test_two_neighbours_flung_together_are_two_needles():
    sphere = shapes.icosphere(8)
    star = sphere.faces[(sphere.faces == 5).any(axis=1)]
    vertices = sphere.vertices.copy()
    vertices[[5, int(star[0][star[0] != 5][0])], 0] = 1e3
    assert meshcurv.diagnose(vertices, sphere.faces).n_needle_vertices == 2


def test_a_known_count_is_taken_as_given():
    # principal_curvatures has the count already (the defect table): mesh_diagnosis does not search again
    sphere = shapes.icosphere(4)
    topology = MeshTopology.from_faces(sphere.faces)
    scales = vertex_length_scales(sphere.vertices, topology)
    assert mesh_diagnosis(sphere.vertices, topology, 0, scales, n_needle_vertices=3).n_needle_vertices == 3


def test_the_result_of_a_call_carries_the_count():
    sphere = shapes.icosphere(6)
    vertices = sphere.vertices.copy()
    vertices[5] *= 30.0
    with pytest.warns(meshcurv.MeshQualityWarning, match="1 needle vertices"):
        result = meshcurv.principal_curvatures(vertices, sphere.faces)
    assert result.diagnosis.n_needle_vertices == 1
    assert not result.valid[5] and np.isnan(result.mean[5])


def test_meshcurv_info_prints_the_count(capsys, tmp_path):
    from meshcurv.cli import main

    sphere = shapes.icosphere(6)
    vertices = sphere.vertices.copy()
    vertices[5] *= 30.0
    path = meshcurv.write_mesh(tmp_path / "spike.obj", vertices, sphere.faces)
    assert main(["info", str(path)]) == 0
    lines = [line.split() for line in capsys.readouterr().out.splitlines()]
    assert ["needle", "vertices", "1"] in lines
