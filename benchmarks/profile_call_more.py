"""``profile_call.py`` with five more stages (issue 31, helper S20): the noisy patches of icc's default radius
(:func:`meshcurv.radius._patch_radii` and ``_patch_factor``, their rings), the voxel grid's reading
(``radius._subset_voxel_grid``), and two pieces of the ball sums (the cell centres and the faces around each vertex).
The same options as ``profile_call.py``::

    .venv/bin/python benchmarks/profile_call_more.py --sizes 100k,1M --repeats 3
"""

from __future__ import annotations

import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import profile_call  # noqa: E402

profile_call.STAGES = (
    *profile_call.STAGES,
    ("radius: noisy patches (rings)", "meshcurv.radius", "_patch_factor"),
    ("radius: noisy patches (rings)", "meshcurv.radius", "_patch_radii"),
    ("ball sums: cell centres", "meshcurv._kernels.neighborhoods", "cell_centres"),
    ("ball sums: vertex face lists", "meshcurv._kernels.neighborhoods", "vertex_face_lists"),
    ("radius: voxel grid (lattice)", "meshcurv.radius", "_subset_voxel_grid"),
)

if __name__ == "__main__":
    sys.exit(profile_call.main())
