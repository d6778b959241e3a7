"""The twins' registry of :mod:`meshcurv._backend` (a NumPy function decorated with ``@twin`` and its kernel), and the
OpenMP wait policy it asks for."""

import importlib
import os
import pkgutil

import numpy as np
import pytest

import meshcurv
from meshcurv import _backend, shapes
from meshcurv._backend import TWINS, twin, use_backend
from meshcurv.topology import MeshTopology


def _import_every_module() -> None:
    """Import every module of meshcurv (but the kernels), so that every ``@twin`` has registered its pair."""
    for info in pkgutil.walk_packages(meshcurv.__path__, "meshcurv."):
        if not info.name.startswith("meshcurv._kernels") and info.name != "meshcurv.__main__":
            importlib.import_module(info.name)


def test_every_registered_twin_has_a_kernel_of_its_name():
    pytest.importorskip("numba")
    _import_every_module()
    assert len(TWINS) >= 5  # the twins of meshcurv._geometry, at least
    for key, function in TWINS.items():
        module, _, name = key.partition(".")
        assert function.__name__ == name, key  # the kernel bears its NumPy function's name
        kernel = getattr(importlib.import_module(f"meshcurv._kernels.{module}"), name, None)
        assert callable(kernel), f"{key}: a twin without a kernel"


def test_a_twin_runs_its_kernel_on_the_compiled_backend_and_its_own_body_on_numpy(monkeypatch):
    pytest.importorskip("numba")
    monkeypatch.setattr(_backend, "TWINS", dict(TWINS))  # this test's stand-in leaves the registry as it was

    @twin("geometry")
    def edge_lengths(vertices, edges):  # the name of a kernel of meshcurv._kernels.geometry
        return "the NumPy body"

    sphere = shapes.icosphere(4)
    edges = MeshTopology.from_faces(sphere.faces, len(sphere.vertices)).edges
    with use_backend("numpy"):
        assert edge_lengths(sphere.vertices, edges) == "the NumPy body"
    with use_backend("numba"):
        lengths = edge_lengths(sphere.vertices, edges)
    assert edge_lengths.numpy(sphere.vertices, edges) == "the NumPy body"
    d = sphere.vertices[edges[:, 1]] - sphere.vertices[edges[:, 0]]
    np.testing.assert_allclose(lengths, np.linalg.norm(d, axis=1), rtol=1e-15)  # the kernel's lengths
    assert _backend.TWINS["geometry.edge_lengths"] is edge_lengths.numpy


def test_a_twin_keeps_its_name_and_documentation():
    from meshcurv import _geometry

    assert _geometry.face_cross_products.__name__ == "face_cross_products"
    assert "cross(b - a, c - a)" in _geometry.face_cross_products.__doc__
    assert TWINS["geometry.face_cross_products"] is _geometry.face_cross_products.numpy


def test_a_twin_hands_its_kernel_every_argument_by_position_with_the_defaults(monkeypatch):
    pytest.importorskip("numba")
    from meshcurv._backend import numba_kernels

    monkeypatch.setattr(_backend, "TWINS", dict(TWINS))

    @twin("tensors")
    def principal_from_shape_operator(tensor, normals, *, rotate=False, mean_from_trace=False):
        return "the NumPy body"

    rng = np.random.default_rng(3)
    tensor = rng.standard_normal((50, 6))
    normals = rng.standard_normal((50, 3))
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    with use_backend("numba"):
        kernel = numba_kernels("tensors").principal_from_shape_operator
        for given, positional in (({}, (False, False)), ({"rotate": True}, (True, False))):
            got = principal_from_shape_operator(tensor, normals, **given)
            for a, b in zip(got, kernel(tensor, normals, *positional)):
                np.testing.assert_array_equal(a, b)


def test_the_kernels_ask_for_a_passive_openmp_wait_unless_the_environment_names_a_policy(monkeypatch):
    # GNU OpenMP's threads spin after each parallel region by default: on shared cores each short kernel
    # launch then costs milliseconds of CPU (benchmarks/speed_profile.md); the policy is set before the
    # kernels first run, and a policy the user gave is kept
    pytest.importorskip("numba")
    monkeypatch.setenv("OMP_WAIT_POLICY", "restored at teardown")
    monkeypatch.delenv("OMP_WAIT_POLICY")
    monkeypatch.setattr(_backend, "_imported", None)
    _backend._import_kernels()
    assert os.environ["OMP_WAIT_POLICY"] == _backend.WAIT_POLICY == "PASSIVE"
    monkeypatch.setenv("OMP_WAIT_POLICY", "ACTIVE")
    monkeypatch.setattr(_backend, "_imported", None)
    _backend._import_kernels()
    assert os.environ["OMP_WAIT_POLICY"] == "ACTIVE"
