"""The noisy patches of icc's default radius skipped where no patch can be (issue 31, helper S21).

:func:`meshcurv.radius._patch_radii` reads each vertex's noise level as the spread of the noise fits' signed
offsets over its two rings (:func:`meshcurv.radius._patch_levels`); a vertex grows its radius only where that
level calls for more than :data:`meshcurv.radius.PATCH_MARGIN` times its radius. A spread of some of the offsets is
at most the largest of them in size, so where even that largest offset calls for no growth, no vertex grows:
:func:`meshcurv.radius._patch_possible` says so before the rings are summed (0.2 CPU s of a 1M-vertex icosphere's
call). The factors must be those of the full reading on every mesh: clean ones (skipped), noisy patches and real
scans (read).
"""

import warnings

import numpy as np
import pytest

import meshcurv
from meshcurv import radius, shapes
from meshcurv.estimators import icc


def _capture(monkeypatch, vertices, faces):
    """The arguments of the default call's :func:`meshcurv.radius._patch_radii` (None: not called)."""
    seen = {}
    original = icc._patch_radii

    def keep(*args, **kwargs):
        seen["args"] = (args, kwargs)
        return original(*args, **kwargs)

    monkeypatch.setattr(icc, "_patch_radii", keep)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        meshcurv.principal_curvatures(vertices, faces)
    monkeypatch.undo()
    return seen.get("args")


def _noisy_cap(amplitude, seed=0):
    """The unit icosphere(24), its vertices above z = 0.4 moved along their normals by Gaussian noise of
    ``amplitude`` mean edge lengths."""
    sphere = shapes.icosphere(24)
    vertices, faces = sphere.vertices, sphere.faces
    edge = float(np.mean(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)))
    heights = np.random.default_rng(seed).normal(size=len(vertices)) * amplitude * edge
    return vertices + ((vertices[:, 2] > 0.4) * heights)[:, None] * sphere.normals, faces


MESHES = {
    "clean icosphere": lambda: (shapes.icosphere(24).vertices, shapes.icosphere(24).faces),
    "clean torus": lambda: (shapes.torus().vertices, shapes.torus().faces),
    "noisy cap 0.15": lambda: _noisy_cap(0.15),
    "noisy cap 0.05": lambda: _noisy_cap(0.05, seed=1),
    "noisy torus": lambda: (
        shapes.with_normal_noise(shapes.torus(), 0.3, seed=1).vertices,
        shapes.with_normal_noise(shapes.torus(), 0.3, seed=1).faces,
    ),
}


@pytest.mark.parametrize("name", sorted(MESHES))
def test_the_radii_are_those_of_the_full_reading(monkeypatch, name):
    vertices, faces = MESHES[name]()
    captured = _capture(monkeypatch, vertices, faces)
    assert captured is not None
    args, kwargs = captured
    quick = radius._patch_radii(*args, **kwargs)
    monkeypatch.setattr(radius, "_patch_possible", lambda fits, edge, base: True)  # every level read
    full = radius._patch_radii(*args, **kwargs)
    for a, b in zip(quick, full):
        assert a.dtype == b.dtype and np.array_equal(a, b, equal_nan=True)


def test_a_clean_sphere_sums_no_rings(monkeypatch):
    """On a clean sphere the fits' offsets are their bias (far below the noise floor): no level is read."""
    vertices, faces = MESHES["clean icosphere"]()
    captured = _capture(monkeypatch, vertices, faces)
    args, kwargs = captured

    def refused(*_args, **_kwargs):
        raise AssertionError("the rings of the noise levels were summed on a clean sphere")

    monkeypatch.setattr(radius, "_patch_levels", refused)
    base, radii = radius._patch_radii(*args, **kwargs)
    assert np.array_equal(base, radii)


def test_a_noisy_cap_is_read(monkeypatch):
    """Where the largest offset could call for growth the levels are read, and the cap's radii do grow."""
    vertices, faces = MESHES["noisy cap 0.15"]()
    args, kwargs = _capture(monkeypatch, vertices, faces)
    calls = []
    original = radius._patch_levels

    def counted(*a, **k):
        calls.append(1)
        return original(*a, **k)

    monkeypatch.setattr(radius, "_patch_levels", counted)
    base, radii = radius._patch_radii(*args, **kwargs)
    assert calls
    assert np.any(radii > base)


def test_the_bound_holds_for_every_level():
    """The bound's own arithmetic: one offset at the threshold where ``q`` passes the margin is possible, one
    just below is not (edge lengths 1, radii 1: ``q = 1 + NOISE_GAIN sqrt(L - NOISE_FLOOR)``)."""
    threshold = radius.NOISE_FLOOR + ((radius.PATCH_MARGIN - 1.0) / radius.NOISE_GAIN) ** 2
    ones = np.ones(4)
    fits = [(np.arange(4), np.array([0.0, threshold * 1.001, -0.001, 0.0]), np.ones(4))]
    assert radius._patch_possible(fits, ones, ones)
    fits = [(np.arange(4), np.array([0.0, -threshold * 0.99, 0.001, 0.0]), np.ones(4))]
    assert not radius._patch_possible(fits, ones, ones)
    # an offset whose fit failed (NaN curvedness) is no level: the others decide
    fits = [(np.arange(4), np.array([0.0, 10.0, 0.001, 0.0]), np.array([1.0, np.nan, 1.0, 1.0]))]
    assert not radius._patch_possible(fits, ones, ones)
    # no fit at all: no level, no patch
    assert not radius._patch_possible([], ones, ones)
