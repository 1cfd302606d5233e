"""The work of ``speclight fit`` behind the command line: claims, fit, JSON and figure."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path

import numpy as np
import typer

from speclight.errors import InputError

FIGURE_SUFFIXES = (".png", ".pdf", ".svg")


def run_fit(
    scenario: Path,
    measured: Path,
    output: str,
    free: str,
    bin_s: float | None,
    plot_file: str | None,
    force: bool,
    check_signals: Callable[[], None],
) -> None:
    """Check every input and output name, fit, then write FIT.json (and the figure).

    Bad input (an unknown ``--free`` value, a missing file, a band mismatch, an existing
    output without ``force``) raises :class:`~speclight.errors.InputError` before anything
    is written.
    """
    from contextlib import ExitStack

    from speclight.estimate.measured import read_measured
    from speclight.estimate.scenario_fit import fit_scenario, parse_free
    from speclight.io.output import OutputClaim
    from speclight.scenario import load_scenario

    names = parse_free(free)
    if bin_s is not None and not (bin_s > 0 and bin_s < float("inf")):
        raise InputError(f"--bin-s = {bin_s!r} must be a duration > 0 s", field="--bin-s")
    inputs = {"scenario file": scenario, "measurements": measured}
    if plot_file is not None:
        if Path(plot_file).suffix.lower() not in FIGURE_SUFFIXES:
            raise InputError(
                f"--plot {plot_file}: give a figure file ending in {', '.join(FIGURE_SUFFIXES)}",
                field="--plot",
            )
        if Path(plot_file).resolve() == Path(output).resolve():
            raise InputError(
                f"--plot {plot_file} is the JSON output too; choose another name", field="--plot"
            )
    with ExitStack() as stack:
        claim = stack.enter_context(OutputClaim(output, force=force, inputs=inputs))
        figure = None
        if plot_file is not None:
            try:
                figure = stack.enter_context(OutputClaim(plot_file, force=force, inputs=inputs))
            except InputError as exc:
                raise InputError(exc.message, source=exc.source, field="--plot") from None
        loaded = load_scenario(scenario)
        lc = read_measured(measured)
        result = fit_scenario(loaded, lc, free=names, bin_s=bin_s, progress=True)
        check_signals()
        text = json.dumps(result.to_json(), indent=2) + "\n"
        image = None
        if figure is not None:
            from speclight.plot.fit_figure import fit_figure_bytes

            image = fit_figure_bytes(
                result.time_utc,
                result.measured_per_s,
                result.fitted_per_s,
                result.band_names,
                fmt=Path(plot_file or ".png").suffix.lstrip(".").lower(),
            )
        claim.write(text.encode())
        if figure is not None and image is not None:
            figure.write(image)
    if not result.converged:
        typer.echo(f"not converged: {result.message}", err=True)
    summary = ", ".join(
        f"{b} {a:.4g}" for b, a in zip(result.band_names, result.albedo, strict=True)
    )
    typer.echo(f"albedo: {summary}")
    for name, (value, std) in result.roughness.items():
        spread = f"+- {std:.2g}" if np.isfinite(std) else "(not constrained)"
        typer.echo(f"roughness {name}: {value:.4g} {spread}")
    typer.echo(f"wrote {output}" + (f" and {plot_file}" if plot_file else ""))
