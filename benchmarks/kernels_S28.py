"""CPU seconds of the default's two kernels alone, on their recorded arguments (issue 31, helper S28).

Records the arguments of the normal fits (``_kernels.jets.fit_jets_connected``, the degree-3 call) and of the
ball sums (``_kernels.neighborhoods.connected_face_sums``) in one default call on an icosphere, then calls each
kernel ``--repeats`` times on copies of them and prints the median CPU seconds (``time.process_time``: every
thread). ``--save``: the kernels' outputs to an ``.npz`` file; ``--compare``: the largest differences from such a
file (old and new code in turns: ``PYTHONPATH=<snapshot>/src`` for the old)::

    NUMBA_NUM_THREADS=1 python benchmarks/kernels_S28.py --size 1M --repeats 5 --save /tmp/old.npz
    NUMBA_NUM_THREADS=1 python benchmarks/kernels_S28.py --size 1M --repeats 5 --compare /tmp/old.npz
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from kernel_instructions import SIZES, _copied, _recorded  # benchmarks/kernel_instructions.py

from meshcurv._kernels import jets, neighborhoods


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--size", choices=sorted(SIZES), default="1M")
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--save")
    parser.add_argument("--compare")
    parser.add_argument("--kernels", default="fits,sums")
    options = parser.parse_args(argv)
    calls = _recorded(options.size)
    outputs = {}
    for kernel in options.kernels.split(","):
        if kernel == "fits":
            args = calls["fit_jets_connected"][-1]

            def call(args=args):  # (the arguments as recorded: read-only ones stay so, one compiled signature)
                return jets.fit_jets_connected(*args)[0]

        else:
            args = calls["connected_face_sums"][-1]

            def call(args=args):  # fresh sums and scratch (stamped with the centres it served)
                fresh = list(args)
                fresh[9], fresh[10] = args[9].copy(), _copied(args[10])
                neighborhoods.connected_face_sums(*fresh)
                return fresh[9]

        outputs[kernel] = call()  # warm-up
        spent = []
        for _ in range(options.repeats):
            start = time.process_time()
            call()
            spent.append(time.process_time() - start)
        print(
            f"{kernel}: median CPU {np.median(spent):.3f} s of {options.repeats} ({', '.join(f'{s:.3f}' for s in spent)})"
        )
    if options.save:
        np.savez(options.save, **outputs)
    if options.compare:
        old = np.load(options.compare)
        for kernel, new in outputs.items():
            same = np.array_equal(old[kernel], new, equal_nan=True)
            with np.errstate(invalid="ignore"):
                diff = np.nanmax(np.abs(old[kernel] - new))
            print(f"{kernel}: bit-equal {same}, largest difference {diff:.3g}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
