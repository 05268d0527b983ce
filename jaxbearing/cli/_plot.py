"""`jaxbearing plot DIR`: the standard figures of a sweep (paper Figures 9-13).

Reads DIR/results.nc (assembling it from DIR/batches/ first when a multi-process sweep left it
unassembled) and draws every figure the sweep's axes allow (`jaxbearing._sweep_plots`); it says
which figures it drew and, for the others, which axis is missing.
"""

from __future__ import annotations

import pathlib


def register(sub) -> None:
    p = sub.add_parser(
        "plot",
        help="draw the standard figures of a sweep directory (paper Figs. 9-13)",
        description="Draw the paper's Figures 9-11 (peak pressure, sliding velocity, PV vs "
        "speed, arc and corner ends), Figure 12 (sliding velocity and PV vs R_end and layback "
        "angle) and Figure 13 (contact positions on the end face) from DIR/results.nc of "
        "`jaxbearing sweep`, as far as the sweep has the needed axes.",
    )
    p.add_argument("dir", help="sweep output directory (holds spec.json, results.nc)")
    p.add_argument(
        "--out", help="where to write the figures, checked before anything is read (default: DIR/figures)"
    )
    p.set_defaults(func=run)


def run(args) -> int:
    from .._errors import UserInputError
    from ..sweep import open_results, plot_sweep

    directory = pathlib.Path(args.dir)
    if not directory.is_dir():
        raise UserInputError(f"DIR {str(directory)!r} is not a directory")
    from ..io import check_output_dir

    out = pathlib.Path(args.out) if args.out else directory / "figures"
    check_output_dir(out, "--out")
    ds = open_results(directory)
    drawn, skipped = plot_sweep(ds, out)
    for label, path in drawn:
        print(f"drew {label}: {path}")
    for label, reason in skipped:
        print(f"could not draw {label}: {reason}")
    return 0
