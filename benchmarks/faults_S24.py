"""Where one default call touches fresh memory, stage by stage (issue 31, helper S24).

``profile_call.py``'s stages, each wrapped with a counter of the process's minor page faults and system CPU
seconds (``resource.getrusage``), exclusive of the stages it calls: a minor fault is a first write to a page
the call mapped afresh (glibc hands large freed buffers back to the OS, so every large temporary of every call
is new memory), and the system time of a call is mostly the kernel serving them. Run::

    .venv/bin/python benchmarks/faults_S24.py --sizes 1M --repeats 3

With huge pages (numpy advises them for large arrays) a fault maps 2 MB: the faults undercount the bytes. The
fresh mappings themselves, per stage (one call after the warm-up)::

    strace -f -e trace=mmap,munmap,write -o trace.txt .venv/bin/python benchmarks/faults_S24.py --repeats 1 --marks
    .venv/bin/python benchmarks/faults_S24.py --parse trace.txt
"""

from __future__ import annotations

import argparse
import functools
import os
import re
import resource
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import numpy as np  # noqa: E402

import profile_call  # noqa: E402

import meshcurv  # noqa: E402


def _usage():
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return np.array([usage.ru_minflt, usage.ru_stime, usage.ru_utime])


class Counters(profile_call.Timers):
    """Exclusive (minor faults, system s, user s) per stage."""

    def __init__(self):
        super().__init__()
        self.used: dict[str, np.ndarray] = {}

    def wrap(self, stage, function):
        @functools.wraps(function)
        def counted(*args, **kwargs):
            self.stack.append(np.zeros(3))
            if MARKS is not None:
                os.write(MARKS, f"S24>{stage}".encode())
            before = _usage()
            try:
                return function(*args, **kwargs)
            finally:
                if MARKS is not None:
                    os.write(MARKS, f"S24<{stage}".encode())
                spent = _usage() - before
                nested = self.stack.pop()
                self.used[stage] = self.used.get(stage, 0.0) + spent - nested
                if self.stack:
                    self.stack[-1] += spent

        return counted

    def reset(self):
        self.used.clear()


#: a file descriptor the stages' entries and exits are written to (``--marks``: read by strace)
MARKS = None

_SYSCALL = re.compile(r"^(\d+)\s+(mmap|munmap|brk|write|madvise)\((.*)\)\s+=\s+(\S+)")


def parse(path: str) -> None:
    """Per stage, of an ``strace -f -e trace=mmap,munmap,write,brk,madvise -o path`` of a run with ``--marks``:
    numpy's large arrays (its ``madvise(MADV_HUGEPAGE)`` of every allocation of 4 MB and more), the fresh
    anonymous mappings and the growth of the heap (``brk``), each counted to the innermost stage open when it
    was made (the marks of every thread)."""
    stack: list[str] = []
    rows: dict[str, np.ndarray] = {}  # numpy arrays >= 4 MB: count, MB; mmaps: count, MB; brk growth MB
    top = None
    started = False
    with open(path, encoding="utf-8", errors="replace") as handle:
        for line in handle:
            match = _SYSCALL.match(line)
            if not match:
                continue
            _, name, arguments, result = match.groups()
            if name == "write":
                mark = re.search(r'"S24([<>])(.*?)"', arguments)
                if mark:
                    started = True
                    if mark.group(1) == ">":
                        stack.append(mark.group(2))
                    elif stack:
                        stack.pop()
                continue
            if name == "brk":
                end = int(result, 16)
                grown = 0 if top is None else max(end - top, 0)
                top = end
            if not started:
                continue
            row = rows.setdefault(stack[-1] if stack else "other", np.zeros(5))
            if name == "madvise" and "MADV_HUGEPAGE" in arguments:
                row[0] += 1
                row[1] += int(arguments.split(",")[1]) / 1e6
            elif name == "mmap" and "MAP_ANONYMOUS" in arguments and "PROT_NONE" not in arguments:
                row[2] += 1
                row[3] += int(arguments.split(",")[1].strip(), 0) / 1e6
            elif name == "brk":
                row[4] += grown / 1e6
    print("| stage | numpy arrays >= 4 MB | their MB | fresh mmaps | their MB | heap growth MB |")
    print("|---|--:|--:|--:|--:|--:|")
    for stage, row in sorted(rows.items(), key=lambda item: -item[1][1]):
        print(f"| {stage} | {row[0]:.0f} | {row[1]:.0f} | {row[2]:.0f} | {row[3]:.0f} | {row[4]:.0f} |")
    total = sum(rows.values())
    print(f"| total | {total[0]:.0f} | {total[1]:.0f} | {total[2]:.0f} | {total[3]:.0f} | {total[4]:.0f} |")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sizes", default="1M")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--marks", action="store_true", help="write the stages' marks to /dev/null (for strace)")
    parser.add_argument("--parse", help="the strace output of a run with --marks: fresh mappings per stage")
    args = parser.parse_args(argv)
    if args.parse:
        parse(args.parse)
        return 0
    global MARKS
    counters = Counters()
    profile_call.install(counters)
    page = os.sysconf("SC_PAGE_SIZE")
    for label in args.sizes.split(","):
        mesh = meshcurv.shapes.icosphere(profile_call.SIZES[label])
        v = np.ascontiguousarray(mesh.vertices)
        f = np.ascontiguousarray(mesh.faces, dtype=np.int64)
        meshcurv.principal_curvatures(v, f)
        if args.marks:
            MARKS = os.open(os.devnull, os.O_WRONLY)
        runs = []
        for _ in range(args.repeats):
            counters.reset()
            before = _usage()
            wall = time.perf_counter()
            meshcurv.principal_curvatures(v, f)
            wall = time.perf_counter() - wall
            runs.append((_usage() - before, wall, dict(counters.used)))
        runs.sort(key=lambda run: run[0][1] + run[0][2])
        total, wall, used = runs[len(runs) // 2]
        n = v.shape[0]
        print(f"## icosphere({profile_call.SIZES[label]}), {n:,} vertices: the call of median CPU of {args.repeats}")
        print(
            f"whole call: {total[0]:,.0f} minor faults ({total[0] * page / n:.0f} B/vertex fresh), "
            f"sys {total[1]:.3f} s, user {total[2]:.3f} s, wall {wall:.3f} s"
        )
        print("| stage | minor faults | MB fresh | sys s | user s |")
        print("|---|--:|--:|--:|--:|")
        rows = sorted(used.items(), key=lambda item: -item[1][0])
        other = total - sum(used.values())
        for stage, (faults, sys_s, user_s) in [*rows, ("other", other)]:
            print(f"| {stage} | {faults:,.0f} | {faults * page / 1e6:.0f} | {sys_s:.3f} | {user_s:.3f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
