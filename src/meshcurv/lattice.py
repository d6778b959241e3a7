"""Grids that coordinates lie on: voxel surfaces read as meshes and as point clouds.

A mesh extracted from a 3D image by marching cubes (scikit-image's
``measure.marching_cubes``, VTK's ``vtkMarchingCubes`` / flying edges,
ITK, ...) has every vertex on an edge of the voxel grid: two of its three
coordinates are grid coordinates ``origin + i * spacing``, the third is
interpolated. A blocky (cuberille) surface built from voxel faces has all three
on the grid. Such surfaces carry a staircase of the grid's size that a
curvature estimator must average out over a few voxels; :func:`voxel_grid`
finds the grid so that the default radius can take it into account, and
:func:`read_lattice` finds it in a point cloud (the vertices of such a surface
read as points).

Two readings, one after the other. The exact one: grid coordinates come from
the same ``i * spacing`` (plus the same offset) for every vertex on a grid
plane, so they repeat bit for bit, while interpolated coordinates are almost
all distinct. The periodic one, where no coordinate repeats (the surface
moved off its planes: a triangle soup whose copies of a vertex differ by
round-off, faces detached by a fraction of an edge, noise): the coordinates
along each axis crowd about evenly spaced planes, which the modulus of the mean
of ``exp(2 pi i x / s)`` finds (:func:`_periodic_planes`); a mesh is then a voxel
surface when nearly all its vertices have two coordinates within
:data:`VOXEL_SNAP` of a plane. A grid turned off the coordinate axes is read
in its own: for a mesh, the frame its triangles' sides lie in
(:func:`_turned_frame`), for a cloud, that of its flat facets
(:func:`_lattice_frame`).
"""

from __future__ import annotations

import itertools
from typing import NamedTuple

import numpy as np

__all__ = ["GRID_FRACTION", "NO_LATTICE", "VOXEL_SNAP", "Lattice", "VoxelGrid", "read_lattice", "voxel_grid"]

#: Share of the vertices that must have at least two coordinates on the grid.
GRID_FRACTION = 0.95

#: A coordinate value counts as a grid plane when this many vertices share it.
_PLANE_MULTIPLICITY = 3

#: The grid planes of an axis: its most populated repeated values, taken until they hold this share of
#: the repeated values (a plane of the grid holds dozens to thousands of vertices, a repeated interpolated
#: coordinate a few).
_GRID_SHARE = 0.5

#: Share of those planes that must lie on one lattice (a few busy interpolated values may not).
_PLANES_ON_GRID = 0.8

#: The origin of the lattice is sought among this many of the busiest planes.
_ORIGIN_CANDIDATES = 64

#: Grid coordinates within this fraction of the spacing of a plane of the lattice lie on it.
_ON_GRID = 1e-6

#: The relative round-off of a float32 coordinate (half a unit in its last place). Vertices that went through float32
#: (an STL file, a float32 array) hold every grid coordinate ``origin + i * spacing`` rounded by up to this times its
#: size: still repeated bit for bit, but, where ``spacing`` is no float32 value (0.8, 1.4), no longer evenly spaced
#: within :data:`_ON_GRID` (at 10 voxels from 0, some 1e-6 of a voxel). The exact reading is made again on such
#: vertices with this round-off (:func:`_exact_voxel_grid`), kept where float64's found no grid or a finer one: a
#: small voxel object (under some 8 voxels along an axis: too few planes for the periodic reading) was read as a
#: smooth mesh, its staircase as curvature (``meyer``: every vertex valid, the median H error 100%; float64:
#: refused), or at half its voxel size.
FLOAT32_ROUND_OFF = 2.0**-24


#: A cloud lies on a lattice along an axis when at least this share of its points share their coordinate along it
#: with another point, on at least :data:`LATTICE_PLANES` planes whole multiples of the smallest distance between
#: two of them apart (to :data:`LATTICE_TOLERANCE` of it).
LATTICE_SHARE = 0.5
LATTICE_PLANES = 3
LATTICE_TOLERANCE = 1e-6

#: Coordinates along an axis closer than this share of its largest |coordinate| are one plane of a lattice (their
#: difference is round-off: the same coordinate computed two ways).
LATTICE_ROUND_OFF = 1e-12

#: ... and the step between two planes is at least this many times that round-off: below, one plane whose coordinates
#: round-off spread (a turned grid's coordinates, read in axes off by 2e-10 rad ten sizes from the origin) is split
#: into planes whose gaps are all whole multiples of the smallest to within round-off (fuzz_api 491/8: steps of
#: 6e-7 read on a grid of 500).
LATTICE_ABOVE_ROUND_OFF = 1000.0

#: A turned grid read again in its refined axes is the same grid when its steps agree with the first reading's to
#: this share.
LATTICE_SAME_STEP = 0.01

#: A turned grid whose two axes have steps equal to this share may be the diagonals of the true one: the vertices of
#: a cubic grid of ``h`` lie on the planes at right angles to ``(a + b) / sqrt(2)`` too, ``h / sqrt(2)`` apart, and
#: the frame of the facets found them in one pose only (fuzz_api 811/48: a voxel ellipsoid read on steps 0.35, 0.5,
#: 0.35 turned, 0.5 each along the axes; its staircase then read as stacked sheets, no point valid). The axes are the
#: coarsest grid: the two bisectors are taken where they read one whose cell is this many times larger.
LATTICE_DIAGONAL_STEP = 0.02
LATTICE_DIAGONAL_CELL = 1.5

#: A cloud none of whose coordinates repeats among this many of its points, evenly spaced, is on no lattice (the
#: whole cloud is not read: a lattice of fewer than millions of planes along an axis repeats one there).
LATTICE_PROBE = 4096

#: A cloud whose coordinates share none is on a lattice along an axis whose planes they were moved off (noise, a
#: motion or a registration error of a fraction of a voxel): when the coordinates along it are periodic, the
#: modulus of the mean of ``exp(2 pi i x / s)`` at least this for a step ``s`` within :data:`LATTICE_BAND` spacings
#: (1 on the planes, ``exp(-2 pi^2 sigma^2 / s^2)`` under noise ``sigma``: 0.45 at a tenth of a voxel on the half
#: voxels' grid of marching cubes; ``benchmarks/pointcloud_diagnostics.md``, "A staircase off its grid") ...
LATTICE_PERIODIC = 0.3
LATTICE_BAND = (0.25, 6.0)

#: Of the peaks of the modulus (at most :data:`LATTICE_PEAKS`, the strongest), the grid's is the lowest frequency within
#: this share of the strongest (see :func:`_periodic_planes`) ...
LATTICE_HARMONIC = 0.9
LATTICE_PEAKS = 8

#: ... and the grid full, its planes alike: where the modulus at ``2 / s`` is at least :data:`LATTICE_PERIODIC`,
#: the one at ``1 / s`` at least this share of its power 1/4 (a grid of noise ``sigma``: ``m(1 / s) = m(2 / s) **
#: (1 / 4)``; the grid of every second plane of a finer one holds its points on planes of two kinds, and the modulus
#: falls with their imbalance).
LATTICE_FULL = 0.9

#: ... and a coordinate is on its plane of such a grid within this many times the noise of the coordinates about
#: their planes (a robust standard deviation), at most half a step.
LATTICE_SNAP = 4.0

#: A lattice turned off the coordinate axes (a voxel image with a direction matrix) is read in the frame of its flat
#: facets: the least-variance directions of the neighbourhoods of at most :data:`LATTICE_FRAME_PROBE` points whose
#: least variance is below :data:`LATTICE_FLAT` of the next (coplanar to round-off or a motion of a few thousandths of
#: a voxel: the treads and the diagonal facets of a staircase), grouped within :data:`LATTICE_FRAME_ANGLE` radians
#: (the :data:`LATTICE_FRAME_GROUPS` largest, of :data:`LATTICE_FRAME_GROUP` at least); of those at right angles to
#: each other (to that angle), the three whose coordinates are periodic (:func:`_periodic_planes`) with the coarsest
#: grid (the axes, not the diagonals, whose planes are closer). Where no three are, the other two axes about one of
#: them (:func:`_frame_about`: :data:`LATTICE_FRAME_ANGLES` directions of a quarter turn, the
#: :data:`LATTICE_FRAME_PEAKS` most periodic refined).
LATTICE_FRAME_PROBE = 1024
LATTICE_FLAT = 1e-4
LATTICE_FRAME_ANGLE = 0.01
LATTICE_FRAME_GROUP = 3
LATTICE_FRAME_GROUPS = 24
LATTICE_FRAME_ANGLES = 320
LATTICE_FRAME_PEAKS = 4
LATTICE_FRAME_TRIES = 3


