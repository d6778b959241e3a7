"""Per-label curvature tables of synthetic label images against their exact values (issue 17).

Accuracy: ``--labels`` spheres and ellipsoids (half each) of random semi-axes in
``[--min-radius, --max-radius]`` physical units and random orientation, each
voxelised analytically (a voxel is inside when its centre is) into its own cell
of one label image with voxels of ``--spacing`` (z y x). Per label, the table
of :func:`meshcurv.volume.label_curvatures` (default call) against the exact
area, volume, area-weighted mean of H (``int H dA / area``, computed for an
ellipsoid by quadrature over its parametrisation) and 4 pi (Gauss-Bonnet).

Scale: ``--scale`` builds a label image of ``--scale-shape`` voxels with
``--scale-labels`` balls and ellipsoids of radius 6-20 voxels, times the pass
that finds the labels over the whole image, then processes ``--scale-sample``
labels of it (label by label, on crops) and extrapolates to all of them;
peak memory is the process's maximum resident set size. ``--workers N`` runs
the same labels again on a local Dask cluster of N processes (the cluster's
start timed apart) and gives both, with the CPU seconds of every process
(the machine may be shared: wall times alone can mislead).

    python benchmarks/volume.py                       # accuracy, 50 labels, 1 x 0.25 x 0.25
    python benchmarks/volume.py --scale               # and the scale run
    python benchmarks/volume.py --no-accuracy --scale --workers 2    # serial and on 2 processes
    python benchmarks/volume.py --labels 12 --markdown benchmarks/volume.md
"""

from __future__ import annotations

import argparse
import contextlib
import os
import platform
import resource
import sys
import time
import warnings

import numpy as np


def rotation(rng) -> np.ndarray:
    """A uniformly random rotation matrix (QR of a Gaussian matrix, signs fixed)."""
    q, r = np.linalg.qr(rng.normal(size=(3, 3)))
    q = q * np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] = -q[:, 0]
    return q


def ellipsoid_exact(a, b, c, n: int = 1500) -> tuple[float, float, float]:
    """``(area, int H dA, int K dA)`` of the ellipsoid of semi-axes a, b, c by the midpoint rule.

    ``x = a sin t cos p, y = b sin t sin p, z = c cos t``; with ``g`` the gradient
    of ``sum(x_k^2 / a_k^2)`` / 2, ``K = 1 / ((abc)^2 |g|^4)`` and
    ``H = (a^2 + b^2 + c^2 - |x|^2) / (2 (abc)^2 |g|^3)``.
    """
    t = (np.arange(n) + 0.5) * np.pi / n
    p = (np.arange(2 * n) + 0.5) * np.pi / n
    t, p = np.meshgrid(t, p, indexing="ij")
    st, ct, sp, cp = np.sin(t), np.cos(t), np.sin(p), np.cos(p)
    x, y, z = a * st * cp, b * st * sp, c * ct
    # |r_t x r_p| = sin t * sqrt((bc sin t cos p)^2 + (ac sin t sin p)^2 + (ab cos t)^2)
    element = st * np.sqrt((b * c * st * cp) ** 2 + (a * c * st * sp) ** 2 + (a * b * ct) ** 2)
    g2 = (x / a**2) ** 2 + (y / b**2) ** 2 + (z / c**2) ** 2
    abc2 = (a * b * c) ** 2
    gaussian = 1.0 / (abc2 * g2**2)
    mean = (a * a + b * b + c * c - x * x - y * y - z * z) / (2 * abc2 * g2**1.5)
    dA = element * (np.pi / n) ** 2
    return float(dA.sum()), float((mean * dA).sum()), float((gaussian * dA).sum())


