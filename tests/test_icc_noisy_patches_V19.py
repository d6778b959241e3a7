"""icc's default radius follows the noise of a patch noisier than the rest of the mesh (issue 29, "never lie").

The default radius of ``icc`` is set by the noise level of the whole mesh (its median over the vertices); a patch of
the surface that is noisier than the rest (a scanned region, faces detached off the surface) was measured at the
clean part's radius, one edge length, where its noise is far above what that ball averages out: a unit icosphere
with 30% of its vertices moved along the normal by 0.15 edge lengths (Gaussian) had 1,248 of 5,762 valid vertices
with |H - 1| > 0.5; with half of its faces detached (corners moved 0.054 edge lengths), 34-64 of ~10,800. The
exact mean curvature of the unit sphere is 1 everywhere; a ball of the radius the patch's noise calls for
(about 2 to 4 edge lengths at these levels) errs by a few percent of it, so no valid vertex may be off by half of it.
"""

import sys
import warnings
from pathlib import Path

import numpy as np
import pytest

import meshcurv
from meshcurv import shapes

sys.path.insert(0, str(Path(__file__).parent))
from test_orient_holey_inward import _holey  # noqa: E402

#: Half of the exact mean curvature (1 on the unit sphere): an estimate beyond it is a wrong number.
OFF = 0.5


def _mean_edge(vertices, faces):
    return float(np.mean(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)))


def _default(vertices, faces):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the loose faces and welds are reported: not the point here
        return meshcurv.principal_curvatures(vertices, faces)


def _noisy_cap(seed, amplitude):
    """The unit icosphere(24) with the vertices of a cap (30% of them, above z = 0.4) moved along their normal by
    Gaussian noise of ``amplitude`` mean edge lengths; the cap's mask."""
    sphere = shapes.icosphere(24)
    vertices, faces = sphere.vertices, sphere.faces
    cap = vertices[:, 2] > 0.4
    rng = np.random.default_rng(seed)
    heights = rng.normal(size=len(vertices)) * amplitude * _mean_edge(vertices, faces)
    return vertices + (cap * heights)[:, None] * sphere.normals, faces, cap


@pytest.mark.parametrize("seed", [0, 1])
def test_a_noisy_cap_is_measured_at_its_own_radius(seed):
    vertices, faces, cap = _noisy_cap(seed, 0.15)
    result = _default(vertices, faces)
    mean = (result.k_min + result.k_max) / 2
    valid = result.valid
    assert valid.mean() > 0.95  # the noise is no defect: the vertices keep their values
    assert np.abs(mean[valid] - 1.0).max() < OFF
    # the cap's balls are larger than the clean part's (result.radius shows each vertex's), the clean part far
    # from the cap keeps its radius
    far = vertices[:, 2] < 0.0
    assert np.median(result.radius[cap]) > 1.5 * np.median(result.radius[far])
    assert np.ptp(result.radius[far]) == 0.0


@pytest.mark.parametrize("seed", [0, 1])
def test_detached_faces_are_measured_at_their_noise_radius(seed):
    sphere = shapes.icosphere(24)
    vertices, faces = _holey(sphere.vertices, sphere.faces, seed=seed, detach=True)
    result = _default(vertices, faces)
    mean = (result.k_min + result.k_max) / 2
    valid = result.valid
    assert valid.sum() > 0.1 * len(vertices)  # ~18% before and after: the loose corners are undefined
    assert np.abs(mean[valid] - 1.0).max() < OFF


def test_a_clean_sphere_keeps_one_radius():
    sphere = shapes.icosphere(24)
    result = _default(sphere.vertices, sphere.faces)
    assert np.ptp(result.radius) == 0.0 and result.parameters.get("scale") is None
