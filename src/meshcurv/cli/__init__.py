"""The ``meshcurv`` command: entry point, exit codes and error messages.

The commands themselves live in :mod:`meshcurv.cli._app` (built on click, an
optional extra); this module only runs them and turns what goes wrong into an
exit code and one line on stderr:

- 0: done;
- 1: the mesh cannot be processed (unreadable file, unusable mesh, existing
  output, missing optional dependency);
- 2: bad usage (unknown option or command, bad option value, an option
  beyond its bounds): one line too, naming the option and the help to read.

``--debug`` adds the traceback.
"""

from __future__ import annotations

import sys
import traceback

from ..errors import InvalidOptionError, MissingDependencyError

__all__ = ["main"]


def _fail(message: str, *, debug: bool) -> None:
    if debug:
        traceback.print_exc(file=sys.stderr)
    print(f"meshcurv: error: {message}", file=sys.stderr)


def main(argv=None) -> int:
    """Run the ``meshcurv`` command line and return its exit code.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments after the program name; ``sys.argv[1:]`` by default.

    Returns
    -------
    int
        0 on success, 1 when the mesh cannot be processed, 2 for bad usage.
    """
    args = sys.argv[1:] if argv is None else [str(arg) for arg in argv]
    debug = "--debug" in args
    try:
        from . import _app
    except ImportError as exc:
        if exc.name != "click":
            raise
        print(
            "meshcurv: error: the command line needs click (a dependency of meshcurv that cannot be imported): "
            "pip install click",
            file=sys.stderr,
        )
        return 1
    import click

    session = _app.Session()
    try:
        with session:
            code = _app.meshcurv.main(args=args, prog_name="meshcurv", standalone_mode=False, obj=session)
        return code if isinstance(code, int) else 0
    except click.exceptions.Exit as exc:  # --help, --version
        return exc.exit_code
    except click.exceptions.NoArgsIsHelpError as exc:  # `meshcurv` alone: the help
        exc.show()
        return 2
    except click.UsageError as exc:  # one line, as every other error, and where to find the help
        message = " ".join(exc.format_message().split())
        hint = f" (see '{exc.ctx.command_path} --help')" if exc.ctx is not None else ""
        print(f"meshcurv: error: {message}{hint}", file=sys.stderr)
        return 2
    except click.Abort:
        print("meshcurv: aborted", file=sys.stderr)
        return 1
    except click.ClickException as exc:
        exc.show()
        return exc.exit_code
    except InvalidOptionError as exc:  # an option value the library refused
        _fail(str(exc), debug=debug)
        return 2
    except (ValueError, OSError, MissingDependencyError) as exc:  # MeshFileError, InvalidMeshError, ...
        _fail(str(exc), debug=debug)
        return 1
    except Exception as exc:  # a bug: still one line, the traceback with --debug
        _fail(f"unexpected {type(exc).__name__}: {exc} (run with --debug for the traceback)", debug=debug)
        return 1
