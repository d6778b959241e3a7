"""A label image in Zarr larger than the memory it is processed in: 2000 objects on 2 Dask workers (issue 34).

Writes a ``--shape`` label image (uint16, chunks of ``--chunk`` voxels,
Zarr's default compression) holding ``--objects`` balls of radius
``--min-radius`` to ``--max-radius`` voxels, one per cell of a jittered grid
(apart from each other; a few cut by the image border), one chunk at a time:
the image is never whole in memory, here either. Then runs
:func:`meshcurv.volume.label_curvatures` on the store
(:func:`meshcurv.io._images.read_image`: a :class:`meshcurv._lazy.LazyImage`)
on a local Dask cluster of ``--workers`` processes, and reports:

- the peak memory: the high-water mark of the resident memory (``VmHWM``)
  of this process and of each worker, their sum, and the peak of the summed
  resident memory of this process and all its children (sampled every 0.2 s)
  against the image's size in memory and the cap ``--cap`` (GiB): the run
  fails (exit 1) when the sampled peak passes the cap;
- the wall and CPU time (the machine may be shared: both are given);
- the area of every ball not cut by the border against ``4 pi R^2``.

    python benchmarks/zarr_labels.py                                  # 1024^3 (2 GiB), 2000 balls, cap 1.5 GiB
    python benchmarks/zarr_labels.py --shape 256 256 256 --objects 100 --cap 1.5    # a quick run
    python benchmarks/zarr_labels.py --markdown benchmarks/zarr_labels.md
"""

from __future__ import annotations

import argparse
import contextlib
import itertools
import os
import platform
import resource
import sys
import tempfile
import threading
import time
import warnings

import numpy as np


def balls(shape, n_objects: int, min_radius: float, max_radius: float, seed: int):
    """``(centres (n, 3), radii (n,))``: one ball per cell of a jittered grid, apart from each other."""
    rng = np.random.default_rng(seed)
    shape = np.asarray(shape, dtype=float)
    per_axis = int(np.ceil(n_objects ** (1 / 3)))
    while per_axis**3 < n_objects:
        per_axis += 1
    cells = np.array(list(itertools.product(range(per_axis), repeat=3)), dtype=float)
    cells = cells[rng.choice(len(cells), n_objects, replace=False)]
    size = shape / per_axis
    radii = rng.uniform(min_radius, max_radius, n_objects)
    room = np.maximum(size[None, :] / 2 - radii[:, None] - 1.0, 0.0)
    centres = (cells + 0.5) * size + rng.uniform(-1, 1, (n_objects, 3)) * room
    edge = rng.random(n_objects) < 0.02  # a few pushed onto the image border
    centres[edge, 0] = np.where(centres[edge, 0] < shape[0] / 2, 0.0, shape[0] - 1.0)
    return centres, radii


def write_store(path, shape, chunk: int, centres, radii) -> float:
    """Write the label image chunk by chunk (label ``i + 1`` = ball ``i``); returns the seconds taken."""
    import zarr

    start = time.perf_counter()
    array = zarr.create_array(store=str(path), shape=tuple(shape), chunks=(chunk,) * 3, dtype="uint16", fill_value=0)
    low, high = np.floor(centres - radii[:, None]), np.ceil(centres + radii[:, None]) + 1
    for corner in itertools.product(*[range(0, n, chunk) for n in shape]):
        a = np.array(corner)
        b = np.minimum(a + chunk, shape)
        hit = np.nonzero(((high > a) & (low < b)).all(axis=1))[0]
        if not hit.size:
            continue
        block = np.zeros(tuple(b - a), dtype=np.uint16)
        grid = np.ogrid[tuple(slice(x, y) for x, y in zip(a, b))]
        for index in hit.tolist():
            inside = sum((axis - c) ** 2 for axis, c in zip(grid, centres[index])) <= radii[index] ** 2
            block[inside] = index + 1
        array[tuple(slice(x, y) for x, y in zip(a, b))] = block
    return time.perf_counter() - start


def _high_water() -> float:
    """This process's peak resident memory (GiB): ``VmHWM``, else ``ru_maxrss``."""
    try:
        with open("/proc/self/status") as status:
            return next(int(line.split()[1]) for line in status if line.startswith("VmHWM:")) / 2**20
    except (OSError, StopIteration):
        return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 2**20


def _cpu() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def _worker_usage() -> tuple[float, float]:
    return _cpu(), _high_water()


class TreeMemory:
    """The peak of the summed resident memory of this process and all its children, sampled in a thread."""

    def __init__(self, every: float = 0.2) -> None:
        import psutil

        self._process = psutil.Process()
        self._every = every
        self.peak = 0.0
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def _sample(self) -> float:
        total = 0
        for process in [self._process, *self._process.children(recursive=True)]:
            with contextlib.suppress(Exception):
                total += process.memory_info().rss
        return total / 2**30

    def _run(self) -> None:
        while not self._stop.is_set():
            self.peak = max(self.peak, self._sample())
            self._stop.wait(self._every)

    def __enter__(self) -> TreeMemory:
        self._thread.start()
        return self

    def __exit__(self, *exc) -> None:
        self._stop.set()
        self._thread.join()
        self.peak = max(self.peak, self._sample())


