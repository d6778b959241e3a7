"""The side the default orientation gives surfaces with detached faces (issue 29): draws measured inside out.

The draws are those of ``benchmarks/wide_cracks_icc.py`` (``fuzz_api.m_detached``: a share of the faces given
corners of their own, moved by ``gap`` mean edge lengths), each mesh prepared as
:func:`meshcurv.principal_curvatures` prepares it (welded, then ``orient="outward"``), given as made (outward; the
voxel surfaces inward, as marching cubes winds them) or reversed. A face is *outward* when its normal agrees with
the exact normal (outward) of the base vertex nearest its centroid; a closed base's draw is *inside out* when
less than half of its face area is outward. The open ``hemisphere(6)`` must keep the winding given: its draws are
counted *turned* when less than half of its area keeps it. Run it on a snapshot (``PYTHONPATH=<snapshot>/src``)
to compare two commits.

    python benchmarks/cracked_orient.py [--seeds 0-39] [--wide 1] [--share S] [--shapes NAMES] [--windings W] [--list]
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from scipy.spatial import cKDTree

from meshcurv._prepared import prepare_mesh

import wide_cracks_icc  # (benchmarks/: the bases and the draws)

#: Bases that are open: their draws must keep the winding given, not turn outward.
OPEN_BASES = ("hemisphere(6)",)


def outward_share(vertices, faces, base, normals) -> float:
    """The share of the area of ``faces`` whose normals agree with the exact ``normals`` of the nearest ``base``
    vertex."""
    corners = vertices[faces]
    normal = np.cross(corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0])
    area = np.linalg.norm(normal, axis=1)
    nearest = cKDTree(base).query(corners.mean(axis=1))[1]
    agree = np.einsum("ij,ij->i", normal, normals[nearest]) > 0
    return float(area[agree].sum() / max(area.sum(), np.finfo(float).tiny))


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="0-39", help="seeds, as 0-9 or 1,5,7 (default: %(default)s)")
    parser.add_argument("--wide", type=float, default=1.0, help="share of the draws with wide cracks")
    parser.add_argument("--shapes", default=None, help="names of the bases separated by ';' (default: all)")
    parser.add_argument("--share", type=float, default=None, help="the share of the faces detached (default: drawn)")
    parser.add_argument("--windings", default="as_made,reversed", help="as_made, reversed or both (default)")
    parser.add_argument("--list", action="store_true", help="list every draw inside out (or turned)")
    options = parser.parse_args(argv)
    chosen = wide_cracks_icc.bases()
    names = list(chosen)
    if options.shapes:
        chosen = {name: chosen[name] for name in options.shapes.split(";")}
    seeds = wide_cracks_icc.seed_list(options.seeds)
    print("| mesh | winding | draws | inside out (open: turned) | mean outward share | CPU s |")
    print("|---|---|--:|--:|--:|--:|")
    totals = np.zeros(2, dtype=np.int64)
    for name, make in chosen.items():
        mesh = make()
        base, base_faces = np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)
        normals = np.asarray(mesh.normals, float)  # outward (the hemisphere's: the side it is wound towards)
        for winding in options.windings.split(","):
            given = base_faces[:, [0, 2, 1]] if winding == "reversed" else base_faces
            kept = -1.0 if winding == "reversed" and name in OPEN_BASES else 1.0
            wrong = 0
            shares = []
            cpu = time.process_time()
            for seed in seeds:
                vertices, faces, share, gap = wide_cracks_icc.detached(
                    seed, names.index(name), base, given, options.wide, options.share
                )
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    mesh_ = prepare_mesh(vertices, faces, orient="outward", weld=True)
                value = outward_share(mesh_.vertices, np.asarray(mesh_.topology.faces), base, kept * normals)
                shares.append(value)
                if value < 0.5:
                    wrong += 1
                    if options.list:
                        print(f"  {name} {winding} seed {seed} share {share:g} gap {gap:.3g}: outward {value:.3f}")
            cpu = time.process_time() - cpu
            print(f"| {name} | {winding} | {len(seeds)} | {wrong} | {np.mean(shares):.3f} | {cpu:.1f} |", flush=True)
            totals += [len(seeds), wrong]
    print(f"| all | | {totals[0]} | {totals[1]} | | |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
