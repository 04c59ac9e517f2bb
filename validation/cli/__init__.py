"""The ``contactlab`` command line: one module per subcommand, each with ``add_args`` and ``run``.

Exit codes: 0 success; 1 a solver did not converge (results are still written, flagged
``converged = false``); 2 bad input (scene, option or output location); 130 interrupted
(``SIGINT``, Ctrl-C); 143 terminated (``SIGTERM``); 141 the reader of the standard output went
away (``contactlab run ... | head -3``: the command stops quietly, as a process stopped by
``SIGPIPE``; files it had written are complete). An interrupted or terminated command leaves
the previous output or none, and stops its worker processes; a signal while the command starts
(its packages take seconds to import) stops it the same way, with one line.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import logging
import os
import signal
import sys
import threading

__all__ = ["main", "build_parser"]

#: the subcommands and their modules, in the order ``--help`` lists them; the modules (and the
#: packages they load) are imported by :func:`build_parser`, inside :func:`main`'s signal handling
COMMANDS = {"run": "run", "scenes": "scenes", "check": "check", "sweep": "sweep", "study": "study",
            "report": "report", "layer-law": "layer_law", "surface": "surface"}

DESCRIPTION = """\
contactlab: frictionless normal contact of two elastic bodies with a nonlinear interface
layer (rough surface, coating) between them. Half-space boundary elements (BEM) on a
triangular lattice, an axisymmetric finite-element (FEM) reference, closed-form checks.

A SCENE is a TOML file, or the name of a built-in scene (see `contactlab scenes`). It says
what the bodies, gap, layer and load are and what to run: the BEM always; the FEM reference,
a closed-form comparison, a sweep, the subsurface stresses or a report only when it has a
[fem], [analytic], [sweep], [stress] or [report] section.

Units: every number is in the scene's own consistent units, stated in its [scene] units
label. The built-in scenes use SI: lengths in m, moduli and pressures in Pa, forces in N
(e.g. E1 = 210e9 for steel, R = 0.01 for a 10 mm radius, force = 100.0 for 100 N).
The paper's layer parameters are dimensionless: lam_over_cnn (compliance / C_nn at the
reference step cnn_step [m], which it needs), alpha_a = p_cr / p_max^lambda,
alpha_b = p_max^root / p_max^lambda, alpha_c = arctan(lam2/lam1) [rad].
"""

EPILOG = """\
examples:
  contactlab scenes                                  list the built-in scenes
  contactlab check my_scene.toml                     validate a scene, run nothing
  contactlab run hertz                               BEM + FEM + Hertz; writes results/hertz/
  contactlab run paper_root --out out/root           choose the result directory
  contactlab run hertz --no-fem                      BEM + Hertz without the FEM reference (core install)
  contactlab run my.toml --allow-code                a scene naming Python code you trust (layer.w, ...)
  contactlab run hertz --set bem.nodes_across=80 --set load.force=200
                                                     override scene keys (dotted, TOML values)
  contactlab run paper_elastic_rigid --set alpha_a=0.25
  contactlab sweep paper_elastic_rigid --param alpha_a --values 0,0.25,0.5,0.75,1
  contactlab sweep paper_root --param alpha_b --values 0.8:1.1:4 --workers 2
  contactlab sweep hertz --param load.force --values 50,100,200 --scheduler tcp://10.0.0.5:8786
  contactlab study error-time hertz                  error vs time of the BEM methods
  contactlab study stability                         convergence of the methods across layers
  contactlab study robustness                        every layer method over 12 decades of compliance
  contactlab study two-scale --quick                 resolved rough sphere against its layer law
  contactlab study coating-winkler --quick           coated flat against a linear Winkler layer
  contactlab study coating-fem --quick               coated BEM against the FEM, both refined
  contactlab report results/hertz --out report/      figures + HTML/Markdown report
  contactlab report results/hertz-sweep-load.force   report of a sweep directory
  contactlab report paper --quick                    the paper's test problem, a quick preview
  contactlab layer-law patch.x3p --E-star 115e9 --out laws/patch
                                                     a rough surface's layer law file and figures
  contactlab surface patch.x3p --out surfaces/patch  statistics, spikes, PSD and height map of a file

result directory (run): result.json (p_max, force, approach, contact_area, contact_radius,
iterations, converged, kkt_residual, wall_time_s, comparison metrics...), scene.toml (the
effective scene, re-runnable), bem_field.vtu, fem_field.vtu and stress_field.vtu (open in ParaView).
Written whole or not at all. --out DIR is always the directory written (result, sweep or
report directory); contactlab writes only into a new or empty directory or one it wrote itself
(marked by DIR/.contactlab). Exit codes: 0 ok, 1 not converged, 2 bad input (every error of a
scene is listed), an unknown option or an unusable output directory, 130 interrupted (Ctrl-C),
143 terminated (SIGTERM), 141 the reader of the output went away (contactlab ... | head: a quiet stop).

