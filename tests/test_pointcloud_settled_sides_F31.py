"""An undecided point's side, settled by its neighbours, is not decided by round-off (issue 29; fuzz_api 660/28).

``_pointcloud_normals._settled_sides`` puts each point whose side the orientation left undecided on the side of the
sum of its decided neighbours' oriented normals. Three points of ogre's cloud had their normal at right angles to
that sum (cosines -7e-16 in the file's pose, +3e-12 turned): the sign of the round-off turned them in one pose, and
the fits' check of the side of their neighbours' balls then gave 5 points other reasons (9 <-> 11). A normal within
``SIGN_COSINE`` of right angles to the sum is now left as it was, as an edge at right angles passes no sign.

Oracles: the contract (no side: as it was); the invariance under a rotation (the same reasons in every pose: ogre
turned by 660/28's motion) is tested in ``test_pointcloud_unusable_sides_F33.py``.
"""

from __future__ import annotations

import numpy as np
import pytest


def _star(cosine: float):
    """Point 0 undecided; points 1-8 its decided neighbours, their normals summing to (0, 0, 8); point 0's normal at
    ``cosine`` to that sum. Returns ``(normals, signs, settle, indices, usable)``."""
    normals = np.tile([0.0, 0.0, 1.0], (9, 1))
    normals[0] = [np.sqrt(1.0 - cosine**2), 0.0, cosine]
    signs = np.ones(9)
    settle = np.zeros(9, dtype=bool)
    settle[0] = True
    indices = np.array([[j for j in range(9) if j != i] for i in range(9)])
    return normals, signs, settle, indices, np.ones(9, dtype=bool)


@pytest.mark.parametrize("cosine", [0.0, 1e-13, -1e-13, 3e-12, -7e-16, 5e-5, -5e-5])
def test_a_normal_at_right_angles_to_its_neighbours_keeps_its_sign(cosine):
    from meshcurv._pointcloud_normals import _settled_sides

    normals, signs, settle, indices, usable = _star(cosine)
    assert _settled_sides(normals, signs, settle, indices, usable)[0] == 1.0


@pytest.mark.parametrize(("cosine", "sign"), [(0.5, 1.0), (-0.5, -1.0), (-0.01, -1.0), (0.99, 1.0)])
def test_a_normal_across_its_neighbours_takes_their_side(cosine, sign):
    from meshcurv._pointcloud_normals import _settled_sides

    normals, signs, settle, indices, usable = _star(cosine)
    assert _settled_sides(normals, signs, settle, indices, usable)[0] == sign


def test_undecided_neighbours_do_not_vote():
    # five neighbours facing the other way are undecided themselves (unsettled: the winding number contradicts them):
    # the three decided ones give the side
    from meshcurv._pointcloud_normals import _settled_sides

    normals, signs, settle, indices, usable = _star(-0.5)
    normals[0] = [np.sqrt(0.75), 0.0, 0.5]
    signs[4:] = -1.0
    undecided = settle.copy()
    undecided[4:] = True
    assert _settled_sides(normals, signs, settle, indices, usable)[0] == -1.0  # (all vote: five against three)
    assert _settled_sides(normals, signs, settle, indices, usable, undecided=undecided)[0] == 1.0
