"""The `jaxbearing` command line: one module per command (`_demo`, `_config`, `_zone`,
`_simulate`, `_sweep`, `_plot`, `_validate`), each exposing `register(subparsers)`; `main` dispatches.

User errors print one line and exit 2; failed solves exit 1; a design outside the zone (`zone`)
exits 3; results kept in a fallback directory exit 4; `EXIT_CODES` lists them all
(docs/reference/files-and-exit-codes.md).

May import: every layer below (imports of heavy layers stay inside the command functions, so
`jaxbearing --help` starts fast).
"""

from ._main import (
    COMMANDS,
    EXIT_CODES,
    EXIT_INFEASIBLE,
    EXIT_RESULTS_ELSEWHERE,
    build_parser,
    dispatch,
    exit_codes_text,
    main,
    report_fallback,
)
from ._simulate import format_table
from ._zone import zone_lines, zone_maps

__all__ = [
    "COMMANDS",
    "EXIT_CODES",
    "EXIT_INFEASIBLE",
    "EXIT_RESULTS_ELSEWHERE",
    "build_parser",
    "dispatch",
    "exit_codes_text",
    "format_table",
    "main",
    "report_fallback",
    "zone_lines",
    "zone_maps",
]
