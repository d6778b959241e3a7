"""``python -m meshcurv ...``: the same as the ``meshcurv`` command (see :mod:`meshcurv.cli`)."""

import sys

from .cli import main

if __name__ == "__main__":
    sys.exit(main())
