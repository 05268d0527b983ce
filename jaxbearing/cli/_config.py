"""`jaxbearing config`: show and check TOML configuration files.

jaxbearing config show                 the full reference configuration, every key commented
jaxbearing config show --config FILE   FILE merged over the reference
jaxbearing config check FILE [FILE...] "FILE: ok", or one line "FILE: <field>: <message>"
                                       on stderr and exit status 2; the same checks as
                                       `jaxbearing simulate --config FILE`
jaxbearing config new --bore-mm D --outside-diameter-mm D --width-mm B [--type NU] [--out FILE]
jaxbearing config new --series 02 --bore-mm 70 ...
                                       a complete, commented configuration of a catalogue
                                       bearing, every estimated key marked with its rule and
                                       uncertainty (`jaxbearing.io.estimate_config`)
"""

from __future__ import annotations

import os
import sys

#: `estimate_config` parameter -> the option that gives it (for its one-line errors)
_OPTION_OF = {
    "bore_mm": "--bore-mm",
    "outside_diameter_mm": "--outside-diameter-mm",
    "width_mm": "--width-mm",
    "num_rollers": "--num-rollers",
    "roller_diameter_mm": "--roller-diameter-mm",
    "roller_length_mm": "--roller-length-mm",
    "series": "--series",
    "bearing_type": "--type",
}


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
    new = cmds.add_parser(
        "new",
        help="write the configuration of a catalogue bearing from its boundary dimensions",
        description="Estimate a complete configuration of a cylindrical roller bearing from its "
        "boundary dimensions (or an ISO 15 dimension series and bore), its type and what is known "
        "of the roller set, and write it as commented TOML: every estimated key is marked with "
        "its rule and uncertainty (also in the file's [uncertainty] table), the operating point "
        "is a placeholder to set.",
    )
    new.add_argument(
        "--bore-mm", dest="bore_mm", type=float, required=True, help="bore d [mm] (default: none, required)"
    )
    new.add_argument(
        "--outside-diameter-mm",
        dest="outside_diameter_mm",
        type=float,
        default=None,
        help="outside diameter D [mm] (default: from --series)",
    )
    new.add_argument(
        "--width-mm", dest="width_mm", type=float, default=None, help="width B [mm] (default: from --series)"
    )
    new.add_argument(
        "--series",
        default=None,
        metavar="SERIES",
        help="ISO 15 dimension series (10, 02, 22, 03): outside diameter and width from the bore "
        "(default: none, give both dimensions)",
    )
    new.add_argument(
        "--type",
        dest="bearing_type",
        default="NU",
        metavar="TYPE",
        help="bearing type: NU, N, NJ or NUP (default: %(default)s)",
    )
    new.add_argument(
        "--num-rollers",
        dest="num_rollers",
        type=int,
        default=None,
        help="number of rollers Z (default: estimated)",
    )
    new.add_argument(
        "--roller-diameter-mm",
        dest="roller_diameter_mm",
        type=float,
        default=None,
        help="roller diameter D_r [mm] (default: estimated)",
    )
    new.add_argument(
        "--roller-length-mm",
        dest="roller_length_mm",
        type=float,
        default=None,
        help="roller length L [mm] (default: estimated)",
    )
    new.add_argument(
        "--out", default=None, metavar="FILE", help="write FILE (default: print to standard output)"
    )
    new.add_argument("--force", action="store_true", help="overwrite --out if it exists (default: refuse)")
    new.set_defaults(func=run_new)


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


def run_new(args) -> int:
    """Estimate the configuration (`io.estimate_config`) and write it: --out is checked before
    any work (refused if it exists, without --force, or if its directory cannot be written),
    then written whole or not at all (`io.atomic_write`). Bad input: one line naming the
    option, its value and the valid range, exit 2."""
    from .._errors import ConfigError, UserInputError
    from ..io import atomic_write, check_output_dir, dimension_series, estimate_config

    if args.out is not None:
        if os.path.isdir(args.out):
            raise UserInputError(f"--out {args.out}: is a directory; name the file to write")
        if os.path.exists(args.out) and not args.force:
            raise UserInputError(
                f"--out {args.out}: exists; choose another file or add --force to overwrite it"
            )
        check_output_dir(os.path.dirname(os.path.abspath(args.out)), "--out")
    try:
        if args.series is not None:
            for name in ("outside_diameter_mm", "width_mm"):
                if getattr(args, name) is not None:
                    raise UserInputError(
                        f"{_OPTION_OF[name]}: cannot be combined with --series (the series gives it)"
                    )
            dim = dimension_series(args.series, args.bore_mm)
        else:
            for name in ("outside_diameter_mm", "width_mm"):
                if getattr(args, name) is None:
                    raise UserInputError(f"{_OPTION_OF[name]}: missing: give it, or --series with --bore-mm")
            from ..io import BoundaryDimensions

            dim = BoundaryDimensions(args.bore_mm, args.outside_diameter_mm, args.width_mm)
        new = estimate_config(
            dim.bore_mm,
            dim.outside_diameter_mm,
            dim.width_mm,
            bearing_type=args.bearing_type,
            num_rollers=args.num_rollers,
            roller_diameter_mm=args.roller_diameter_mm,
            roller_length_mm=args.roller_length_mm,
            series=dim.series,
        )
    except ConfigError as exc:
        if exc.field in _OPTION_OF:
            raise UserInputError(f"{_OPTION_OF[exc.field]}: {str(exc).partition(': ')[2]}") from None
        raise
    text = new.to_toml()
    if args.out is None:
        sys.stdout.write(text)
        return 0
    atomic_write(args.out, lambda f: f.write(text.encode("utf-8")))
    cfg = new.config
    print(
        f"{args.out}: {new.bearing_type} d x D x B = {dim.bore_mm:g} x {dim.outside_diameter_mm:g} x "
        f"{dim.width_mm:g} mm: {cfg['bearing.num_rollers']} rollers {cfg['roller.diameter_mm']:g} x "
        f"{cfg['roller.length_mm']:g} mm on d_m {cfg['bearing.pitch_diameter_mm']:g} mm; "
        f"{len(cfg.uncertainty)} keys estimated (marked ESTIMATED), the operating point a placeholder"
    )
    return 0
