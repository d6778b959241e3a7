"""Choice between the pure-NumPy code paths and the compiled (numba) kernels.

The NumPy paths are always there and are the reference; the numba kernels
(:mod:`meshcurv._kernels`, one module beside each module of NumPy code) compute
the same quantities in single passes without temporaries. numba is a dependency of meshcurv: they
are used unless the NumPy paths are asked for (or numba cannot be imported: a broken install).

Twins: a kernel bears the name of the NumPy function it mirrors, and that
function carries the decorator :func:`twin`, which registers the pair in
:data:`TWINS` and runs the kernel in its place on the compiled backend
(``tests/test_backend.py`` holds every registered twin to a kernel of its
name). Code whose NumPy side does not yet have the kernel's arguments asks
:func:`numba_kernels` for the module and branches itself.

Decided once per process: the first call that needs a kernel tries to import
numba (never ``import meshcurv`` itself) and remembers the outcome, so that a
base install without numba does not retry the failed import (some 11 ms, 10 to
15 times per call) on every lookup; a lookup then costs an environment read.
The first decision of each backend is logged once, at INFO on the
``meshcurv`` logger (``meshcurv -v`` shows it): which backend runs and, when
numba cannot be imported, why, and that ``pip install numba`` gives the compiled one.

Which backend runs, highest precedence first: :func:`use_backend` (a context
manager, for tests and for callers who want one block on one backend), the
``MESHCURV_BACKEND`` environment variable (``auto``, ``numpy`` or ``numba``,
read at each call), then ``auto`` (numba when importable).

Interrupts: Ctrl-C while a compiled kernel runs reaches Python when the kernel
returns, where CPython reports it as a :class:`SystemError` ("returned a
result with an exception set") whose cause is the :class:`KeyboardInterrupt`;
every kernel handed out here re-raises the KeyboardInterrupt itself.

Thread safety: numba's ``workqueue`` threading layer (the one numba falls back
to where neither TBB nor OpenMP is installed) aborts the process when two
threads launch parallel kernels at once. :func:`numba_kernels` therefore hands
out the kernels behind :class:`_SerialisedKernels`: every kernel call takes a
process-wide lock while the layer is unknown (the first call decides it) and
whenever it is ``workqueue``; under ``tbb`` and ``omp`` (both thread-safe) the
calls go straight through. The cost is one attribute lookup and one function
call per kernel call (about a microsecond) on the other layers; under
``workqueue``, concurrent calls run one after the other instead of aborting.

First use: numba compiles a kernel on its first call (only the kernels a call
reaches, each once per argument types) and caches the machine code on disk
(``cache=True``; ``NUMBA_CACHE_DIR`` or numba's default), so a later process
loads it instead. A compilation, unlike a load from the cache, is announced
once per process on the ``meshcurv`` logger at WARNING level with its rough
cost (:data:`COMPILE_MESSAGE`), and each compiled kernel at INFO level with its
time: a first call that spends half a minute compiling must not look like a
hang, and WARNING is the lowest level that Python shows without any logging
configuration (its last-resort handler) and that the CLI shows by default; it
happens once per installation, so it is no noise. numba's event API
(:mod:`numba.core.event`, ``numba:compile``, fired on cache misses only) tells
a compilation from a load. While kernels compile, a clock on stderr gives the
compilation's elapsed time every :data:`TICK_SECONDS` (one line rewritten in
place, cleared when the compilation ends), only when stderr is a terminal
(:func:`show_compile_time` changes that), so that the library stays silent
in tests, pipes and logs.
"""

from __future__ import annotations

import contextlib
import contextvars
import functools
import importlib
import inspect
import logging
import os
import sys
import threading
import time
from collections.abc import Callable
from types import ModuleType
from typing import TypeVar

from .errors import InvalidOptionError, MissingDependencyError

BACKENDS = ("auto", "numpy", "numba")

_F = TypeVar("_F", bound=Callable)

#: The backend :func:`use_backend` asks for in this thread or task (None: the environment decides). A
#: context variable: a block on one backend in one thread (or asyncio task) leaves the others' as it was.
_override: contextvars.ContextVar[str | None] = contextvars.ContextVar("meshcurv_backend", default=None)

logger = logging.getLogger(__name__)

#: Logged once per process (WARNING) when a kernel is compiled rather than loaded from the disk cache.
COMPILE_MESSAGE = (
    "compiling meshcurv's numba kernels for first use (once per installation: 10 to 30 s of CPU for the "
    "default method, one to two minutes for all methods, by machine); they are cached on disk for later processes (%s)"
)


def _requested() -> str:
    choice = _override.get() or os.environ.get("MESHCURV_BACKEND", "auto")
    if choice not in BACKENDS:
        raise InvalidOptionError(f"unknown backend {choice!r} (MESHCURV_BACKEND); choose one of {', '.join(BACKENDS)}")
    return choice