def synthetic_labels(n_labels: int, spacing, min_radius: float, max_radius: float, seed: int):
    """A label image of ``n_labels`` spheres and ellipsoids, one per cell, and their exact figures."""
    rng = np.random.default_rng(seed)
    spacing = np.asarray(spacing, dtype=float)
    cell = 2 * max_radius + 4 * spacing.max()
    per_side = int(np.ceil(n_labels ** (1 / 3)))
    shape = np.ceil(per_side * cell / spacing).astype(int) + 2
    image = np.zeros(tuple(shape), dtype=np.uint16)
    exact = {}
    for index in range(n_labels):
        label = index + 1
        cell_index = np.array(np.unravel_index(index, (per_side,) * 3))
        kind = "sphere" if index % 2 == 0 else "ellipsoid"
        axes = (
            np.full(3, rng.uniform(min_radius, max_radius))
            if kind == "sphere"
            else np.sort(rng.uniform(min_radius, max_radius, 3))[::-1]
        )
        turn = rotation(rng)
        center = (cell_index + 0.5) * cell + rng.uniform(-1, 1, 3) * spacing + spacing
        low = np.maximum(np.floor((center - axes.max() - 1) / spacing).astype(int), 0)
        high = np.minimum(np.ceil((center + axes.max() + 1) / spacing).astype(int) + 1, shape)
        grids = np.meshgrid(
            *[np.arange(lo, hi) * s - c for lo, hi, s, c in zip(low, high, spacing, center)], indexing="ij", sparse=True
        )
        # body coordinates q = turn^T p: inside when sum((q / axes)^2) <= 1
        q = [sum(turn[k, j] * grids[k] for k in range(3)) for j in range(3)]
        inside = sum((q[j] / axes[j]) ** 2 for j in range(3)) <= 1
        box = image[tuple(slice(lo, hi) for lo, hi in zip(low, high))]
        box[inside] = label
        a, b, c = axes
        if kind == "sphere":
            area, integral_h = 4 * np.pi * a * a, 4 * np.pi * a
        else:
            area, integral_h, _ = ellipsoid_exact(a, b, c)
        exact[label] = {
            "kind": kind,
            "axes": axes,
            "area": area,
            "volume": 4 / 3 * np.pi * a * b * c,
            "mean_weighted": integral_h / area,
            "total_gaussian": 4 * np.pi,
        }
    return image, exact


def accuracy(args) -> list[str]:
    from meshcurv.volume import label_surfaces, _table

    image, exact = synthetic_labels(args.labels, args.spacing, args.min_radius, args.max_radius, args.seed)
    total, rows_iter = label_surfaces(image, spacing=args.spacing)
    rows, alternatives = [], {}
    start = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for row, surface in rows_iter:
            rows.append(row)
            truth = exact[row["label"]]
            if surface is not None:  # the choices not taken: vertex sums, and H from the measures
                keep = surface.used & np.isfinite(surface.result.gaussian)
                alternatives[row["label"]] = {
                    "total_gaussian": float(np.sum(surface.result.gaussian[keep] * surface.vertex_areas[keep])),
                    "mean_weighted": float(
                        np.sum(surface.result.mean[keep] * surface.vertex_areas[keep])
                        / np.sum(surface.vertex_areas[keep])
                    ),
                }
            print(
                f"label {row['label']:3d} {truth['kind']:9s} axes {np.round(truth['axes'], 1)} "
                f"{row['n_vertices']:7d} vertices  area {row['area'] / truth['area'] - 1:+.4f} "
                f"volume {row['volume'] / truth['volume'] - 1:+.4f} "
                f"H {row['mean_weighted'] / truth['mean_weighted'] - 1:+.4f} "
                f"K {row['total_gaussian'] / (4 * np.pi) - 1:+.4f} {row['surface']} r {row['radius']:.2f} "
                f"{time.perf_counter() - start:.0f} s",
                file=sys.stderr,
                flush=True,
            )
    seconds = time.perf_counter() - start
    table = _table(rows)
    inner = table[~table["touches_border"] & (table["status"] == "ok")]
    errors = {}
    for column, name in [
        ("area", "area"),
        ("area_mesh", "area (raw triangles)"),
        ("volume", "volume"),
        ("mean_weighted", "area-weighted mean of H"),
        ("total_gaussian", "total Gaussian curvature"),
    ]:
        key = "area" if column == "area_mesh" else column
        truth = np.array([exact[label][key] for label in inner["label"]])
        errors[name] = np.abs(inner[column].to_numpy() / truth - 1)
    labels = inner["label"].to_numpy()
    errors["total Gaussian curvature, vertex sum K_i A_i (not used)"] = np.abs(
        np.array([alternatives[label]["total_gaussian"] for label in labels]) / (4 * np.pi) - 1
    )
    errors["area-weighted mean of H as sum H_i A_i / sum A_i (not used)"] = np.abs(
        np.array([alternatives[label]["mean_weighted"] / exact[label]["mean_weighted"] for label in labels]) - 1
    )
    targets = {"area": 0.03, "volume": 0.02, "area-weighted mean of H": 0.03, "total Gaussian curvature": 0.02}
    lines = [
        f"## Accuracy: {args.labels} spheres and ellipsoids, semi-axes {args.min_radius:g}-{args.max_radius:g}, "
        f"voxels {' x '.join(f'{s:g}' for s in args.spacing)} (z y x)",
        "",
        f"Image {' x '.join(map(str, image.shape))} voxels; {len(inner)} labels measured (none touch the "
        f"border), {int((table['surface'] == 'voxel').sum())} with the voxel radius detected; "
        f"{seconds:.0f} s for all labels ({seconds / max(len(table), 1):.1f} s per label, median "
        f"{int(np.median(table['n_vertices']))} vertices).",
        "",
        "| quantity | median error | 95th percentile | worst | target | labels within |",
        "|---|--:|--:|--:|--:|--:|",
    ]
    for name, values in errors.items():
        target = targets.get(name)
        within = f"{int((values <= target).sum())}/{values.size}" if target else "-"
        lines.append(
            f"| {name} | {np.median(values):.2%} | {np.percentile(values, 95):.2%} | {values.max():.2%} | "
            f"{f'{target:.0%}' if target else '-'} | {within} |"
        )
    worst = inner.assign(
        area_error=errors["area"],
        h_error=errors["area-weighted mean of H"],
        k_error=errors["total Gaussian curvature"],
        volume_error=errors["volume"],
    )
    lines += [
        "",
        "Worst labels:",
        "",
        "| label | kind | semi-axes | vertices | area | volume | mean H | total K |",
        "|--:|---|---|--:|--:|--:|--:|--:|",
    ]
    order = np.argsort(
        -np.maximum.reduce(
            [worst["area_error"] / 0.03, worst["volume_error"] / 0.02, worst["h_error"] / 0.03, worst["k_error"] / 0.02]
        )
    )
    for position in order[:5]:
        row = worst.iloc[position]
        truth = exact[int(row["label"])]
        lines.append(
            f"| {int(row['label'])} | {truth['kind']} | {', '.join(f'{x:.1f}' for x in truth['axes'])} | "
            f"{int(row['n_vertices'])} | {row['area_error']:.2%} | {row['volume_error']:.2%} | "
            f"{row['h_error']:.2%} | {row['k_error']:.2%} |"
        )
    return lines


