"""The ``surfprep`` command line: one argparse parser, one subcommand per module.

Subcommands live in :mod:`surfprep.plugin.commands` (see its docstring for how
to add one). This module builds the parser from that list, dispatches, and turns
failures into exit codes:

* 0 success;
* 1 done with faces skipped (an entity the reader did not translate, a face a
  command could not process: each said on stderr), a check a command reports as
  failed, or an unexpected internal error (one line; the traceback with
  ``--debug``);
* 2 a usage error (argparse) or an expected failure
  (:class:`~surfprep.errors.SurfprepError`: bad input file, refused output...),
  printed as one line ``surfprep: error: <message>`` on stderr.

Warnings (e.g. intersection curves left out because they stray from the
surfaces) are printed as one line ``surfprep: warning: <message>`` each.
"""

from __future__ import annotations

import argparse
import re
import sys
import textwrap
import traceback
import warnings
from collections.abc import Sequence

from ..errors import SurfprepError
from .commands import COMMANDS, Console

__all__ = ["main", "build_parser", "EXIT_OK", "EXIT_FAILURE", "EXIT_ERROR"]

EXIT_OK = 0
EXIT_FAILURE = 1
EXIT_ERROR = 2
EXIT_INTERRUPTED = 130

PROG = "surfprep"

DESCRIPTION = """\
Prepare B-spline CAD geometry for grid generation: read STEP/IGES files through
OpenCascade, inspect how their surfaces are parametrized, reparametrize, heal,
intersect and cut faces, and grid them (structured surface grids to Plot3D, CGNS
or VTK), cross-checked against OpenCascade and Gmsh."""

EPILOG = """\
examples:
  surfprep info part.step              faces, surface types, degrees, areas,
                                       parametrization quality
  surfprep info part.igs --json -      the same as JSON on stdout
  surfprep demo -o out/                the whole pipeline on a bundled sample
  surfprep grid part.step -o part.cgns  structured grids on the four-sided faces
  surfprep split a.step b.step -o c.step   faces cut along their intersection curves
  surfprep COMMAND --help              options of one command

exit codes: 0 done; 1 done with faces skipped (entities the reader did not
translate, faces a command could not process; each said on stderr) or an internal
error; 2 nothing done: bad usage or an input/output error (one line on stderr; add
--debug for a traceback).
Progress ("face pair 12/255 (5 %, 3 s, about 60 s left)") goes to stderr when it is a
terminal or with --progress; --quiet leaves out progress and notes."""


def _version() -> str:
    try:
        from importlib.metadata import version
        return version("surfprep")
    except Exception:  # not installed as a distribution: fall back to the package
        from .. import __version__
        return __version__


class _VersionAction(argparse.Action):
    """``--version``: the version looked up when asked (``importlib.metadata`` costs a
    twentieth of a second, which every other call need not pay)."""

    def __init__(self, option_strings, dest=argparse.SUPPRESS, default=argparse.SUPPRESS, help=None):
        super().__init__(option_strings, dest=dest, default=default, nargs=0,
                         help=help or "show the version and exit")

    def __call__(self, parser, namespace, values, option_string=None):
        print(f"{parser.prog} {_version()}")         # stdout, as argparse's own version action
        parser.exit()


def _common_options(defaults: bool) -> argparse.ArgumentParser:
    """--debug/--progress, accepted before and after the subcommand name."""
    default = (lambda value: value) if defaults else (lambda value: argparse.SUPPRESS)
    parent = argparse.ArgumentParser(add_help=False)
    group = parent.add_argument_group("general options")
    group.add_argument("--debug", action="store_true", default=default(False),
                       help="show the Python traceback of an error")
    group.add_argument("--progress", action="store_true", default=default(None),
                       help="report progress on stderr even when it is not a terminal")
    group.add_argument("--quiet", action="store_true", default=default(False),
                       help="no progress and no notes on stderr (warnings and errors stay)")
    group.add_argument("--strict", action="store_true", default=default(False),
                       help="an entity of an input file that OpenCascade does not translate "
                            "is an error (exit 2), not a warning")
    return parent


