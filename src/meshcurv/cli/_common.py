"""What the commands of ``meshcurv`` share: the session, the options, progress, reading and estimating.

Every command module of this package (:mod:`._app`, :mod:`._batch`,
:mod:`._volume`, :mod:`._view`) imports from here and from nothing else of the
package but the library, so that the dependencies point one way.
"""

from __future__ import annotations

import contextlib
import logging
import pathlib
import sys
import warnings
from typing import Any, NamedTuple

import click
import numpy as np

from .. import _backend
from .._validation import as_faces
from ..batch import MAX_WORKERS
from ..curvature import multiscale_curvatures, principal_curvatures
from ..estimators import DEFAULT_METHOD, ESTIMATORS
from ..io import is_point_cloud, read_mesh, read_points
from ..io._files import check_output
from ..io.fields import FIELDS
from ..pointcloud import POINT_CLOUD_METHODS, multiscale_point_cloud_curvatures, point_cloud_curvatures
from ..smoothing import MAX_SMOOTHING_STEPS
from ..topology import MeshTopology

__all__ = ["Session", "current_session", "common_options", "method_options", "estimated"]

SCALAR_FIELDS = [name for name in FIELDS if name not in ("dir_min", "dir_max", "normals", "valid", "radius")]

#: The type of the path arguments and options: the library checks the file and names it in its errors.
PATH = click.Path(readable=False, path_type=pathlib.Path)


def _names(names) -> tuple:
    return (names,) if isinstance(names, str) else tuple(names)


def path_option(names, help_text: str, **settings):
    """A :data:`PATH` option (default None); ``names`` one name or a tuple of them."""
    return click.option(*_names(names), type=PATH, help=help_text, **{"default": None, **settings})


def choice(names, choices, default, help_text: str, **settings):
    """An option of ``choices`` whose default is shown in the help; ``names`` one name or a tuple of them."""
    return click.option(
        *_names(names), type=click.Choice(choices), default=default, show_default=True, help=help_text, **settings
    )


#: A length or a width: a float > 0 and finite (a value that parses to infinity, ``1e400``, is beyond it).
POSITIVE = click.FloatRange(min=0, min_open=True, max=sys.float_info.max)


class RadiusType(click.ParamType):
    """``--radius``: a length (:data:`POSITIVE`) or ``adaptive`` (icc: each vertex its own rung of a ladder)."""

    name = "radius"

    def convert(self, value, param, ctx):
        if isinstance(value, str) and value.strip().lower() == "adaptive":
            return "adaptive"
        try:
            return POSITIVE.convert(value, param, ctx)
        except click.BadParameter:
            self.fail(f"{value!r} is neither a length > 0 nor 'adaptive'", param, ctx)

    def get_metavar(self, param, ctx=None):
        return "LENGTH|adaptive"


def radii_option(help_text: str):
    """``--radii R1,R2,...``: several ball radii (:func:`meshcurv.multiscale_curvatures`, and
    :func:`meshcurv.multiscale_point_cloud_curvatures` for a point cloud)."""
    return click.option("--radii", callback=_radii, default=None, metavar="R1,R2,...", help=help_text)


def _radii(ctx, param, value):
    if value is None:
        return None
    try:
        radii = [float(part) for part in value.split(",") if part.strip()]
    except ValueError:
        radii = []
    if not radii or not all(0 < radius <= sys.float_info.max for radius in radii):
        raise click.BadParameter(f"expected lengths > 0 separated by commas (e.g. 1,2,4); got {value!r}")
    return radii


def mesh_argument(function):
    """The MESH argument: a :data:`PATH`."""
    return click.argument("mesh", type=PATH)(function)


def output_dir_option(help_text: str):
    """-o/--output-dir (the parameter ``out_dir``), required."""
    return path_option(("-o", "--output-dir", "out_dir"), help_text, required=True)