#: What the once-per-process import of the kernels gave: ``(module, None)`` or ``(None, ImportError)``;
#: None before the first call that needs a kernel.
_imported: tuple[ModuleType, None] | tuple[None, ImportError] | None = None

#: The backend lines already logged (each once per process).
_logged: set = set()

#: The INFO line when numba cannot be imported.
MISSING_MESSAGE = (
    "meshcurv backend: numpy (numba cannot be imported: %s); pip install numba gives "
    "the compiled kernels, several times faster"
)


#: The OpenMP wait policy asked for before the compiled kernels first run, unless the environment names one
#: (see :func:`_import_kernels`).
WAIT_POLICY = "PASSIVE"


def _import_kernels() -> tuple[ModuleType, None] | tuple[None, ImportError]:
    """``(kernels package, None)``, imported once per process, or ``(None, ImportError)`` when numba (or the
    package) cannot be imported.

    Before the first import, ``OMP_WAIT_POLICY`` is set to :data:`WAIT_POLICY` unless the environment
    names a policy: numba runs its parallel kernels on OpenMP (``omp``) where it is installed, and GNU
    OpenMP's threads spin for a while after each parallel region by default, waiting for the next one. A
    call makes some 30 kernel launches, mostly short: on a machine whose cores are shared (a server, a
    Dask worker beside others) each launch then cost 3-6 ms of CPU and wall time instead of 0.03-0.6 ms
    (edge lengths of 16,000 to 300,000 edges, 2 threads, load average 4), the whole default call on a
    100,000-vertex icosphere 0.58 s of CPU instead of 0.46 (``benchmarks/speed_profile.md``). The results do
    not change. The policy is read when OpenMP starts, once per process: a program that ran OpenMP code
    before keeps the policy it started with.
    """
    global _imported
    if _imported is None:
        os.environ.setdefault("OMP_WAIT_POLICY", WAIT_POLICY)
        try:
            from . import _kernels
        except ImportError as error:
            _imported = (None, error)
        else:
            _imported = (_kernels, None)
            _announce_compilation()
    return _imported


def _log_once(key: str, message: str, *args) -> None:
    if key not in _logged:
        _logged.add(key)
        logger.info(message, *args)


def _forget() -> None:
    """Forget the decision (for tests that hide or restore numba); the next lookup decides again."""
    global _imported
    _imported = None
    _logged.clear()


def backend_name() -> str:
    """``'numba'`` or ``'numpy'``: the backend the next call will use (see the module's doc)."""
    return "numpy" if _compiled() is None else "numba"


def _compiled():
    """The kernels package when the compiled backend is to be used, else None (and the backend logged once)."""
    choice = _requested()
    if choice == "numpy":
        _log_once("numpy", "meshcurv backend: numpy (asked for: MESHCURV_BACKEND or use_backend)")
        return None
    package, error = _import_kernels()
    if package is None:
        if choice == "numba":
            raise MissingDependencyError(f"the numba backend needs numba ({error}): pip install numba") from None
        _log_once("missing", MISSING_MESSAGE, error)
        return None
    if "numba" not in _logged:
        _log_once("numba", "meshcurv backend: numba %s (the fast kernels)", _numba_version())
    return package


def numba_kernels(module: str):
    """The compiled kernels of ``meshcurv._kernels.<module>``, or None when the NumPy paths are to be used.

    ``module`` names the module of NumPy code the kernels mirror
    (``"geometry"``, ``"jets"``, ``"icc"``, ...). The module is imported on
    first use and handed out behind :class:`_SerialisedKernels`.
    """
    package = _compiled()
    if package is None:
        return None
    return _serialised(importlib.import_module(f"{package.__name__}.{module}"))


#: The registered twins: ``"module.name"`` of a kernel of :mod:`meshcurv._kernels` -> the NumPy function it
#: mirrors (:func:`twin`), which bears its name.
TWINS: dict[str, Callable] = {}


def twin(module: str) -> Callable[[_F], _F]:
    """Decorator: the NumPy function is the twin of the kernel of the same name in ``meshcurv._kernels.<module>``.

    The kernel takes the same arguments, in the same order (keyword-only
    ones too: the kernel gets them all by position, defaults filled in), and
    returns the same result (to the bit, or within the tolerance
    ``tests/test_kernel_twins.py`` states). The
    decorated function runs the kernel when the compiled backend is to be used
    (:func:`numba_kernels`), its own NumPy body otherwise; the body stays
    reachable as ``function.numpy``, the reference the kernel is tested
    against. The pair is registered in :data:`TWINS`.

    Parameters
    ----------
    module : str
        The module of :mod:`meshcurv._kernels` that holds the kernel (``"geometry"``, ...).

    Returns
    -------
    callable
        The decorator.
    """

    def register(function: _F) -> _F:
        name = function.__name__
        TWINS[f"{module}.{name}"] = function
        signature = inspect.signature(function)

        @functools.wraps(function)
        def dispatch(*args, **kwargs):
            kernels = numba_kernels(module)
            if kernels is None:
                return function(*args, **kwargs)
            # the kernel takes every argument by position, in the order of the NumPy function's (defaults filled)
            bound = signature.bind(*args, **kwargs)
            bound.apply_defaults()
            return getattr(kernels, name)(*bound.arguments.values())

        dispatch.numpy = function  # type: ignore[attr-defined]
        return dispatch  # type: ignore[return-value]

    return register


