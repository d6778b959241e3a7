"""The weld's cost on a noisy triangle soup, and a hash of its output on many soups and cracked meshes.

Run it on two checkouts (``PYTHONPATH=<checkout>/src``): the CPU medians compare the speed, the hashes (``--hashes``)
show that the welds are the same, case by case (``diff`` the two outputs).

    python benchmarks/weld_cost.py --runs 9
    python benchmarks/weld_cost.py --hashes > after.txt
"""

from __future__ import annotations

import argparse
import hashlib
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from meshcurv import MeshTopology, shapes
from meshcurv.weld import _weld_coincident, _weld_cracks, weld_vertices

sys.path.insert(0, str(Path(__file__).resolve().parent))
from wide_cracks import moved_corners  # noqa: E402


def noisy_soup(mesh, scale, seed=0):
    """``(vertices, faces)``: every face of ``mesh`` with its own corners, moved by ``scale`` mean edge lengths."""
    vertices, faces = mesh.vertices, mesh.faces
    rng = np.random.default_rng(seed)
    soup = vertices[faces.ravel()]
    edge = float(np.mean(np.linalg.norm(vertices[faces[:, 0]] - vertices[faces[:, 1]], axis=1)))
    return soup + rng.normal(scale=scale * edge, size=soup.shape), np.arange(soup.shape[0]).reshape(-1, 3)


def timing(runs):
    """CPU medians of the weld of a 40,000-face soup whose corners moved by 0.01 mean edge lengths."""
    vertices, faces = noisy_soup(shapes.random_sphere(20000), 0.01)
    weld_vertices(vertices, MeshTopology.from_faces(faces))  # imports and lazy caches
    whole, coincident, cracks = [], [], []
    for _ in range(runs):
        topology = MeshTopology.from_faces(faces)
        start = time.process_time()
        weld_vertices(vertices, topology)
        whole.append(time.process_time() - start)
        start = time.process_time()
        strict = _weld_coincident(vertices, topology, 1e-5)
        coincident.append(time.process_time() - start)
        start = time.process_time()
        _weld_cracks(strict.vertices, strict.topology, 0.05)
        cracks.append(time.process_time() - start)
    print(
        f"{faces.shape[0]} faces, {runs} runs, CPU s medians: weld_vertices {np.median(whole):.3f} "
        f"(coincident {np.median(coincident):.3f}, cracks {np.median(cracks):.3f})"
    )


def cases():
    """Yield ``(name, vertices, faces)``: wide_cracks.py's meshes, noisy soups, cracked meshes, random soups."""
    for name, mesh in {
        "icosphere(8)": shapes.icosphere(8),
        "random_sphere(500)": shapes.random_sphere(500),
        "random_sphere(642)": shapes.random_sphere(642),
    }.items():
        for kind in ("hanging", "detached"):
            for seed in range(6):
                for gap in (0.1, 0.05, 0.2):
                    vertices, faces = moved_corners(
                        mesh.vertices, mesh.faces, 0.2, gap, seed, keep_one=kind == "hanging"
                    )
                    yield f"wide_cracks-{name}-{kind}-{seed}-{gap}", vertices, faces
    for name, mesh in {
        "icosphere(3)": shapes.icosphere(3),
        "torus": shapes.torus(),
        "random_sphere(500)": shapes.random_sphere(500),
    }.items():
        for seed in range(4):
            for scale in (0.0, 5e-8, 5e-4, 0.005, 0.015, 0.025, 0.04):
                vertices, faces = noisy_soup(mesh, scale, seed)
                yield f"soup-{name}-{seed}-{scale}", vertices, faces
    rng = np.random.default_rng(19)
    for k in range(200):
        n = int(rng.integers(20, 1500))
        if k % 4 == 0:  # soups of parts at scales 1e-6 to 1e6
            parts = []
            for _ in range(int(rng.integers(1, 4))):
                mesh = shapes.icosphere(int(rng.integers(1, 4)))
                scale = 10.0 ** rng.uniform(-6, 6)
                soup = mesh.vertices[mesh.faces.ravel()] * scale + rng.normal(size=3) * scale
                parts.append(soup + rng.normal(scale=scale * 10.0 ** rng.uniform(-9, -2), size=soup.shape))
            vertices = np.vstack(parts)
            faces = np.arange(vertices.shape[0]).reshape(-1, 3)
        elif k % 4 == 1:  # random faces over collinear points (fuzz 342/923's class)
            t = rng.random(3 * n)
            vertices, faces = np.stack([t, 2 * t, 3 * t], axis=1), rng.integers(0, 3 * n, size=(n, 3))
        elif k % 4 == 2:  # corners on a few points, with round-off
            centres = rng.normal(size=(int(rng.integers(1, 6)), 3))
            vertices = centres[rng.integers(0, centres.shape[0], 3 * n)]
            vertices = vertices + rng.normal(scale=10.0 ** rng.uniform(-12, -3), size=vertices.shape)
            faces = np.arange(3 * n).reshape(-1, 3)
        else:  # random faces over points on a coarse grid
            vertices = np.round(rng.random((3 * n, 3)) * int(rng.integers(2, 20))) / 7
            faces = np.arange(3 * n).reshape(-1, 3)
        yield f"random-{k}", vertices, faces


def hashes():
    """Print each case's welded counts and a hash of its welded vertices, faces and index."""
    for name, vertices, faces in cases():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            welded = weld_vertices(vertices, MeshTopology.from_faces(faces))
        digest = hashlib.sha1(welded.index.tobytes() + welded.topology.faces.tobytes() + welded.vertices.tobytes())
        print(name, welded.n_welded, welded.n_cracked, digest.hexdigest()[:12])


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=7)
    parser.add_argument("--hashes", action="store_true", help="print the hashes of the welds instead of timing")
    args = parser.parse_args(argv)
    if args.hashes:
        hashes()
    else:
        timing(args.runs)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