def overwrite_option(help_text: str):
    """--overwrite, a flag."""
    return click.option("--overwrite", is_flag=True, help=help_text)


def workers_option(help_text: str):
    """--workers, 1 to :data:`meshcurv.batch.MAX_WORKERS` processes (default None)."""
    return click.option("--workers", type=click.IntRange(min=1, max=MAX_WORKERS), default=None, help=help_text)


def up_option(help_text: str):
    """--up, the axis drawn upwards: auto (the default), y, z or x."""
    return choice("--up", ["auto", "y", "z", "x"], "auto", help_text)


def percentiles_option(help_text: str):
    """--percentiles LOW,HIGH (default 2,98), parsed to a pair of floats."""
    return click.option(
        "--percentiles", callback=_percentiles, default="2,98", show_default=True, metavar="LOW,HIGH", help=help_text
    )


def method_option(default, help_text: str, **settings):
    """-m/--method, one of :class:`MethodChoice`."""
    return click.option("-m", "--method", type=MethodChoice(), default=default, help=help_text, **settings)


def _stacked(function, options):
    """``function`` under the decorators ``options``, the first outermost (as written above a ``def``)."""
    for option in reversed(options):
        function = option(function)
    return function


_LEVELS = {-2: logging.CRITICAL, -1: logging.ERROR, 0: logging.WARNING, 1: logging.INFO, 2: logging.DEBUG}


class Session:
    """What one run of the command configures: logging level, warnings, progress; undone on exit."""

    def __init__(self):
        self.verbose = 0
        self.quiet = 0
        self.debug = False
        self.progress: bool | None = None
        self._logger = logging.getLogger("meshcurv")
        self._handler: logging.Handler | None = None
        self._warnings: warnings.catch_warnings | None = None
        self._level: int | None = None

    def __enter__(self):
        self._level = self._logger.level
        self._handler = logging.StreamHandler(sys.stderr)
        self._handler.setFormatter(logging.Formatter("meshcurv: %(message)s"))
        self._logger.addHandler(self._handler)
        self._warnings = warnings.catch_warnings()
        self._warnings.__enter__()
        warnings.simplefilter("always")
        warnings.showwarning = self._show_warning
        self.update()
        return self

    def __exit__(self, *exc_info):
        if self._warnings is None or self._handler is None or self._level is None:
            raise RuntimeError("a Session left without being entered")
        self._warnings.__exit__(*exc_info)
        self._logger.removeHandler(self._handler)
        self._logger.setLevel(self._level)
        _backend.show_compile_time(None)
        return False

    def update(self) -> None:
        level = _LEVELS[max(-2, min(2, self.verbose - self.quiet))]
        self._logger.setLevel(level)
        _backend.show_compile_time(self.progress)  # the compile's clock as the bars: --progress, terminal
        if level <= logging.DEBUG and self._handler is not None:  # None only before __enter__, which updates
            self._handler.setFormatter(logging.Formatter("meshcurv: %(name)s: %(message)s"))

    def _show_warning(self, message, category, filename, lineno, file=None, line=None):
        if self.verbose - self.quiet >= 0:
            click.echo(f"meshcurv: warning: {message}", err=True)

    def info(self, text: str) -> None:
        """A line on stderr unless -q."""
        if self.verbose - self.quiet >= 0:
            click.echo(f"meshcurv: {text}", err=True)

    def bar(self, kind, *args):
        """A ``kind`` progress bar (:class:`ProgressBar` subclass) on stderr, silent when not wanted:
        stderr not a terminal, or ``--no-progress``. ``args`` go before its stream."""
        stream = sys.stderr
        show = self.progress if self.progress is not None else stream.isatty()
        return kind(*args, stream if show else None, tty=stream.isatty())


def current_session(ctx: click.Context | None = None) -> Session:
    """The :class:`Session` of this run: the context object :func:`meshcurv.cli.main` gives the commands."""
    session = (ctx or click.get_current_context()).find_object(Session)
    if session is None:
        raise RuntimeError("no meshcurv Session in the click context: run the commands through meshcurv.cli.main")
    return session