def kernel_threads() -> int:
    """The threads numba's parallel kernels use (``NUMBA_NUM_THREADS``, ``numba.set_num_threads``).

    For sizing the chunks of a kernel's work; call it only on the compiled path.
    """
    import numba

    return numba.get_num_threads()


def _numba_version() -> str:
    import numba

    return numba.__version__


_announcer = None


def _announce_compilation() -> None:
    """Install (once) the listener that announces the compilation of meshcurv's kernels."""
    global _announcer
    if _announcer is not None:
        return
    from numba.core import event

    class Announcer(_CompileAnnouncer, event.Listener):
        pass

    _announcer = Announcer()
    event.register("numba:compile", _announcer)


def _cache_location() -> str:
    from numba.core import config

    cache_dir = config.CACHE_DIR  # type: ignore[attr-defined]  # numba's config sets its names at import
    return f"NUMBA_CACHE_DIR={cache_dir}" if cache_dir else "numba's cache beside the package"


#: Seconds between two readings of the compilation clock (see :func:`show_compile_time`).
TICK_SECONDS = 3.0

#: Whether the compilation clock runs: None on a terminal only (the default), True always, False never.
_clock_wanted: bool | None = None


def show_compile_time(enabled: bool | None = True) -> None:
    """Show the elapsed time of a compilation of the kernels on stderr while it runs.

    Parameters
    ----------
    enabled : bool or None, default: True
        True: always (a line every :data:`TICK_SECONDS`, rewritten in place on
        a terminal); False: never; None: only when stderr is a terminal (what
        happens without any call).
    """
    global _clock_wanted
    _clock_wanted = enabled


class _CompileClock:
    """A thread that writes the compilation's elapsed time to stderr every :data:`TICK_SECONDS`."""

    def __init__(self, elapsed_before: float, started: float):
        self.elapsed_before = elapsed_before
        self.started = started
        self.wrote = False
        self.stream = sys.stderr
        self.terminal = _isatty(self.stream)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, name="meshcurv-compile-clock", daemon=True)
        self._thread.start()

    def _run(self) -> None:
        # on a terminal, a later kernel's clock goes on at once from the time of the earlier ones
        wait = 0.0 if self.elapsed_before > 0 and self.terminal else TICK_SECONDS
        while not self._stop.wait(wait):
            wait = TICK_SECONDS
            seconds = self.elapsed_before + time.perf_counter() - self.started
            line = f"meshcurv: compiling the numba kernels (first use): {seconds:.0f} s"
            try:
                self.stream.write(f"\r{line}\033[K" if self.terminal else f"{line}\n")
                self.stream.flush()
            except (OSError, ValueError):  # stderr closed under us: no clock, never an error
                return
            self.wrote = True

    def stop(self) -> None:
        self._stop.set()
        self._thread.join()
        if self.wrote and self.terminal:
            with contextlib.suppress(OSError, ValueError):
                self.stream.write("\r\033[K")  # the line cleared: what follows starts on a clean line
                self.stream.flush()


def _isatty(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, OSError, ValueError):
        return False


def _clock_runs() -> bool:
    return _isatty(sys.stderr) if _clock_wanted is None else _clock_wanted


class _CompileAnnouncer:
    """numba event listener: logs the compilation of meshcurv's kernels (not loads from the cache)."""

    def __init__(self):
        self.announced = False
        self.depth = 0
        self.started = 0.0
        self.compiled: list[tuple[str, float]] = []
        self.clock: _CompileClock | None = None

    @staticmethod
    def _ours(event) -> str | None:
        data = event.data or {}
        function = getattr(data.get("dispatcher"), "py_func", None)
        module = getattr(function, "__module__", "") or ""
        return function.__name__ if function is not None and module.startswith("meshcurv.") else None

    def on_start(self, event):
        if self._ours(event) is None:
            return
        if self.depth == 0:
            self.started = time.perf_counter()
            if not self.announced:
                self.announced = True
                logger.warning(COMPILE_MESSAGE, _cache_location())
            if _clock_runs():
                self.clock = _CompileClock(sum(seconds for _, seconds in self.compiled), self.started)
        self.depth += 1

    def on_end(self, event):
        name = self._ours(event)
        if name is None:
            return
        self.depth = max(self.depth - 1, 0)
        if self.depth == 0:
            seconds = time.perf_counter() - self.started
            if self.clock is not None:
                self.clock.stop()
                self.clock = None
            self.compiled.append((name, seconds))
            logger.info("compiled the numba kernel %s in %.1f s", name, seconds)