def scale(args) -> list[str]:
    from scipy import ndimage

    shape = tuple(args.scale_shape)
    rng = np.random.default_rng(args.seed)
    start = time.perf_counter()
    image = np.zeros(shape, dtype=np.uint16)
    centres = np.column_stack([rng.uniform(22, n - 22, args.scale_labels) for n in shape])
    for label, centre in enumerate(centres, start=1):
        axes = np.sort(rng.uniform(6, 20, 3))[::-1] if label % 2 else np.full(3, rng.uniform(6, 20))
        turn = rotation(rng)
        low = np.maximum(np.floor(centre - axes.max() - 1).astype(int), 0)
        high = np.minimum(np.ceil(centre + axes.max() + 1).astype(int) + 1, shape)
        grids = np.meshgrid(
            *[np.arange(lo, hi) - c for lo, hi, c in zip(low, high, centre)], indexing="ij", sparse=True
        )
        q = [sum(turn[k, j] * grids[k] for k in range(3)) for j in range(3)]
        inside = sum((q[j] / axes[j]) ** 2 for j in range(3)) <= 1
        box = image[tuple(slice(lo, hi) for lo, hi in zip(low, high))]
        box[inside & (box == 0)] = label  # overlapping objects: the first keeps its voxels
    built = time.perf_counter() - start
    start = time.perf_counter()
    boxes = ndimage.find_objects(image)
    found = time.perf_counter() - start
    present = [index + 1 for index, box in enumerate(boxes) if box is not None]
    sample = present[:: max(1, len(present) // args.scale_sample)][: args.scale_sample]
    runs = [("serial", *_timed(image, sample, None))]
    if args.workers and args.workers > 1:
        runs.append((f"{args.workers} workers", *_timed(image, sample, args.workers)))
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20
    lines = [
        f"## Scale: {' x '.join(map(str, shape))} voxels (uint16, {image.nbytes / 2**30:.2f} GiB), "
        f"{len(present)} labels",
        "",
        f"- image built in {built:.0f} s; the labels' boxes found (one pass, scipy.ndimage.find_objects) "
        f"in {found:.1f} s",
        f"- {len(sample)} labels spread over the label range processed end to end (crop, marching cubes, "
        f"curvatures, statistics), the same labels in each run; load average before the runs "
        f"{' '.join(f'{value:.1f}' for value in runs[0][5])} on {os.cpu_count()} cores",
        "",
        "| run | wall | per label | CPU seconds (all processes) | extrapolated to all labels | "
        "peak resident memory | labels ok |",
        "|---|--:|--:|--:|--:|--:|--:|",
    ]
    serial_seconds = runs[0][1]
    for name, seconds, cpu, statuses, extra, _, memory in runs:
        per_label = seconds / len(sample)
        estimate = found + extra + per_label * len(present)
        speedup = "" if name == "serial" else f" ({serial_seconds / seconds:.2f}x)"
        lines.append(
            f"| {name} | {seconds:.0f} s{speedup} | {per_label:.2f} s | {cpu:.0f} s | {estimate / 60:.1f} min | "
            f"{memory} | {statuses.count('ok')}/{len(sample)} |"
        )
    lines += [
        "",
        f"Extrapolated: the label pass ({found:.1f} s), the cluster's start (workers) and the wall "
        f"time per label times the {len(present)} labels. Peak resident memory: of this process "
        f"({peak:.2f} GiB over the whole benchmark, the image itself {image.nbytes / 2**30:.2f} GiB), "
        "and of each worker process.",
    ]
    return lines


def _cpu_seconds() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def _worker_usage() -> tuple[float, float]:
    """CPU seconds and peak resident memory (GiB) of this process.

    The peak is the kernel's high-water mark of the process's own memory
    (``VmHWM``): ``ru_maxrss`` of a worker started by fork and exec keeps that
    of the process it was forked from (here the one holding the image).
    """
    usage = resource.getrusage(resource.RUSAGE_SELF)
    try:
        with open("/proc/self/status") as status:
            peak = next(int(line.split()[1]) for line in status if line.startswith("VmHWM:")) / 2**20
    except (OSError, StopIteration):
        peak = usage.ru_maxrss / 2**20
    return usage.ru_utime + usage.ru_stime, peak


def _timed(image, sample, workers):
    """``(wall seconds, CPU seconds, statuses, cluster start seconds, load average, peak memory text)``."""
    from meshcurv.volume import label_surfaces

    load = os.getloadavg()
    with contextlib.ExitStack() as stack:
        client, started = None, 0.0
        if workers:
            import dask

            from meshcurv import batch, volume

            start = time.perf_counter()
            client = stack.enter_context(dask.config.set(volume.CLUSTER_CONFIG))
            client = stack.enter_context(batch.local_cluster(workers=workers, dashboard=False))
            started = time.perf_counter() - start
            before = sum(cpu for cpu, _ in client.run(_worker_usage).values())
        cpu = _cpu_seconds()
        start = time.perf_counter()
        total, rows = label_surfaces(
            image, spacing=(1.0, 1.0, 1.0), labels_to_use=sample, keep_surfaces=False, client=client
        )
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            statuses = [row["status"] for row, _ in rows]
        seconds = time.perf_counter() - start
        cpu = _cpu_seconds() - cpu
        memory = f"{resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20:.2f} GiB"
        if workers:
            usage = client.run(_worker_usage).values()
            cpu += sum(seconds for seconds, _ in usage) - before
            memory += " + " + " + ".join(f"{peak:.2f}" for _, peak in usage) + " GiB (workers)"
    return seconds, cpu, statuses, started, load, memory


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--labels", type=int, default=50)
    parser.add_argument("--spacing", type=float, nargs=3, default=[1.0, 0.25, 0.25], metavar=("Z", "Y", "X"))
    parser.add_argument("--min-radius", type=float, default=6.0)
    parser.add_argument("--max-radius", type=float, default=20.0)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--no-accuracy", action="store_true")
    parser.add_argument("--scale", action="store_true")
    parser.add_argument("--scale-shape", type=int, nargs=3, default=[512, 1024, 1024])
    parser.add_argument("--scale-labels", type=int, default=2000)
    parser.add_argument("--scale-sample", type=int, default=100)
    parser.add_argument(
        "--workers",
        type=int,
        default=None,
        help="Also run the scale sample on a local Dask cluster of this many processes.",
    )
    parser.add_argument("--markdown", default=None, help="Also write the tables to this file.")
    args = parser.parse_args(argv)
    lines = [
        "# Label images: per-label curvature tables (benchmarks/volume.py)",
        "",
        f"`python benchmarks/volume.py {' '.join(sys.argv[1:] if argv is None else argv)}` on "
        f"{platform.machine()}, Python {platform.python_version()}.",
        "",
    ]
    if not args.no_accuracy:
        lines += accuracy(args) + [""]
    if args.scale:
        lines += scale(args) + [""]
    text = "\n".join(lines)
    print(text)
    if args.markdown:
        with open(args.markdown, "w") as handle:
            handle.write(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
