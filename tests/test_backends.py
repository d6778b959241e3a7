"""The compiled kernels compute what the NumPy paths compute.

The rest of the suite runs with whatever backend is installed; these tests run
both on the same meshes (skipped when numba is not installed). CI installs
numba, so both paths are exercised there; MESHCURV_BACKEND=numpy forces the
NumPy path for a whole run.
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes
from meshcurv._backend import use_backend
from meshcurv.errors import InvalidOptionError, MeshQualityWarning
from meshcurv.topology import MeshTopology

pytest.importorskip("numba")


def meshes():
    sphere = shapes.icosphere(6)
    v, f = sphere.vertices.copy(), sphere.faces
    v[f[0, 2]] = v[f[0, 0]]  # two zero-area faces
    fin = np.vstack([f, [f[50, 0], f[50, 1], 0], [f[7, 1], f[7, 1], f[9, 2]]])
    saddle = shapes.saddle(spacing=0.1)
    torus = shapes.torus(n_major=20, n_minor=12)
    flipped = torus.faces.copy()
    flipped[::7] = flipped[::7, ::-1]
    # two spheres touching at one shared vertex: a bow-tie
    a = shapes.icosphere(3)
    top = np.argmax(a.vertices[:, 2])
    bottom = np.argmin(a.vertices[:, 2])
    b_vertices = a.vertices + (a.vertices[top] - a.vertices[bottom])
    b_faces = a.faces + a.vertices.shape[0]
    b_faces[b_faces == bottom + a.vertices.shape[0]] = top
    bowtie = (np.vstack([a.vertices, b_vertices]), np.vstack([a.faces, b_faces]))
    return {
        "bowtie": bowtie,
        "torus": (torus.vertices, torus.faces),
        "saddle": (saddle.vertices, saddle.faces),
        "defects": (v, fin),
        "flipped_faces": (torus.vertices, flipped),
        "unreferenced": (np.vstack([torus.vertices, [[1.0, 2.0, 3.0]]]), torus.faces),
    }


MESHES = meshes()


def run(name, method, backend):
    vertices, faces = MESHES[name]
    with use_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore", MeshQualityWarning)
        return meshcurv.principal_curvatures(vertices, faces, method=method)


@pytest.mark.parametrize("name", sorted(MESHES))
def test_topology_is_identical(name):
    vertices, faces = MESHES[name]
    with use_backend("numpy"):
        a = MeshTopology._build(np.asarray(faces, np.int64), vertices.shape[0])
    with use_backend("numba"):
        b = MeshTopology._build(np.asarray(faces, np.int64), vertices.shape[0])
    for field in ("edges", "face_edges", "edge_faces", "edge_face_counts", "_edge_forward_counts"):
        np.testing.assert_array_equal(getattr(a, field), getattr(b, field), err_msg=field)
    with use_backend("numpy"):
        expected = a.bowtie_vertices
    with use_backend("numba"):
        np.testing.assert_array_equal(b.bowtie_vertices, expected)
    if name == "bowtie":
        assert expected.sum() == 1


@pytest.mark.parametrize("width", [np.int32, np.int64])
def test_topology_does_not_depend_on_the_bucket_width(width):
    """The compiled build sorts its buckets in int32 when the mesh fits, else int64: the same edges."""
    from meshcurv._kernels import topology as kernels_topology
    from meshcurv.topology import _bucket_template, _build_edges

    vertices, faces = MESHES["defects"]
    faces = np.asarray(faces, np.int64)
    expected = _build_edges(faces, vertices.shape[0])
    built = kernels_topology.build_edges(faces, vertices.shape[0], np.zeros(0, width))
    for got, want in zip(built, expected, strict=True):
        np.testing.assert_array_equal(got, want)
    assert _bucket_template(10, 20).dtype == np.int32
    assert _bucket_template(2**30, 20).dtype == np.int64  # 2 V + 1 beyond int32
    assert _bucket_template(10, 2**30).dtype == np.int64  # 3 F beyond int32


def test_neighbour_lists_match_the_adjacency():
    from meshcurv._kernels import topology as kernels_topology

    vertices, faces = MESHES["defects"]
    top = MeshTopology._build(np.asarray(faces, np.int64), vertices.shape[0])
    indptr, indices = kernels_topology.neighbour_lists(top.edges, top.n_vertices)
    with use_backend("numpy"):  # the same neighbours as the adjacency matrix, in edge order
        adjacency = MeshTopology._build(np.asarray(faces, np.int64), vertices.shape[0]).adjacency
    for v in range(top.n_vertices):
        assert sorted(indices[indptr[v] : indptr[v + 1]]) == sorted(
            adjacency.indices[adjacency.indptr[v] : adjacency.indptr[v + 1]]
        )


@pytest.mark.parametrize("threads", [1, 2])
def test_bowtie_vertices_do_not_depend_on_the_number_of_threads(threads):
    import numba

    from meshcurv._kernels import topology as kernels_topology
    from meshcurv.topology import _bowtie_vertices

    vertices, faces = MESHES["bowtie"]
    top = MeshTopology._build(np.asarray(faces, np.int64), vertices.shape[0])
    linked = (top.edge_face_counts == 2) & (top.edge_faces[:, 0] != top.edge_faces[:, 1])
    before = numba.get_num_threads()
    numba.set_num_threads(min(threads, numba.config.NUMBA_NUM_THREADS))
    try:
        found = kernels_topology.bowtie_vertices(
            top.faces, top.face_edges, top.edge_faces, linked, ~top.degenerate_faces, top.n_vertices
        )
    finally:
        numba.set_num_threads(before)
    np.testing.assert_array_equal(found, _bowtie_vertices(top))
    assert found.sum() == 1


@pytest.mark.parametrize("name", ["defects", "flipped_faces"])
def test_normal_cycle_sums_do_not_depend_on_the_number_of_threads(name):
    """Each thread adds what falls on its own range of vertices, in the same order: the sums are identical."""
    from meshcurv._kernels import normal_cycle as kernels_normal_cycle
    from meshcurv.geometry import DEGENERATE_AREA_RATIO, vertex_length_scales

    vertices, faces = MESHES[name]
    top = MeshTopology._build(np.asarray(faces, np.int64), vertices.shape[0])
    arguments = (
        vertices,
        top.faces,
        top.edges,
        top.edge_faces,
        top.edge_face_counts,
        top._edge_forward_counts,
        vertex_length_scales(vertices, top),
        DEGENERATE_AREA_RATIO,
    )
    sums, degenerate = kernels_normal_cycle.normal_cycle_sums(*arguments, 1)
    for chunks in (2, 5):
        other_sums, other_degenerate = kernels_normal_cycle.normal_cycle_sums(*arguments, chunks)
        np.testing.assert_array_equal(other_sums, sums)
        np.testing.assert_array_equal(other_degenerate, degenerate)
    assert np.abs(sums[:, :6]).sum() > 0 and (name != "defects" or degenerate.sum() == 3)


@pytest.mark.parametrize("name", ["defects", "torus"])
def test_matgeom_sums_do_not_depend_on_the_number_of_threads(name):
    from meshcurv._kernels import matgeom as kernels_matgeom

    vertices, faces = MESHES[name]
    top = MeshTopology._build(np.asarray(faces, np.int64), vertices.shape[0])
    arguments = (
        vertices,
        top.faces,
        top.edges[:, 0].copy(),
        top.edges[:, 1].copy(),
        np.maximum(top.edge_faces[:, 0], 0),
        np.maximum(top.edge_faces[:, 1], 0),
    )
    sums = kernels_matgeom.matgeom_vertex_tensors(*arguments, 1)
    assert np.isfinite(sums).any()
    for chunks in (2, 5):
        np.testing.assert_array_equal(kernels_matgeom.matgeom_vertex_tensors(*arguments, chunks), sums)


@pytest.mark.parametrize("method", ["normal_cycle", "matgeom"])
@pytest.mark.parametrize("name", sorted(MESHES))
def test_curvatures_agree(name, method):
    a = run(name, method, "numpy")
    b = run(name, method, "numba")
    np.testing.assert_array_equal(a.valid, b.valid)
    finite = np.abs(a.k_max[np.isfinite(a.k_max)])
    scale = finite.max() if finite.size else 1.0  # quadric on the coarse torus: every ball holds the tube's far side
    for field in ("k_min", "k_max", "mean", "gaussian"):
        np.testing.assert_allclose(
            getattr(b, field), getattr(a, field), rtol=0, atol=1e-11 * scale * max(scale, 1), err_msg=field
        )
    separated = a.valid & (np.abs(a.k_max - a.k_min) > 1e-6 * scale)
    for field in ("dir_min", "dir_max"):
        dots = np.abs(np.sum(getattr(a, field) * getattr(b, field), axis=1))[separated]
        assert (1 - dots).max(initial=0) < 1e-9, field


@pytest.mark.parametrize("method", ["icc", "quadric", "normal_cycle_ball"])
@pytest.mark.parametrize("name", ["torus", "saddle", "defects", "noisy", "coincident"])
def test_ball_methods_agree(name, method):
    # the compiled ball queries, jet fits, face and edge sums against the cKDTree / NumPy path;
    # summation order differs (grid cells against k-d tree pairs), hence the tolerance
    if name == "noisy":
        mesh = shapes.with_normal_noise(shapes.icosphere(8), 0.3, seed=5)
        vertices, faces = mesh.vertices, mesh.faces
    elif name == "coincident":  # a second copy of the torus: every ball holds each point twice
        torus = shapes.torus(n_major=20, n_minor=12)
        vertices = np.vstack([torus.vertices, torus.vertices])
        faces = np.vstack([torus.faces, torus.faces + torus.vertices.shape[0]])
    else:
        vertices, faces = MESHES[name]
    results = []
    for backend in ("numpy", "numba"):
        with use_backend(backend), warnings.catch_warnings():
            warnings.simplefilter("ignore", MeshQualityWarning)
            results.append(meshcurv.principal_curvatures(vertices, faces, method=method))
    a, b = results
    np.testing.assert_array_equal(a.valid, b.valid)
    numeric = {k for k, v in a.parameters.items() if isinstance(v, (int, float)) and not isinstance(v, bool)}
    assert {k: a.parameters[k] for k in numeric} == pytest.approx({k: b.parameters[k] for k in numeric}, rel=1e-9)
    assert {k: v for k, v in a.parameters.items() if k not in numeric} == {
        k: v for k, v in b.parameters.items() if k not in numeric
    }
    finite = np.abs(a.k_max[np.isfinite(a.k_max)])
    scale = finite.max() if finite.size else 1.0  # quadric on the coarse torus: every ball holds the tube's far side
    for field in ("k_min", "k_max", "normals"):
        np.testing.assert_allclose(
            getattr(b, field), getattr(a, field), rtol=0, atol=1e-8 * max(scale, 1), err_msg=field
        )


def noisy_sphere():
    """The jet tests' surface and its first frames: a sphere with noise of 0.2 edges, its radial normals."""
    mesh = shapes.with_normal_noise(shapes.icosphere(8), 0.2, seed=2)
    return mesh, mesh.vertices / np.linalg.norm(mesh.vertices, axis=1, keepdims=True)