A scene file is data: the Python code it names is imported only with --allow-code, and the
files it names are read only inside its folder unless --allow-outside-files (docs/scenes.md).
"""


class Terminated(KeyboardInterrupt):
    """Raised in the main thread when the process receives ``SIGTERM``: unwinds like Ctrl-C."""


_HANDLER_PID = None  # the process that handles SIGTERM by _raise_terminated


def _raise_terminated(signum, frame):
    if os.getpid() != _HANDLER_PID:
        # a worker forked with this handler, terminated before its initializer restored the default action
        # (validation.run.pool): it ends by that action, without a traceback
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        os.kill(os.getpid(), signal.SIGTERM)
    raise Terminated()


@contextlib.contextmanager
def _terminate_as_interrupt():
    """Handle ``SIGTERM`` like ``SIGINT`` while a command runs (main thread only)."""
    global _HANDLER_PID
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    _HANDLER_PID = os.getpid()
    previous = signal.signal(signal.SIGTERM, _raise_terminated)
    try:
        yield
    finally:
        signal.signal(signal.SIGTERM, previous)


def build_parser():
    """The argparse parser of ``contactlab``: each subcommand module adds its own."""
    fmt = argparse.RawDescriptionHelpFormatter
    parser = argparse.ArgumentParser(prog="contactlab", description=DESCRIPTION, epilog=EPILOG, formatter_class=fmt)
    parser.add_argument("-v", "--verbose", action="store_true", help="log progress details (INFO)")
    parser.add_argument("--no-progress", action="store_true", help="no progress bars")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for name in COMMANDS:
        module = _command(name)
        module.add_args(sub.add_parser(name, formatter_class=fmt, **module.PARSER))
    return parser


def _command(name):
    """The module of the subcommand ``name``."""
    return importlib.import_module(f".{COMMANDS[name]}", __name__)


@contextlib.contextmanager
def _log_to_stderr(verbose):
    """Show the library's log records on the current stderr while a command runs."""
    handler = logging.StreamHandler(sys.stderr)
    handler.setFormatter(logging.Formatter("contactlab: %(levelname)s: %(message)s"))
    # the packages' loggers, and scikit-fem's (its INFO lines only with --verbose)
    loggers = [logging.getLogger(name) for name in ("bem", "fem_reference", "validation", "skfem")]
    saved = [(lg.level, lg.propagate) for lg in loggers]
    for lg in loggers:
        lg.addHandler(handler)
        lg.setLevel(logging.INFO if verbose else logging.WARNING)
        lg.propagate = False
    try:
        yield
    finally:
        for lg, (level, propagate) in zip(loggers, saved):
            lg.removeHandler(handler)
            lg.setLevel(level)
            lg.propagate = propagate


def _stdout_closed():
    """Whether the standard output is a pipe that its reader has closed."""
    import select

    try:
        fd = sys.stdout.fileno()
    except (AttributeError, OSError, ValueError):  # replaced by a stream without a file
        return False
    if not hasattr(select, "poll"):
        return True
    poll = select.poll()
    poll.register(fd, select.POLLOUT)
    return any(events & select.POLLERR for _, events in poll.poll(0))


#: the arguments that name files -> how the user wrote them
_FILE_ARGUMENTS = {"scene": "SCENE", "surface": "SURFACE", "target": "SCENE_OR_DIR", "out": "--out"}


def _check_file_names(args):
    from bem.checks import check_file_name

    for dest, name in _FILE_ARGUMENTS.items():
        if isinstance(getattr(args, dest, None), str):
            check_file_name(name, getattr(args, dest))


def _run(argv):
    """Parse ``argv``, run the subcommand and print its errors; returns the exit code."""
    parser = build_parser()  # imports the subcommands
    try:  # argparse exits on --help (0) and on bad or unknown options (2): return the code instead
        args = parser.parse_args(argv)
    except SystemExit as exc:
        return exc.code
    from bem.checks import InputError

    from ..io import OutputError
    from ..run.calibrate import CalibrationError

    try:
        _check_file_names(args)
        with _log_to_stderr(args.verbose):
            return _command(args.command).run(args)
    except (InputError, OutputError) as exc:
        for message in getattr(exc, "errors", None) or (str(exc),):
            print(f"contactlab: error: {message}", file=sys.stderr)
        return 2
    except CalibrationError as exc:
        print(f"contactlab: error: {exc}", file=sys.stderr)
        return 1


def main(argv=None):
    """Entry point of the ``contactlab`` console script; returns the exit code (module docstring)."""
    try:
        with _terminate_as_interrupt():  # from the first import on: start-up is interrupted cleanly too
            code = _run(argv)
            sys.stdout.flush()  # a closed pipe shows here, not at the interpreter's exit
            return code
    except Terminated:
        print("contactlab: terminated (no partial output was left)", file=sys.stderr)
        return 128 + signal.SIGTERM
    except KeyboardInterrupt:
        print("contactlab: interrupted (no partial output was left)", file=sys.stderr)
        return 128 + signal.SIGINT
    except BrokenPipeError:
        if not _stdout_closed():
            raise
        # as a process stopped by SIGPIPE, quietly; what is left in the buffer goes nowhere
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 128 + signal.SIGPIPE
