"""The threads that run a kernel's chunks (``_kernels._common.run_chunks``): one pool kept between calls."""

from __future__ import annotations

import multiprocessing
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

numba = pytest.importorskip("numba")

from meshcurv._kernels import _common  # noqa: E402  (numba first: the kernels need it)
from meshcurv._kernels._common import run_chunks  # noqa: E402


def _fill(lo, hi, out, value):
    out[lo:hi] += value


@pytest.fixture
def two_threads():
    if numba.config.NUMBA_NUM_THREADS < 2:
        pytest.skip("numba has one thread here (NUMBA_NUM_THREADS)")
    threads = numba.get_num_threads()
    numba.set_num_threads(2)
    yield
    numba.set_num_threads(threads)


def test_the_pool_is_made_once_and_kept(two_threads):
    out = np.zeros(100)
    run_chunks(_fill, 100, 8, out, 1.0)
    pool = _common._pool()
    alive = threading.active_count()
    for _ in range(50):
        run_chunks(_fill, 100, 8, out, 1.0)
    assert _common._pool() is pool
    assert threading.active_count() == alive  # no thread started per call
    assert (out == 51.0).all()  # every item once per call


def test_calls_from_several_threads_each_write_their_rows(two_threads):
    outs = [np.zeros(1000) for _ in range(6)]

    def caller(k):
        for _ in range(20):
            run_chunks(_fill, 1000, 16, outs[k], float(k + 1))

    callers = [threading.Thread(target=caller, args=(k,)) for k in range(6)]
    for thread in callers:
        thread.start()
    for thread in callers:
        thread.join(timeout=60)
    assert not any(thread.is_alive() for thread in callers)
    for k, out in enumerate(outs):
        np.testing.assert_array_equal(out, np.full(1000, 20.0 * (k + 1)))


def test_a_call_from_a_worker_of_the_pool_does_not_wait_on_its_queue(two_threads):
    """Ranges that call run_chunks again: the inner helper, queued behind the busy workers, is cancelled."""
    out = np.zeros(64)

    def outer(lo, hi):
        run_chunks(_fill, hi - lo, 4, out[lo:hi], 1.0)

    caller = threading.Thread(target=run_chunks, args=(outer, 64, 8))
    caller.start()
    caller.join(timeout=60)
    assert not caller.is_alive()
    assert (out == 1.0).all()


def test_no_range_runs_on_after_an_error_is_raised(two_threads):
    running = []

    def failing(lo, hi):
        if lo == 0:
            raise ValueError(f"range {lo}-{hi} failed")
        running.append(lo)
        time.sleep(0.05)  # the other thread's ranges outlast the error
        running.remove(lo)

    for _ in range(5):
        with pytest.raises(ValueError, match="range 0-1 failed"):
            run_chunks(failing, 8, 8)
        assert running == []  # every range started has ended when the call returns


def _child(queue):
    out = np.zeros(100)
    run_chunks(_fill, 100, 8, out, 2.0)
    queue.put(float(out.sum()))


@pytest.mark.skipif(sys.platform == "win32", reason="no fork on Windows")
@pytest.mark.filterwarnings("ignore:This process .* is multi-threaded:DeprecationWarning")
def test_a_forked_child_makes_its_own_pool(two_threads):
    run_chunks(_fill, 100, 8, np.zeros(100), 1.0)  # the parent's pool and threads exist
    context = multiprocessing.get_context("fork")
    queue = context.Queue()
    child = context.Process(target=_child, args=(queue,))
    child.start()
    child.join(timeout=120)
    if child.is_alive():
        child.kill()
    assert child.exitcode == 0
    assert queue.get(timeout=5) == 200.0


def test_a_process_with_the_pool_exits():
    code = (
        "import numpy as np, numba\n"
        "from meshcurv._kernels._common import run_chunks\n"
        "def fill(lo, hi, out): out[lo:hi] = 1.0\n"
        "out = np.zeros(100)\n"
        "run_chunks(fill, 100, 8, out)\n"
        "assert out.all()\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, timeout=120, check=False)
    assert done.returncode == 0, done.stderr.decode()