def edge_lists(mesh):
    """The mesh's edge neighbours in CSR form (``adjacency=`` of the jet fits)."""
    return MeshTopology.from_faces(mesh.faces, mesh.vertices.shape[0]).neighbour_lists


@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_jets_fitted_at_chosen_centres(backend):
    # fitting a subset of the vertices gives their rows of the full fit; the other rows are NaN
    from meshcurv.jets import fit_jets

    mesh, normals = noisy_sphere()
    centres = np.arange(3, mesh.vertices.shape[0], 7)
    with use_backend(backend):
        full, full_frame, full_counts = fit_jets(mesh.vertices, normals, 0.4, degree=3)
        some, frame, counts = fit_jets(mesh.vertices, normals, 0.4, degree=3, centres=centres)
    others = np.setdiff1d(np.arange(mesh.vertices.shape[0]), centres)
    assert np.isnan(some[others]).all() and np.isnan(frame[2][others]).all() and (counts[others] == 0).all()
    np.testing.assert_allclose(some[centres], full[centres], rtol=0, atol=1e-12)
    np.testing.assert_allclose(frame[2][centres], full_frame[2][centres], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(counts[centres], full_counts[centres])


@pytest.mark.parametrize("connected", [False, True])
@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_compact_jets_are_the_rows_of_their_centres(backend, connected):
    # compact=True: one row per centre, in the order given (unsorted, repeats), equal to those rows of
    # the fit with one row per vertex; details["away"] likewise
    from meshcurv.jets import fit_jets

    mesh, normals = noisy_sphere()
    adjacency = edge_lists(mesh) if connected else None
    centres = np.array([40, 3, 3, 3, 17, 3, mesh.vertices.shape[0] - 1])  # a centre listed twice in a row
    with use_backend(backend):
        full_details, details = {}, {}
        full = fit_jets(
            mesh.vertices,
            normals,
            0.4,
            degree=3,
            centres=centres,
            facing=normals,
            adjacency=adjacency,
            details=full_details,
        )
        rows = fit_jets(
            mesh.vertices,
            normals,
            0.4,
            degree=3,
            centres=centres,
            facing=normals,
            adjacency=adjacency,
            details=details,
            compact=True,
        )
    assert rows[0].shape == (centres.size, 6) and rows[2].shape == (centres.size,)
    assert np.isfinite(rows[0]).all()
    np.testing.assert_array_equal(rows[0], full[0][centres])
    for got, expected in zip(rows[1], full[1]):
        np.testing.assert_array_equal(got, expected[centres])
    np.testing.assert_array_equal(rows[2], full[2][centres])
    np.testing.assert_array_equal(details["away"], full_details["away"][centres])


@pytest.mark.parametrize("connected", [False, True])
@pytest.mark.parametrize("backend", ["numpy", "numba"])
def test_settled_fits_keep_their_first_fit(backend, connected):
    # a centre whose first fit has a slope c10^2 + c01^2 below `settled` keeps that fit and its
    # frame (the result of one iteration); every other centre gets its two iterations
    from meshcurv.jets import fit_jets

    mesh, normals = noisy_sphere()
    adjacency = edge_lists(mesh) if connected else None
    with use_backend(backend):
        once, once_frame, _ = fit_jets(mesh.vertices, normals, 0.4, degree=3, iterations=1, adjacency=adjacency)
        twice, twice_frame, _ = fit_jets(mesh.vertices, normals, 0.4, degree=3, iterations=2, adjacency=adjacency)
        slope = once[:, 1] ** 2 + once[:, 2] ** 2
        settled = float(np.median(slope))
        mixed, frame, _ = fit_jets(
            mesh.vertices, normals, 0.4, degree=3, iterations=2, adjacency=adjacency, settled=settled
        )
        unchanged, _, _ = fit_jets(
            mesh.vertices, normals, 0.4, degree=3, iterations=2, adjacency=adjacency, settled=0.0
        )
    kept = slope < settled
    assert 0 < kept.sum() < kept.size and np.isfinite(once).all()
    assert np.abs(once[kept] - twice[kept]).max() > 1e-9  # the second fit moves them: the test can tell
    np.testing.assert_allclose(mixed[kept], once[kept], rtol=0, atol=1e-12)
    np.testing.assert_allclose(frame[2][kept], once_frame[2][kept], rtol=0, atol=1e-12)
    np.testing.assert_allclose(mixed[~kept], twice[~kept], rtol=0, atol=1e-12)
    np.testing.assert_allclose(frame[2][~kept], twice_frame[2][~kept], rtol=0, atol=1e-12)
    np.testing.assert_array_equal(unchanged, twice)


def test_ball_grid_finds_every_neighbour_of_a_sparse_flat_cloud():
    # 50 clusters of 40 points scattered over a 1000 x 1000 square, radius 5: cells of side 5
    # would make 20 columns per point, so the kernel widens its cells; every ball must still
    # hold every point within the radius (brute force)
    from meshcurv.jets import fit_jets

    rng = np.random.default_rng(4)
    clusters = rng.uniform(0, 1000, (50, 2)).repeat(40, axis=0)
    points = np.column_stack([clusters + rng.uniform(-5, 5, (2000, 2)), rng.normal(0, 1, 2000)])
    normals = np.tile([0.0, 0.0, 1.0], (2000, 1))
    with use_backend("numba"):
        _, _, counts = fit_jets(points, normals, 5.0, degree=2)
    distances = np.linalg.norm(points[:, None, :] - points[None, :, :], axis=2)
    inside = (distances < 5.0).sum(axis=1)
    assert inside.mean() > 10
    np.testing.assert_array_equal(counts, inside)


def test_unknown_backend_is_refused(monkeypatch):
    with pytest.raises(InvalidOptionError, match="unknown backend 'gpu'"):
        with use_backend("gpu"):
            pass
    monkeypatch.setenv("MESHCURV_BACKEND", "fortran")
    torus = shapes.torus(n_major=8, n_minor=6)
    with pytest.raises(InvalidOptionError, match=r"unknown backend 'fortran' \(MESHCURV_BACKEND\)"):
        meshcurv.principal_curvatures(torus.vertices, torus.faces)


@pytest.mark.parametrize("name", sorted(MESHES))
def test_diagnosis_agrees(name):
    vertices, faces = MESHES[name]
    facts = {}
    for backend in ("numpy", "numba"):
        with use_backend(backend):
            top = MeshTopology._build(np.asarray(faces, np.int64), vertices.shape[0])
            facts[backend] = meshcurv.diagnose(vertices, top).as_dict()
    for key, value in facts["numpy"].items():
        if isinstance(value, float):
            assert facts["numba"][key] == pytest.approx(value, rel=1e-12, abs=1e-12), key
        else:
            assert facts["numba"][key] == value, key


# -- first use: a compilation is announced, a load from the cache is not --------------------


class _Event:
    """A stand-in for numba.core.event.Event of kind ``numba:compile``."""

    def __init__(self, function, start):
        self.data = {"dispatcher": type("Dispatcher", (), {"py_func": function})()}
        self.is_start, self.is_end = start, not start


def test_compilation_is_announced_once_on_the_logger(caplog):
    from meshcurv import _backend
    from meshcurv._kernels.icc import _face_measures_chunk
    from meshcurv._kernels.jets import _grid_chunk

    announcer = _backend._CompileAnnouncer()
    foreign = _Event(warnings.warn, True)  # a function of another package: never announced
    with caplog.at_level("INFO", logger="meshcurv"):
        announcer.on_start(foreign)
        announcer.on_end(_Event(warnings.warn, False))
        assert not caplog.records
        for kernel in (_grid_chunk.py_func, _face_measures_chunk.py_func):
            announcer.on_start(_Event(kernel, True))
            announcer.on_end(_Event(kernel, False))
    warned = [r for r in caplog.records if r.levelname == "WARNING"]
    assert len(warned) == 1 and "compiling meshcurv's numba kernels" in warned[0].getMessage()
    assert "cached on disk" in warned[0].getMessage()
    infos = [r.getMessage() for r in caplog.records if r.levelname == "INFO"]
    assert [m.split()[4] for m in infos] == ["_grid_chunk", "_face_measures_chunk"]
    assert [name for name, _ in announcer.compiled] == ["_grid_chunk", "_face_measures_chunk"]


def test_nested_compilations_count_once(caplog):
    from meshcurv import _backend
    from meshcurv._kernels.jets import _grid_chunk
    from meshcurv._kernels.neighborhoods import _grid

    announcer = _backend._CompileAnnouncer()
    with caplog.at_level("INFO", logger="meshcurv"):
        announcer.on_start(_Event(_grid_chunk.py_func, True))
        announcer.on_start(_Event(_grid.py_func, True))  # a callee compiled inside its caller
        announcer.on_end(_Event(_grid.py_func, False))
        announcer.on_end(_Event(_grid_chunk.py_func, False))
    assert [name for name, _ in announcer.compiled] == ["_grid_chunk"]


SNIPPET = """
import logging, numpy as np
logging.basicConfig(level=logging.INFO, format="%(levelname)s %(message)s")
from meshcurv._backend import numba_kernels
numba_kernels("geometry").edge_lengths(np.eye(3), np.array([[0, 1], [1, 2]]))
"""


@pytest.mark.slow
def test_cold_cache_compiles_and_announces_warm_cache_loads_silently(tmp_path):
    import os
    import subprocess
    import sys

    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path), MESHCURV_BACKEND="numba")
    runs = [
        subprocess.run([sys.executable, "-c", SNIPPET], capture_output=True, text=True, env=env, timeout=120)
        for _ in range(2)
    ]
    cold, warm = (run.stderr for run in runs)
    assert all(run.returncode == 0 for run in runs), cold + warm
    assert cold.count("WARNING compiling meshcurv's numba kernels") == 1
    assert "compiled the numba kernel edge_lengths" in cold
    assert "compiling" not in warm and "compiled" not in warm


