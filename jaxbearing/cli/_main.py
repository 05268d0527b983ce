"""`jaxbearing` command line.

Each command lives in its own module `jaxbearing.cli._<name>` exposing
`register(subparsers) -> None` (adds its parser, sets `func`) so commands stay independent.
Errors a user can fix (`jaxbearing.ConfigError` and friends) print one line and exit 2; they never
show a traceback.
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


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="jaxbearing",
        description="Differentiable dynamic model of cylindrical roller bearings "
        "(arc-end rollers against ring flanges).",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    for name, module in COMMANDS.items():
        importlib.import_module(module).register(sub)
    return parser


def dispatch(parser: argparse.ArgumentParser, argv: list[str] | None) -> int:
    """Parse `argv`, run the chosen command's `func`; help when none is given. A
    `UserInputError` prints one line "PROG COMMAND: error: ..." and returns 2 (no traceback)."""
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


def main(argv: list[str] | None = None) -> int:
    return dispatch(build_parser(), argv)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
