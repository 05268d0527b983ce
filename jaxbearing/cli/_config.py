"""`jaxbearing config`: show and check TOML configuration files.

jaxbearing config show                 the full reference configuration, every key commented
jaxbearing config show --config FILE   FILE merged over the reference
jaxbearing config check FILE [FILE...] "FILE: ok", or one line "FILE: <field>: <message>"
                                       on stderr and exit status 2; the same checks as
                                       `jaxbearing simulate --config FILE`
"""

from __future__ import annotations

import sys


def register(sub) -> None:
    p = sub.add_parser(
        "config",
        help="show or check a TOML configuration file",
        description="Show the full configuration (every key, its meaning, symbol "
        "and valid range) or check configuration files.",
    )
    cmds = p.add_subparsers(dest="config_command", metavar="ACTION", required=True)
    show = cmds.add_parser(
        "show",
        help="print the full configuration as commented TOML",
        description="Print every key of the configuration (the file merged over the reference) as "
        "TOML with a comment per key: meaning, symbol, unit and valid range.",
    )
    show.add_argument(
        "--config",
        metavar="FILE",
        default=None,
        help="configuration file to merge over the reference (default: reference)",
    )
    show.set_defaults(func=run_show)
    check = cmds.add_parser(
        "check",
        help="validate configuration files",
        description="Check each file as `jaxbearing simulate --config FILE` would run it: every "
        "key's type and range, then what a run needs; one line per error (exit 2) and one "
        "warning line per valid value that looks like a unit slip.",
    )
    check.add_argument("files", metavar="FILE", nargs="+", help="TOML configuration file(s)")
    check.set_defaults(func=run_check)


def run_show(args) -> int:
    from .._errors import ConfigError
    from ..io import load_config

    try:
        cfg = load_config(args.config)
    except ConfigError as exc:
        print(f"{args.config}: {exc}", file=sys.stderr)
        return 2
    sys.stdout.write(cfg.to_toml())
    return 0


def run_check(args) -> int:
    """Each file as `jaxbearing simulate --config FILE` would run it (without options): the
    ranges of every key, then `check_runnable` (one code path with `simulate`); valid values
    that look like a unit slip are warned about (`plausibility_warnings`), one line each."""
    from .._errors import ConfigError
    from ..io import check_runnable, load_config, plausibility_warnings

    status = 0
    for path in args.files:
        try:
            cfg = load_config(path)
            check_runnable(cfg)
        except ConfigError as exc:
            print(f"{path}: {exc}", file=sys.stderr)
            status = 2
        else:
            for line in plausibility_warnings(cfg):
                print(f"{path}: warning: {line}", file=sys.stderr)
            print(f"{path}: ok")
    return status