def _store(ctx, param, value):
    session = current_session(ctx)
    if param.name in ("verbose", "quiet"):
        setattr(session, param.name, getattr(session, param.name) + value)
    elif param.name == "debug":
        session.debug = session.debug or value
    elif value is not None:
        session.progress = value
    if session._handler is not None:
        session.update()
    return value


def common_options(function):
    """-v/-q/--debug/--progress, accepted before or after the command name."""
    stored: dict[str, Any] = {"expose_value": False, "callback": _store}
    progress = "Progress bar on stderr (default: only when stderr is a terminal)."
    options = [
        click.option("-v", "--verbose", count=True, help="More messages on stderr (-v: stages, -vv: debug).", **stored),
        click.option("-q", "--quiet", count=True, help="Fewer messages: no warnings (-q), only errors.", **stored),
        click.option("--debug", is_flag=True, help="Show the traceback when something fails.", **stored),
        click.option("--progress/--no-progress", default=None, help=progress, **stored),
    ]
    return _stacked(function, options)


class MethodChoice(click.Choice):
    """The names of :data:`meshcurv.estimators.ESTIMATORS`, read when used (methods can be added)."""

    def __init__(self):
        super().__init__(list(ESTIMATORS) + list(POINT_CLOUD_METHODS))

    @property
    def choices(self):
        return tuple(ESTIMATORS) + tuple(POINT_CLOUD_METHODS)

    @choices.setter
    def choices(self, value):
        pass


def _default_method() -> str:
    return DEFAULT_METHOD


def method_options(function):
    """--method and the estimator options: the command takes them as ``**estimate`` and hands them on."""
    options = [
        method_option(_default_method(), "Curvature estimator (see `meshcurv methods`).", show_default=True),
        click.option(
            "--smoothing-steps",
            type=click.IntRange(min=0, max=MAX_SMOOTHING_STEPS),
            default=None,
            help=f"Passes of 1-ring smoothing (normal_cycle, matgeom; default 3; at most {MAX_SMOOTHING_STEPS}).",
        ),
        click.option(
            "--radius",
            type=RadiusType(),
            default=None,
            help="Neighbourhood radius in mesh units (icc, quadric, normal_cycle_ball; "
            "default from the mesh: see `meshcurv methods`), or 'adaptive' (icc: each vertex at the "
            "radius where its estimate is stable).",
        ),
        click.option(
            "--orient",
            type=click.Choice(["auto", "outward", "consistent", "keep"]),
            default=None,
            help="Reorient the faces first (default: auto = outward, keep for matgeom).",
        ),
    ]
    return _stacked(function, options)


def _estimate(vertices, faces, method, options, bar):
    given = {name: value for name, value in options.items() if value is not None}
    takes = ESTIMATORS[method].options
    for name in given:
        if name != "orient" and name not in takes:
            accepted = ", ".join(f"--{option.replace('_', '-')}" for option in takes) or "none"
            raise click.UsageError(
                f"method {method!r} does not take --{name.replace('_', '-')} (its options: {accepted})"
            )
    return principal_curvatures(
        vertices, faces, method=method, **given, progress=lambda stage, index, total: bar(stage, index, total, offset=1)
    )


def low_high(value, *, what: str, example: str, need: str, holds):
    """``value`` "LOW,HIGH" as two finite floats for which ``holds(low, high)``; None stays None.

    A ``click.BadParameter`` otherwise: "give two ``what`` as LOW,HIGH (e.g.
    ``example``)", or "need ``need``".
    """
    if value is None:
        return None
    try:
        low, high = (float(part) for part in value.split(","))
    except ValueError:
        raise click.BadParameter(f"give two {what} as LOW,HIGH (e.g. {example}); got {value!r}") from None
    if not (np.isfinite(low) and np.isfinite(high) and holds(low, high)):
        raise click.BadParameter(f"need {need}; got {value!r}")
    return low, high


