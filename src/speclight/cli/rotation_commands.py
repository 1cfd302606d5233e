"""Commands of the body's rotation: ``period`` (speclight.estimate.period) and ``spin-axis``
(speclight.estimate.spin_axis)."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Annotated, Any

import typer

from speclight.cli.flags import flag_names
from speclight.cli.guard import guarded
from speclight.cli.options import (
    BinS,
    Force,
    Plot,
    dataset_file,
    json_bytes,
    measured_inputs,
    optional_scenario,
    output_option,
    say_wrote,
    scenario_option,
    source_option,
    write_products,
)
from speclight.errors import InputError

#: Python parameter -> flag of the cores ``spin-axis`` calls.
SPIN_AXIS_FLAGS = {
    "grid_deg": "--grid-deg", "n_phases": "--phases", "period_s": "--period-s",
    "bands": "--bands", "refine_method": "--refine", "period_bound": "--period-bound",
    "y": "MEASURED", "bmap": "--map", "map_path": "--map", "ranging_weight": "--ranging-weight",
    "light": "--source", "phase_angles_deg": "--phase-angles-deg",
    "period_kind": "--period-kind",
}  # fmt: skip
#: Python parameter -> flag of the cores ``period`` calls.
PERIOD_FLAGS = {
    "min_period_s": "--min-period-s", "max_period_s": "--max-period-s", "draws": "--draws",
    "harmonics": "--harmonics", "seed": "--seed", "synodic": "--synodic", "bin_s": "--bin-s",
    "loaded": "--scenario", "source": "--source", "fap_method": "--fap",
}  # fmt: skip


def spin_axis(
    scenario: Annotated[
        Path, typer.Argument(help="Scenario YAML: orbit, observer, bands, spin body axis, period.")
    ],
    measured: Annotated[
        Path, typer.Argument(help="MEASURED: a speclight NetCDF or a CSV of band count rates.")
    ],
    map_file: Annotated[
        Path, typer.Option("--map", metavar="MAP.zarr", help="Reflectivity map of the target.")
    ],
    output: Annotated[str, output_option("FILE", "Output NetCDF (AXIS.nc).")] = "axis.nc",
    period_s: Annotated[
        float | None,
        typer.Option("--period-s", help="Rotation period \\[s] (default: the scenario's)."),
    ] = None,
    period_kind: Annotated[
        str | None,
        typer.Option(
            "--period-kind",
            help="What the period is: sidereal (the body's), synodic (the light curve's, "
            "as speclight period measures it: each axis gets its own sidereal period) or auto "
            "(both tried, the better fit kept); default: auto with --period-s, else sidereal.",
        ),
    ] = None,
    grid_deg: Annotated[
        float, typer.Option("--grid-deg", help="RA/Dec grid step in deg, 0.01..90.")
    ] = 2.0,
    phases: Annotated[
        int, typer.Option("--phases", help="Rotation phases tried per axis (1..36000).")
    ] = 72,
    bands: Annotated[
        str | None, typer.Option("--bands", metavar="LIST", help="Comma-separated band names.")
    ] = None,
    no_refine: Annotated[
        bool, typer.Option("--no-refine", help="Skip the local refinement.")
    ] = False,
    refine_method: Annotated[
        str,
        typer.Option(
            "--refine",
            help="Refinement: nelder-mead, gradient (L-BFGS-B, analytic gradient), "
            "gradient-continuation (gradient on coarsened maps, then the map: a larger "
            "basin), gauss-newton (least squares, analytic Jacobian) or slsqp (numerical "
            "gradient).",
        ),
    ] = "nelder-mead",
    free_period: Annotated[
        bool | None,
        typer.Option(
            "--free-period/--fixed-period",
            help="Scan and refine the period too, within --period-bound (default: free with "
            "--period-s, a light curve's period, fixed with the scenario's).",
        ),
    ] = None,
    period_bound: Annotated[
        float,
        typer.Option(
            "--period-bound",
            help="With a free period: largest relative change of the period (scanned, then "
            "refined).",
        ),
    ] = 0.05,
    no_period_check: Annotated[
        bool,
        typer.Option(
            "--no-period-check",
            help="With a fixed period, skip the check that scans the periods within 8 % and "
            "warns where another fits better or moves the axis (about 30 passes of a coarse "
            "axis grid).",
        ),
    ] = False,
    source: Annotated[
        str | None,
        source_option(
            "Light: sun or laser (coaxial, the map's phase-0 slice); default: what MEASURED has."
        ),
    ] = None,
    ranging_weight: Annotated[
        float | None,
        typer.Option(
            "--ranging-weight",
            help="Weight of the range-offset term (0: off); default 1 where MEASURED and "
            "the map have range offsets.",
        ),
    ] = None,
    plot_file: Plot = None,
    force: Force = False,
) -> None:
    """Grid search of the spin axis (RA, Dec in GCRS) and the rotation phase at the scenario
    start: every candidate's band light curves are predicted from the reflectivity map and
    compared with the measured ones (each divided by its mean); then the mirror minimum and
    a local refinement (--refine; --free-period fits the period too). Writes AXIS.nc:
    error(ra, dec), best_phase(ra, dec) and the best, mirror and refined axes in its
    attributes.

    Example: speclight spin-axis pass.yaml pass.nc --map map.zarr -o axis.nc --plot axis.png
    """

    def run() -> None:
        from speclight.estimate.inputs.source_spectrum import check_light
        from speclight.estimate.spin_axis.spin_axis_core import check_search_options
        from speclight.estimate.spin_axis.spin_axis_dataset import axis_dataset
        from speclight.estimate.spin_axis.spin_axis_period import check_period_kind
        from speclight.estimate.spin_axis.spin_axis_refine import check_refine_options
        from speclight.estimate.spin_axis.spin_axis_run import spin_axis_measured
        from speclight.scenario import load_scenario

        free = free_period if free_period is not None else period_s is not None
        bound = period_bound if free else None
        with flag_names(**SPIN_AXIS_FLAGS):
            check_search_options(grid_deg, phases)
            check_refine_options(refine_method, bound)
            check_light(source)
            if period_kind is not None:
                check_period_kind(period_kind)
        names = [b.strip() for b in bands.split(",") if b.strip()] if bands else None

        def search() -> tuple[Any, Any]:
            result = spin_axis_measured(
                load_scenario(scenario), measured, map_file, period_s=period_s,
                grid_deg=grid_deg, n_phases=phases, bands=names, refine=not no_refine,
                light=source, ranging_weight=ranging_weight, refine_method=refine_method,
                period_bound=bound, period_kind=period_kind, period_check=not no_period_check,
            )  # fmt: skip
            return result, axis_dataset(result, str(map_file), str(scenario))

        result, ds = write_products(
            output, plot_file, force,
            {"scenario file": scenario, "measured file": measured, "map": map_file},
            compute=search, data=lambda found: dataset_file(found[1]),
            figure=lambda found: _axis_figure(found[1]), flags=SPIN_AXIS_FLAGS,
        )  # fmt: skip
        typer.echo(_axis_summary(ds.attrs, result, free))
        say_wrote(output, plot_file)

    guarded(run)


def _axis_figure(ds: Any) -> Any:
    from speclight.plot.spin_axis_figure import spin_axis_figure

    return spin_axis_figure(ds)


def _axis_summary(a: Any, result: Any, free_period: bool) -> str:
    """The line ``spin-axis`` prints: best, mirror and refined axes (AXIS.nc's attributes)."""
    head = (
        f"best axis RA {a['best_ra_deg']:.1f} Dec {a['best_dec_deg']:.1f} deg, phase "
        f"{a['best_phase_deg']:.1f} deg (misfit {a['best_error']:.4g}); mirror RA "
        f"{a['mirror_ra_deg']:.1f} Dec {a['mirror_dec_deg']:.1f} (misfit "
        f"{a['mirror_error']:.4g}); "
    )
    refined = math.isfinite(float(a["refined_ra_deg"]))
    if refined and not result.result.refine_note:
        how = (
            f"refined RA {a['refined_ra_deg']:.2f} Dec {a['refined_dec_deg']:.2f} phase "
            f"{a['refined_phase_deg']:.1f} "
            + (
                f"sidereal period {a['refined_period_s']:.6g} s "
                if free_period or a["period_kind"] == "synodic"
                else ""
            )
            + f"by {a['refine_method']} with {a['refine_misfit_evaluations']} misfit and "
            f"{a['refine_gradient_evaluations']} gradient evaluations "
        )
    elif refined:
        how = (
            f"refined RA {a['refined_ra_deg']:.2f} Dec {a['refined_dec_deg']:.2f}: "
            f"{result.result.refine_note} "
        )
    else:
        how = "not refined (--no-refine) "
    kinds = ", ".join(
        f"{k} {a[k + '_best_error']:.4g}" for k in ("sidereal", "synodic") if k + "_best_error" in a
    )
    return (
        head + how + f"({result.result.n_epochs} epochs, {result.light}, ranging weight "
        f"{result.ranging_weight:g}, period read as {a['period_kind']} (best misfit {kinds}), "
        f"{result.seconds:.1f} s)\n"
        + ("" if a["axis_constrained"] else "WARNING: ")
        + a["axis_note"]
    )


def period(
    measured: Annotated[
        Path, typer.Argument(help="Light curves: a speclight NetCDF or a CSV of count rates.")
    ],
    output: Annotated[str, output_option("FILE", "Output JSON (PERIOD.json).")] = "period.json",
    scenario: Annotated[
        Path | None,
        scenario_option(
            "Scenario YAML: geometry and spin axis for the synodic correction (for a "
            "NetCDF default: the one it carries)."
        ),
    ] = None,
    bands: Annotated[
        list[str] | None,
        typer.Option("--bands", help="Bands to use (repeatable; default: all)."),
    ] = None,
    min_period_s: Annotated[
        float | None,
        typer.Option("--min-period-s", help="Shortest period searched \\[s] (default 2 K dt)."),
    ] = None,
    max_period_s: Annotated[
        float | None,
        typer.Option("--max-period-s", help="Longest period searched \\[s] (default span/3)."),
    ] = None,
    harmonics: Annotated[
        int, typer.Option("--harmonics", help="Harmonics K of the periodogram's model.")
    ] = 2,
    bin_s: BinS = None,
    draws: Annotated[
        int,
        typer.Option("--draws", help="Bootstrap draws for the false-alarm probability (1..10000)."),
    ] = 40,
    fap: Annotated[
        str,
        typer.Option(
            "--fap",
            help="auto, analytic or bootstrap: the false-alarm probability by Baluev's "
            "approximation (analytic), by --draws permutations (bootstrap), or analytic "
            "where every band has 10 points per model parameter (auto).",
        ),
    ] = "auto",
    seed: Annotated[int, typer.Option("--seed", help="Seed of the bootstrap.")] = 0,
    if_symmetric: Annotated[
        str,
        typer.Option(
            "--if-symmetric",
            help="auto, double or keep: the rotation period when the halves of the 2P fold "
            "agree (P or 2P, said in the decision): double (the body looks alike after half a "
            "turn), keep, or auto (2P if the folded curve has one principal maximum, P if two; "
            "stated as ambiguous); see docs/period.md.",
        ),
    ] = "auto",
    synodic: Annotated[
        str,
        typer.Option(
            "--synodic",
            help="auto, report or bisector: the synodic correction in the phase-angle "
            "bisector's frame: applied to the period (bisector), only reported (report), or "
            "applied where the median phase angle is at most 30 deg (auto; see "
            "docs/period.md).",
        ),
    ] = "auto",
    source: Annotated[
        str,
        source_option(
            "sun (the count rates) or laser (a NetCDF's laser return rates, phase angle 0)."
        ),
    ] = "sun",
    plot_file: Plot = None,
    force: Force = False,
) -> None:
    """Rotation period from one or many bands: multi-band multi-harmonic Lomb-Scargle,
    false-alarm probability at the noise level beside the peak (no period below 1 %: a
    lower bound where the light curve varies slowly), outliers left out, photometric or
    rotation period (the halves of the 2P fold), tumbling (two frequencies), synodic
    correction where the geometry is known. Writes PERIOD.json.

    Example: speclight period pass.nc -o period.json --plot period.png
    """

    def run() -> None:
        from speclight.estimate.period.period_decision import IfSymmetric
        from speclight.estimate.period.period_run import estimate_period

        if if_symmetric not in ("auto", "double", "keep"):
            raise InputError(
                f"--if-symmetric = '{if_symmetric}' (choices: auto, double, keep)",
                field="--if-symmetric",
            )
        rule: IfSymmetric = (
            "double" if if_symmetric == "double" else "keep" if if_symmetric == "keep" else "auto"
        )
        result = write_products(
            output, plot_file, force, measured_inputs(measured, scenario),
            compute=lambda: estimate_period(
                measured, loaded=optional_scenario(scenario), bands=bands,
                min_period_s=min_period_s, max_period_s=max_period_s, harmonics=harmonics,
                bin_s=bin_s, draws=draws, seed=seed, if_symmetric=rule,
                synodic=synodic,  # type: ignore[arg-type]  # checked by estimate_period
                source=source, fap_method=fap,  # type: ignore[arg-type]  # checked there
            ),
            data=lambda r: json_bytes(r.to_json()), figure=_period_figure, flags=PERIOD_FLAGS,
        )  # fmt: skip
        summary = result.to_json()

        def shown(key: str, spec: str) -> str:  # null: not determined (PERIOD.json says)
            return "undetermined" if summary[key] is None else format(summary[key], spec)

        if not summary["detected"]:
            typer.echo(summary["verdict"])
        else:
            typer.echo(
                f"rotation period {shown('period_s', '.6g')} +- "
                f"{shown('period_std_s', '.2g')} s (photometric "
                f"{shown('photometric_period_s', '.6g')} s, false-alarm probability "
                f"{shown('false_alarm_probability', '.2g')})"
            )
            if summary["search_edge"] or (summary["tumbling"] or {}).get("detected"):
                typer.echo(summary["verdict"])
        for notice in summary["outliers"]:
            typer.echo(
                f"outlier left out: band {notice['band']} at {notice['time_s']:.6g} s "
                f"({notice['residual_sigma']:.3g} sigma)"
            )
        say_wrote(output, plot_file)

    guarded(run)


def _period_figure(result: Any) -> Any:
    from speclight.plot.period_figure import period_figure

    return period_figure(result)