class Lattice(NamedTuple):
    """The grid a cloud's coordinates lie on (see :func:`read_lattice`).

    Parameters
    ----------
    steps : ndarray of shape (3,)
        The distance between two planes of the grid along each of its axes (0: no grid along that axis).
    offsets : ndarray of shape (3,)
        The coordinate of one plane along each axis.
    tolerance : ndarray of shape (3,)
        The distance within which a coordinate is on a plane.
    frame : ndarray of shape (3, 3), optional
        The grid's axes as rows; None: the coordinate axes.
    """

    steps: np.ndarray
    offsets: np.ndarray
    tolerance: np.ndarray
    frame: np.ndarray | None = None

    def along(self, vectors: np.ndarray) -> np.ndarray:
        """Vectors in the grid's axes.

        Parameters
        ----------
        vectors : ndarray of shape (..., 3)
            Points or normals, in the coordinate axes.

        Returns
        -------
        ndarray of shape (..., 3)
            The same vectors in the grid's axes (``vectors`` itself when the grid has no frame).
        """
        return vectors if self.frame is None else vectors @ self.frame.T

    def snap(self, points: np.ndarray) -> np.ndarray:
        """Points in the grid's axes, moved onto the planes they are near.

        Parameters
        ----------
        points : ndarray of shape (N, 3)
            Points in the coordinate axes.

        Returns
        -------
        ndarray of shape (N, 3)
            The points in the grid's axes, each coordinate within the tolerance of a plane moved onto it.
        """
        snapped = np.array(self.along(points), dtype=float)
        for axis in np.flatnonzero(self.steps > 0):
            step, offset = self.steps[axis], self.offsets[axis]
            plane = offset + np.round((snapped[:, axis] - offset) / step) * step
            near = np.abs(snapped[:, axis] - plane) <= self.tolerance[axis]
            snapped[near, axis] = plane[near]
        return snapped


NO_LATTICE = Lattice(np.zeros(3), np.zeros(3), np.zeros(3))


def _evenly(candidates: np.ndarray, most: int) -> np.ndarray:
    """``candidates`` (sorted), or ``most`` of them evenly spaced in their order when there are more."""
    if candidates.size <= most:
        return candidates
    return candidates[np.linspace(0, candidates.size - 1, most).round().astype(np.int64)]


def _spread(candidates: np.ndarray, most: int, points: np.ndarray, local: np.ndarray) -> np.ndarray:
    """``candidates`` (sorted), or about ``most`` of them (sorted) that the pose and the order of ``points`` (N, 3)
    do not choose when there are more: :func:`meshcurv.radius._intrinsic_sample` of their ``local`` (N,) lengths
    (each point's spacing: what rigid motions and scaling carry with it) and distances to their centroid.

    A sample evenly spaced in the order of a cloud's points (its Morton order, which a rotation changes) chose the
    winding numbers' sources: fandisk's vertices turned had 20 normals turned the other way.
    """
    if candidates.size <= most:
        return candidates
    from .radius import _intrinsic_sample  # (radius reads voxel grids from here)

    return candidates[_intrinsic_sample(points[candidates], np.asarray(local, dtype=np.float64)[candidates], most)]


#: Off the exact grid (:func:`voxel_grid`'s periodic reading), a coordinate is on a plane of the grid read when it
#: lies within this share of the distance between its planes (the half voxels of a mask's isosurface: a fortieth of
#: a voxel). Voxel meshes whose every coordinate got Gaussian noise are read up to a hundredth of a voxel (0.975 to
#: 0.997 of their vertices with two coordinates on the grid), not at two hundredths. Smooth meshes would be read from
#: between 0.3 and 0.4 on (the periodic ones: the icosphere of 8 subdivisions 0.72 of its vertices at 0.2, 0.89 at
#: 0.3, all at 0.4; ``shapes.cylinder()`` 0.875 at 0.2 and 0.3), a margin of 6 (``benchmarks/lattice_perturbed.md``).
VOXEL_SNAP = 0.05

#: ... and every axis holds at least this share of its coordinates on the planes (three times what chance puts
#: within :data:`VOXEL_SNAP`): a height field sampled on a grid has two coordinates of every vertex on it, and the
#: few values of a height that changes along one axis only are periodic, but seldom near their planes
#: (``z = 0.5 sin(3 x)`` on a grid of 0.05: 0.17 to 0.27 of them).
VOXEL_AXIS_SHARE = 1.0 / 3.0

#: A voxel surface whose vertices were moved further (a soup whose corners moved by up to a tenth of a voxel, issue
#: 29, fuzz 415/108) has its coordinates spread about the planes: along an axis whose robust spread about them
#: (1.4826 times the median distance) is at most this share of the planes' distance, a coordinate is on a plane
#: within :data:`VOXEL_NOISE_SNAP` spreads (at least :data:`VOXEL_SNAP`). Corners moved by 0.1 voxel in random
#: directions spread by 0.15 of the half voxels' distance; a smooth mesh's coordinates, evenly between the planes,
#: by 0.37 (``benchmarks/lattice_noisy_L21.md``).
VOXEL_NOISE = 0.2

#: ... see :data:`VOXEL_NOISE`: 98.8% of the coordinates of a Gaussian spread, all of a uniform one.
VOXEL_NOISE_SNAP = 2.5


_EXACT = np.zeros(3)
_EXACT.flags.writeable = False


class VoxelGrid(NamedTuple):
    """The grid found by :func:`voxel_grid`.

    Attributes
    ----------
    spacing : ndarray of shape (3,)
        Distance between grid planes along x, y and z (the vertices' own axes).
    origin : ndarray of shape (3,)
        One grid coordinate per axis.
    fraction : float
        Share of the vertices with at least two coordinates on the grid.
    tolerance : ndarray of shape (3,)
        How far off its plane a coordinate on the grid may lie along each axis: 0 for the exact reading (the
        coordinates repeat bit for bit), :data:`VOXEL_SNAP` of the distance between the planes read for the
        periodic one, or more where the vertices were moved off the grid (:data:`VOXEL_NOISE`).
    noise : float
        The spread of the coordinates about their planes for which that tolerance was widened (a length: 1.4826
        times their median distance to them, the least of the three axes'); 0 where it was not.
    frame : ndarray of shape (3, 3), optional
        The grid's axes as rows (an image turned off the coordinate axes, see :func:`_turned_frame`); None: x, y
        and z. ``spacing``, ``origin`` and ``tolerance`` are along these axes.
    """

    spacing: np.ndarray
    origin: np.ndarray
    fraction: float
    tolerance: np.ndarray = _EXACT
    noise: float = 0.0
    frame: np.ndarray | None = None

    def along(self, vectors: np.ndarray) -> np.ndarray:
        """The ``vectors`` turned into the grid's axes (its ``frame``), those its ``spacing`` is read along.

        Parameters
        ----------
        vectors : ndarray of shape (..., 3)
            Points or normals in x, y and z.

        Returns
        -------
        ndarray of shape (..., 3)
            ``vectors @ frame.T``; ``vectors`` itself for a grid along x, y and z (no ``frame``).
        """
        return Lattice.along(self, vectors)  # type: ignore[arg-type]  # (it reads the frame only)


#: :func:`_plane_lattice` reads each candidate's lattice on this many planes more than 1.25 times the share it may
#: miss before it may give it up (0.25 of a smooth mesh's repeated coordinates against all of them before).
_HEAD_PLANES = 4096