def _percentiles(ctx, param, value):
    return low_high(
        value, what="percentiles", example="2,98", need="0 <= LOW < HIGH <= 100", holds=lambda a, b: 0 <= a < b <= 100
    )


def output_file(output, default: str, suffixes, expected: str, *, overwrite: bool, source) -> pathlib.Path:
    """The -o file of a command that writes one (``default`` when None), checked before computing.

    Its suffix must be one of ``suffixes`` (else "``expected``; got NAME",
    a bad -o); it must not exist unless ``overwrite``, nor be ``source``.
    """
    output = output if output is not None else pathlib.Path(default)
    if output.suffix.lower() not in suffixes:
        raise click.BadParameter(f"{expected}; got {output.name!r}", param_hint="'-o'")
    check_output(output, overwrite=overwrite, source=source)
    return output


_SHOWN_FAILURES = 10


def report_failures(names, errors, where: str) -> None:
    """On stderr, "failed: NAME: ERROR" for the first ten ``names`` that failed, and how many more (see ``where``)."""
    for name, error in zip(list(names)[:_SHOWN_FAILURES], list(errors)[:_SHOWN_FAILURES]):
        click.echo(f"meshcurv: failed: {name}: {error}", err=True)
    if len(names) > _SHOWN_FAILURES:
        click.echo(f"meshcurv: ... and {len(names) - _SHOWN_FAILURES} more (see {where})", err=True)


def _check_radii(path, method: str, *, cloud: bool, radius, smoothing_steps) -> None:
    """``--radii`` needs a method over balls (a point cloud's are), and neither ``--radius`` nor ``--smoothing-steps``."""
    if radius is not None:
        raise click.UsageError("give --radius (one scale) or --radii (several), not both")
    if cloud:
        return  # (the cloud's own checks follow: its methods all measure balls)
    if smoothing_steps is not None:
        raise click.UsageError(f"method {method!r} with --radii does not take --smoothing-steps (no ball method does)")
    if method not in ESTIMATORS or "radius" not in ESTIMATORS[method].options:
        with_balls = ", ".join(name for name, estimator in ESTIMATORS.items() if "radius" in estimator.options)
        raise click.UsageError(f"--radii takes a method over balls ({with_balls}); got {method!r}")


def _check_point_cloud_options(path, method, smoothing_steps, orient) -> None:
    """Refuse the options of meshes for a point cloud (``method`` None when not given)."""
    if method is not None and method not in POINT_CLOUD_METHODS:
        raise click.UsageError(
            f"method {method!r} needs faces; {path} is a point cloud (methods: {', '.join(POINT_CLOUD_METHODS)})"
        )
    for name, value in (("smoothing-steps", smoothing_steps), ("orient", orient)):
        if value is not None:
            raise click.UsageError(f"--{name} is for meshes; {path} is a point cloud")


class ProgressBar:
    """A progress line on stderr, ``[####....] done/total <tail>``: redrawn in place on a terminal,
    otherwise one line per call; ``close`` clears a terminal's line once something was drawn."""

    def __init__(self, stream, *, tty: bool, width: int = 24):
        self.stream = stream
        self.tty = tty
        self.width = width
        self._shown: object = None  # what the subclass last drew (None: nothing yet)

    def _draw(self, done: int, total: int, tail: str, *, filled: int | None = None) -> None:
        if filled is None:
            filled = round(self.width * done / total) if total else self.width
        text = f"[{'#' * filled}{'.' * (self.width - filled)}] {done}/{total} {tail}"
        if self.tty:
            self.stream.write(f"\r\033[K{text}")
        else:
            self.stream.write(f"meshcurv: {text}\n")
        self.stream.flush()

    def close(self) -> None:
        if self.stream is not None and self.tty and self._shown is not None:
            self.stream.write("\r\033[K")
            self.stream.flush()

    def __enter__(self):
        return self

    def __exit__(self, *exc_info):
        self.close()
        return False