def build_parser() -> argparse.ArgumentParser:
    """The full parser: global options plus one subparser per registered command."""
    parser = argparse.ArgumentParser(
        prog=PROG, description=DESCRIPTION, epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
        parents=[_common_options(defaults=True)])
    parser.add_argument("--version", action=_VersionAction)
    sub = parser.add_subparsers(title="commands", dest="command", metavar="COMMAND")
    for command in COMMANDS:
        cmd_parser = sub.add_parser(
            command.name, help=command.summary, description=_wrap(command.description),
            epilog=command.epilog, formatter_class=argparse.RawDescriptionHelpFormatter,
            parents=[_common_options(defaults=False)])
        command.add_arguments(cmd_parser)
        cmd_parser.set_defaults(run=command.run)
    return parser


def _wrap(text: str, width: int = 79) -> str:
    """Fill each blank-line separated paragraph (the epilogs stay as written)."""
    return "\n\n".join(textwrap.fill(" ".join(par.split()), width)
                       for par in text.split("\n\n"))


def _one_line(exc: BaseException) -> str:
    text = " ".join(str(exc).split())
    return text or type(exc).__name__


_NUMBER = re.compile(r"[-+]?\d+(?:\.\d*)?(?:e[-+]?\d+)?", re.I)


def _warning_lines(caught: list[warnings.WarningMessage]) -> list[str]:
    """One line per kind of warning: the first of its kind, with how many there were.

    Kinds are the message with its numbers left out (a stray curve per face pair is one
    kind); numpy's floating-point warnings (``RuntimeWarning``) say they are numerical.
    """
    groups: dict[str, list[str]] = {}
    for w in caught:
        text = _one_line(w.message)
        if issubclass(w.category, RuntimeWarning) and "encountered" in text:
            text = f"numerical: {text} (in a step whose result is checked against the tolerance)"
        groups.setdefault(_NUMBER.sub("#", text), []).append(text)
    lines = []
    for texts in groups.values():
        more = f" (and {len(texts) - 1} more like it)" if len(texts) > 1 else ""
        lines.append(f"{PROG}: warning: {texts[0]}{more}")
    return lines


def main(argv: Sequence[str] | None = None) -> int:
    """Run the command line on ``argv`` (default ``sys.argv[1:]``); returns the exit code.

    Never raises ``SystemExit``, so tests can call ``main([...])`` in-process.
    """
    err = sys.stderr
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exit_:  # --help, --version, usage errors
        code = exit_.code
        return code if isinstance(code, int) else (EXIT_OK if code is None else EXIT_ERROR)
    run = getattr(args, "run", None)
    if run is None:
        parser.print_usage(err)
        print(f"{PROG}: error: no command given (try '{PROG} --help')", file=err)
        return EXIT_ERROR
    console = Console.for_streams(progress=True if args.progress else None, quiet=args.quiet)
    caught: list[warnings.WarningMessage] = []

    def finish(code: int, *lines: str) -> int:
        """The warnings of the run (one line per kind), then ``lines``; ``code``."""
        for line in (*_warning_lines(caught), *lines):
            print(line, file=err)
        return code

    try:
        with warnings.catch_warnings(record=not args.debug) as recorded:
            if not args.debug:                            # --debug: Python's own warnings
                caught = recorded
                warnings.simplefilter("always")
                for quiet in (DeprecationWarning, PendingDeprecationWarning, ImportWarning):
                    warnings.simplefilter("ignore", quiet)
            code = int(run(args, console))
        return finish(code)
    except SurfprepError as exc:
        if args.debug:
            traceback.print_exc(file=err)
        return finish(EXIT_ERROR, f"{PROG}: error: {_one_line(exc)}")
    except KeyboardInterrupt:
        return finish(EXIT_INTERRUPTED, f"{PROG}: interrupted")
    except BrokenPipeError:  # e.g. `surfprep info x.step | head`
        return EXIT_OK
    except Exception as exc:  # noqa: BLE001 - the CLI's last line of defence
        if args.debug:
            traceback.print_exc(file=err)
        from .occ.failures import describe, is_occ_failure  # OCP is loaded by now if it ran
        if is_occ_failure(exc):   # an OpenCascade exception no command turned into ours
            return finish(EXIT_ERROR, f"{PROG}: error: OpenCascade failed: {describe(exc)}")
        hint = "" if args.debug else " (run with --debug for the traceback)"
        return finish(EXIT_FAILURE,
                      f"{PROG}: internal error: {type(exc).__name__}: {_one_line(exc)}{hint}")

if __name__ == "__main__":
    raise SystemExit(main())
