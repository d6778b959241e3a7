"""``equal_S28.py`` for any mesh method, with large meshes and the invalid reasons (issue 31, helper S30).

The cases of :mod:`equal_S28` (the options a method does not take left out: ``radius``, ``radii`` for the ring
methods), plus meshes above :data:`meshcurv._locality.MIN_VERTICES` (an icosphere of 100k vertices, computed with
its faces sorted, the same with its vertices shuffled: the scattered order, a torus with holes) and every result
field with ``invalid_reason``; saved to an ``.npz`` or compared with one. Old and new code in turns::

    PYTHONPATH=/tmp/old/src python benchmarks/equal_S30.py --method normal_cycle --save /tmp/old_nc.npz
    python benchmarks/equal_S30.py --method normal_cycle --compare /tmp/old_nc.npz
"""

from __future__ import annotations

import argparse
import os
import sys
from types import SimpleNamespace

import numpy as np

from meshcurv import shapes

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import equal_S28  # noqa: E402

FIELDS = (*equal_S28.FIELDS, "invalid_reason")
BALL_METHODS = ("icc", "quadric", "normal_cycle_ball")


def _large():
    sphere = shapes.icosphere(100)
    yield "icosphere(100)", sphere
    order = np.random.default_rng(7).permutation(sphere.vertices.shape[0])
    rows = np.empty_like(order)
    rows[order] = np.arange(order.size)
    yield "icosphere(100) shuffled", SimpleNamespace(vertices=sphere.vertices[order], faces=rows[sphere.faces])
    torus = shapes.torus(n_major=400, n_minor=120)
    keep = np.random.default_rng(8).random(torus.faces.shape[0]) > 0.02
    yield "torus holed", SimpleNamespace(vertices=torus.vertices, faces=torus.faces[keep])


def main(argv=None) -> int:
    """``equal_S28.py``'s options, saving and comparison, on these cases and fields."""
    cases, method = equal_S28._cases, argparse.ArgumentParser(add_help=False)
    method.add_argument("--method", default="icc")
    ball = method.parse_known_args(argv)[0].method in BALL_METHODS

    def every_case(quick: bool):
        yield from ((name, mesh, options) for name, mesh, options in cases(quick) if ball or not options)
        yield from ((name, mesh, {}) for name, mesh in _large())

    equal_S28._cases, equal_S28.FIELDS = every_case, FIELDS
    return equal_S28.main(argv)


if __name__ == "__main__":
    raise SystemExit(main())
