"""The worked example of the guide (docs/guide/worked_example_cells.md): a label image of cells.

A synthetic confocal-like label image (voxels 0.5 x 0.2 x 0.2 um along z, y, x) of 12 cells: spheres and
rotated ellipsoids of radii 2-5 um, one torus-like cell (genus 1) and one sphere cut by the image border,
at random centres (fixed generator) without overlap; a voxel belongs to a cell when its centre is inside.
``meshcurv.label_curvatures`` measures each cell, with and without ``smooth=`` (one voxel along x and y); the
script prints the table beside the analytic values of the smooth shapes (areas, volumes, integrals of H and
of the bending energy of the ellipsoids and the torus by quadrature over their parametrisation) and draws
``docs/cells_mean.png``: every cell coloured by its mean curvature, drawn with :func:`meshcurv.plotting.plot_field`
as ``meshcurv volume`` draws its picture.

Run from the repository's root (the ``volume`` and ``plot`` extras): ``python docs/cells_example.py``
(``--no-picture`` to print the tables only). About 25 s on 2 cores (more at first use, while numba compiles).
"""

from __future__ import annotations

import argparse
import pathlib
import sys
import warnings

import numpy as np

import meshcurv
from meshcurv.plotting import plot_field, save_figure

DOCS = pathlib.Path(__file__).resolve().parent
SPACING = (0.5, 0.2, 0.2)  # um, along image axes z, y, x (a confocal stack: coarser along the optical axis)
SHAPE = (64, 240, 240)  # voxels: 32 x 48 x 48 um
RNG = np.random.default_rng(7)


# ---------------------------------------------------------------- the cells and their analytic values


