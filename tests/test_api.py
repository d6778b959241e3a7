"""The result type, the conventions table, options, logging and progress."""

import dataclasses
import logging

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes


@pytest.fixture(scope="module")
def torus_result():
    torus = shapes.torus(n_major=24, n_minor=16)
    return torus, meshcurv.principal_curvatures(torus.vertices, torus.faces, method="normal_cycle")


def test_result_is_frozen_and_read_only(torus_result):
    _, r = torus_result
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.k_min = r.k_max
    for name in ("k_min", "k_max", "dir_min", "dir_max", "normals", "valid", "mean", "gaussian"):
        with pytest.raises(ValueError, match="read-only"):
            getattr(r, name)[0] = 0
    assert r.k_min.dtype == np.float64 and r.valid.dtype == bool


def test_derived_fields_and_ordering(torus_result):
    _, r = torus_result
    assert (r.k_max >= r.k_min).all()
    np.testing.assert_array_equal(r.mean, (r.k_min + r.k_max) / 2)
    np.testing.assert_array_equal(r.gaussian, r.k_min * r.k_max)


def test_as_matgeom_is_the_documented_mapping(torus_result):
    _, r = torus_result
    C1, C2, U1, U2, H, K, N = r.as_matgeom()
    assert C1 is r.k_min and C2 is r.k_max and U1 is r.dir_min and U2 is r.dir_max
    assert H is r.mean and K is r.gaussian and N is r.normals


def test_topology_object_is_reused_and_gives_the_same_answer(torus_result):
    torus, r = torus_result
    top = meshcurv.MeshTopology.from_faces(torus.faces, torus.vertices.shape[0])
    again = meshcurv.principal_curvatures(torus.vertices, top, method="normal_cycle")
    np.testing.assert_array_equal(again.k_min, r.k_min)
    moved = meshcurv.principal_curvatures(torus.vertices * 2, top, method="matgeom")
    assert moved.method == "matgeom"


def test_silent_by_default_and_stages_on_the_logger_at_info(caplog, capsys):
    torus = shapes.torus(n_major=12, n_minor=8)
    with caplog.at_level(logging.WARNING, logger="meshcurv"):
        meshcurv.principal_curvatures(torus.vertices, torus.faces)
    assert caplog.records == []
    with caplog.at_level(logging.INFO, logger="meshcurv"):
        meshcurv.principal_curvatures(torus.vertices, torus.faces, method="matgeom")
    messages = [rec.getMessage() for rec in caplog.records]
    assert [m.split(" (")[0] for m in messages] == [
        "compute adjacencies",
        "compute edge tensors",
        "average vertex tensors",
        "retrieve curvatures",
    ]
    out = capsys.readouterr()
    assert out.out == "" and out.err == ""


def test_progress_callback_sees_every_stage():
    torus = shapes.torus(n_major=12, n_minor=8)
    calls = []
    meshcurv.principal_curvatures(
        torus.vertices, torus.faces, method="normal_cycle", progress=lambda *a: calls.append(a)
    )
    assert [c[1:] for c in calls] == [(1, 4), (2, 4), (3, 4), (4, 4)]
    assert calls[-1][0] == "retrieve curvatures"


def test_list_of_polygons_is_fan_triangulated_with_a_warning():
    torus = shapes.torus(n_major=12, n_minor=8)
    polygons = [list(q) for q in torus.quads]
    with pytest.warns(meshcurv.TriangulationWarning, match="forces triangulation"):
        r = meshcurv.principal_curvatures(torus.vertices, polygons)
    np.testing.assert_array_equal(r.k_min, meshcurv.principal_curvatures(torus.vertices, torus.faces).k_min)


def test_repr_names_method_and_counts(torus_result):
    _, r = torus_result
    assert "method='normal_cycle'" in repr(r) and "n_vertices=384" in repr(r)
