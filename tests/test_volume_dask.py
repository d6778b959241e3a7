"""meshcurv.volume on Dask (``label_curvatures(workers=..., client=...)``, ``meshcurv volume --workers``).

Oracle: the serial run of the same call. The rows must be the same, label by
label and in the same order: text and integer columns exactly, the others up
to the order of floating-point sums (rtol 1e-9; the workers run their kernels
on one thread, the serial run on several).

Faults are injected in the workers by a Dask preload file (run again in each
worker a nanny restarts) that replaces ``meshcurv.volume._crop_label`` for
chosen labels: one raises, one ends its process (``os._exit``, as a segfault
or the kernel's out-of-memory killer would).
"""

import sys
import textwrap

import numpy as np
import pytest

pytest.importorskip("skimage")
pandas = pytest.importorskip("pandas")

from meshcurv import volume  # noqa: E402
from meshcurv.errors import InvalidOptionError, MeshQualityWarning, MissingDependencyError  # noqa: E402
from meshcurv.volume import label_curvatures  # noqa: E402

UNIT = (1.0, 1.0, 1.0)  # the voxel size of the tests (a call without spacing warns)

#: Labels 1-6: three balls and three rotated ellipsoids, of semi-axes 5-8 voxels (well under a second each).
SOLIDS = {
    1: ((9.3, 10.1, 9.7), (6.0, 6.0, 6.0)),
    2: ((10.2, 30.4, 11.1), (7.5, 5.0, 6.0)),
    3: ((29.6, 10.3, 30.2), (5.5, 5.5, 5.5)),
    4: ((30.1, 29.8, 9.6), (8.0, 6.0, 5.0)),
    5: ((10.4, 10.6, 30.3), (6.5, 6.5, 6.5)),
    6: ((29.7, 30.2, 29.9), (7.0, 5.5, 5.0)),
}


def labelled_solids() -> np.ndarray:
    """A 40^3 label image of :data:`SOLIDS`, a one-voxel label 9 and a ball cut by the image border (label 7)."""
    rng = np.random.default_rng(17)
    image = np.zeros((40, 40, 40), dtype=np.uint16)
    grid = np.meshgrid(*[np.arange(40.0)] * 3, indexing="ij", sparse=True)
    for label, (center, axes) in {**SOLIDS, 7: ((20.0, 1.5, 20.2), (5.0, 5.0, 5.0))}.items():
        q, r = np.linalg.qr(rng.normal(size=(3, 3)))
        turn = q * np.sign(np.diag(r))
        body = [sum(turn[k, j] * (grid[k] - center[k]) for k in range(3)) for j in range(3)]
        image[(sum((body[j] / axes[j]) ** 2 for j in range(3)) <= 1) & (image == 0)] = label
    image[20, 20, 20] = 9
    return image


def assert_same_rows(table, expected):
    assert list(table.columns) == list(expected.columns)
    numeric = [name for name in expected.columns if expected[name].dtype.kind == "f"]
    exact = [name for name in expected.columns if name not in numeric]
    pandas.testing.assert_frame_equal(table[exact], expected[exact])
    np.testing.assert_allclose(table[numeric].to_numpy(), expected[numeric].to_numpy(), rtol=1e-9, atol=0)


@pytest.fixture(scope="module")
def image():
    return labelled_solids()


@pytest.fixture(scope="module")
def serial(image):
    with pytest.warns(MeshQualityWarning):
        return label_curvatures(
            image, spacing=(1.0, 0.8, 0.8), labels_to_use=[6, 9, 2, 11, 7, 1, 3, 4, 5], return_meshes=True
        )


def test_the_image_has_what_the_tests_need(serial):
    table, _ = serial
    status = dict(zip(table.label, table.status))
    assert status == {6: "ok", 9: "too_small", 2: "ok", 11: "empty", 7: "ok", 1: "ok", 3: "ok", 4: "ok", 5: "ok"}
    assert table.set_index("label").touches_border.to_dict() == {label: label == 7 for label in status}


