"""`jaxbearing sensitivity CONFIG`: which unknown inputs matter.

Ranks every key of the configuration's `[uncertainty]` table and the model's representative
constants (`jaxbearing.design.MODEL_CONSTANTS`: traction curve A-D, oil fraction) by its effect
on settled statistics, effect = derivative x the key's stated uncertainty, with a 95 % interval
(`jaxbearing.design.sensitivity`; docs/model.md 18): CRN central differences of settled runs for
every statistic, or with `--quick` the static skid equilibrium for the cage slip alone. Prints a
table (key, uncertainty, effect on each statistic with its interval and rank); with `--out DIR`
writes DIR/sensitivity.json (data only) and DIR/sensitivity.png (a bar chart per statistic),
each atomically, the directory checked before anything is computed.
"""

from __future__ import annotations

import math

from .._errors import UserInputError

#: the statistics of a full study and of a quick one
DEFAULT_STATISTICS = "cage_slip,mean_pv,peak_pv,contact_height"
QUICK_STATISTICS = "cage_slip"
#: reduced settled runs by default, affordable on two cores
DEFAULT_SEEDS = 3
DEFAULT_WINDOW_REVS = 3.0


def register(sub) -> None:
    p = sub.add_parser(
        "sensitivity",
        help="which uncertain inputs matter: effect of each on settled statistics, ranked",
        description="Rank every key of CONFIG's [uncertainty] table and the model's representative "
        "constants (traction curve A-D, oil fraction) by its effect on settled statistics: "
        "derivative x the key's stated uncertainty, with a 95 %% interval. Settled statistics by "
        "common-random-number central differences of settled runs (same seeds); --quick: the cage "
        "slip alone from the static skid equilibrium (no dynamic run).",
    )
    p.add_argument("config", metavar="CONFIG", help="TOML configuration with an optional [uncertainty] table")
    p.add_argument(
        "--statistics",
        default=None,
        help=f"comma-separated: cage_slip, mean_pv, peak_pv, contact_height (default: {DEFAULT_STATISTICS}; "
        f"with --quick: {QUICK_STATISTICS})",
    )
    p.add_argument(
        "--quick",
        action="store_true",
        help="cage slip only, from the static skid equilibrium: seconds per input, no settled run "
        "(default: off, settled runs)",
    )
    p.add_argument(
        "--seeds",
        type=float,
        default=DEFAULT_SEEDS,
        help="seeds of each settled run x +/- h (default: %(default)g; the interval is over seeds)",
    )
    p.add_argument(
        "--window-revs",
        type=float,
        default=DEFAULT_WINDOW_REVS,
        help="measurement window of each settled run [cage revolutions] (default: %(default)g)",
    )
    p.add_argument(
        "--out",
        default=None,
        help="directory for sensitivity.json and sensitivity.png, checked before work (default: print only)",
    )
    p.set_defaults(func=run)


def _shown(value: float, factor: float) -> str:
    return "-" if not math.isfinite(value) else f"{value * factor:+.3g}"


def table_lines(result) -> list[str]:
    """One row per input: key, value +/- uncertainty, source, and per statistic the effect
    [95 % interval] in the statistic's printed unit with the input's rank."""
    from ..design import SENSITIVITY_METHODS, SENSITIVITY_STATISTICS

    ranks = {s: {i: r + 1 for r, i in enumerate(result.ranking(s))} for s in result.statistics}
    w = 34
    head = f"{'input':<28}{'value +/- u':>22}  {'source':<15}" + "".join(
        f"{SENSITIVITY_STATISTICS[s].label + ' [' + SENSITIVITY_STATISTICS[s].shown_unit + ']':>{w}}"
        for s in result.statistics
    )
    lines = [head, "-" * len(head)]
    for i, item in enumerate(result.inputs):
        row = f"{item.key:<28}{f'{item.value:.4g} +/- {item.plus_minus:.3g}':>22}  {item.source:<15}"
        for s in result.statistics:
            e = result.effects[s][i]
            k = SENSITIVITY_STATISTICS[s].shown_factor
            cell = f"{_shown(e.effect, k)} [{_shown(e.ci95_low, k)}, {_shown(e.ci95_high, k)}] #{ranks[s][i]}"
            row += f"{cell:>{w}}"
        lines.append(row)
    lines.append("")
    lines.append("effect = derivative x uncertainty u; [95 % interval]; #rank by |effect|")
    methods = sorted({e.method for s in result.statistics for e in result.effects[s]})
    for m in methods:
        lines.append(f"method {m}: {SENSITIVITY_METHODS[m]}")
    if result.seeds:
        lines.append(
            f"settled runs: {result.seeds} seeds, {result.window_revs:g} revolutions each, "
            f"{result.num_slices} slices"
        )
    return lines


