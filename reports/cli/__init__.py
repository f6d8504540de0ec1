"""The ``microcyl`` command line.

Each verb lives in its own module under :mod:`reports` (``reports/cli/*.py``) that defines
``register(subparsers)``; the parser it adds sets ``func=run`` through
``set_defaults``.  ``main`` turns every expected failure (bad input, unreadable or
corrupt files, interrupts) into one line on stderr and a non-zero exit status, never a
traceback.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.metadata
import logging
import os
import sys
import warnings

from gonio.errors import TableWarning
from gonio.terminal import shown

__all__ = ["main", "build_parser", "COMMAND_MODULES"]

#: Modules that each contribute one or more verbs, in the order ``--help`` lists them, with
#: the verbs each registers: ``microcyl VERB`` imports its module alone (the others and what
#: they import are not loaded: about 1.2 s of a short verb's start on the 2-core machine).
#: ``tests/test_cli_verbs.py`` holds the verbs to what the modules register.
COMMAND_MODULES = {
    "reports.cli.model": ("fabrics", "eval", "report"),
    "reports.cli.measure": ("measure",),
    "reports.cli.plan": ("plan",),
    "reports.cli.tables": ("convert", "info"),
    "reports.cli.render": ("render",),
    "reports.cli.physics": ("energy", "reciprocity", "sanity"),
    "reports.cli.fit": ("fit",),
    "reports.cli.fitimages": ("fit-images",),
    "reports.cli.compare": ("compare",),
    "reports.cli.measured": ("fit-measured",),
    "reports.cli.batch": ("fit-batch",),
    "reports.cli.plot": ("plot",),
    "reports.cli.export": ("export",),
    "reports.cli.explore": ("explore",),
}
#: Each verb and its module (from :data:`COMMAND_MODULES`).
VERBS = {verb: module for module, verbs in COMMAND_MODULES.items() for verb in verbs}


class _Parser(argparse.ArgumentParser):
    """An ArgumentParser whose usage errors are one line and exit status 2, that never takes
    an abbreviation for an option (``--out`` is not ``--output``), and whose verbs take
    options and inputs in any order (``fit-batch a.dat --sample 3 b.csv``: argparse's
    intermixed parsing; ``intermixed=False`` for the top level, whose verbs are a
    sub-parser)."""

    def __init__(self, *args, intermixed: bool = True, **kwargs):
        kwargs.setdefault("allow_abbrev", False)
        super().__init__(*args, **kwargs)
        self.intermixed = intermixed
        self._mixing = False

    def parse_known_args(self, args=None, namespace=None):  # noqa: D401 - argparse API
        if not self.intermixed or self._mixing:
            return super().parse_known_args(args, namespace)
        self._mixing = True          # parse_known_intermixed_args calls back here
        try:
            return self.parse_known_intermixed_args(args, namespace)
        finally:
            self._mixing = False

    def error(self, message):  # noqa: D401 - argparse API
        self.exit(2, f"microcyl {self.prog.split(' ', 1)[-1]}: error: {message}\n"
                  if " " in self.prog else f"microcyl: error: {message}\n")


def _version() -> str:
    try:
        return importlib.metadata.version("microcyl")
    except importlib.metadata.PackageNotFoundError:     # run from a source tree, not installed
        return "(not installed)"


def build_parser(argv: list[str] | None = None) -> argparse.ArgumentParser:
    """Return the ``microcyl`` parser: with every registered verb, or, when the arguments
    ``argv`` name a verb of :data:`VERBS` (its first argument not an option), with the verbs
    of that verb's module alone.

    Examples
    --------
    >>> sorted(_subparsers(build_parser(["-q", "sanity", "velvet"])).choices)
    ['energy', 'reciprocity', 'sanity']
    >>> len(_subparsers(build_parser()).choices) == len(VERBS)
    True
    """
    parser = _Parser(
        prog="microcyl", intermixed=False,
        description="Measure and analyse the microcylinder cloth BRDF "
                    "(Sadeghi et al., ACM TOG 2013).",
    )
    parser.add_argument("--version", action="version", version=f"microcyl {_version()}")
    noise = parser.add_mutually_exclusive_group()
    noise.add_argument("-v", "--verbose", action="store_true", dest="log_verbose",
                       help="more diagnostics on stderr (logging level DEBUG)")
    noise.add_argument("-q", "--quiet", action="store_true", dest="log_quiet",
                       help="only warnings and errors on stderr (no 'wrote ...' lines)")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    verb = next((a for a in argv or () if not a.startswith("-")), None)
    for name in (VERBS[verb],) if verb in VERBS else COMMAND_MODULES:
        importlib.import_module(name).register(sub)
    return parser


def _subparsers(parser) -> argparse._SubParsersAction:
    """The verbs' sub-parser action of a parser of :func:`build_parser`."""
    return next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))