def _rotation(rng) -> np.ndarray:
    """A random rotation matrix (QR of a Gaussian matrix, signs fixed)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    return q if np.linalg.det(q) > 0 else -q


def _ellipsoid_integrals(a: float, b: float, c: float, n: int = 400) -> dict[str, float]:
    """Area, integral of H dA and bending energy of the ellipsoid of semi-axes a, b, c by quadrature.

    ``p(u, v) = (a cos u sin v, b sin u sin v, c cos v)``; Gauss-Legendre over ``v`` in (0, pi) and the
    trapezoidal rule (spectrally accurate for periodic integrands) over ``u``: converged to 1e-13 at
    ``n = 400`` (against ``n = 800``), and ``int K dA = 4 pi`` to 1e-14 checks ``K`` and ``dA``. With
    ``q = x^2/a^4 + y^2/b^4 + z^2/c^4``: ``K = 1 / (a^2 b^2 c^2 q^2)`` and
    ``H = (a^2 + b^2 + c^2 - |p|^2) / (2 a^2 b^2 c^2 q^(3/2))`` (outward normal: H > 0).
    """
    nodes, weights = np.polynomial.legendre.leggauss(n)
    v = (nodes + 1) * np.pi / 2
    wv = weights * np.pi / 2
    u = np.linspace(0, 2 * np.pi, 2 * n, endpoint=False)
    wu = np.full(u.size, 2 * np.pi / u.size)
    uu, vv = np.meshgrid(u, v, indexing="ij")
    weight = wu[:, None] * wv[None, :]
    x, y, z = a * np.cos(uu) * np.sin(vv), b * np.sin(uu) * np.sin(vv), c * np.cos(vv)
    # |p_u x p_v| = sin v sqrt(b^2 c^2 cos^2 u sin^2 v + a^2 c^2 sin^2 u sin^2 v + a^2 b^2 cos^2 v)
    element = np.sin(vv) * np.sqrt(
        (b * c * np.cos(uu) * np.sin(vv)) ** 2 + (a * c * np.sin(uu) * np.sin(vv)) ** 2 + (a * b * np.cos(vv)) ** 2
    )
    q = x**2 / a**4 + y**2 / b**4 + z**2 / c**4
    abc2 = (a * b * c) ** 2
    gaussian = 1 / (abc2 * q**2)
    mean = (a**2 + b**2 + c**2 - x**2 - y**2 - z**2) / (2 * abc2 * q**1.5)
    k_max = mean + np.sqrt(np.maximum(mean**2 - gaussian, 0))
    k_min = mean - np.sqrt(np.maximum(mean**2 - gaussian, 0))
    dA = element * weight
    shape_index = 2 / np.pi * np.arctan2(k_max + k_min, k_max - k_min)
    return {
        "area": dA.sum(),
        "mean_integral": (mean * dA).sum(),
        "bending_energy": ((k_max**2 + k_min**2) * dA).sum(),
        "gaussian_integral": (gaussian * dA).sum(),
        "shape_index_mean": (shape_index * dA).sum() / dA.sum(),
    }


def _torus_integrals(big: float, small: float, n: int = 2000) -> dict[str, float]:
    """The same for the torus of radii ``big`` (centre of the tube) and ``small`` (tube), over its tube angle."""
    v = np.linspace(0, 2 * np.pi, n, endpoint=False)
    element = 2 * np.pi * small * (big + small * np.cos(v)) * (2 * np.pi / n)  # dA integrated over the long way
    k_tube, k_ring = 1 / small, np.cos(v) / (big + small * np.cos(v))
    k_max, k_min = np.maximum(k_tube, k_ring), np.minimum(k_tube, k_ring)
    shape_index = 2 / np.pi * np.arctan2(k_max + k_min, k_max - k_min)
    return {
        "area": element.sum(),
        "mean_integral": ((k_tube + k_ring) / 2 * element).sum(),
        "bending_energy": ((k_tube**2 + k_ring**2) * element).sum(),
        "gaussian_integral": (k_tube * k_ring * element).sum(),
        "shape_index_mean": (shape_index * element).sum() / element.sum(),
    }


def _cells(rng) -> list[dict]:
    """The 12 cells: shape, semi-axes, rotation, centre (um), analytic values; placed without overlap."""
    extent = np.array(SHAPE) * SPACING
    wanted = [
        ("sphere", (2.0, 2.0, 2.0)),
        ("sphere", (3.0, 3.0, 3.0)),
        ("sphere", (4.0, 4.0, 4.0)),
        ("sphere", (5.0, 5.0, 5.0)),
        ("sphere", (3.5, 3.5, 3.5)),
        ("ellipsoid", (4.5, 3.0, 2.5)),
        ("ellipsoid", (5.0, 4.0, 3.0)),
        ("ellipsoid", (3.5, 2.5, 2.0)),
        ("ellipsoid", (5.0, 3.0, 3.0)),
        ("ellipsoid", (4.0, 4.0, 2.5)),
        ("torus", (4.5, 2.2, 0.0)),
    ]
    cells = []
    # the cut cell first, at a fixed place: a sphere of radius 4 whose centre is 1 um outside the face x = 0
    cells.append(
        {
            "shape": "sphere, cut",
            "axes": (4.0, 4.0, 4.0),
            "rotation": np.eye(3),
            "centre": np.array([extent[0] / 2, extent[1] / 2, -1.0]),
            "bound": 4.0,
        }
    )
    for shape, axes in wanted:
        bound = axes[0] + axes[1] if shape == "torus" else max(axes)
        for _ in range(10_000):
            centre = rng.uniform(bound + 0.6, extent - bound - 0.6)  # whole inside the image
            if all(np.linalg.norm(centre - other["centre"]) > bound + other["bound"] + 0.8 for other in cells):
                break
        else:  # pragma: no cover - the sizes above fit
            raise RuntimeError("no room for the cells")
        cells.append({"shape": shape, "axes": axes, "rotation": _rotation(rng), "centre": centre, "bound": bound})
    for cell in cells:
        cell["exact"] = _exact(cell, extent)
    return cells


def _exact(cell: dict, extent) -> dict[str, float]:
    """Analytic values of the smooth shape (for the cut sphere: of its part inside the image)."""
    a, b, c = cell["axes"]
    if cell["shape"] == "torus":
        exact = _torus_integrals(a, b)
        return {**exact, "volume": 2 * np.pi**2 * a * b**2, "genus": 1}
    if cell["shape"] == "sphere, cut":
        # the image ends half a voxel before the centre of its first voxel: the cap inside has height h
        h = a + cell["centre"][2] + SPACING[2] / 2
        return {
            "area": 2 * np.pi * a * h,
            "volume": np.pi * h**2 * (3 * a - h) / 3,
            "mean_integral": np.nan,
            "bending_energy": np.nan,
            "gaussian_integral": np.nan,
            "shape_index_mean": 1.0,
            "genus": np.nan,
        }
    return {**_ellipsoid_integrals(a, b, c), "volume": 4 / 3 * np.pi * a * b * c, "genus": 0}


def _inside(cell: dict, points: np.ndarray) -> np.ndarray:
    """Which of ``points`` (N, 3), in um, are inside ``cell``."""
    local = (points - cell["centre"]) @ cell["rotation"]  # coordinates along the cell's own axes
    a, b, c = cell["axes"]
    if cell["shape"] == "torus":
        ring = np.hypot(local[:, 0], local[:, 1]) - a
        return ring**2 + local[:, 2] ** 2 <= b**2
    return (local[:, 0] / a) ** 2 + (local[:, 1] / b) ** 2 + (local[:, 2] / c) ** 2 <= 1


def label_image(cells: list[dict]) -> np.ndarray:
    """The label image: voxel ``(i, j, k)`` (centre at ``(i, j, k) * SPACING``) gets the label of the cell holding it."""
    labels = np.zeros(SHAPE, dtype=np.uint16)
    spacing = np.asarray(SPACING)
    for label, cell in enumerate(cells, start=1):
        low = np.maximum(np.floor((cell["centre"] - cell["bound"]) / spacing).astype(int) - 1, 0)
        high = np.minimum(np.ceil((cell["centre"] + cell["bound"]) / spacing).astype(int) + 2, SHAPE)
        box = np.stack(np.meshgrid(*[np.arange(lo, hi) for lo, hi in zip(low, high)], indexing="ij"), axis=-1)
        inside = _inside(cell, box.reshape(-1, 3) * spacing).reshape(box.shape[:3])
        region = labels[low[0] : high[0], low[1] : high[1], low[2] : high[2]]
        region[inside] = label
    return labels


# ---------------------------------------------------------------- the table as users read it


def _error(measured, exact) -> str:
    if not np.isfinite(measured):
        return "NaN"
    if not np.isfinite(exact):
        return f"{measured:.3f}"
    return f"{measured:.4g} ({100 * (measured / exact - 1):+.1f}%)"


def comparison(table, cells) -> str:
    """A Markdown table: each column measured (relative error to the analytic value)."""
    lines = [
        "| label | cell (semi-axes, um) | area um² | volume um³ | ∫H dA um | ∫K dA / 4π (exact) | "
        "bending energy | ici_positive | shape_index_mean |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for cell, row in zip(cells, table.itertuples()):
        exact = cell["exact"]
        size = (
            "R " + f"{cell['axes'][0]:g}"
            if cell["shape"].startswith("sphere")
            else (
                f"R {cell['axes'][0]:g}, r {cell['axes'][1]:g}"
                if cell["shape"] == "torus"
                else " x ".join(f"{x:g}" for x in cell["axes"])
            )
        )
        genus = exact["genus"]
        gauss = (
            "NaN"
            if not np.isfinite(row.gaussian_integral)
            else f"{row.gaussian_integral / (4 * np.pi):.3f} ({1 - genus:g})"
        )
        lines.append(
            f"| {row.label} | {cell['shape']} {size} | {_error(row.area, exact['area'])} | "
            f"{_error(row.volume, exact['volume'])} | {_error(row.mean_integral, exact['mean_integral'])} | "
            f"{gauss} | {_error(row.bending_energy, exact['bending_energy'])} | "
            f"{_error(row.ici_positive, np.nan)} | {_error(row.shape_index_mean, exact['shape_index_mean'])} |"
        )
    notes = [
        f"label {row.label}: {row.warnings}"
        for row in table.itertuples()
        if isinstance(row.warnings, str) and row.warnings
    ]
    return "\n".join(lines + [""] + notes)


def exact_table(cells) -> str:
    """The analytic values the comparison uses."""
    lines = [
        "| label | cell | area um² | volume um³ | ∫H dA um | bending energy | shape_index_mean |",
        "|---|---|---|---|---|---|---|",
    ]
    for label, cell in enumerate(cells, start=1):
        e = cell["exact"]
        values = [
            f"{e[key]:.4g}" if np.isfinite(e[key]) else "-"
            for key in ("area", "volume", "mean_integral", "bending_energy", "shape_index_mean")
        ]
        lines.append(f"| {label} | {cell['shape']} | " + " | ".join(values) + " |")
    return "\n".join(lines)


def picture(surfaces, path: pathlib.Path) -> None:
    """Every cell coloured by its mean curvature (grey: vertices left out, by the cut face)."""
    drawn = [surfaces[label] for label in sorted(surfaces)]
    offsets = np.cumsum([0] + [len(s.vertices) for s in drawn[:-1]])
    vertices = np.concatenate([s.vertices for s in drawn])
    faces = np.concatenate([s.faces + offset for s, offset in zip(drawn, offsets)])
    values = np.concatenate([np.where(s.used, s.result.mean, np.nan) for s in drawn])
    normals = np.concatenate([s.result.normals for s in drawn])  # the fitted normals: shading without the staircase
    figure = plot_field(
        vertices,
        faces,
        values,
        view=[(25.0, -60.0), "top"],
        up="x",
        limits=(0.0, 0.55),
        cmap="viridis",
        normals=normals,
        label="mean curvature H (1/um); grey: too close to the image border",
        title="12 cells, voxels 0.5 x 0.2 x 0.2 um (image z up; right: seen from +z)",
        pixels=1600,
        dpi=130,
    )
    save_figure(figure, path, overwrite=True)


def _say(text: str) -> None:
    sys.stdout.write(f"{text}\n")


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-picture", action="store_true", help="print the tables only")
    args = parser.parse_args(argv)
    cells = _cells(RNG)
    labels = label_image(cells)
    _say(
        f"image {labels.shape} voxels of {' x '.join(map(str, SPACING))} um, {labels.max()} cells, "
        f"{labels.nbytes / 2**20:.1f} MiB"
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the one MeshQualityWarning names the cut cell: the table says it too
        table, surfaces = meshcurv.label_curvatures(labels, spacing=SPACING, return_meshes=True)
        smoothed = meshcurv.label_curvatures(labels, spacing=SPACING, smooth=SPACING[2])
    columns = [
        "label",
        "touches_border",
        "area",
        "volume",
        "mean_integral",
        "gaussian_integral",
        "bending_energy",
        "ici_positive",
        "shape_index_mean",
    ]
    import pandas as pd

    with pd.option_context("display.width", 200, "display.max_columns", 20, "display.precision", 4):
        _say("\nThe table (a few columns) as label_curvatures returns it:\n")
        _say(table[columns].to_string(index=False))
    _say("\nAnalytic values:\n")
    _say(exact_table(cells))
    _say("\nMeasured (relative error), default call:\n")
    _say(comparison(table, cells))
    _say(f"\nMeasured (relative error), smooth={SPACING[2]} um:\n")
    _say(comparison(smoothed, cells))
    if not args.no_picture:
        picture(surfaces, DOCS / "cells_mean.png")
        _say(f"\npicture: {DOCS / 'cells_mean.png'}")


if __name__ == "__main__":
    main()
