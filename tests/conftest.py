import pathlib

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


@pytest.fixture
def data_dir():
    return DATA
