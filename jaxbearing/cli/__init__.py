"""The `jaxbearing` command line: one module per command (`_demo`, `_config`, `_zone`,
`_simulate`, `_sweep`, `_plot`), each exposing `register(subparsers)`; `main` dispatches.

User errors print one line and exit 2; failed solves exit 1; `EXIT_CODES` lists them all
(docs/how-to/reading-results.md).

May import: every layer below (imports of heavy layers stay inside the command functions, so
`jaxbearing --help` starts fast).
"""

from ._main import COMMANDS, EXIT_CODES, build_parser, dispatch, exit_codes_text, main
from ._simulate import format_table
from ._zone import zone_lines, zone_maps

__all__ = [
    "COMMANDS",
    "EXIT_CODES",
    "build_parser",
    "dispatch",
    "exit_codes_text",
    "format_table",
    "main",
    "zone_lines",
    "zone_maps",
]