@pytest.mark.slow  # starts a local cluster of two processes: several seconds
def test_two_workers_give_the_rows_and_surfaces_of_the_serial_run(image, serial):
    pytest.importorskip("distributed")
    expected, expected_surfaces = serial
    calls = []
    with pytest.warns(MeshQualityWarning, match="1 empty, 1 too_small"):
        table, surfaces = label_curvatures(
            image,
            spacing=(1.0, 0.8, 0.8),
            labels_to_use=[6, 9, 2, 11, 7, 1, 3, 4, 5],
            return_meshes=True,
            workers=2,
            progress=lambda done, total, label: calls.append((done, total, label)),
        )
    assert_same_rows(table, expected)
    assert calls == [(done, 9, label) for done, label in enumerate(expected.label, start=1)]
    assert sorted(surfaces) == sorted(expected_surfaces)
    for label, surface in surfaces.items():
        np.testing.assert_array_equal(surface.faces, expected_surfaces[label].faces)
        np.testing.assert_array_equal(surface.vertices, expected_surfaces[label].vertices)
        np.testing.assert_array_equal(surface.used, expected_surfaces[label].used)
        np.testing.assert_allclose(surface.result.mean, expected_surfaces[label].result.mean, rtol=1e-9)


FAULTS = """
import json, os

import numpy as np

import meshcurv.volume as volume

_original = volume._crop_label


def _faulty(label, padded, starts, stops, image_shape, spacing, method, radius):
    with open({log!r}, "a") as log:  # what the task received
        log.write(json.dumps([int(label), list(padded.shape), str(padded.dtype), starts.tolist(), stops.tolist()])
                  + "\\n")
    if label == {raising}:
        raise ValueError("a fault in the estimator")
    if label == {dying}:
        os._exit(3)  # as a segfault would: no exception, no clean-up
    return _original(label, padded, starts, stops, image_shape, spacing, method, radius)


def dask_setup(worker):
    volume._crop_label = _faulty
"""


@pytest.fixture(scope="module")
def faulty_client(tmp_path_factory):
    """A local cluster of two processes whose workers raise for label 2 and die for label 4."""
    distributed = pytest.importorskip("distributed")
    import dask

    folder = tmp_path_factory.mktemp("faults")
    preload = folder / "meshcurv_faults.py"
    preload.write_text(textwrap.dedent(FAULTS.format(log=str(folder / "calls.jsonl"), raising=2, dying=4)))
    with (
        dask.config.set(volume.CLUSTER_CONFIG),
        distributed.LocalCluster(
            n_workers=2,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            dashboard_address=None,
            preload=[str(preload)],
        ) as cluster,
        distributed.Client(cluster) as client,
    ):
        client.calls = folder / "calls.jsonl"
        yield client


@pytest.mark.slow  # a cluster whose workers die: tens of seconds
def test_a_label_that_raises_or_kills_its_worker_fails_alone(image, serial, faulty_client):
    import json

    expected, _ = serial
    with pytest.warns(MeshQualityWarning, match="2 failed"):
        table = label_curvatures(
            image, spacing=(1.0, 0.8, 0.8), labels_to_use=[6, 9, 2, 11, 7, 1, 3, 4, 5], client=faulty_client
        )
    assert list(table.label) == list(expected.label)
    failed = table[table.status == "failed"].set_index("label")
    assert list(failed.index) == [2, 4]
    assert failed.error[2] == "ValueError: a fault in the estimator"  # as serially
    assert failed.error[4].startswith("WorkerDied: the worker process computing this label died")
    others = ~table.label.isin([2, 4])
    assert_same_rows(table[others].reset_index(drop=True), expected[others].reset_index(drop=True))
    with pytest.raises(InvalidOptionError, match="method"):  # wrong for every label: raised, as serially
        label_curvatures(image, spacing=UNIT, labels_to_use=[1, 3], method="nope", client=faulty_client)
    # each task received its labels' crops only: the box padded by one voxel, as a boolean mask
    boxes = volume._objects(image, None)
    received = [json.loads(line) for line in faulty_client.calls.read_text().splitlines()]
    assert {label for label, *_ in received} == {1, 2, 3, 4, 5, 6, 7, 9}
    assert [label for label, *_ in received].count(4) >= 2  # tried again after its worker died
    for label, shape, dtype, starts, stops in received:
        box = boxes[label]
        assert dtype == "bool"
        assert shape == [part.stop - part.start + 2 for part in box]
        assert starts == [part.start for part in box] and stops == [part.stop for part in box]


