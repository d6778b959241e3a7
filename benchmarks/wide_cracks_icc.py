"""icc (the default method) on meshes whose faces are detached by cracks: valid vertices off the exact H (issue 29).

The draws are those of ``benchmarks/fuzz_api.py``'s detached faces (its ``m_detached``): a share (0.05, 0.2, 0.5
or 1 of the faces, at random; ``--share`` keeps the draws of that share) gets corners of its own, each moved in a
random direction by ``gap`` mean edge lengths, ``gap`` log-uniform in [0.05, 0.1] (beyond the weld:
``--wide-cracks``) in ``--wide`` of the draws and in [1e-4, 1e-2] (welded back) in the others. The bases are the fuzzer's coarse shapes and two finer ones. For each shape the
table gives the draws, the valid vertices, those off the exact H at their corner (a copy takes its nearest base
vertex's) by more than half of the shape's largest exact ``|k|`` (the fuzzer's bar), those off the clean mesh's own
icc estimate by as much (the fuzzer's ``detached`` relation), and the largest error in units of that ``|k|``.
Run it on a snapshot (``PYTHONPATH=<snapshot>/src``) to compare two commits.

    python benchmarks/wide_cracks_icc.py [--seeds 0-9] [--wide 1] [--share S] [--shapes NAMES] [--radius-edges R]
"""

from __future__ import annotations

import argparse
import time
import warnings

import numpy as np
from scipy.spatial import cKDTree

import meshcurv
from meshcurv import shapes

import fuzz_api  # (benchmarks/: the fuzzer's draw of detached faces)


def bases() -> dict:
    """The meshes drawn from: the fuzzer's coarse shapes (``fuzz_api.base_meshes``) and finer ones."""
    return {
        "uv_sphere(12, 8)": lambda: shapes.uv_sphere(n_longitude=12, n_latitude=8),
        "uv_sphere()": lambda: shapes.uv_sphere(),
        "icosphere(6)": lambda: shapes.icosphere(subdivisions=6),
        "icosphere(12)": lambda: shapes.icosphere(subdivisions=12),
        "ellipsoid(5)": lambda: shapes.ellipsoid(subdivisions=5),
        "torus(16, 8)": lambda: shapes.torus(n_major=16, n_minor=8),
        "torus(32, 16)": lambda: shapes.torus(n_major=32, n_minor=16),
        "hemisphere(6)": lambda: shapes.hemisphere(subdivisions=6),
        "random_sphere(200)": lambda: shapes.random_sphere(n_vertices=200),
        "voxel_sphere(4)": lambda: shapes.voxel_sphere(radius=4.0),
        "voxel_sphere(6)": lambda: shapes.voxel_sphere(radius=6.0),
    }


def detached(seed: int, index: int, vertices, faces, wide: float, share: float | None = None):
    """``(vertices, faces, share, gap)``: ``fuzz_api.m_detached``'s draw (the fuzzer's own, its wide gaps in
    ``wide`` of the draws) from the stream ``[seed, index, 29, j]``, the first ``j`` whose share is ``share`` when
    given."""
    fuzz_api.WIDE_CRACKS = wide
    for attempt in range(1000):
        rng = np.random.default_rng([seed, index, 29, attempt])
        moved, moved_faces, label = fuzz_api.m_detached(rng, vertices, faces)
        drawn, gap = (float(word) for word in label.split()[-3::2])  # "detached faces {share} by {gap}"
        if share is None or drawn == share:
            return moved, moved_faces, drawn, gap
    raise ValueError(f"no draw of share {share}")


def seed_list(text: str) -> list[int]:
    """``"0-9"`` or ``"1,5,7"`` as a list of ints."""
    if "-" in text:
        first, last = text.split("-")
        return list(range(int(first), int(last) + 1))
    return [int(part) for part in text.split(",")]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", default="0-9", help="seeds, as 0-9 or 1,5,7 (default: %(default)s)")
    parser.add_argument("--wide", type=float, default=1.0, help="share of the draws with wide cracks")
    parser.add_argument("--shapes", default=None, help="names of bases() separated by ';' (default: all)")
    parser.add_argument("--share", type=float, default=None, help="the share of the faces detached (default: drawn)")
    parser.add_argument("--radius-edges", type=float, default=None, help="a given radius, in median edge lengths")
    parser.add_argument("--list", action="store_true", help="list every valid vertex off (draw, row, H, exact)")
    options = parser.parse_args(argv)
    chosen = bases()
    if options.shapes:
        chosen = {name: chosen[name] for name in options.shapes.split(";")}
    print("| mesh | draws | valid | off exact | off clean | max error / max abs k | CPU s |")
    print("|---|--:|--:|--:|--:|--:|--:|")
    totals = np.zeros(4, dtype=np.int64)
    for name, make in chosen.items():
        index = list(bases()).index(name)  # (the draws of a shape do not depend on the others chosen)
        mesh = make()
        base, base_faces = np.asarray(mesh.vertices, float), np.asarray(mesh.faces, np.int64)
        exact_h = 0.5 * (np.asarray(mesh.k_min) + np.asarray(mesh.k_max))
        scale = float(np.max(np.abs(np.concatenate([mesh.k_min, mesh.k_max]))))
        edge = float(np.median(np.linalg.norm(base[base_faces[:, 0]] - base[base_faces[:, 1]], axis=1)))
        kwargs = {"method": "icc"}
        if options.radius_edges is not None:
            kwargs["radius"] = options.radius_edges * edge
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            clean = meshcurv.principal_curvatures(base, base_faces, **kwargs)
        valid = off = off_clean = 0
        largest = 0.0
        cpu = time.process_time()
        tree = cKDTree(base)
        for seed in seed_list(options.seeds):
            vertices, faces, share, gap = detached(seed, index, base, base_faces, options.wide, options.share)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                result = meshcurv.principal_curvatures(vertices, faces, **kwargs)
            nearest = tree.query(vertices)[1]
            rows = np.flatnonzero(result.valid)
            error = np.abs(result.mean[rows] - exact_h[nearest[rows]]) / scale
            error_clean = np.abs(result.mean[rows] - clean.mean[nearest[rows]]) / scale
            valid += rows.size
            off += int((error > 0.5).sum())
            off_clean += int((error_clean > 0.5).sum())
            largest = max(largest, float(error.max(initial=0.0)))
            if options.list:
                for row in rows[error > 0.5]:
                    print(
                        f"  {name} seed {seed} share {share:g} gap {gap:.3g}: row {row} H {result.mean[row]:.3f} "
                        f"exact {exact_h[nearest[row]]:.3f}"
                    )
        cpu = time.process_time() - cpu
        draws = len(seed_list(options.seeds))
        print(f"| {name} | {draws} | {valid} | {off} | {off_clean} | {largest:.3f} | {cpu:.1f} |", flush=True)
        totals += [draws, valid, off, off_clean]
    print(f"| all | {totals[0]} | {totals[1]} | {totals[2]} | {totals[3]} | | |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
