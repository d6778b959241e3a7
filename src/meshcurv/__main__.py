"""``python -m meshcurv demo``: the seed's torus example."""

import sys

from .demo import run_demo


def main(argv=None) -> int:
    args = sys.argv[1:] if argv is None else list(argv)
    if args[:1] != ["demo"]:
        print("usage: python -m meshcurv demo [OUTPUT.png]", file=sys.stderr)
        return 2
    print(run_demo(*args[1:2]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