def _plane_lattice(planes: np.ndarray, candidates: np.ndarray, share: float):
    """``(spacing, origin)`` of the lattice that holds ``share`` of the sorted ``planes``, or None.

    The spacing is the smallest gap common among the planes (wider gaps are
    multiples of it), or, where small gaps are rare (a few busy interpolated
    values among the grid planes), the median gap. The origin is the one of
    ``candidates`` whose lattice holds the most planes.
    """
    if planes.size < 3:
        return None
    gaps = np.diff(planes)
    gaps = gaps[gaps > 0]
    if gaps.size == 0:
        return None
    smallest = float(np.min(gaps))
    near = gaps[gaps < 1.5 * smallest]
    spacing = float(np.median(near if near.size >= 0.5 * gaps.size else gaps))
    # one candidate at a time: no (candidates, planes) temporaries (64 rows of a large mesh's planes each); the
    # operations of `abs(steps - round(steps)) <= tolerance`, steps = (planes - candidate) / spacing, in buffers
    # made once. A candidate is read first on a head of the planes a little longer than the share it may miss:
    # where even all the planes after it held could not reach `share`, its lattice is not the one (its held
    # share stays 0, below `share` as its own; the largest, and its candidate, are those of every plane read)
    size = planes.size
    head = min(size, _HEAD_PLANES + int(np.ceil(1.25 * (1.0 - share) * size)))
    held = np.zeros(candidates.size)
    steps, off = np.zeros(size), np.zeros(size)
    near = np.zeros(size, dtype=bool)
    with np.errstate(over="ignore", invalid="ignore"):  # a subnormal spacing (coordinates of 1e-310): no grid
        for j, candidate in enumerate(candidates):
            count = 0
            for lo, hi in ((0, head), (head, size)):
                np.subtract(planes[lo:hi], candidate, out=steps[lo:hi])
                np.divide(steps[lo:hi], spacing, out=steps[lo:hi])
                np.round(steps[lo:hi], out=off[lo:hi])
                np.subtract(steps[lo:hi], off[lo:hi], out=off[lo:hi])
                np.abs(off[lo:hi], out=off[lo:hi])
                np.less_equal(off[lo:hi], 1e3 * _ON_GRID, out=near[lo:hi])
                count += int(np.count_nonzero(near[lo:hi]))
                if (count + size - hi) / size < share:
                    break  # (its share is at most this, below `share`)
            else:
                held[j] = count / size
    if held.max() < share:
        return None  # the repeated values are not evenly spaced: not a grid (a symmetric height field, say)
    return spacing, float(candidates[np.argmax(held)])


def _axis_lattice(values: np.ndarray, round_off: float = 0.0):
    """``(spacing, origin, on_grid)`` of one coordinate axis, or None when its repeated values form no lattice.

    The lattice of every repeated value (a binary mask's isosurface: the grid
    planes and the middles between them), or else that of the busiest ones:
    the interpolated coordinates of a smoothed mask's isosurface repeat too, a
    few times each (a symmetric solid, float32 coordinates), where a plane of
    the grid holds every vertex on the grid edges that lie in it. ``round_off``
    (relative, :data:`FLOAT32_ROUND_OFF`): the values were rounded by up to that
    much; the lattice is then fitted to its planes (least squares) and a value
    within that round-off (four times, of the largest |value|) of it lies on it.
    """
    planes, counts = np.unique(values, return_counts=True)
    repeated = counts >= _PLANE_MULTIPLICITY
    planes, counts = planes[repeated], counts[repeated]
    found = _plane_lattice(planes, planes[:1], 1.0)
    if found is None and planes.size:
        busiest = np.argsort(counts, kind="stable")[::-1]
        enough = int(np.searchsorted(np.cumsum(counts[busiest]), _GRID_SHARE * counts.sum())) + 1
        found = _plane_lattice(np.sort(planes[busiest[:enough]]), planes[busiest[:_ORIGIN_CANDIDATES]], _PLANES_ON_GRID)
    if found is None:
        return None
    spacing, origin = found
    tolerance = 0.0
    if round_off:
        # the planes' rounding pulls a spacing read from their gaps off by some 1e-7, a drift of 1e-6 of a voxel
        # across ten planes: the lattice fitted to every plane on it instead
        index, off = _nearest_planes(planes, spacing, origin)
        on_lattice = np.abs(off) <= 1e3 * _ON_GRID * spacing
        if np.ptp(index[on_lattice]) > 0:
            fitted, intercept = np.polyfit(index[on_lattice], planes[on_lattice], 1)
            spacing, origin = float(fitted), float(intercept)
        tolerance = 4.0 * round_off * float(np.abs(values).max()) / spacing
    with np.errstate(over="ignore", invalid="ignore"):
        steps = (values - origin) / spacing
    if not np.isfinite(steps).all() or np.abs(steps).max() > 2.0**52:
        return None  # a coordinate billions of voxels away (a spike): not a voxel image
    whole = np.round(steps)
    on_grid = np.abs(steps - whole) <= max(_ON_GRID * max(1.0, np.abs(steps).max() * 1e-9), tolerance)
    return spacing, origin, on_grid, whole.astype(np.int64) % 2


def voxel_grid(
    vertices: np.ndarray, faces: np.ndarray | None = None, *, spacing: float | None = None
) -> VoxelGrid | None:
    """The voxel grid a mesh's vertices lie on, or None.

    Parameters
    ----------
    vertices : ndarray of shape (V, 3)
        Vertex coordinates (of the referenced vertices).
    faces : ndarray of shape (F, 3) of int, optional
        The triangles (indices into ``vertices``): given, a mesh whose coordinates repeat too little is read from
        their periodicity, at steps within :data:`LATTICE_BAND` of its median edge length, each face within one
        voxel (see Notes); without them, only the exact reading is made.
    spacing : float, optional
        The mesh's typical edge length for the periodic reading; default: the median length of the faces' first
        edges (their corners 0 and 1).

    Returns
    -------
    VoxelGrid or None
        The spacing and origin of the grid when at least :data:`GRID_FRACTION`
        of the vertices have two or more coordinates on it along every axis
        (marching cubes: exactly two; voxel faces: three); None otherwise. Its
        ``frame`` is None unless the grid is turned off the coordinate axes.

    Notes
    -----
    The grid is read from the coordinates that repeat (the exact reading), or,
    where that finds none and ``faces`` are given, from the coordinates' periodicity along each axis
    (:func:`_periodic_planes`, as for point clouds: :func:`read_lattice`): a
    voxel surface whose vertices were moved off the grid by a little (up to a
    hundredth of a voxel or so, see :data:`VOXEL_SNAP`), each coordinate then
    on the grid within :data:`VOXEL_SNAP` of the distance between its planes,
    each axis with :data:`VOXEL_AXIS_SHARE` of its coordinates on them, and
    :data:`GRID_FRACTION` of the faces within one voxel (as marching cubes
    makes them: a height field sampled on a grid has its x and y there, and
    its faces across the planes of its heights). A
    surface moved by a translation is on a grid of another origin. A turned
    one (an image whose affine has a rotation) is read, where given its
    ``faces`` and on no grid along the coordinate axes, in the frame of the
    sides of its triangles (:func:`_turned_frame`: a marching-cubes triangle's
    sides lie in the voxels' faces, at right angles to an axis of the grid),
    by the same two readings: the exact one on its coordinates rounded to
    :data:`VOXEL_ROUNDING` of their largest, then the periodic one. Its
    ``frame`` holds the grid's axes, along which ``spacing`` is read; the
    frame of the image's own axes turned, to round-off on an exact grid
    (``tests/test_turned_voxel.py``). Smooth meshes find no frame (most of
    them: within 2 ms for a few thousand vertices) or no grid in it.

    Examples
    --------
    >>> import numpy as np
    >>> from meshcurv.lattice import voxel_grid
    >>> voxel_grid(np.random.default_rng(0).normal(size=(500, 3))) is None
    True
    """
    if vertices.shape[0] < 16:
        return None
    exact = _exact_voxel_grid(vertices)
    if exact is not None or faces is None or len(faces) == 0:
        return exact
    if spacing is None:
        spacing = float(np.median(np.linalg.norm(vertices[faces[:, 1]] - vertices[faces[:, 0]], axis=1)))
    grid = _faces_voxel_grid(vertices, faces, spacing)
    if grid is not None:
        return grid
    # a grid turned off the coordinate axes (an image whose affine has a rotation): read in its own axes, the same
    # two readings; the exact one on the coordinates rounded to their round-off (a plane's coordinates, turned, agree
    # to a few last bits)
    frame = _turned_frame(vertices, faces)
    if frame is None or np.abs(frame - np.eye(3)).max() <= VOXEL_ROUNDING:
        return None  # (no frame, or x, y and z, read already: a CAD part's flats, a grid's rows, a cylinder's rings)
    turned = vertices @ frame.T
    grid = _exact_voxel_grid(_rounded(turned)) or _faces_voxel_grid(turned, faces, spacing)
    return None if grid is None else grid._replace(frame=frame)


def _faces_voxel_grid(vertices: np.ndarray, faces: np.ndarray, spacing: float) -> VoxelGrid | None:
    """:func:`voxel_grid`'s periodic reading along the coordinate axes, with its faces' test (see its Notes)."""
    grid = _periodic_voxel_grid(vertices, spacing)
    if grid is None:
        return None
    # every face of marching cubes lies within one voxel (its corners on the edges of one cube): along each axis
    # its coordinates within one cell of the grid, to twice the tolerance (nine coordinates, a third of them on
    # the cell's faces)
    cells = (vertices[faces] - grid.origin) / grid.spacing
    slack = 2 * grid.tolerance / grid.spacing
    low = np.floor(cells.min(axis=1) + slack)
    within = (cells.max(axis=1) <= low + 1 + slack).all(axis=1)
    return grid if within.mean() >= GRID_FRACTION else None