def run(path, workers: int):
    """``(table, seconds, cpu seconds, worker peaks GiB, main peak GiB, tree peak GiB)`` of the store on ``workers``."""
    import dask

    from meshcurv import batch, volume
    from meshcurv.io._images import read_image

    with (
        TreeMemory() as tree,
        dask.config.set(volume.CLUSTER_CONFIG),
        batch.local_cluster(workers=workers, dashboard=False) as client,
    ):
        before = sum(cpu for cpu, _ in client.run(_worker_usage).values())
        cpu = _cpu()
        start = time.perf_counter()
        image = read_image(path)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            table = volume.label_curvatures(image, spacing=(1.0, 1.0, 1.0), client=client)
        seconds = time.perf_counter() - start
        usage = list(client.run(_worker_usage).values())
        cpu = _cpu() - cpu + sum(c for c, _ in usage) - before
    return table, seconds, cpu, [peak for _, peak in usage], _high_water(), tree.peak


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--shape", type=int, nargs=3, default=[1024, 1024, 1024], metavar=("Z", "Y", "X"))
    parser.add_argument("--objects", type=int, default=2000)
    parser.add_argument("--min-radius", type=float, default=5.0)
    parser.add_argument("--max-radius", type=float, default=9.0)
    parser.add_argument("--chunk", type=int, default=128)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--cap", type=float, default=1.5, help="GiB the process tree must stay under.")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--store", default=None, help="Folder of the Zarr store (default: a temporary one).")
    parser.add_argument("--markdown", default=None)
    args = parser.parse_args(argv)
    shape = np.array(args.shape)
    nbytes = int(np.prod(shape)) * 2
    centres, radii = balls(shape, args.objects, args.min_radius, args.max_radius, args.seed)
    with contextlib.ExitStack() as stack:
        folder = args.store or stack.enter_context(tempfile.TemporaryDirectory(prefix="zarr_labels_"))
        path = os.path.join(folder, "labels.zarr")
        writing = write_store(path, shape, args.chunk, centres, radii)
        on_disk = sum(os.path.getsize(os.path.join(root, name)) for root, _, names in os.walk(path) for name in names)
        load = os.getloadavg()
        table, seconds, cpu, worker_peaks, main_peak, tree_peak = run(path, args.workers)
    table = table.set_index("label")
    inner = table[~table.touches_border & (table.status == "ok")]
    truth = 4 * np.pi * radii[inner.index.to_numpy() - 1] ** 2
    error = np.abs(inner.area.to_numpy() / truth - 1)
    statuses = table.status.value_counts().to_dict()
    lines = [
        "# A Zarr label image larger than its memory cap, on 2 workers (benchmarks/zarr_labels.py)",
        "",
        f"`python benchmarks/zarr_labels.py {' '.join(sys.argv[1:] if argv is None else argv)}` on "
        f"{platform.machine()}, {os.cpu_count()} cores shared with other work (load average before the run "
        f"{load[0]:.1f}), Python {platform.python_version()}.",
        "",
        "| what | value |",
        "|---|--:|",
        f"| image | {' x '.join(map(str, shape))} uint16, {nbytes / 2**30:.2f} GiB in memory, chunks {args.chunk}^3, "
        f"{on_disk / 2**20:.0f} MiB on disk (written chunk by chunk in {writing:.0f} s) |",
        f"| objects | {len(table)} balls of radius {args.min_radius:g}-{args.max_radius:g} voxels "
        f"({', '.join(f'{n} {s}' for s, n in statuses.items())}; {int(table.touches_border.sum())} cut by the border) |",
        f"| wall time (cluster started) | {seconds:.0f} s on {args.workers} workers |",
        f"| CPU time, all processes | {cpu:.0f} s |",
        f"| peak memory, this process (VmHWM) | {main_peak:.2f} GiB |",
        f"| peak memory, each worker (VmHWM) | {', '.join(f'{p:.2f}' for p in worker_peaks)} GiB |",
        f"| peak of the summed resident memory of all processes (sampled 5/s) | {tree_peak:.2f} GiB |",
        f"| cap | {args.cap:.2f} GiB: {'kept' if tree_peak <= args.cap else 'PASSED'} |",
        f"| area of the {len(inner)} balls not cut by the border vs 4 pi R^2 | median {np.median(error):.2%}, "
        f"worst {error.max():.2%} |",
    ]
    text = "\n".join(lines) + "\n"
    print(text)
    if args.markdown:
        with open(args.markdown, "w") as handle:
            handle.write(text)
    return 0 if tree_peak <= args.cap else 1


if __name__ == "__main__":
    sys.exit(main())