class _ShownFormatter(logging.Formatter):
    """Each line of a log message through :func:`gonio.terminal.shown`: a file or table name
    in a "wrote ..." line or a warning reaches the terminal escaped, never as a control."""

    def format(self, record):
        return shown(super().format(record), lines=True)


def _configure_logging(args) -> None:
    """Diagnostics ("wrote FILE", what a verb is about to do) go through the ``microcyl``
    logger to stderr: INFO by default, DEBUG with -v, WARNING with -q (``microcyl -q VERB``
    or a long verb's own ``VERB -q``). Results go to stdout."""
    log = logging.getLogger("microcyl")
    log.handlers[:] = [logging.StreamHandler(sys.stderr)]
    log.handlers[0].setFormatter(_ShownFormatter("%(message)s"))
    log.propagate = False
    quiet = getattr(args, "log_quiet", False) or getattr(args, "quiet", False)
    log.setLevel(logging.DEBUG if getattr(args, "log_verbose", False)
                 else logging.WARNING if quiet else logging.INFO)


def _run(args):
    """``args.func(args)``, each table's warning (:class:`gonio.TableWarning`: radians where
    degrees are meant) printed as one line ``microcyl VERB: warning: MESSAGE`` through the
    ``microcyl`` logger (shown with -q too); other warnings as Python shows them."""
    log = logging.getLogger("microcyl")
    with warnings.catch_warnings():
        python_shows = warnings.showwarning

        def show(message, category, filename, lineno, file=None, line=None):
            if not issubclass(category, TableWarning):
                return python_shows(message, category, filename, lineno, file, line)
            text = " ".join(str(message).split())
            log.warning(f"microcyl {args.command}: warning: {shown(text)}")

        warnings.showwarning = show
        return args.func(args)


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit status.

    Parameters
    ----------
    argv : list of str, optional
        Arguments without the program name; ``sys.argv[1:]`` when None.

    Returns
    -------
    int
        0 on success, 1 on a reported error, 130 on interrupt (2 for usage errors,
        raised by argparse as ``SystemExit``).
    """
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = build_parser(argv)
    args = parser.parse_args(argv)
    _configure_logging(args)
    try:
        status = _run(args)
        sys.stdout.flush()                # a closed pipe surfaces here, not at exit
    except BrokenPipeError:               # `microcyl fabrics | head`: the reader left
        devnull = os.open(os.devnull, os.O_WRONLY)
        os.dup2(devnull, sys.stdout.fileno())   # and the flush at exit must not fail either
        return 0
    except KeyboardInterrupt as exc:      # a fit says where its checkpoint is
        print(f"microcyl {args.command}: {shown(str(exc) or 'interrupted')}", file=sys.stderr)
        return 130
    except (ValueError, OSError, KeyError, RuntimeError) as exc:
        # the first line (a file's text in it escaped: one line, no terminal control)
        message = str(exc).strip().split("\n")[0] if str(exc).strip() else type(exc).__name__
        filename = getattr(exc, "filename", None) if isinstance(exc, OSError) else None
        if filename and str(filename) not in message:
            message = f"{filename}: {message}"
        print(f"microcyl {args.command}: error: {shown(message)}", file=sys.stderr)
        return 1
    return int(status or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