#: A mesh's grid turned off the coordinate axes is read in the frame of its edges (:func:`_turned_frame`): each side
#: of a marching-cubes triangle joins two edges of one voxel's face but the few across a voxel, so that it lies in a
#: plane at right angles to an axis of the grid (a binary mask's isosurface: 80-90% of them; a smooth image's, a
#: signed distance: 65%). Of the sides of at most :data:`VOXEL_FRAME_FACES` faces, evenly spaced,
#: :data:`VOXEL_FRAME_PAIRS` pairs (drawn with a fixed seed) give the directions at right angles to both (their
#: sides at least :data:`VOXEL_FRAME_SINE` apart) ...
VOXEL_FRAME_FACES = 512
VOXEL_FRAME_PAIRS = 384
VOXEL_FRAME_SINE = 0.1

#: ... grouped within this angle (radians; the sides of a grid moved by a hundredth of a voxel turn by 0.02): two sides
#: in one voxel face give the axis at right angles to it ...
VOXEL_FRAME_ANGLE = 0.05

#: ... the mesh is on no turned grid unless its largest group holds this share of the pairs (each axis of a grid: about
#: the square of the share of sides at right angles to it, 0.05 to 0.13 on the marching cubes of spheres and
#: ellipsoids; the icospheres, ``spot``, ``rocker-arm``, ``nefertiti``, ``igea``: 0.02 at most, most none: the quick
#: reject) ...
VOXEL_FRAME_GROUP = 0.03

#: ... each of the :data:`VOXEL_FRAME_AXES` largest groups' direction is refitted to the sides at right angles to it
#: (least squares, within the angle, then within :data:`VOXEL_FRAME_SPREAD` robust spreads of their angles, at least
#: round-off), and the frame is the three of them at right angles to each other (within the angle; or two and their
#: cross product) at right angles to which the most sides are, at least :data:`VOXEL_FRAME_SHARE` of them (the grid's
#: axes, not its diagonals: the planes through two axes' diagonals hold the sides across voxels only). Its axes are
#: then refitted over the sides of every face.
VOXEL_FRAME_AXES = 6
VOXEL_FRAME_SPREAD = 8.0
VOXEL_FRAME_SHARE = 0.5

#: ... each fit over sides that span the plane (see :func:`_refitted_axis`).
VOXEL_FRAME_SPAN = 0.05