#: Serialises kernel calls where the threading layer is not thread-safe (see the module's doc).
_KERNEL_LOCK = threading.RLock()

#: The threading layer numba chose, once a parallel kernel has run (None before).
_layer: str | None = None

#: Threading layers that may be entered by several threads at once.
THREAD_SAFE_LAYERS = ("tbb", "omp")


def _threading_layer() -> str | None:
    """numba's threading layer, or None before the first parallel kernel has run."""
    import numba

    try:
        return numba.threading_layer()
    except ValueError:  # no parallel kernel has run yet
        return None


class _SerialisedKernels:
    """The kernels module, with each call under :data:`_KERNEL_LOCK` unless the layer is thread-safe."""

    def __init__(self, module):
        self._module = module
        self._wrapped: dict = {}

    def __getattr__(self, name):
        value = getattr(self._module, name)
        if not callable(value) or isinstance(value, type):
            return value
        wrapped = self._wrapped.get(name)
        if wrapped is None:
            wrapped = self._wrapped[name] = _locked(value)
        return wrapped


#: Kernels whose arrays all have fewer rows than this run on one thread (see :func:`_small`).
SERIAL_ROWS = 16384


def _small(args) -> bool:
    """Whether every array argument has fewer than :data:`SERIAL_ROWS` rows.

    Such a kernel does well under a millisecond of work: a second thread saves
    microseconds on an idle machine, while each parallel launch waits at its
    barrier for every worker thread to be scheduled, which on a busy machine
    (a shared server, a Dask worker beside others) costs milliseconds. A
    2930-vertex mesh (spot.obj) took 0.3-1.4 s per ``icc`` call on 2 threads
    of this project's loaded 2-core machine against 0.05-0.09 s on one. The
    kernels' results do not depend on the number of threads.
    """
    for value in args:
        shape = getattr(value, "shape", None)
        if shape and shape[0] >= SERIAL_ROWS:
            return False
    return True


def _run(function, args, kwargs):
    if not _small(args):
        return function(*args, **kwargs)
    import numba

    threads = numba.get_num_threads()
    if threads == 1:
        return function(*args, **kwargs)
    numba.set_num_threads(1)  # for this thread's launches only
    try:
        return function(*args, **kwargs)
    finally:
        numba.set_num_threads(threads)


def _direct(function, args, kwargs):
    return function(*args, **kwargs)


def _locked(function):
    # compiled kernels (and those that run compiled chunks on threads) only: a module's Python helpers run as
    # they are
    run = _run if hasattr(function, "py_func") or getattr(function, "runs_chunks", False) else _direct

    @functools.wraps(function)
    def call(*args, **kwargs):
        global _layer
        try:
            if _layer in THREAD_SAFE_LAYERS:
                return run(function, args, kwargs)
            with _KERNEL_LOCK:
                result = run(function, args, kwargs)
                if _layer is None:
                    _layer = _threading_layer()
                return result
        except SystemError as error:  # Ctrl-C during the kernel (see the module's doc)
            interrupt = _interrupt_of(error)
            if interrupt is None:
                raise
            raise interrupt from None

    return call


def _interrupt_of(error: BaseException | None) -> KeyboardInterrupt | None:
    """The KeyboardInterrupt behind a SystemError of a compiled call (its cause or context), or None."""
    seen = 0
    while error is not None and seen < 8:
        if isinstance(error, KeyboardInterrupt):
            return error
        error = error.__cause__ or error.__context__
        seen += 1
    return None


_proxies: dict = {}


def _serialised(module) -> _SerialisedKernels:
    proxy = _proxies.get(id(module))
    if proxy is None:
        proxy = _proxies[id(module)] = _SerialisedKernels(module)
    return proxy


@contextlib.contextmanager
def use_backend(name: str):
    """Run a block with the given backend (``'numpy'``, ``'numba'`` or ``'auto'``).

    The choice holds in the calling thread (or asyncio task) only: other
    threads keep theirs (:mod:`contextvars`).

    Parameters
    ----------
    name : {'numpy', 'numba', 'auto'}
        The backend of the block.

    Raises
    ------
    InvalidOptionError
        ``name`` is not one of :data:`BACKENDS`.
    """
    if name not in BACKENDS:
        raise InvalidOptionError(f"unknown backend {name!r}; choose one of {', '.join(BACKENDS)}")
    token = _override.set(name)
    try:
        yield
    finally:
        _override.reset(token)