def test_normalized_normal_sums_agree():
    from meshcurv import geometry
    from meshcurv._backend import numba_kernels

    rng = np.random.default_rng(0)
    summed = rng.standard_normal((2000, 3)) * 10.0 ** rng.integers(-150, 150, (2000, 1))
    summed[:5] = 0.0  # cancelled sums: NaN
    summed[5:10] = [1e-100, 0.0, 0.0]  # tiny but not cancelled: unit
    expected = geometry.normalize_normal_sums(summed)
    assert np.isnan(expected[:5]).all() and np.allclose(expected[5:10], [1.0, 0.0, 0.0])
    np.testing.assert_array_equal(numba_kernels("geometry").normalize_normal_sums(summed), expected)


def test_small_kernels_run_on_one_thread_and_the_count_is_restored():
    import numba

    from meshcurv import _backend

    threads = numba.get_num_threads()
    small, large = np.zeros((_backend.SERIAL_ROWS - 1, 3)), np.zeros(_backend.SERIAL_ROWS)
    assert _backend._run(lambda *arrays: numba.get_num_threads(), (small, 1.0), {}) == 1
    assert _backend._run(lambda *arrays: numba.get_num_threads(), (small, large), {}) == threads
    assert numba.get_num_threads() == threads
    with pytest.raises(ZeroDivisionError):
        _backend._run(lambda *arrays: 1 / 0, (small,), {})
    assert numba.get_num_threads() == threads  # restored after a failing kernel too


def test_kernel_threads_are_numbas_thread_count():
    import numba

    from meshcurv._backend import kernel_threads

    assert kernel_threads() == numba.get_num_threads()


def test_a_kernel_of_threaded_chunks_runs_on_one_thread_when_small():
    """A kernel that runs compiled chunks on Python threads (``_common.threaded``) is handed out as the compiled
    ones are: on one thread for arrays of fewer than SERIAL_ROWS rows (issue 31)."""
    import numba

    from meshcurv import _backend
    from meshcurv._kernels._common import threaded

    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba has one thread here (NUMBA_NUM_THREADS)")

    @threaded
    def kernel(array):
        return numba.get_num_threads()

    call = _backend._locked(kernel)
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(2)
        assert call(np.zeros(10)) == 1
        assert call(np.zeros(_backend.SERIAL_ROWS)) == 2
        assert numba.get_num_threads() == 2  # given back
    finally:
        numba.set_num_threads(threads)