def _turned_frame(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray | None:
    """(3, 3) the axes (rows, orthonormal) of a grid turned off the coordinate axes that the sides of the ``faces``
    (F, 3) over ``vertices`` (V, 3) lie at right angles to (see :data:`VOXEL_FRAME_FACES`), or None.

    The frame is a proposal: the mesh is a voxel surface only where the grid is read in it (:func:`voxel_grid`).
    Its rows are ordered and signed to lie nearest x, y and z.
    """
    sides = _unit_sides(vertices, faces[_evenly(np.arange(len(faces)), VOXEL_FRAME_FACES)])
    if sides.shape[0] < 16:
        return None
    first, second = np.random.default_rng(0).integers(0, sides.shape[0], (2, VOXEL_FRAME_PAIRS))
    across = np.cross(sides[first], sides[second])
    sines = np.linalg.norm(across, axis=1)
    across = across[sines >= VOXEL_FRAME_SINE] / sines[sines >= VOXEL_FRAME_SINE, None]
    # (the products of the three components summed: no BLAS call for a few hundred rows, whose threads cost more)
    gram = sum(np.multiply.outer(across[:, k], across[:, k]) for k in range(3))
    close = np.abs(gram) >= np.cos(VOXEL_FRAME_ANGLE)
    left = np.ones(across.shape[0], dtype=bool)
    axes: list[tuple[np.ndarray, float]] = []
    while len(axes) < VOXEL_FRAME_AXES and left.any():  # the largest group of directions left, its axis
        counts = (close & left).sum(axis=1) * left
        best = int(np.argmax(counts))
        if counts[best] < VOXEL_FRAME_GROUP * VOXEL_FRAME_PAIRS:
            break
        members = close[best] & left
        left &= ~members
        axis = (across[members] * np.sign(across[members] @ across[best])[:, None]).sum(axis=0)
        found = _refitted_axis(sides, axis / np.linalg.norm(axis), np.sin(VOXEL_FRAME_ANGLE))
        if found is not None:
            axes.append(found)
    frame, bounds = _orthogonal_axes(sides, axes)
    if frame is None:
        return None
    every = _unit_sides(vertices, faces)
    for k in range(3):  # (a few thousand sides fit an axis to a thousandth of their scatter; every side, finer)
        found = _refitted_axis(every, frame[k], bounds[k])
        frame[k] = frame[k] if found is None else found[0]
    left_vectors, _, right_vectors = np.linalg.svd(frame)  # the nearest orthonormal axes
    frame = left_vectors @ right_vectors
    order = [int(np.argmax(np.abs(frame[:, k]))) for k in range(3)]
    if sorted(order) != [0, 1, 2]:
        order = [0, 1, 2]  # (no row nearest each axis: their order as found)
    frame = frame[order]
    return frame * np.where(np.diag(frame) < 0, -1.0, 1.0)[:, None]


#: A voxel soup's grid turned off the coordinate axes (:func:`soup_frame`, for :func:`meshcurv.radius.soup_voxel_grid`):
#: its faces' sides are read for the grid's axes at right angles to them within this angle (radians), where
#: :func:`voxel_grid`'s proposal groups them within 0.05 (:data:`VOXEL_FRAME_ANGLE`): every face moved by 0.05 edge
#: lengths turns the sides by about 0.07, and that proposal found no frame for ``voxel_sphere(6)`` so detached and
#: turned by (0.3, 0.5, 0.7) (issue 29, R29's F6) ...
SOUP_FRAME_ANGLE = 0.15
#: ... from this many pairs of sides, their cross products at least this sine apart ...
SOUP_FRAME_PAIRS = 1024
SOUP_FRAME_SINE = 0.3
#: ... each axis then refitted over every side in this many steps (:func:`_refitted_axis`), to round-off on the faces
#: that kept their place (half of them detached: the frame to 1e-16, where the lattice's three steps left 1e-13,
#: enough to part a plane's coordinates).
SOUP_FRAME_STEPS = 12


def soup_frame(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray | None:
    """(3, 3) the axes (rows, orthonormal) that the sides of the ``faces`` (F, 3) over ``vertices`` (V, 3) lie at
    right angles to, read for a voxel soup (:func:`meshcurv.radius.soup_voxel_grid`), or None: the proposal of
    :func:`voxel_grid` (:func:`_turned_frame`), else the direction at right angles
    to the most sides (within :data:`SOUP_FRAME_ANGLE`) among the cross products of pairs of sides, then the one at
    right angles to it and to the most sides; each axis refitted over every side (:data:`SOUP_FRAME_STEPS`). A
    proposal: the grid must then be read in it."""
    sides = _unit_sides(vertices, faces)
    if sides.shape[0] < 16:
        return None
    bound = float(np.sin(SOUP_FRAME_ANGLE))
    frame = _turned_frame(vertices, faces)
    if frame is None:
        first, second = np.random.default_rng(0).integers(0, sides.shape[0], (3, SOUP_FRAME_PAIRS))[:2]
        across = np.cross(sides[first], sides[second])
        sines = np.linalg.norm(across, axis=1)
        across = across[sines >= SOUP_FRAME_SINE] / sines[sines >= SOUP_FRAME_SINE, None]
        sample = sides[np.random.default_rng(1).integers(0, sides.shape[0], SOUP_FRAME_PAIRS)]
        if across.shape[0] < 16:
            return None
        counts = (np.abs(across @ sample.T) <= bound).sum(axis=1)
        axis = across[int(np.argmax(counts))]
        counts *= np.abs(across @ axis) <= bound  # (then the densest at right angles to it)
        if not counts.any():
            return None
        other = across[int(np.argmax(counts))]
        other = other - (other @ axis) * axis
        frame = np.stack([axis, other / np.linalg.norm(other), np.cross(axis, other / np.linalg.norm(other))])
    for k in range(3):
        found = _refitted_axis(sides, frame[k], bound, steps=SOUP_FRAME_STEPS)
        if found is None:
            return None
        frame[k] = found[0]
    left_vectors, _, right_vectors = np.linalg.svd(frame)
    return left_vectors @ right_vectors  # (the nearest orthonormal axes)


def _unit_sides(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """(M, 3) the unit directions of the sides of ``faces`` (F, 3) but those of length 0."""
    corners = vertices[faces]
    sides = np.concatenate(
        [corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 1], corners[:, 0] - corners[:, 2]]
    )
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        sides = sides / np.linalg.norm(sides, axis=1, keepdims=True)
    return sides[np.isfinite(sides).all(axis=1)]


def _orthogonal_axes(sides: np.ndarray, axes: list) -> tuple:
    """``(frame, bounds)``: of the ``axes`` (``(axis, bound)`` each, :func:`_refitted_axis`), the three at right angles
    to each other (or two and their cross product) at right angles to which the most of the unit ``sides`` (N, 3)
    are (each within its bound), at least :data:`VOXEL_FRAME_SHARE` of them; ``(None, None)`` where none are."""
    right = np.sin(VOXEL_FRAME_ANGLE)
    best = VOXEL_FRAME_SHARE
    found: tuple = (None, None)
    for a, b in itertools.combinations(range(len(axes)), 2):
        (first, first_bound), (second, second_bound) = axes[a], axes[b]
        if abs(first @ second) > right:
            continue
        third = np.cross(first, second)
        third /= np.linalg.norm(third)
        # the cross product, or a group's axis along it (fitted, as the two others)
        aligned = np.cos(VOXEL_FRAME_ANGLE)
        thirds = [
            (third, right),
            *(axes[c] for c in range(len(axes)) if c not in (a, b) and abs(axes[c][0] @ third) >= aligned),
        ]
        for last, last_bound in thirds:
            frame, bounds = np.array([first, second, last]), np.array([first_bound, second_bound, last_bound])
            share = float((np.abs(sides @ frame.T) <= bounds).any(axis=1).mean())
            if share > best:
                best, found = share, (frame, bounds)
    return found


def _refitted_axis(sides: np.ndarray, axis: np.ndarray, bound: float, *, steps: int = 3):
    """``(axis, bound)``: the direction (3,) at right angles to most of the unit ``sides`` (N, 3) within ``bound`` (the
    sine of an angle) of right angles to ``axis`` (3,), by least squares over them, then (``steps`` fits in all) over
    those within :data:`VOXEL_FRAME_SPREAD` robust spreads of its own, at least round-off; None when fewer than three
    sides are held, or they lie along one direction (the smaller of their two spreads in the plane below
    :data:`VOXEL_FRAME_SPAN` of their number: no plane; a later fit's: the previous one kept)."""
    found = None
    for _ in range(steps):
        held = np.abs(sides @ axis) <= bound
        if held.sum() < 3:
            break
        values, vectors = np.linalg.eigh(sides[held].T @ sides[held])
        if values[1] < VOXEL_FRAME_SPAN * held.sum():
            break
        axis = vectors[:, 0] * (1.0 if vectors[:, 0] @ axis >= 0 else -1.0)
        off = np.abs(sides[held] @ axis)
        bound = min(bound, max(VOXEL_FRAME_SPREAD * 1.4826 * float(np.median(off)), 64 * np.finfo(float).eps))
        found = (axis, bound)
    return found


def _rounded(points: np.ndarray) -> np.ndarray:
    """``points`` (N, 3) rounded to a power of two near :data:`VOXEL_ROUNDING` of their extent plus their round-off
    (8 eps of the largest |coordinate|): the coordinates of one plane of a grid, turned into its axes, equal again
    (they differed by round-off). The extent, not the largest |coordinate| (as radius._snapped): 1e-11 of the
    coordinates of a unit grid 1.2e6 away is 2**-16, a lattice of its own that the exact reading read as the grid
    (``voxel_sphere(6)``'s turned soup 1e5 sizes away: spacing (2**-16, 0.5, 2**-16); W32)."""
    largest = float(np.abs(points).max())
    if not (np.isfinite(largest) and largest > 0.0):
        return points
    extent = float(np.ptp(points, axis=0).max())
    quantum = 2.0 ** np.ceil(np.log2(VOXEL_ROUNDING * extent + 8.0 * np.finfo(float).eps * largest))
    return np.round(points / quantum) * quantum


#: See :func:`_rounded`: far above the round-off of a turn (a few units of 1e-16), far below the distance between two
#: interpolated coordinates (1e-10 of the extent would take a billion voxels across).
VOXEL_ROUNDING = 1e-11


def _exact_voxel_grid(vertices: np.ndarray) -> VoxelGrid | None:
    """:func:`voxel_grid` on the coordinates that repeat bit for bit; on vertices that went through float32, also at
    float32's round-off (:data:`FLOAT32_ROUND_OFF`), that reading kept where float64's found none or a finer grid
    (the half voxels' of a binary mask's isosurface, where the rounding left too few coordinates on the voxels' own
    planes to choose them: a voxel torus in 0.9 x 1 x 1.3 voxels, read at half its voxel size)."""
    grid = _exact_voxel_grid_at(vertices, 0.0)
    if _float32_values(vertices):
        rounded = _exact_voxel_grid_at(vertices, FLOAT32_ROUND_OFF)
        coarser = grid is None or (rounded is not None and np.prod(rounded.spacing) > 1.5 * np.prod(grid.spacing))
        if rounded is not None and coarser:
            grid = rounded
    return grid


def _float32_values(vertices: np.ndarray) -> bool:
    """Whether every coordinate of ``vertices`` is a float32 value (exactly: they went through float32)."""
    with np.errstate(over="ignore", invalid="ignore"):
        return bool(np.array_equal(vertices, vertices.astype(np.float32)))


def _exact_voxel_grid_at(vertices: np.ndarray, round_off: float) -> VoxelGrid | None:
    """:func:`_exact_voxel_grid` at one relative ``round_off`` of the coordinates (0: float64's)."""
    found = []
    for k in range(3):  # an axis without a lattice settles it: the others are not sorted (most meshes)
        axis = _axis_lattice(vertices[:, k], round_off)
        if axis is None:
            return None
        found.append(axis)
    return _on_voxel_grid(found)


def _periodic_voxel_grid(vertices: np.ndarray, spacing: float) -> VoxelGrid | None:
    """:func:`voxel_grid` on the coordinates' periodicity (see :data:`VOXEL_SNAP`).

    Along each axis the planes read are refitted (least squares) to the coordinates within :data:`VOXEL_SNAP` of
    them (the fit of :func:`_periodic_planes` takes those within a quarter step, where a smooth image's interpolated
    coordinates pull the step off by a few thousandths: a few hundredths of a voxel across 25 planes). The voxel
    grid is then every plane or every other one (one of the two kinds) along each axis, the coarsest choice
    that keeps two coordinates of :data:`GRID_FRACTION` of the vertices on it: a mask's isosurface has every
    coordinate on the half voxels' grid along every axis, a smooth image's where the surface crosses the voxels'
    edges at one height (a flat face: its interpolated coordinates crowd at one level between the planes).
    """
    if not (np.isfinite(spacing) and spacing > 0.0):
        return None
    probe = vertices[:: max(1, vertices.shape[0] // LATTICE_PROBE)]
    found = []
    for k in range(3):  # (most meshes: no periodic axis, settled by the first)
        planes = _periodic_planes(vertices[:, k], probe[:, k], spacing, full=False)
        if planes is None:
            return None
        found.append(planes[:2])
    snaps, noise = _voxel_snaps(vertices, found)
    axes, tolerances = [], []
    for k, ((step, offset), snap) in enumerate(zip(found, snaps)):
        values = vertices[:, k]
        for _ in range(2):
            index, off = _nearest_planes(values, step, offset)
            near = np.abs(off) <= snap * step
            if not near.any() or np.ptp(index[near]) < LATTICE_PLANES - 1:
                return None
            step, offset = np.polyfit(index[near], values[near], 1)
        index, off = _nearest_planes(values, step, offset)
        on_grid = np.abs(off) <= snap * step
        if on_grid.mean() < VOXEL_AXIS_SHARE:
            return None
        even = index.astype(np.int64) % 2 == 0
        # the choices along this axis: (spacing, origin, the coordinates on those planes)
        tolerances.append(snap * step)
        axes.append(
            [
                (step, offset, on_grid),
                (2 * step, offset, on_grid & even),
                (2 * step, offset + step, on_grid & ~even),
            ]
        )
    best: tuple = (0.0, 0.0, None)  # (voxel volume, fraction, choice)
    for choice in itertools.product(*axes):
        fraction = float((sum(on.astype(np.int64) for _, _, on in choice) >= 2).mean())
        volume = float(np.prod([spacing for spacing, _, _ in choice]))
        if fraction >= GRID_FRACTION and (volume, fraction) > best[:2]:
            best = (volume, fraction, choice)
    _, fraction, choice = best
    if choice is None:
        return None
    steps, origin = np.array([c[0] for c in choice]), np.array([c[1] for c in choice])
    return VoxelGrid(steps, origin, fraction, np.array(tolerances), noise)


def _voxel_snaps(vertices: np.ndarray, found: list) -> tuple[list, float]:
    """``(snaps, noise)``: how far off its plane (a share of the planes' distance) a coordinate is on the grid
    along each axis, the planes ``found`` (``(step, offset)`` along x, y and z): :data:`VOXEL_SNAP`, or, where the
    vertices were moved off a voxel grid (in every direction: the least of the three axes' spreads about their
    planes, at most :data:`VOXEL_NOISE` of each axis' step), :data:`VOXEL_NOISE_SNAP` times that spread; ``noise``
    that spread (a length) where it widened some axis' snap, else 0. A grid along some axes only (a cylinder's
    axis, a height field's x and y) is no noisy voxel surface: its least spread is 0."""
    spreads = [
        1.4826 * float(np.median(np.abs(_nearest_planes(vertices[:, k], step, offset)[1])))
        for k, (step, offset) in enumerate(found)
    ]
    noise = min(spreads)
    if any(noise > VOXEL_NOISE * step for step, _ in found):
        return [VOXEL_SNAP] * 3, 0.0
    snaps = [max(VOXEL_SNAP, VOXEL_NOISE_SNAP * noise / step) for step, _ in found]
    return snaps, (noise if max(snaps) > VOXEL_SNAP else 0.0)


def _on_voxel_grid(found: list) -> VoxelGrid | None:
    """The :class:`VoxelGrid` of the exact lattices ``found`` along the three axes (each ``(step, origin, on_grid,
    parity)``, the last two (V,)), or None when fewer than :data:`GRID_FRACTION` of the vertices have two
    coordinates on them."""
    on_grid = np.column_stack([axis[2] for axis in found])
    fraction = float((on_grid.sum(axis=1) >= 2).mean())
    if fraction < GRID_FRACTION:
        return None
    spacing = np.array([axis[0] for axis in found])
    origin = np.array([axis[1] for axis in found])
    # a binary mask cut at 0.5 puts the interpolated coordinate at the middle of its grid edge: every
    # coordinate is then on the half grid, and the voxel grid is every other plane of it along each axis,
    # the choice of planes (one of eight) that puts two coordinates of every vertex on the grid
    parity = np.column_stack([axis[3] for axis in found])
    for pattern in np.ndindex(2, 2, 2):
        on_voxel_grid = on_grid & (parity == np.array(pattern))
        voxel_fraction = float((on_voxel_grid.sum(axis=1) >= 2).mean())
        if voxel_fraction >= GRID_FRACTION:
            return VoxelGrid(2 * spacing, origin + np.array(pattern) * spacing, voxel_fraction, _EXACT)
    return VoxelGrid(spacing, origin, fraction, _EXACT)


def read_lattice(
    points: np.ndarray,
    spacing: float | None = None,
    *,
    usable: np.ndarray | None = None,
    neighbours: np.ndarray | None = None,
) -> Lattice:
    """The grid the coordinates of the ``usable`` (N,) bool (default: all) of ``points`` (N, 3) lie on.

    Along an axis, the coordinates that two points or more share (the planes of the grid) must hold
    :data:`LATTICE_SHARE` of the points, be :data:`LATTICE_PLANES` at least, and lie whole multiples of the
    smallest distance between two of them apart: the vertices of marching cubes over a voxel image (each on an
    edge of the voxels: at its midpoint for a mask, every coordinate then on the grid of half voxels; two of its
    three for a smooth image). Given the cloud's ``spacing``, coordinates that share none are on a grid when they
    are periodic along all three axes (:func:`_periodic_planes`: the same surface moved off its planes by noise or
    a motion of a fraction of a voxel); given each point's ``neighbours`` (N, k) too, a lattice turned off the
    coordinate axes is read in its own (:func:`_lattice_frame`). A scan's points are on none.

    Parameters
    ----------
    points : ndarray of shape (N, 3)
        The points.
    spacing : float, optional
        The cloud's spacing: with it, coordinates moved off their planes are read from their periodicity.
    usable : ndarray of shape (N,) of bool, optional
        The points to read the grid from (default: all).
    neighbours : ndarray of shape (N, k) of int, optional
        Each point's nearest neighbours: with ``spacing``, a grid turned off the coordinate axes is read too.

    Returns
    -------
    Lattice
        The grid (:data:`NO_LATTICE` when there is none).
    """
    points = np.asarray(points, dtype=float)
    rows = points if usable is None else points[usable]
    if rows.shape[0] == 0:
        return NO_LATTICE
    lattice = _lattice_in(rows, spacing)
    if lattice.steps.any() or spacing is None or neighbours is None:
        return lattice
    frame = _lattice_frame(points, rows, neighbours, usable, spacing)
    if frame is None:
        return lattice
    turned = _lattice_in(rows @ frame.T, spacing)
    if not turned.steps.all():
        return lattice
    frame, turned = _undiagonal(rows, frame, turned, spacing)
    # the axes to the planes' own precision (the frame's search is to a thousandth of a radian): along each, the
    # plane index of every coordinate near its plane is a linear function of the point, w . x + c, whose gradient w
    # is the axis over its step; least squares, then the nearest orthonormal axes. The points are taken from their
    # centroid: a cloud ten sizes from the origin gave a system of condition about 1e9 whose axes were off by 2e-10
    # rad, which spread each plane over 1e-5 and split it into planes 6e-7 apart (fuzz_api 491/8)
    centred = rows - rows.mean(axis=0)
    scaled = np.empty((3, 3))
    for axis in range(3):
        step, offset = turned.steps[axis], turned.offsets[axis]
        index, off = _nearest_planes(rows @ frame[axis], step, offset)
        near = np.abs(off) <= step / 4
        scaled[axis] = np.linalg.lstsq(np.c_[centred[near], np.ones(near.sum())], index[near], rcond=None)[0][:3]
    left, _, right = np.linalg.svd(scaled / np.linalg.norm(scaled, axis=1, keepdims=True))
    refined = left @ right
    exact = _lattice_in(rows @ refined.T, spacing)
    # (the same grid, read to the planes' precision: not another one that round-off made)
    same = exact.steps.all() and np.allclose(exact.steps, turned.steps, rtol=LATTICE_SAME_STEP)
    return exact._replace(frame=refined) if same else turned._replace(frame=frame)


def _undiagonal(rows, frame, turned, spacing):
    """``(frame, lattice)``: the ``frame`` (3, 3) of the :class:`Lattice` ``turned`` of ``rows`` (M, 3), or the frame
    of its axes where two of them are diagonals of a coarser grid (see :data:`LATTICE_DIAGONAL_STEP`)."""
    for _ in range(3):  # (each turn halves the cell's count of planes: a frame of three diagonals takes two)
        steps = turned.steps
        better = None
        for i, j in itertools.combinations(range(3), 2):
            if abs(steps[i] - steps[j]) > LATTICE_DIAGONAL_STEP * max(steps[i], steps[j]):
                continue
            axes = frame.copy()
            axes[i], axes[j] = (frame[i] + frame[j]) / np.sqrt(2.0), (frame[i] - frame[j]) / np.sqrt(2.0)
            found = _lattice_in(rows @ axes.T, spacing)
            if found.steps.all() and np.prod(found.steps) > LATTICE_DIAGONAL_CELL * np.prod(steps):
                better = (axes, found) if better is None or np.prod(found.steps) > np.prod(better[1].steps) else better
        if better is None:
            break
        frame, turned = better
    return frame, turned


def _lattice_in(points, spacing):
    """The :class:`Lattice` of ``points`` (N, 3) along the coordinate axes (see :func:`read_lattice`)."""
    probe = points[:: max(1, points.shape[0] // LATTICE_PROBE)]
    shared = not all(np.unique(probe[:, axis]).size == probe.shape[0] for axis in range(3))
    exact = [_shared_planes(points[:, axis]) if shared else None for axis in range(3)]
    found = exact
    if spacing is not None and spacing > 0.0 and not all(exact):
        # periodic planes only on all three axes, as marching cubes over a mask puts them (the two faces of a
        # plate, on two planes along one axis, are periodic at any step that divides their distance)
        periodic = [e or _periodic_planes(points[:, axis], probe[:, axis], spacing) for axis, e in enumerate(exact)]
        found = periodic if all(periodic) else exact
    steps, offsets, tolerance = (np.array([f[j] if f else 0.0 for f in found]) for j in range(3))
    return Lattice(steps, offsets, tolerance)


def _lattice_frame(points, rows, neighbours, usable, spacing):
    """(3, 3) the axes (rows) of a lattice turned off the coordinate axes, or None (see :data:`LATTICE_FRAME_PROBE`):
    the ``rows`` (M, 3) the ``usable`` of ``points`` (N, 3), ``neighbours`` (N, k) each point's nearest. Where no
    facet is flat to :data:`LATTICE_FLAT` (a turned voxel surface under noise), the facets of
    :data:`LATTICE_NOISY_FLAT` (see there)."""
    candidates = np.arange(points.shape[0]) if usable is None else np.flatnonzero(usable)
    reach = np.linalg.norm(points[neighbours[:, -1]] - points, axis=1)  # (a length the motions carry)
    probe = _spread(candidates, LATTICE_FRAME_PROBE, points, reach)
    group = np.concatenate([points[probe, None, :], points[neighbours[probe]]], axis=1)
    group = group - group.mean(axis=1, keepdims=True)
    values, vectors = np.linalg.eigh(np.einsum("nki,nkj->nij", group, group))
    sample = rows[:: max(1, rows.shape[0] // LATTICE_PROBE)]
    normals = vectors[values[:, 0] <= LATTICE_FLAT * values[:, 1], :, 0]
    directions = _facet_directions(normals, LATTICE_FRAME_ANGLE, LATTICE_FRAME_GROUP, LATTICE_FRAME_GROUPS)
    frame = _frame_of(directions, rows, sample, spacing, every=False)
    if frame is not None:
        return frame
    normals = vectors[values[:, 0] <= LATTICE_NOISY_FLAT * values[:, 1], :, 0]
    least = max(LATTICE_FRAME_GROUP, int(np.ceil(LATTICE_NOISY_GROUP * probe.size)))
    directions = _facet_directions(normals, LATTICE_NOISY_ANGLE, least, LATTICE_NOISY_GROUPS)
    sharpened = (_sharpened(direction, sample, spacing) for direction in directions)
    return _frame_of([found for found in sharpened if found is not None], rows, sample, spacing, every=True)


def _facet_directions(normals, angle, least, most):
    """The directions (unit (3,) each) of the largest groups of the unit ``normals`` (M, 3) within ``angle`` (radians)
    of one of them, up to sign: at most ``most`` groups of ``least`` normals or more, largest first."""
    close = np.abs(normals @ normals.T) >= np.cos(angle)
    left = np.ones(normals.shape[0], dtype=bool)
    directions: list[np.ndarray] = []
    while left.any() and len(directions) < most:  # the largest group of facets left, its direction
        counts = (close & left).sum(axis=1) * left
        best = int(np.argmax(counts))
        if counts[best] < least:
            break
        members = close[best] & left
        direction = (normals[members] * np.sign(normals[members] @ normals[best])[:, None]).sum(axis=0)
        directions.append(direction / np.linalg.norm(direction))
        left &= ~members
    return directions


#: A turned voxel surface under noise (a twentieth of a voxel or more along the normal: fuzz_api 510/77, 608/15) has
#: no facet coplanar to :data:`LATTICE_FLAT`: its frame is then sought among the facets whose least variance is below
#: this share of the next (a tread under noise of a tenth of a voxel over ten neighbours: 0.002-0.01), grouped within
#: :data:`LATTICE_NOISY_ANGLE` radians (their normals scatter by 0.02-0.04), the :data:`LATTICE_NOISY_GROUPS`
#: largest of at least :data:`LATTICE_NOISY_GROUP` of the probed points; each group's direction (off its axis by a
#: few thousandths of a radian) is sharpened to the one along which the coordinates are most periodic
#: (:func:`_sharpened`), and up to :data:`LATTICE_FRAME_TRIES` of them are tried as an axis of the frame (the
#: coarsest grid first, then the largest groups).
LATTICE_NOISY_FLAT = 0.01
LATTICE_NOISY_ANGLE = 0.05
LATTICE_NOISY_GROUP = 0.01
LATTICE_NOISY_GROUPS = 4

#: :func:`_sharpened`'s search: the tilts of a direction (radians) of a square grid of 7 x 7 about the best so far,
#: each level's half-width a quarter of the previous one's (the first level's spacing, 0.004, is about the width of
#: the modulus's peak on a grid of a hundred planes). A direction along which the coordinates are not periodic
#: (:data:`LATTICE_PERIODIC`) after the first level is dropped: a smooth cloud's facets (most clouds reach here)
#: cost 49 spectra each.
LATTICE_SHARPEN = (0.012, 0.003, 0.00075, 0.0002)


def _strength(values, spacing):
    """The strongest modulus of :func:`_spectrum` of ``values`` (M,) within :data:`LATTICE_BAND` (0: none)."""
    modulus, _, band, _ = _spectrum(values, spacing)
    return 0.0 if band.size == 0 else float(modulus[band].max())


def _sharpened(direction, sample, spacing):
    """The unit direction near ``direction`` (3,) along which the ``sample`` (S, 3) is most periodic
    (:func:`_strength`), by the tilts of :data:`LATTICE_SHARPEN`; None where it is not periodic."""
    first = np.cross(direction, np.eye(3)[int(np.argmin(np.abs(direction)))])
    first /= np.linalg.norm(first)
    second = np.cross(direction, first)
    along, across, other = sample @ direction, sample @ first, sample @ second
    best, at = _strength(along, spacing), (0.0, 0.0)
    for width in LATTICE_SHARPEN:
        centre = at
        for a in centre[0] + np.linspace(-width, width, 7):
            for b in centre[1] + np.linspace(-width, width, 7):
                strength = _strength(along + a * across + b * other, spacing)
                if strength > best:
                    best, at = strength, (float(a), float(b))
        if best < LATTICE_PERIODIC:
            return None
    tilted = direction + at[0] * first + at[1] * second
    return tilted / np.linalg.norm(tilted)


def _frame_of(directions, rows, sample, spacing, *, every):
    """(3, 3) the frame (rows) of a lattice of the facets' ``directions`` (unit, largest group first), or None (see
    :func:`_lattice_frame`): the coarsest grid of three at right angles, or the frames about up to
    :data:`LATTICE_FRAME_TRIES` of them (:func:`_frame_about`): those of the three and the coarsest grid's, and with
    ``every`` then every other periodic one in order (the coarsest grid of a noisy turned surface may be a diagonal's
    facets: fuzz_api 510/77)."""
    steps = []
    for direction in directions:
        found = _periodic_planes(rows @ direction, sample @ direction, spacing)
        steps.append(0.0 if found is None else found[0])
    # the coarsest grid (its axes, not its diagonals: their planes are closer) of three of the facets' directions at
    # right angles to each other, or of the one of the coarsest grid and the two others at right angles to it
    # (anisotropic voxels: the facets facing them are seldom flat over ten neighbours), found from every probed normal;
    # then the same about the other axes of the best frame (up to LATTICE_FRAME_TRIES axes in all)
    largest, frame = 0.0, None
    triple: tuple[int, ...] = ()
    right = np.sin(LATTICE_FRAME_ANGLE)
    for a, b, c in itertools.combinations(range(len(directions)), 3):
        axes = np.array([directions[a], directions[b], directions[c]])
        cell = steps[a] * steps[b] * steps[c]
        if cell > largest and np.all(np.abs(axes @ axes.T - np.eye(3)) <= right):
            largest, frame, triple = cell, axes, (a, b, c)
    coarsest = sorted([k for k, step in enumerate(steps) if step > 0], key=lambda k: -steps[k])
    others = [k for k in range(len(directions)) if steps[k] > 0 and k not in coarsest[:1]] if every else []
    queue = [directions[k] for k in [*sorted(triple, key=lambda k: -steps[k]), *coarsest[:1], *others]]
    tried: list[np.ndarray] = []
    while queue and len(tried) < LATTICE_FRAME_TRIES:  # (a diagonal's frame holds an axis: then that axis')
        axis = queue.pop(0)
        own = _grid_frequency(sample @ axis, spacing)
        if own is None or any(abs(axis @ other) >= np.cos(LATTICE_FRAME_ANGLE) for other in tried):
            continue
        tried.append(axis)
        found = _frame_about(axis, sample, spacing)
        if found is not None and found[1] / own[0] > largest:
            frame, largest = found[0], found[1] / own[0]
            queue.extend(found[0][1:])
    if frame is None:
        return None
    turn, _ = np.linalg.qr(frame.T)  # (exactly orthonormal, the axes' signs as found)
    return (turn * np.sign(np.diag(turn.T @ frame.T))).T


def _frame_about(axis, sample, spacing):
    """``(frame, area)``: the axes (rows, (3, 3)) of a lattice one of whose axes is ``axis`` (3,) and the product of
    the two others' steps, or None.

    The two others lie in the plane at right angles to it, a quarter turn apart: of the directions of a quarter turn
    there, :data:`LATTICE_FRAME_ANGLES` evenly spaced, the :data:`LATTICE_FRAME_PEAKS` along which the ``sample``
    (S, 3) is most periodic (the strongest peak of :func:`_spectrum`), each refined to a twentieth of that spacing
    and completed by the direction at right angles: of those periodic along both (:func:`_grid_frequency`), the
    coarsest grid (the axes, not the diagonals between them).
    """
    first = np.cross(axis, np.eye(3)[int(np.argmin(np.abs(axis)))])
    first /= np.linalg.norm(first)
    second = np.cross(axis, first)

    def direction(angle):
        return np.cos(angle) * first + np.sin(angle) * second

    def strongest(angle):
        return _strength(sample @ direction(angle), spacing)

    coarse = np.arange(LATTICE_FRAME_ANGLES) * (np.pi / 2 / LATTICE_FRAME_ANGLES)
    strength = np.array([strongest(t) for t in coarse])
    tops = np.flatnonzero((strength >= np.roll(strength, 1)) & (strength >= np.roll(strength, -1)))
    frame, largest = None, 0.0
    for start in coarse[tops[np.argsort(-strength[tops])][:LATTICE_FRAME_PEAKS]]:
        fine = start + np.linspace(-1, 1, 41) * (np.pi / 2 / LATTICE_FRAME_ANGLES)
        along = direction(fine[int(np.argmax([strongest(t) for t in fine]))])
        found = _grid_frequency(sample @ along, spacing)
        third = _grid_frequency(sample @ np.cross(axis, along), spacing)
        if found is None or third is None:
            continue
        cell = 1 / (found[0] * third[0])
        if cell > largest:
            frame, largest = np.array([axis, along, np.cross(axis, along)]), cell
    return None if frame is None else (frame, largest)


def _shared_planes(values):
    """``(step, offset, tolerance)`` of the planes that ``values`` (N,) share (see :func:`read_lattice`), or None."""
    # the coordinates within round-off of each other are one plane (a coordinate computed two ways)
    values = np.sort(values)
    round_off = LATTICE_ROUND_OFF * max(float(np.abs(values).max()), np.finfo(float).tiny)
    first = np.flatnonzero(np.r_[True, np.diff(values) > round_off])
    counts = np.diff(np.r_[first, values.size])
    planes = values[first[counts > 1]]
    if planes.size < LATTICE_PLANES or counts[counts > 1].sum() < LATTICE_SHARE * values.size:
        return None
    gaps = np.diff(planes)
    step = gaps.min()
    if step < LATTICE_ABOVE_ROUND_OFF * round_off:
        return None  # (planes that round-off split: any gap is a whole multiple of such a step)
    # whole multiples of the step to LATTICE_TOLERANCE of it, each plane known to its round-off: not relative
    # to the multiple (a gap a million steps long is a whole multiple of any step to a millionth of itself)
    off = np.abs(gaps - np.round(gaps / step) * step)
    tolerance = LATTICE_TOLERANCE * step + 2 * round_off
    if not np.all(off <= tolerance):
        return None
    return float(step), float(planes[0]), float(tolerance)


def _periodic_planes(values, probe, spacing, *, full=True):
    """``(step, offset, tolerance)`` of the grid whose planes ``values`` (N,) lie about, or None.

    The modulus ``m(f)`` of the mean of ``exp(2 pi i f x)`` over the ``probe`` values (M,): its peaks within
    :data:`LATTICE_BAND` over every frequency at once (the Fourier transform of their histogram in bins of 1/32 of
    the ``spacing``), the :data:`LATTICE_PEAKS` strongest of at least :data:`LATTICE_PERIODIC` each measured at its
    top (the mean at 17 frequencies across its bin) and kept unless ``m(f) < LATTICE_FULL m(2 f) ** (1 / 4)`` where
    ``m(2 f)`` is at least that (see :data:`LATTICE_FULL`; not ``full``: a mesh of a smooth image has a third of its
    coordinates between the planes, evenly spread, and ``m(f) = m(2 f)``). The grid's frequency is the lowest of those within
    :data:`LATTICE_HARMONIC` of the strongest (an exact grid's harmonics are as strong as its fundamental; two planes
    that hold many points, the treads at the poles, make peaks at every multiple of the inverse of their distance,
    weaker than the grid's). Its step and a plane are then fitted by least squares to the coordinates within a
    quarter step of the planes, and the tolerance is :data:`LATTICE_SNAP` times the coordinates' spread about them.
    """
    found = _grid_frequency(probe, spacing, full=full)
    if found is None:
        return None
    frequency, mean, low = found
    step = 1 / frequency
    offset = low + np.angle(mean) / (2 * np.pi) * step
    for _ in range(2):  # least squares over the coordinates near the planes
        index, off = _nearest_planes(values, step, offset)
        close = np.abs(off) <= step / 4
        if close.sum() < LATTICE_SHARE * values.size or np.ptp(index[close]) < LATTICE_PLANES - 1:
            return None
        step, offset = np.polyfit(index[close], values[close], 1)
    spread = 1.4826 * float(np.median(np.abs(_nearest_planes(values, step, offset)[1])))
    return float(step), float(offset), min(LATTICE_SNAP * spread, step / 2)


def _nearest_planes(values, step, offset):
    """``(index, off)``: the plane of the grid of ``step`` through ``offset`` nearest each of ``values`` (N,), and
    how far off it each lies."""
    index = np.round((values - offset) / step)
    return index, values - offset - index * step


def _spectrum(probe, spacing):
    """``(modulus, frequency, band, low)``: the modulus of the mean of ``exp(2 pi i f (x - low))`` over the ``probe``
    (M,) at every ``frequency`` of the Fourier transform of their histogram in bins of 1/32 of the ``spacing``, the
    indices of those within :data:`LATTICE_BAND` (none when the probe spans too few or too many bins) and ``low``,
    the least value."""
    low, high = float(probe.min()), float(probe.max())
    width = spacing / 32
    span = (high - low) / width if width > 0.0 else np.inf
    if not (np.isfinite(span) and 8 * 32 <= span + 1 <= 1 << 18):
        return np.zeros(0), np.zeros(0), np.zeros(0, dtype=np.int64), low
    bins = int(span) + 1
    histogram = np.bincount(((probe - low) / width).astype(np.int64), minlength=bins)
    size = 1 << int(np.ceil(np.log2(2 * bins)))
    modulus = np.abs(np.fft.rfft(histogram, size)) / probe.size
    frequency = np.arange(modulus.size) / (size * width)
    band = np.flatnonzero(
        (frequency >= 1 / (LATTICE_BAND[1] * spacing)) & (frequency <= 1 / (LATTICE_BAND[0] * spacing))
    )
    return modulus, frequency, band, low


def _grid_frequency(probe, spacing, *, full=True):
    """``(frequency, mean, low)``: the grid's frequency, the mean of ``exp(2 pi i f (x - low))`` over the ``probe``
    (M,) there and their least value ``low``, or None (see :func:`_periodic_planes`, ``full`` too)."""
    modulus, frequency, band, low = _spectrum(probe, spacing)
    if band.size < 3:
        return None
    width = spacing / 32
    size = 2 * (modulus.size - 1)
    inner = modulus[band[1:-1]]
    peaks = band[1:-1][(inner >= modulus[band[:-2]]) & (inner >= modulus[band[2:]]) & (inner >= LATTICE_PERIODIC)]
    centred = probe - low
    tops = []  # (frequency, mean) at the top of each peak kept
    for peak in peaks[np.argsort(-modulus[peaks], kind="stable")[:LATTICE_PEAKS]]:
        near = frequency[peak] + np.linspace(-1, 1, 17) / (size * width)
        means = np.exp(2j * np.pi * np.outer(near, centred)).mean(axis=1)
        top = int(np.argmax(np.abs(means)))
        double = abs(np.exp(4j * np.pi * near[top] * centred).mean())
        if full and double >= LATTICE_PERIODIC and abs(means[top]) < LATTICE_FULL * double**0.25:
            continue  # (every second plane of a grid at 2 f; tested only where m(2 f) is above the sampling's floor)
        tops.append((near[top], means[top]))
    if not tops:
        return None
    strongest = max(abs(mean) for _, mean in tops)
    found, mean = min((f, mean) for f, mean in tops if abs(mean) >= LATTICE_HARMONIC * strongest)
    return found, mean, low
