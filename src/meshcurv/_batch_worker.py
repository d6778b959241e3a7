"""Setup of the worker processes of the local cluster of :mod:`meshcurv.batch` (a Dask preload module)."""

import signal


def dask_setup(worker) -> None:
    """Leave Ctrl-C to the command that started the cluster.

    In a terminal, Ctrl-C reaches every process of the group; the workers would
    each print a ``KeyboardInterrupt`` traceback. The command stops them itself
    when it is interrupted (closing the cluster).
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
