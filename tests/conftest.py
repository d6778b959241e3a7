import pathlib
import warnings

import numpy as np
import pytest

DATA = pathlib.Path(__file__).parent / "data"


def relative_error(estimate, truth):
    """|estimate - truth| / |truth| (truth never zero where this is used)."""
    return np.abs(np.asarray(estimate) - truth) / np.abs(truth)


def random_rotation(seed):
    """A proper rotation matrix drawn from a seeded generator."""
    rng = np.random.default_rng(seed)
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q *= np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def chosen_backend(name: str):
    """``meshcurv._backend.use_backend(name)``, the test skipped where ``name`` is numba and numba is missing."""
    from meshcurv._backend import use_backend

    if name == "numba":
        pytest.importorskip("numba")
    return use_backend(name)


def label_row(image, scale: float, backend: str, radius=None):
    """``label_curvatures``' one row for ``image`` at an isotropic ``scale`` (and ``radius`` in voxels, scaled)."""
    from meshcurv.volume import label_curvatures

    with chosen_backend(backend), warnings.catch_warnings():
        warnings.simplefilter("ignore")
        options = {} if radius is None else {"radius": radius * scale}
        return label_curvatures(image, spacing=[scale] * 3, **options).iloc[0]


def assert_label_row_scaled(row, scaled, scale):
    """``scaled`` is ``row`` of the unit spacing scaled by ``scale``: lengths by s, areas by s^2, curvatures by 1/s."""
    assert scaled["radius"] == pytest.approx(row["radius"] * scale, rel=1e-9)
    assert scaled["area"] == pytest.approx(row["area"] * scale**2, rel=1e-9)
    assert scaled["n_used"] == row["n_used"]
    for column, power in (("mean_weighted", 1), ("mean_median", 1), ("k_min_p5", 1), ("gaussian_weighted", 2)):
        assert scaled[column] * scale**power == pytest.approx(row[column], rel=1e-9), column


@pytest.fixture
def data_dir():
    return DATA
