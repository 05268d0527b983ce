"""`jaxbearing` command line.

Each command lives in its own module `jaxbearing.cli._<name>` exposing
`register(subparsers) -> None` (adds its parser, sets `func`) so commands stay independent.
Errors a user can fix (`jaxbearing.ConfigError` and friends) print one line and exit 2; they never
show a traceback. Exit codes (`EXIT_CODES`, also in `jaxbearing --help` and
docs/reference/files-and-exit-codes.md): 0 success; 1 a solve failed (results are written, the failure marked);
2 bad input, an output directory in use or not writable (one line on stderr, checked before
anything is computed); 3 no feasible design (`optimise`) or the design is outside the design
zone (`zone`); 4 the results could not be written to --out and were kept in a fallback
directory, whose path is printed (`jaxbearing.io.write_or_fallback`); 130 interrupted (Ctrl-C).
docs/reference/files-and-exit-codes.md lists them with the files every command writes.
"""

from __future__ import annotations

import argparse
import contextlib
import importlib
import sys
import warnings

#: command name -> module; the order is the order of `jaxbearing --help`.
COMMANDS = {
    "demo": "jaxbearing.cli._demo",
    "config": "jaxbearing.cli._config",
    "zone": "jaxbearing.cli._zone",
    "simulate": "jaxbearing.cli._simulate",
    "sweep": "jaxbearing.cli._sweep",
    "sensitivity": "jaxbearing.cli._sensitivity",
    "plot": "jaxbearing.cli._plot",
    "validate": "jaxbearing.cli._validate",
}


#: exit status of a design outside the design zone (`zone`) or no feasible design (`optimise`)
EXIT_INFEASIBLE = 3
#: exit status when the results went to a fallback directory (`report_fallback`)
EXIT_RESULTS_ELSEWHERE = 4

#: exit status -> meaning, for every command
EXIT_CODES = {
    0: "success",
    1: "a solve failed (results are still written; the failure is marked in them)",
    2: "bad input, or an output directory in use or not writable (one line on stderr, nothing computed)",
    3: "no feasible design (optimise); the design is outside the design zone (zone)",
    4: "results could not be written to --out: they are kept in the fallback directory printed on stderr",
    130: "interrupted (Ctrl-C); finished files are kept, a sweep resumes where it stopped",
}


def report_fallback(prog: str, out, used, reason: str | None) -> int:
    """After `jaxbearing.io.write_or_fallback`: 0 when the results are in `out`; else one line
    on stderr naming the fallback directory, and `EXIT_RESULTS_ELSEWHERE`."""
    if reason is None:
        return 0
    print(
        f"{prog}: error: results could not be written to {out} ({reason}); they are kept in {used}",
        file=sys.stderr,
    )
    return EXIT_RESULTS_ELSEWHERE


def exit_codes_text() -> str:
    return "exit status:\n" + "\n".join(f"  {code:<4}{text}" for code, text in EXIT_CODES.items())


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="jaxbearing",
        description="Differentiable dynamic model of cylindrical roller bearings "
        "(arc-end rollers against ring flanges).",
        epilog=exit_codes_text(),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, module in COMMANDS.items():
        importlib.import_module(module).register(sub)
    return parser


def dispatch(parser: argparse.ArgumentParser, argv: list[str] | None) -> int:
    """Parse `argv`, run the chosen command's `func`; help when none is given. A
    `UserInputError` prints one line "PROG COMMAND: error: ..." and returns 2 (no traceback);
    Ctrl-C prints "PROG COMMAND: interrupted" and returns 130 (`EXIT_CODES`)."""
    from .._errors import UserInputError
    from ..io import set_command_line

    args = parser.parse_args(argv)
    set_command_line([parser.prog, *(sys.argv[1:] if argv is None else argv)])
    if not getattr(args, "func", None):
        parser.print_help()
        return 0
    try:
        with one_line_warnings(f"{parser.prog} {args.command}"):
            return int(args.func(args) or 0)
    except UserInputError as exc:
        print(f"{parser.prog} {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{parser.prog} {args.command}: interrupted", file=sys.stderr)
        return 130


@contextlib.contextmanager
def one_line_warnings(prog: str):
    """While a command runs, every warning is one line on stderr, "PROG COMMAND: warning: ..."
    (its first line; no source line or file position), as errors are."""
    with warnings.catch_warnings():  # restores the previous display on exit

        def show(message, category, filename, lineno, file=None, line=None):
            text = str(message).strip().splitlines()[0] if str(message).strip() else category.__name__
            print(f"{prog}: warning: {text}", file=sys.stderr)

        warnings.showwarning = show
        yield


def main(argv: list[str] | None = None) -> int:
    return dispatch(build_parser(), argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
