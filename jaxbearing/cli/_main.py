"""`jaxbearing` command line.

Each command lives in its own module `jaxbearing.cli._<name>` exposing
`register(subparsers) -> None` (adds its parser, sets `func`) so commands stay independent.
Errors a user can fix (`jaxbearing.ConfigError` and friends) print one line and exit 2; they never
show a traceback. Exit codes (`EXIT_CODES`, also in `jaxbearing --help` and the README's
"Reliability" section): 0 success; 1 a solve failed (results are written, the failure marked);
2 bad input, or an output directory in use (one line on stderr); 3 no feasible design
(`optimise`); 130 interrupted (Ctrl-C).
"""

from __future__ import annotations

import argparse
import importlib
import sys

#: command name -> module; the order is the order of `jaxbearing --help`.
COMMANDS = {
    "demo": "jaxbearing.cli._demo",
    "config": "jaxbearing.cli._config",
    "zone": "jaxbearing.cli._zone",
    "simulate": "jaxbearing.cli._simulate",
    "sweep": "jaxbearing.cli._sweep",
    "plot": "jaxbearing.cli._plot",
}


#: exit status -> meaning, for every command
EXIT_CODES = {
    0: "success",
    1: "a solve failed (results are still written; the failure is marked in them)",
    2: "bad input or an output directory in use (one line on stderr, nothing computed)",
    3: "no feasible design (optimise)",
    130: "interrupted (Ctrl-C); finished files are kept, a sweep resumes where it stopped",
}


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

    args = parser.parse_args(argv)
    if not getattr(args, "func", None):
        parser.print_help()
        return 0
    try:
        return int(args.func(args) or 0)
    except UserInputError as exc:
        print(f"{parser.prog} {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"{parser.prog} {args.command}: interrupted", file=sys.stderr)
        return 130


def main(argv: list[str] | None = None) -> int:
    return dispatch(build_parser(), argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
