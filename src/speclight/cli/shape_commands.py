"""The command of shape inversion: ``shape`` (speclight.estimate.shape)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from speclight.cli.flags import flag_names
from speclight.cli.guard import guarded
from speclight.cli.options import Force, Plot, output_option, scenario_option
from speclight.errors import InputError

#: Python parameter -> flag of the cores ``shape`` calls.
SHAPE_FLAGS = {
    "fmt": "--format", "period_range_h": "--period-range-h", "law": "--law",
    "bands": "--bands", "nside": "--nside", "pole_step_deg": "--pole-step-deg",
    "loaded": "--scenario", "n_starts": "--tumbling-starts", "map_path": "--map",
    "map_resolution": "--map-nside", "no_map": "--no-map",
}  # fmt: skip


def shape(
    lc: Annotated[
        Path, typer.Argument(help="Light curves: DAMIT .lc, or a speclight NetCDF or CSV.")
    ],
    period_range_h: Annotated[
        tuple[float, float],
        typer.Option(
            "--period-range-h", metavar="LO HI", help="Sidereal periods scanned, in hours."
        ),
    ],
    output: Annotated[str, output_option("FILE", "Output NetCDF (SHAPE.nc).")] = "shape.nc",
    scenario: Annotated[
        Path | None,
        scenario_option(
            "Scenario YAML: geometry and instrument (speclight input; a NetCDF's own by default)."
        ),
    ] = None,
    fmt: Annotated[
        str, typer.Option("--format", help="Input format: speclight or damit.")
    ] = "speclight",
    law: Annotated[
        str,
        typer.Option(
            "--law",
            help="Scattering law: lambert, lommel-seeliger, ls-lambert, "
            "material:NAME (a scenario material) or auto (ls-lambert for DAMIT, "
            "lambert for speclight).",
        ),
    ] = "auto",
    bands: Annotated[
        str | None, typer.Option("--bands", metavar="LIST", help="Comma-separated band names.")
    ] = None,
    nside: Annotated[int, typer.Option("--nside", help="HEALPix nside of the EGI.")] = 4,
    pole_step_deg: Annotated[
        float, typer.Option("--pole-step-deg", help="Pole-map grid step in degrees.")
    ] = 30.0,
    bootstrap: Annotated[
        int, typer.Option("--bootstrap", help="Bootstrap refits for the uncertainties.")
    ] = 0,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the bootstrap.")] = 0,
    tumbling_starts: Annotated[
        int,
        typer.Option(
            "--tumbling-starts",
            help="Also fit torque-free (tumbling) states from this many random starts, the "
            "scenario's target as the light model: its reflectivity map (--map, else built "
            "and cached) or, with --no-map or DAMIT input, its mesh's convex model (0: off).",
        ),
    ] = 0,
    tumbling_map: Annotated[
        Path | None,
        typer.Option(
            "--map",
            metavar="MAP.zarr",
            help="Reflectivity map of the scenario's target (speclight reflectivity-map) as "
            "the tumbling fit's light model, with the shadows (default: the scenario's "
            "render.map_file, else a map built from the scenario and cached). Needs "
            "--tumbling-starts.",
        ),
    ] = None,
    map_nside: Annotated[
        int | None,
        typer.Option(
            "--map-nside",
            metavar="NSIDE",
            help="Resolution of the reflectivity map built from the scenario without --map: "
            "the HEALPix nside of its 12 NSIDE^2 phase-vector directions (1, 2, 4, 8 or 16; "
            "default 16: minutes to build), with 32 rolls, phase angles every 10 deg around "
            "the light curves' and renders of 64 px. Cached: a rerun does not render again.",
        ),
    ] = None,
    no_map: Annotated[
        bool,
        typer.Option(
            "--no-map",
            help="Fit tumbling states with the convex model of the scenario's mesh (no "
            "shadows, no map built).",
        ),
    ] = False,
    plot_file: Plot = None,
    force: Force = False,
) -> None:
    """Convex shape (EGI), sidereal period and pole (ecliptic J2000) from light curves: period
    scan, pole map, Levenberg-Marquardt with analytic derivatives, uncertainties, the mirror
    pole; writes SHAPE.nc, SHAPE.obj beside it and the figure (docs/shape.md).

    Example: speclight shape asteroid.lc --format damit --period-range-h 5 8 -o shape.nc
    """

    def run() -> None:
        from speclight.cli.shape_files import shape_files
        from speclight.estimate.shape.shape_run import ShapeOptions
        from speclight.maps.writer.cached_map import MapResolution

        for name, value, ok in (
            ("--nside", nside, nside in (1, 2, 4, 8, 16)),
            ("--bootstrap", bootstrap, bootstrap >= 0),
            ("--tumbling-starts", tumbling_starts, tumbling_starts >= 0),
        ):
            if not ok:
                raise InputError(
                    f"{name} = {value} is not accepted (nside: 1, 2, 4, 8 or 16; the others: >= 0)",
                    field=name,
                )
        for flag, given, text in (
            ("--map", tumbling_map is not None, f"--map {tumbling_map}"),
            ("--map-nside", map_nside is not None, f"--map-nside {map_nside}"),
            ("--no-map", no_map, "--no-map"),
        ):
            if given and tumbling_starts == 0:
                raise InputError(
                    f"{text} is about the tumbling fit's light model: give it with "
                    "--tumbling-starts N (N > 0)",
                    field=flag,
                )
        names = [b.strip() for b in bands.split(",") if b.strip()] if bands else None
        options = ShapeOptions(
            *period_range_h,
            law=law,
            nside=nside,
            search_nside=min(2, nside),
            pole_step_deg=pole_step_deg,
            bootstrap_draws=bootstrap,
            seed=seed,
            progress=True,
        )
        resolution = None
        if map_nside is not None:
            with flag_names(nside="--map-nside"):
                resolution = MapResolution.of_nside(map_nside)
        with flag_names(**SHAPE_FLAGS):
            ds, _ = shape_files(
                lc=lc, fmt=fmt, scenario=scenario, options=options, output=output,
                plot=plot_file, force=force, bands=names, tumbling_starts=tumbling_starts,
                tumbling_map=tumbling_map, no_map=no_map, map_resolution=resolution,
                say=lambda line: typer.echo(line, err=True),
            )  # fmt: skip
        a = ds.attrs
        if "tumbling_families" in a:
            typer.echo(
                f"tumbling: {a['tumbling_families']} solution families (SHAPE.nc tumbling_*), "
                f"light model: {a['tumbling_light_model']} ({a['tumbling_light_note']})"
            )
        typer.echo(
            f"period {a['period_h']:.7g} +- {a['period_std_h']:.2g} h, pole (lambda, "
            f"beta) ({a['pole_lambda_deg']:.1f}, {a['pole_beta_deg']:.1f}) +- "
            f"{a['pole_std_deg']:.2g} deg ecliptic J2000; {a['verdict']}"
        )
        written = [
            output,
            *([a["obj_file"]] if "obj_file" in a else []),
            *([plot_file] if plot_file else []),
        ]
        typer.echo(f"wrote {', '.join(written)}")

    guarded(run)
