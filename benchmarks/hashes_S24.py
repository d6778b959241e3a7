"""Hashes of the default method's fields on a set of meshes (issue 31, helper S24: changes that must not move a bit).

Prints one line per mesh: the SHA-256 of ``k_min, k_max, dir_min, dir_max, normals, valid`` of
``meshcurv.principal_curvatures(v, f)`` (default method and options). Run it on two commits (one through
``PYTHONPATH=<snapshot>/src``) and on both backends (``MESHCURV_BACKEND=numpy``), and compare the outputs::

    .venv/bin/python benchmarks/hashes_S24.py > new.txt
"""

from __future__ import annotations

import hashlib
import os
import sys
import warnings

import numpy as np

import meshcurv
from meshcurv import shapes

MESHES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "meshes")


def _soup(mesh, seed=0):
    """Every face with its own corners, each face moved by 0.03 of an edge: welded back by the call."""
    rng = np.random.default_rng(seed)
    corners = mesh.vertices[mesh.faces].reshape(-1, 3)
    edge = float(np.linalg.norm(mesh.vertices[mesh.faces[0, 0]] - mesh.vertices[mesh.faces[0, 1]]))
    shift = np.repeat(rng.normal(scale=0.03 * edge, size=(mesh.faces.shape[0], 3)), 3, axis=0)
    return corners + shift, np.arange(corners.shape[0]).reshape(-1, 3)


def cases():
    sphere = shapes.icosphere(24)
    yield "icosphere(24)", sphere.vertices, sphere.faces
    torus = shapes.torus()
    yield "torus()", torus.vertices, torus.faces
    voxel = shapes.voxel_sphere(8)
    yield "voxel_sphere(8)", voxel.vertices, voxel.faces
    random = shapes.random_sphere(3000)
    yield "random_sphere(3000)", random.vertices, random.faces
    yield "soup of icosphere(12)", *_soup(shapes.icosphere(12))
    half = shapes.icosphere(16)
    kept = half.faces[half.vertices[half.faces].mean(axis=1)[:, 2] > -0.3]
    yield "icosphere(16) cut", half.vertices, kept
    for name in ("spot.obj", "fandisk.obj", "rocker-arm.obj"):
        path = os.path.join(MESHES, name)
        if os.path.exists(path):
            mesh = meshcurv.io.read_mesh(path)
            yield name, mesh.vertices, mesh.faces


def main() -> int:
    for name, vertices, faces in cases():
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = meshcurv.principal_curvatures(np.asarray(vertices), np.asarray(faces))
        digest = hashlib.sha256()
        for field in ("k_min", "k_max", "dir_min", "dir_max", "normals", "valid"):
            digest.update(np.ascontiguousarray(getattr(result, field)).tobytes())
        print(f"{name}: {digest.hexdigest()[:16]} valid {int(result.valid.sum())}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