@pytest.mark.slow  # starts a local cluster: several seconds
def test_cli_workers_writes_the_serial_table(tmp_path, image, serial):
    pytest.importorskip("pyarrow")
    pytest.importorskip("distributed")
    from test_volume import run_volume

    np.save(tmp_path / "cells.npy", image)
    result = run_volume(
        [
            tmp_path / "cells.npy",
            "-o",
            tmp_path / "out",
            "--spacing",
            1,
            0.8,
            0.8,
            "--no-picture",
            "--workers",
            2,
            "--labels",
            "6,9,2,11,7,1,3,4,5",
            "--meshes",
            "npz",
        ]
    )
    assert result.exit_code == 0, result.output
    table = pandas.read_parquet(tmp_path / "out" / "cells_labels.parquet")
    expected, _ = serial
    assert_same_rows(table, expected)
    assert sorted(path.name for path in (tmp_path / "out").glob("*.npz")) == sorted(
        f"cells_label_{label}.npz" for label in (1, 2, 3, 4, 5, 6, 7)
    )


def test_groups_share_the_labels_out_by_voxels_in_order():
    image = np.zeros((60, 60, 60), dtype=np.uint16)
    image[2:52, 2:52, 2:52] = 1  # a box of 52^3 voxels with its margin: above TASK_VOXELS, alone
    for label in range(2, 42):  # forty single voxels, 27 voxels with the margin
        image[55 + label % 4, label, 57] = label
    objects = volume._objects(image, None)
    groups = volume._groups(objects, workers=1)
    assert [label for group in groups for label in group] == list(range(1, 42))
    assert groups[0] == [1]
    assert all(len(group) > 1 for group in groups[1:])  # small labels share tasks
    assert len(groups) >= min(41, volume.TASKS_PER_WORKER)  # enough tasks to keep every worker busy
    assert volume._groups(volume._objects(image, [100]), workers=2) == []  # an empty label is no task


@pytest.mark.parametrize(
    "options, message",
    [
        ({"workers": 0}, "`workers` must be an integer between 1 and"),
        ({"workers": 2.5}, "`workers` must be an integer"),
        ({"workers": 2, "client": object()}, "not both"),
        ({"client": object()}, "`client` must be a distributed.Client; got object"),
    ],
)
def test_parallel_option_errors(options, message):
    pytest.importorskip("distributed")
    with pytest.raises(InvalidOptionError, match=message):
        label_curvatures(np.ones((4, 4, 4), dtype=np.uint8), **options)


def test_no_label_to_compute_starts_no_cluster(monkeypatch):
    pytest.importorskip("distributed")

    def refuse(**options):
        raise AssertionError("a cluster was started")

    monkeypatch.setattr(volume.driver, "cluster", refuse)
    with pytest.warns(MeshQualityWarning, match="1 empty"):
        table = label_curvatures(np.zeros((6, 6, 6), dtype=np.uint8), spacing=UNIT, labels_to_use=[3], workers=2)
    assert list(table.status) == ["empty"]


def test_workers_without_dask_name_the_extra(monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed raises ImportError
    with pytest.raises(MissingDependencyError, match=r"pip install 'meshcurv\[batch\]'"):
        label_curvatures(np.ones((4, 4, 4), dtype=np.uint8), workers=2)
    serial = label_curvatures(np.ones((4, 4, 4), dtype=np.uint8), spacing=UNIT, workers=1)  # serial: no Dask
    assert list(serial.label) == [1]
