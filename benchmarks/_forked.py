"""What the fuzzers share: a forked child's answer read under a wall-clock limit.

``benchmarks/fuzz_api.py`` and ``benchmarks/fuzz_labels.py`` run each case in a
forked child that writes its pickled outcome to a pipe; :func:`collect` reads
it, kills the child at the limit and reaps it.
"""

from __future__ import annotations

import os
import resource
import select
import signal
import time


def vsize() -> int:
    """This process's virtual size in bytes (the base of the children's address-space caps)."""
    with open("/proc/self/statm") as fh:
        return int(fh.read().split()[0]) * resource.getpagesize()


def collect(pid: int, read_end: int, timeout: float) -> tuple[bytes, int, bool, float]:
    """``(data, status, timed_out, elapsed)``: what child ``pid`` wrote to ``read_end`` within ``timeout`` s.

    A child still running at the limit is killed; the child is always reaped
    (``status`` as :func:`os.waitpid` gives it) and ``read_end`` closed.
    """
    start = time.monotonic()
    chunks, timed_out = [], False
    while True:
        remaining = timeout - (time.monotonic() - start)
        if remaining <= 0:
            timed_out = True
            break
        ready, _, _ = select.select([read_end], [], [], remaining)
        if ready:
            chunk = os.read(read_end, 1 << 20)
            if not chunk:
                break
            chunks.append(chunk)
    elapsed = time.monotonic() - start
    if timed_out:
        os.kill(pid, signal.SIGKILL)
    _, status = os.waitpid(pid, 0)
    os.close(read_end)
    return b"".join(chunks), status, timed_out, elapsed