def draw(result, path) -> None:
    """A horizontal bar chart per statistic: each input's effect with its 95 % interval, largest
    |effect| on top; written atomically to `path`."""
    import numpy as np

    from ..design import SENSITIVITY_STATISTICS
    from ..io import atomic_write, pyplot

    plt = pyplot()
    n = len(result.statistics)
    fig, axes = plt.subplots(1, n, figsize=(6.0 * n, 0.45 * len(result.inputs) + 1.6), squeeze=False)
    for ax, s in zip(axes[0], result.statistics):
        st = SENSITIVITY_STATISTICS[s]
        order = result.ranking(s)[::-1]
        eff = np.array([result.effects[s][i].effect for i in order]) * st.shown_factor
        lo = np.array([result.effects[s][i].ci95_low for i in order]) * st.shown_factor
        hi = np.array([result.effects[s][i].ci95_high for i in order]) * st.shown_factor
        err = np.nan_to_num(np.vstack([eff - lo, hi - eff]))
        y = np.arange(len(order))
        ax.barh(y, np.nan_to_num(eff), xerr=err, color="tab:blue", ecolor="k", capsize=3)
        ax.axvline(0.0, color="k", lw=0.8)
        ax.set_yticks(y, [result.inputs[i].key for i in order], fontsize=8)  # each panel in its own order
        ax.set_xlabel(f"effect on {st.label} [{st.shown_unit}]")
        ax.set_title(f"{st.label} ({result.effects[s][0].method})", fontsize=9)
    fig.suptitle("effect of each input over its stated uncertainty (95 % interval)", fontsize=10)
    fig.tight_layout()
    atomic_write(path, lambda f: fig.savefig(f, format="png", dpi=110))
    plt.close(fig)


def run(args) -> int:
    from ..design import parse_sensitivity_statistics, sensitivity
    from ..io import check_output_dir, load_config, provenance, write_json, write_or_fallback
    from ..run import SteadySettings, available_cpus, steady_settings
    from ._main import report_fallback

    statistics = parse_sensitivity_statistics(
        args.statistics
        if args.statistics is not None
        else (QUICK_STATISTICS if args.quick else DEFAULT_STATISTICS)
    )
    settings = steady_settings(
        {"seeds": "--seeds", "window_revs": "--window-revs"},
        settle=str(SteadySettings.settle),
        window_revs=args.window_revs,
        seeds=args.seeds,
        workers=available_cpus(),
    )
    if args.out is not None:
        check_output_dir(args.out, "--out")
    try:
        cfg = load_config(args.config)
    except UserInputError as exc:
        raise UserInputError(f"{args.config}: {exc}") from None
    result = sensitivity(cfg, statistics, settings, quick=args.quick)
    print("\n".join(table_lines(result)))
    if args.out is None:
        return 0

    def write(d):
        doc = {**result.to_dict(), "provenance": provenance(cfg, seeds=list(range(result.seeds)))}
        write_json(d / "sensitivity.json", doc)
        draw(result, d / "sensitivity.png")

    used, reason = write_or_fallback(args.out, write)
    print(f"wrote {used / 'sensitivity.json'} and {used / 'sensitivity.png'}")
    return report_fallback("jaxbearing sensitivity", args.out, used, reason)
