"""Spheres with half of their faces removed or detached, wound either way: which side orient_faces gives them.

Per case: the share of the faces that face away from the sphere's centre after ``orient_faces`` (1: outward,
as a sphere must be measured; 0.5: the detached half left inside out) and the CPU time of the call. Run it on
two checkouts to compare (``PYTHONPATH=<checkout>/src``); ``--faces`` also prints each case's flips, so that two
runs can be compared face by face (``--save``).

    python benchmarks/orient_winding.py --spheres icosphere_50 voxel_36 --save after.npz
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from meshcurv import shapes
from meshcurv.orient import orient_faces

# the cases of tests/test_orient_holey_inward.py: half of the faces removed, or detached (moved off by 0.054 edges)
sys.path.insert(0, str(Path(__file__).resolve().parent.parent / "tests"))
from test_orient_holey_inward import _holey as holey  # noqa: E402


def sphere(name):
    """``(vertices, faces)`` of ``icosphere_<n>`` (20 n^2 faces) or ``voxel_<r>`` (marching cubes, radius r)."""
    kind, size = name.split("_")
    made = shapes.icosphere(int(size)) if kind == "icosphere" else shapes.voxel_sphere(radius=float(size))
    return made.vertices, made.faces


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spheres", nargs="+", default=["icosphere_50", "voxel_36"])
    parser.add_argument("--seeds", nargs="+", type=int, default=[0, 1, 2])
    parser.add_argument("--windings", nargs="+", default=["as_made", "reversed"])
    parser.add_argument("--modes", nargs="+", default=["removed", "detached"])
    parser.add_argument("--save", help="an .npz of each case's flipped faces")
    args = parser.parse_args(argv)
    saved = {}
    print("sphere faces mode winding seed kept_faces outward_share orient_cpu_s")
    for name in args.spheres:
        vertices, faces = sphere(name)
        centre = vertices.mean(axis=0)
        for mode in args.modes:
            for winding in args.windings:
                for seed in args.seeds:
                    given = faces[:, [0, 2, 1]] if winding == "reversed" else faces
                    points, cut = holey(vertices, given, seed=seed, detach=mode == "detached")
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")  # welds, isolated faces: reported, not the point here
                        start = time.process_time()
                        oriented, _ = orient_faces(points, cut)
                        cpu = time.process_time() - start
                    corners = points[oriented]
                    normals = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
                    outward = np.einsum("ij,ij->i", normals, corners.mean(axis=1) - centre) > 0
                    print(name, len(faces), mode, winding, seed, len(cut), f"{outward.mean():.4f}", f"{cpu:.2f}")
                    saved[f"{name}-{mode}-{winding}-{seed}"] = oriented[:, 1] != cut[:, 1]
    if args.save:
        np.savez_compressed(args.save, **saved)


if __name__ == "__main__":
    main()