class StageBar(ProgressBar):
    """Progress over named stages: ``[###.....] 2/6 fit normals``, the bar filled up to the stage begun."""

    def __init__(self, stages, stream, *, tty: bool, width: int = 24):
        super().__init__(stream, tty=tty, width=width)
        self.stages = list(stages)

    def __call__(self, stage: str, index: int | None = None, total: int | None = None, *, offset: int = 0):
        if self.stream is None:
            return
        position = offset + (index if index is not None else self.stages.index(stage) + 1)
        count = len(self.stages)
        self._draw(position, count, stage, filled=round(self.width * (position - 1) / count))
        self._shown = position


class Estimated(NamedTuple):
    """What :func:`estimated` read and computed."""

    vertices: np.ndarray
    #: The faces as read (polygons kept, for writing them back); None for a point cloud.
    faces: object
    #: The mesh's topology (its faces as triangles: ``topology.faces``); None for a point cloud.
    topology: MeshTopology | None
    result: object
    cloud: bool


@contextlib.contextmanager
def estimated(path, session: Session, last_stage: str, *, method, smoothing_steps, radius, orient, radii=None):
    """Read ``path`` (a mesh, or a point cloud: a file without faces) and compute its curvatures.

    With ``radii`` (not with ``radius``; a mesh's method over balls, or a
    point cloud), the result is the list of :func:`meshcurv.multiscale_curvatures`
    or :func:`meshcurv.multiscale_point_cloud_curvatures`.

    A progress bar runs over the stages ``read``, the method's own and
    ``last_stage``, which is the block under the ``with`` (writing, drawing);
    the bar is cleared when the block ends. The options of meshes are refused
    for a point cloud, and the methods of each kind for the other; a point
    cloud takes the method only when it was given (else its own default).
    Yields an :class:`Estimated`.
    """
    context = click.get_current_context()
    given_method = context.get_parameter_source("method") != click.core.ParameterSource.DEFAULT
    cloud = is_point_cloud(path)
    if radii is not None:
        _check_radii(path, method, cloud=cloud, radius=radius, smoothing_steps=smoothing_steps)
    if cloud:
        _check_point_cloud_options(path, method if given_method else None, smoothing_steps, orient)
    elif method in POINT_CLOUD_METHODS:
        raise click.UsageError(
            f"method {method!r} is for point clouds; {path} is a mesh (methods: {', '.join(ESTIMATORS)})"
        )
    stages = ["read", *([] if cloud else ESTIMATORS[method].stages), last_stage]
    with session.bar(StageBar, stages) as bar:
        bar("read")
        result: object
        if cloud:
            vertices, normals = read_points(path)
            faces = topology = None
            cloud_method = method if given_method else None
            if radii is None:
                result = point_cloud_curvatures(vertices, normals=normals, radius=radius, method=cloud_method)
            else:
                result = multiscale_point_cloud_curvatures(vertices, radii, normals=normals, method=cloud_method)
        else:
            vertices, faces = read_mesh(path)
            # triangulated (and warned about) once: the estimate takes the topology as it is
            topology = MeshTopology.from_faces(as_faces(faces, len(vertices)), len(vertices))
            options = {"smoothing_steps": smoothing_steps, "radius": radius, "orient": orient}
            if radii is None:
                result = _estimate(vertices, topology, method, options, bar)
            else:
                result = multiscale_curvatures(
                    vertices,
                    topology,
                    radii,
                    method=method,
                    **({} if orient is None else {"orient": orient}),
                    progress=lambda stage, index, total: bar(stage, index, total, offset=1),
                )
        bar(last_stage, len(stages))
        yield Estimated(vertices, faces, topology, result, cloud)
