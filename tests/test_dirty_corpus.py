"""A corpus of small dirty meshes, each built from a clean torus by one local defect.

Every case knows, by construction, which vertices the defect touches
(``core``: vertices whose neighbourhood is not a clean disc) and what the
clean mesh was, so tests can check the valid mask and that vertices far
from the defect keep their clean values. Shared by tests/test_dirty*.py (this module holds no tests).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from meshcurv import shapes

TORUS = shapes.torus(n_major=48, n_minor=24)  # 1152 vertices, closed, outward
EDGE = 2 * np.pi * 10 / 24  # about the minor-circle edge length


@dataclass
class Dirty:
    name: str
    vertices: np.ndarray
    faces: object
    core: np.ndarray  # vertices the defect touches (indices into vertices)
    clean_index: np.ndarray  # for every vertex, its index in TORUS, or -1 if new
    kind: str  # which defect: used to pick expectations
    warns: bool = True  # one MeshQualityWarning expected


def _vertex_faces(faces, v):
    return np.flatnonzero((faces == v).any(axis=1))


def cases() -> list[Dirty]:
    V, F = TORUS.vertices, TORUS.faces
    n = V.shape[0]
    ident = np.arange(n)
    p = 0  # the defect sits at vertex 0 (on the outer equator)
    star = _vertex_faces(F, p)
    out = []

    # open boundary: remove the faces around p (a hole)
    keep = np.ones(F.shape[0], dtype=bool)
    keep[star] = False
    ring = np.setdiff1d(np.unique(F[star]), [p])
    out.append(Dirty("hole", V, F[keep], np.append(ring, p), ident, "boundary"))

    # non-manifold edge: a fin on edge (a, b) of face 0
    a, b, c = F[star[0]]
    tip = (V[a] + V[b]) / 2 + 0.5 * EDGE * (V[a] - TORUS.vertices.mean(0)) / np.linalg.norm(V[a])
    out.append(
        Dirty(
            "fin",
            np.vstack([V, tip]),
            np.vstack([F, [[a, b, n]]]),
            np.array([a, b]),
            np.append(ident, -1),
            "nonmanifold",
        )
    )

    # bow-tie vertex: a small closed icosahedron touching the torus at p from outside
    ico = shapes.icosphere(1, radius=0.4 * EDGE)
    touch = np.argmin(ico.vertices[:, 0])  # p is on the outer equator (largest x)
    small = ico.vertices + (V[p] - ico.vertices[touch])
    others = np.arange(ico.vertices.shape[0]) != touch
    new_index = np.full(ico.vertices.shape[0], p)
    new_index[others] = n + np.arange(others.sum())
    out.append(
        Dirty(
            "bowtie",
            np.vstack([V, small[others]]),
            np.vstack([F, new_index[ico.faces]]),
            np.array([p]),
            np.append(ident, -np.ones(others.sum(), int)),
            "bowtie",
        )
    )

    # inconsistently oriented faces: two faces of the star reversed
    flipped = F.copy()
    flipped[star[:2]] = flipped[star[:2]][:, [0, 2, 1]]
    out.append(Dirty("flipped", V, flipped, np.unique(F[star[:2]]), ident, "inconsistent"))

    # duplicate face (same corners, same order)
    out.append(Dirty("duplicate", V, np.vstack([F, F[star[0]]]), np.unique(F[star[0]]), ident, "nonmanifold"))

    # a face with a repeated vertex, on an existing edge (a, b)
    out.append(Dirty("repeated", V, np.vstack([F, [[a, a, b]]]), np.array([a, b]), ident, "degenerate"))

    # zero-area face: c moved onto the middle of (a, b)
    moved = V.copy()
    moved[c] = (V[a] + V[b]) / 2
    out.append(Dirty("collinear", moved, F, np.array([a, b, c]), ident, "degenerate"))

    # zero-length edge: c moved onto a
    moved = V.copy()
    moved[c] = V[a]
    out.append(Dirty("zero_edge", moved, F, np.array([a, c]), ident, "degenerate"))

    # coincident vertices: p duplicated, half its faces moved to the copy (a cut through p)
    cut = F.copy()
    cut[star[:3]] = np.where(cut[star[:3]] == p, n, cut[star[:3]])
    from meshcurv.topology import MeshTopology

    seam = MeshTopology.from_faces(cut, n + 1).boundary_vertices
    out.append(Dirty("coincident", np.vstack([V, V[p]]), cut, np.flatnonzero(seam), np.append(ident, p), "boundary"))

    # unreferenced vertices, in the middle and at the end
    middle = np.vstack([V[:5], [[100.0, 100.0, 100.0]], V[5:]])
    out.append(
        Dirty(
            "unreferenced_middle",
            middle,
            np.where(F >= 5, F + 1, F),
            np.array([5]),
            np.concatenate([ident[:5], [-1], ident[5:]]),
            "unreferenced",
        )
    )
    out.append(
        Dirty(
            "unreferenced_end", np.vstack([V, [0.0, 0.0, 0.0]]), F, np.array([n]), np.append(ident, -1), "unreferenced"
        )
    )

    # several components: a sphere far away
    sphere = shapes.icosphere(2, radius=5.0, center=(200.0, 0.0, 0.0))
    out.append(
        Dirty(
            "components",
            np.vstack([V, sphere.vertices]),
            np.vstack([F, sphere.faces + n]),
            np.array([], dtype=int),
            np.append(ident, -np.ones(sphere.vertices.shape[0], int)),
            "clean",
            warns=False,
        )
    )
    return out
