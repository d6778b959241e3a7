"""Entries into ``meshcurv._validation`` of one default call of each public entry point (issue 33).

Run from the repository root::

    python benchmarks/validation_entries.py

For ``principal_curvatures`` (an icosphere of 642 vertices), ``multiscale_curvatures``
(the same, radii 0.1 and 0.2) and ``point_cloud_curvatures`` (2,000 points on a unit
sphere), each compiled and imported first: the calls into :mod:`meshcurv._validation`
from outside it (``sys.setprofile``), by function and caller. One entry per array
argument is the target ("validates once"); a check of an option is one entry more.
``benchmarks/prepared_mesh.py --count`` gives the same count for every method.
"""

import collections
import functools
import sys
import warnings

import numpy as np

import meshcurv
from meshcurv import _validation, shapes


def calls() -> dict:
    sphere = shapes.icosphere(3)
    points = np.random.default_rng(0).normal(size=(2000, 3))
    points /= np.linalg.norm(points, axis=1, keepdims=True)
    return {
        "principal_curvatures": lambda: meshcurv.principal_curvatures(sphere.vertices, sphere.faces),
        "multiscale_curvatures": lambda: meshcurv.multiscale_curvatures(sphere.vertices, sphere.faces, [0.1, 0.2]),
        "point_cloud_curvatures": lambda: meshcurv.point_cloud_curvatures(points),
    }


def _count(found: collections.Counter, frame, event, arg) -> None:
    """The profile function: a call into _validation from outside it, as ``"function from file:caller"``."""
    inside, caller = _validation.__file__, frame.f_back
    if event == "call" and frame.f_code.co_filename == inside and caller is not None:
        if caller.f_code.co_filename != inside:
            where = caller.f_code.co_filename.rsplit("meshcurv/", 1)[-1]
            found[f"{frame.f_code.co_name} from {where}:{caller.f_code.co_name}"] += 1


def main() -> None:
    warnings.simplefilter("ignore")
    for name, call in calls().items():
        call()  # compiled, imported
        found: collections.Counter = collections.Counter()
        sys.setprofile(functools.partial(_count, found))
        try:
            call()
        finally:
            sys.setprofile(None)
        print(f"{name}: {sum(found.values())} entries into _validation")
        for key, n in sorted(found.items()):
            print(f"    {n:3d}  {key}")


if __name__ == "__main__":
    main()
