"""Commands of maps on the body's sphere: ``reflection-map`` (measurements placed on it,
speclight.estimate.reflection_maps) and ``reflectivity-map`` (the target rendered over it,
speclight.maps)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import Annotated, Any

import typer

from speclight.cli.flags import flag_names
from speclight.cli.guard import fail, guarded, raise_if_signalled
from speclight.cli.options import (
    BinS,
    Force,
    MeasuredAndEndmembers,
    Plot,
    dataset_file,
    endmember_files,
    endmembers_option,
    force_option,
    measured_inputs,
    method_option,
    optional_scenario,
    output_option,
    say_wrote,
    scenario_option,
    source_option,
    write_products,
)
from speclight.errors import InputError

#: Python parameter -> flag of the cores ``reflection-map`` calls.
REFLECTION_MAP_FLAGS = {
    "nside": "--nside", "loaded": "--scenario", "light": "--source",
    "endmembers": "--endmembers", "method": "--method", "bin_s": "--bin-s",
}  # fmt: skip
#: Python parameter -> flag of the cores ``reflectivity-map`` calls.
MAP_FLAGS = {
    "output": "--output", "force": "--force", "directions": "--directions",
    "phase_angles_deg": "--phase-angles-deg", "rolls": "--rolls", "chunk": "--chunk",
    "n_workers": "--workers",
}  # fmt: skip


def reflection_map(
    measured: MeasuredAndEndmembers,
    output: Annotated[str, output_option("FILE", "Output NetCDF (RMAP.nc).")] = "reflection-map.nc",
    nside: Annotated[
        int, typer.Option("--nside", help="HEALPix resolution, a power of 2 (12 nside^2 pixels).")
    ] = 16,
    scenario: Annotated[
        Path | None,
        scenario_option(
            "Scenario YAML: the geometry at the epochs of a CSV (or of a NetCDF without "
            "body-frame directions), the lasers' lines, -e scenario."
        ),
    ] = None,
    source: Annotated[
        str | None,
        source_option(
            "sun (map along the phase vector) or laser (coaxial lasers: along the "
            "observer direction); default: the lasers' where the data have no solar factors."
        ),
    ] = None,
    endmembers: Annotated[
        list[str] | None,
        endmembers_option(
            "Endmember spectrum CSV to unmix every pixel with (repeat for each), or "
            "'scenario' for the scenario's materials."
        ),
    ] = None,
    method: Annotated[
        str, method_option("Unmixing: ls, nnls, nnls-norm (default) or fcls.")
    ] = "nnls-norm",
    bin_s: BinS = None,
    band: Annotated[
        str | None, typer.Option("--band", help="Band of the figure (default: most pixels).")
    ] = None,
    plot_file: Plot = None,
    force: Force = False,
) -> None:
    """Reflection map: each epoch's band reflectance factor placed on a HEALPix sphere (RING)
    in the body frame along its phase vector (the observer direction under coaxial lasers),
    averaged per pixel (Kucharski; paper section 5.3). Writes RMAP.nc:
    reflectance_factor(band, pixel), n_samples(pixel), range_offset(band, pixel) where the
    input has ranging, abundance(endmember, pixel) with --endmembers.

    Example: speclight reflection-map out.nc -o rmap.nc --nside 16 --plot rmap.png
    """

    def run() -> None:
        from speclight.estimate.inputs.source_spectrum import check_light
        from speclight.estimate.reflection_maps.reflection_map_core import check_nside
        from speclight.estimate.reflection_maps.reflection_map_run import reflection_map_measured

        members = endmember_files(measured, endmembers)
        with flag_names(**REFLECTION_MAP_FLAGS):
            check_nside(nside)
            check_light(source)

        def draw(ds: Any) -> Any:
            from speclight.plot.reflection_map_figure import reflection_map_figure

            return reflection_map_figure(ds, band)

        ds = write_products(
            output, plot_file, force, measured_inputs(measured[0], scenario, members),
            compute=lambda: reflection_map_measured(
                measured[0], nside=nside, loaded=optional_scenario(scenario), light=source,
                endmembers=members, method=method, bin_s=bin_s, progress=sys.stderr.isatty(),
            ),
            data=dataset_file, figure=draw, flags=REFLECTION_MAP_FLAGS,
        )  # fmt: skip
        mapped = int((ds["n_samples"].values > 0).sum())
        typer.echo(
            f"{int(ds['n_samples'].values.sum())} epochs in {mapped} of "
            f"{ds.sizes['pixel']} pixels (nside {nside}, {ds.attrs['light']})"
        )
        say_wrote(output, plot_file)

    guarded(run)


def _phase_angles(text: str) -> list[float]:
    """``--phase-angles-deg 0,30,60,90``: comma-separated numbers."""
    try:
        return [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise InputError(
            f"--phase-angles-deg = {text!r} must be comma-separated numbers, e.g. 0,30,60,90",
            field="--phase-angles-deg",
        ) from None


def reflectivity_map(
    scenario: Annotated[
        Path, typer.Argument(help="Scenario YAML: target, materials, spectrum, render, bands.")
    ],
    output: Annotated[str, output_option("MAP.zarr", "Output Zarr store.")] = "map.zarr",
    directions: Annotated[
        int, typer.Option("--directions", help="At least N phase-vector directions (HEALPix).")
    ] = 10_000,
    phase_angles_deg: Annotated[
        str, typer.Option("--phase-angles-deg", metavar="LIST", help="e.g. 0 or 0,30,60,90.")
    ] = "0",
    rolls: Annotated[
        int, typer.Option("--rolls", help="Rolls of the Sun-observer plane (phase > 0).")
    ] = 8,
    chunk: Annotated[int, typer.Option("--chunk", help="Directions per chunk.")] = 512,
    force: Annotated[bool, force_option("Replace an existing store.")] = False,
    scheduler: Annotated[
        str,
        typer.Option(
            "--scheduler",
            metavar="ADDRESS",
            help="Where chunks render: none (this process), local (a local Dask cluster) "
            "or a running Dask scheduler, e.g. tcp://HOST:8786.",
        ),
    ] = "none",  # docs/scale-out.md: a local cluster was no faster on 2 cores
    workers: Annotated[
        int | None,
        typer.Option("--workers", help="Workers of a local cluster (default: the cores)."),
    ] = None,
) -> None:
    """Render the target for N body-frame phase-vector directions x phase angles x rolls and
    store intensity (Sun at 1 AU) and count rates per band (1 m, 1 m2, no atmosphere) in a
    chunked Zarr store. An interrupted run resumes where it stopped when rerun with the same
    parameters; a chunk that fails is recorded and retried on the next run (exit 1).

    Chunks of directions are tasks: in this process (--scheduler none), on a local Dask
    cluster (--scheduler local) or on an existing one (--scheduler tcp://HOST:8786, see
    docs/scale-out.md); the map is the same, bit for bit.

    Example: speclight reflectivity-map box-wing.yaml -o map.zarr --phase-angles-deg 0,30,60,90
    """

    def run() -> None:
        from speclight.maps.writer import check_map_options
        from speclight.maps.writer import reflectivity_map as build
        from speclight.scenario import load_scenario

        angles = _phase_angles(phase_angles_deg)
        with flag_names(**MAP_FLAGS):
            check_map_options(  # before loading
                directions=directions, phase_angles_deg=angles, rolls=rolls, chunk=chunk,
                n_workers=workers,
            )  # fmt: skip
            result = build(
                load_scenario(scenario), output, directions=directions,
                phase_angles_deg=angles, rolls=rolls, chunk=chunk, force=force,
                progress=sys.stderr.isatty(), scheduler=scheduler, n_workers=workers,
                announce=True,
            )  # fmt: skip
        raise_if_signalled()
        if result.damaged:
            typer.echo(
                f"notice: {len(result.damaged)} chunk(s) marked done did not read back "
                f"(chunk {result.damaged[0]}: a file cut short or deleted): rendered again",
                err=True,
            )
        typer.echo(
            f"{result.n_directions} directions in {result.n_chunks} chunks: rendered "
            f"{result.rendered}, skipped {result.skipped} done before, in {result.seconds:.1f} s"
        )
        if result.failed:
            first = next(iter(result.failed.items()))
            fail(
                f"{len(result.failed)} chunk(s) failed (chunk {first[0]}: {first[1]}); "
                f"{output} is unfinished: rerun the same command to retry them",
                1,
            )
        say_wrote(output)

    guarded(run)
