"""Mesh families for the per-vertex scale study (issue 30), with exact curvatures.

Used by ``benchmarks/scale_prototype.py``; see ``benchmarks/scale.md``. Every
builder returns a :class:`Case`: vertices, faces wound **outward**, and the exact
``k_min, k_max, H, K`` per vertex (at the vertex, or at its closest point on the
analytic surface for marching-cubes meshes).

Tuning families (constants may be tuned on them):

- ``accuracy``: the clean (regular, irregular) and noisy (0.1 h and 0.3 h of
  uniform normal noise) spheres, tori and ellipsoids of ``benchmarks/accuracy.py``
  (its own builder, levels 0-2).
- ``voxel``: the binary marching-cubes meshes of ``accuracy.py --voxel`` that it
  does not mark held out (``meshcurv.shapes.voxel_*``).

Held-out families (never tuned on):

- ``smoothed``: a binary mask (voxel 1) blurred by a Gaussian of sigma 0.5, 1, 2
  voxels, then ``skimage.measure.marching_cubes`` at level 0.5; spheres, tori and
  ellipsoids of radii 6-40 voxels; exact values at the closest point of the
  analytic (unblurred) surface.
- ``varying``: a sphere and an ellipsoid through random points whose density
  is 100 times larger on the upper half (z > 0) than on the lower (edge lengths
  10:1), triangulated by their convex hull; ``parts`` names the fine
  (z > 0.1 of the extent) and coarse (z < -0.1) vertices.
- ``elongated``: binary marching cubes of elongated ellipsoids (4:1:1, 6:1.5:1)
  and thin tori (R / r = 6, 10) under voxels of aspect 2:1 and 3:1.
- ``failing``: the 5 meshes of ``benchmarks/accuracy_voxel.md`` whose default
  call misses its target (two of them are in the tuning set of ``accuracy.py``:
  they are listed in both).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from meshcurv import shapes


@dataclass(eq=False)
class Case:
    """One mesh of the study and its exact curvatures.

    Attributes
    ----------
    name : str
    family : str
        ``accuracy``, ``voxel``, ``smoothed``, ``varying``, ``elongated`` or ``failing``.
    group : str
        A finer label for the tables (``sphere regular``, ``sigma 1``, ...).
    tuning : bool
        True for the families constants may be tuned on.
    vertices : ndarray of shape (V, 3)
    faces : ndarray of shape (F, 3)
        Wound outward.
    k_min, k_max : ndarray of shape (V,)
        Exact principal curvatures (outward normal: a convex solid is positive).
    parts : dict of str to ndarray of bool, optional
        Vertex subsets reported on their own (``fine``, ``coarse``).
    spacing : tuple of 3 floats or None
        The voxel size of a marching-cubes mesh.
    """

    name: str
    family: str
    group: str
    tuning: bool
    vertices: np.ndarray
    faces: np.ndarray
    k_min: np.ndarray
    k_max: np.ndarray
    parts: dict = field(default_factory=dict)
    spacing: tuple | None = None

    @property
    def mean(self) -> np.ndarray:
        return (self.k_min + self.k_max) / 2

    @property
    def gaussian(self) -> np.ndarray:
        return self.k_min * self.k_max


def _from_analytic(mesh, family, group, tuning, *, outward=True, spacing=None, parts=None) -> Case:
    faces = np.ascontiguousarray(mesh.faces if outward else mesh.faces[:, ::-1], dtype=np.int64)
    return Case(
        mesh.name,
        family,
        group,
        tuning,
        np.asarray(mesh.vertices, dtype=float),
        faces,
        np.asarray(mesh.k_min, dtype=float),
        np.asarray(mesh.k_max, dtype=float),
        parts or {},
        spacing,
    )


# -- tuning families ------------------------------------------------------------------


def accuracy_cases(levels=(0, 1, 2)):
    """The spheres, tori and ellipsoids of ``benchmarks/accuracy.py`` (clean, irregular, noisy)."""
    import accuracy  # benchmarks/ is on sys.path when run from there or through scale_prototype.py

    families = ["sphere", "torus", "ellipsoid"]
    for surface, variant, level, mesh in accuracy.surfaces(list(levels), families):
        case = _from_analytic(mesh, "accuracy", f"{surface} {variant}", True)
        case.name = f"{mesh.name} [level {level}]"
        yield case


def voxel_cases(held_out=False):
    """The binary marching-cubes meshes of ``accuracy.py --voxel`` (those tuned on, or the held-out ones)."""
    import accuracy

    for mesh, out in accuracy.voxel_meshes(held_out=held_out):
        aspect = max(mesh.spacing) / min(mesh.spacing)
        yield _from_analytic(
            mesh, "voxel", "isotropic" if aspect == 1 else "anisotropic", not out, outward=False, spacing=mesh.spacing
        )


# -- held-out families ------------------------------------------------------------------


def _grid(extent, spacing, seed):
    """Axes of a grid spanning ``extent`` (half-widths) plus margins, centred at a random sub-voxel offset."""
    spacing = np.asarray(spacing, dtype=float)
    counts = np.ceil(2 * (np.asarray(extent, dtype=float) + 4 * spacing.max()) / spacing).astype(int) + 5
    center = ((counts - 1) / 2 + np.random.default_rng(seed).random(3) - 0.5) * spacing
    axes = [np.arange(n) * s - c for n, s, c in zip(counts, spacing, center)]
    return axes, center


def _smoothed_mesh(inside, extent, sigma, seed):
    """Marching cubes at 0.5 of the binary mask of ``inside`` blurred by a Gaussian of ``sigma`` voxels (voxel 1)."""
    from scipy.ndimage import gaussian_filter
    from skimage.measure import marching_cubes

    axes, center = _grid(extent, (1.0, 1.0, 1.0), seed)
    mask = inside(*np.meshgrid(*axes, indexing="ij", sparse=True)).astype(float)
    blurred = gaussian_filter(mask, sigma) if sigma > 0 else mask
    vertices, faces, _, _ = marching_cubes(blurred, 0.5)
    return vertices.astype(float) - center, np.ascontiguousarray(faces[:, ::-1], dtype=np.int64)


def _sphere_exact(points, radius):
    n = points.shape[0]
    return np.full(n, 1 / radius), np.full(n, 1 / radius)


def _torus_exact(points, major, minor):
    """Torus around axis 0: ``k_min`` along the ring, ``k_max = 1 / r`` around the tube (outward)."""
    rho = np.hypot(points[:, 1], points[:, 2])
    radial = np.zeros_like(points)
    radial[:, 1:] = points[:, 1:] / rho[:, None]
    tube = points - major * radial
    normals = tube / np.linalg.norm(tube, axis=1, keepdims=True)
    cos_phi = np.sum(normals * radial, axis=1)
    return cos_phi / (major + minor * cos_phi), np.full(points.shape[0], 1 / minor)


def _ellipsoid_exact(points, semi_axes, *, closest=True):
    a = np.asarray(semi_axes, dtype=float)
    local = shapes.ellipsoid_closest_points(points, a) if closest else points
    inv2 = 1.0 / a**2
    hessian = np.zeros((local.shape[0], 6))
    hessian[:, :3] = 2 * inv2
    k_min, k_max, *_ = shapes._implicit(local, 2 * local * inv2, hessian)
    return k_min, k_max


def _solid(kind, size):
    """``(inside(x, y, z), extent, exact(points))`` of a solid centred at the origin."""
    if kind == "sphere":
        (r,) = size
        return (lambda x, y, z: x * x + y * y + z * z <= r * r), np.full(3, r), lambda p: _sphere_exact(p, r)
    if kind == "torus":
        big, small = size
        return (
            (lambda x, y, z: x * x + (np.sqrt(y * y + z * z) - big) ** 2 <= small * small),
            np.array([small, big + small, big + small]),
            lambda p: _torus_exact(p, big, small),
        )
    a = np.asarray(size, dtype=float)
    return (
        (lambda x, y, z: x * x / a[0] ** 2 + y * y / a[1] ** 2 + z * z / a[2] ** 2 <= 1),
        a,
        lambda p: _ellipsoid_exact(p, a),
    )


#: The smoothed isosurfaces: (kind, size in voxels, blur sigmas).
SMOOTHED = [
    ("sphere", (6.0,), (1.0,)),
    ("sphere", (10.0,), (0.5, 1.0, 2.0)),
    ("sphere", (20.0,), (0.5, 1.0, 2.0)),
    ("sphere", (40.0,), (1.0,)),
    ("torus", (25.0, 10.0), (0.5, 1.0, 2.0)),
    ("torus", (16.0, 6.0), (1.0,)),
    ("ellipsoid", (24.0, 16.0, 10.0), (1.0, 2.0)),
]


def smoothed_cases():
    """Marching cubes of blurred binary masks (voxel 1): the held-out ``smoothed`` family."""
    seed = 100
    for kind, size, sigmas in SMOOTHED:
        inside, extent, exact = _solid(kind, size)
        for sigma in sigmas:
            seed += 1
            vertices, faces = _smoothed_mesh(inside, extent, sigma, seed)
            k_min, k_max = exact(vertices)
            label = ", ".join(f"{s:g}" for s in size)
            yield Case(
                f"smoothed {kind}({label}), sigma {sigma:g}",
                "smoothed",
                f"sigma {sigma:g}",
                False,
                vertices,
                faces,
                k_min,
                k_max,
                spacing=(1.0, 1.0, 1.0),
            )


def _varying_points(n_coarse, ratio, seed):
    """Unit-sphere points, ``ratio`` times denser on z > 0 (in points per area)."""
    rng = np.random.default_rng(seed)

    def draw(n, sign):
        p = rng.normal(size=(n, 3))
        p[:, 2] = sign * np.abs(p[:, 2])
        return p / np.linalg.norm(p, axis=1, keepdims=True)

    return np.concatenate([draw(int(n_coarse * ratio), 1.0), draw(n_coarse, -1.0)])


def _hull(points):
    from scipy.spatial import ConvexHull

    faces = ConvexHull(points).simplices.astype(np.int64)
    a, b, c = (points[faces[:, k]] for k in range(3))
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), a + b + c) < 0
    faces[inward] = faces[inward][:, ::-1]
    return faces


def varying_cases(n_coarse=250, ratio=100.0):
    """A sphere (r 1) and an ellipsoid (3, 2, 1) whose upper half has 100x the point density (10:1 edges)."""
    unit = _varying_points(n_coarse, ratio, seed=7)
    faces = _hull(unit)
    parts = {"fine": unit[:, 2] > 0.1, "coarse": unit[:, 2] < -0.1}
    n = unit.shape[0]
    yield Case(
        f"varying sphere ({n} points, density 100:1)",
        "varying",
        "sphere",
        False,
        unit,
        faces,
        np.ones(n),
        np.ones(n),
        parts,
    )
    a = np.array([3.0, 2.0, 1.0])
    k_min, k_max = _ellipsoid_exact(unit * a, a, closest=False)
    yield Case(
        f"varying ellipsoid(3, 2, 1) ({n} points, density 100:1)",
        "varying",
        "ellipsoid",
        False,
        unit * a,
        faces,
        k_min,
        k_max,
        parts,
    )


#: Elongated ellipsoids and thin tori under anisotropic voxels: (kind, size, spacing).
ELONGATED = [
    ("ellipsoid", (20.0, 5.0, 5.0), (1.0, 0.5, 0.5)),
    ("ellipsoid", (20.0, 5.0, 5.0), (1.5, 0.5, 0.5)),
    ("ellipsoid", (5.0, 20.0, 5.0), (1.0, 0.5, 0.5)),
    ("ellipsoid", (24.0, 6.0, 4.0), (1.0, 0.5, 0.5)),
    ("ellipsoid", (24.0, 6.0, 4.0), (1.5, 0.5, 0.5)),
    ("torus", (18.0, 3.0), (0.6, 0.3, 0.3)),
    ("torus", (18.0, 3.0), (0.9, 0.3, 0.3)),
    ("torus", (20.0, 2.0), (0.5, 0.25, 0.25)),
]


def elongated_cases():
    """Binary marching cubes of elongated ellipsoids and thin tori, voxels 2:1 and 3:1 (held out)."""
    for seed, (kind, size, spacing) in enumerate(ELONGATED, start=200):
        mesh = (
            shapes.voxel_ellipsoid(size, spacing, seed=seed)
            if kind == "ellipsoid"
            else shapes.voxel_torus(*size, spacing, seed=seed)
        )
        aspect = max(spacing) / min(spacing)
        yield _from_analytic(mesh, "elongated", f"{kind} {aspect:g}:1", False, outward=False, spacing=mesh.spacing)


#: The meshes of benchmarks/accuracy_voxel.md whose default call misses its target (at 8e135c3).
FAILING = [
    ("torus", (12.0, 4.0), (0.5, 0.5, 0.5), 5),
    ("torus", (12.0, 4.0), (2.0, 0.5, 0.5), 12),
    ("ellipsoid", ((12.0, 6.0, 4.0),), (0.4, 0.4, 0.4), 15),
    ("ellipsoid", ((5.0, 8.0, 12.0),), (1.2, 0.4, 0.4), 16),
    ("torus", (20.0, 5.0), (1.5, 0.5, 0.5), 18),
]


def failing_cases():
    """The 5 failing rows of ``accuracy_voxel.md``, built with the same seeds as ``accuracy.py --voxel``."""
    for kind, arguments, spacing, seed in FAILING:
        build = shapes.voxel_torus if kind == "torus" else shapes.voxel_ellipsoid
        mesh = build(*arguments, spacing, seed=seed)
        aspect = max(spacing) / min(spacing)
        yield _from_analytic(
            mesh, "failing", "isotropic" if aspect == 1 else "anisotropic", False, outward=False, spacing=mesh.spacing
        )


BUILDERS = {
    "accuracy": accuracy_cases,
    "voxel": voxel_cases,
    "smoothed": smoothed_cases,
    "varying": varying_cases,
    "elongated": elongated_cases,
    "failing": failing_cases,
}


def cases(families=None):
    """Yield every :class:`Case` of the selected ``families`` (default: all, tuning ones first)."""
    for name, build in BUILDERS.items():
        if families is None or name in families:
            yield from build()
