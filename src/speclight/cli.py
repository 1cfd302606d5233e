"""The ``speclight`` command line (README: the command table).

Exit codes: 0 success, 2 bad input (the message names the file, the field and what is
accepted), 1 internal error or an output the file system refused (full disk), 128 + N when
ended by signal N: 130 for Ctrl-C (SIGINT), 143 for SIGTERM, 129 for SIGHUP. An interrupted
run removes its temporary file and its output lock; one killed by SIGKILL leaves them to be
removed by the next run writing to the same folder (see :mod:`speclight.io.output`).
"""

from __future__ import annotations

import json
import math
import re
import signal
import sys
import threading
import traceback
import warnings
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from types import FrameType
from typing import Annotated, Any

import typer

from speclight.errors import InputError
from speclight.io.held_signals import INTERRUPTING_SIGNALS
from speclight.io.output import OutputWriteError

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="Spectral light curves of satellites and space debris, as a ground telescope sees them.",
    pretty_exceptions_enable=False,
    context_settings={"help_option_names": ["-h", "--help"]},
)


def _print_version(value: bool) -> None:
    if value:
        from speclight import __version__

        typer.echo(f"speclight {__version__}")
        raise typer.Exit()


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option(
            "--version",
            callback=_print_version,
            is_eager=True,
            help="Print the version and exit.",
        ),
    ] = False,
) -> None:
    """Spectral light curves of satellites and space debris, as a ground telescope sees them."""


class Terminated(BaseException):
    """SIGTERM or SIGHUP, raised like ``KeyboardInterrupt`` (which ``except Exception`` skips).

    Parameters
    ----------
    signum
        The signal received.
    """

    def __init__(self, signum: int) -> None:
        self.signum = signum
        super().__init__(signal.Signals(signum).name)


#: Signals received during this command (a library may drop the exception of one).
_received: list[int] = []


def _on_signal(signum: int, frame: FrameType | None) -> None:
    _received.append(signum)
    if signum == signal.SIGINT:
        raise KeyboardInterrupt
    raise Terminated(signum)


def _raise_if_signalled() -> None:
    """Raise for a signal whose exception was dropped (printed as "Exception ignored")."""
    if _received:
        _on_signal(_received[0], None)


def _quiet_unraisable(unraisable: Any) -> None:
    if not isinstance(unraisable.exc_value, (KeyboardInterrupt, Terminated)):
        sys.__unraisablehook__(unraisable)


@contextmanager
def _signals_end_the_run() -> Iterator[None]:
    """SIGINT, SIGTERM and SIGHUP raise in the block; ignored ones stay ignored (nohup)."""
    _received.clear()
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {}
    for signum in INTERRUPTING_SIGNALS:
        if signal.getsignal(signum) in (signal.SIG_DFL, signal.default_int_handler):
            previous[signum] = signal.signal(signum, _on_signal)
    hook, sys.unraisablehook = sys.unraisablehook, _quiet_unraisable
    try:
        yield
    finally:
        sys.unraisablehook = hook
        for signum, handler in previous.items():
            signal.signal(signum, handler)


def _fail(message: str, code: int) -> None:
    typer.echo(f"error: {message}", err=True)
    raise typer.Exit(code)


@contextmanager
def _flag_names(**flags: str) -> Iterator[None]:
    """Say the command-line flags where a plain-array core's error names its Python
    parameters (``n_phases = 0`` -> ``--phases = 0``): ``flags`` maps parameter names to
    flags. A name with an underscore is replaced wherever it stands; a plain word
    (``draws``) only as ``draws =``, so that the prose around it stays."""
    try:
        yield
    except InputError as exc:
        if exc.field not in flags:
            raise
        message = exc.message
        for name, flag in flags.items():
            tail = r"(?!\w)" if "_" in name else r"(?= = )"
            message = re.sub(rf"(?<![\w-]){re.escape(name)}{tail}", flag, message)
        raise InputError(message, source=exc.source, field=flags[str(exc.field)]) from None


def _guarded(func: Callable[[], Any]) -> Any:
    try:
        with _signals_end_the_run():
            result = func()
            _raise_if_signalled()
            return result
    except InputError as exc:
        _fail(str(exc), 2)
    except OutputWriteError as exc:
        _fail(str(exc), 1)
    except KeyboardInterrupt:
        _fail("interrupted", 128 + signal.SIGINT)
    except Terminated as exc:
        _fail(f"terminated by {exc}", 128 + exc.signum)
    except typer.Exit:
        raise
    except Exception:  # an internal error: say so, with the traceback for a bug report
        traceback.print_exc()
        _fail("internal error (please report it with the traceback above)", 1)


@app.command()
def simulate(
    scenario: Annotated[
        Path | None, typer.Argument(help="Scenario YAML file (see `speclight example`).")
    ] = None,
    output: Annotated[
        str, typer.Option("--output", "-o", metavar="FILE", help="Output NetCDF file.")
    ] = "speclight.nc",
    example: Annotated[
        str | None, typer.Option("--example", help="Run a built-in scenario instead of a file.")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite an existing output.")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Print nothing but errors.")] = False,
) -> None:
    """Run one scenario and write its NetCDF dataset (geometry, spectra, bands) to OUTPUT.

    OUTPUT is claimed before the work starts: a bad name or folder, the scenario file itself,
    an existing file without --force, or another run writing it is refused at once (exit 2).
    """

    def run() -> None:
        from speclight.io.output import OutputClaim

        if (scenario is None) == (example is None):
            raise InputError("give a scenario file or --example NAME (one of them)")
        inputs = {"scenario file": scenario} if scenario is not None else {}
        with OutputClaim(output, force=force, inputs=inputs) as claim:
            from speclight.io.netcdf import dataset_bytes
            from speclight.scenario import load_example, load_scenario
            from speclight.simulate import simulate as run_simulation

            loaded = load_example(example) if example else load_scenario(scenario)  # type: ignore[arg-type]
            result = run_simulation(loaded, progress=sys.stderr.isatty() and not quiet)
            _raise_if_signalled()
            claim.write(dataset_bytes(result.dataset))
        if not quiet:
            for note in result.notes:
                typer.echo(note)
            typer.echo(f"wrote {output}")

    _guarded(run)


@app.command("example")
def example_cmd(
    name: Annotated[str | None, typer.Argument(help="Name of a built-in scenario.")] = None,
) -> None:
    """Print a built-in scenario as YAML (without NAME: list them)."""

    def run() -> None:
        from speclight.scenario import example_names, example_text

        if name is None:
            typer.echo("\n".join(example_names()))
        else:
            typer.echo(example_text(name), nl=False)

    _guarded(run)


@app.command()
def plot(
    dataset: Annotated[Path, typer.Argument(help="A dataset written by `speclight simulate`.")],
    output: Annotated[
        str, typer.Option("--output", "-o", metavar="FILE", help="Figure file (.png, .pdf).")
    ] = "speclight.png",
    epoch: Annotated[
        str | None,
        typer.Option(
            "--epoch",
            help="Epoch of the chain figure: index or UTC time (default: brightest observable).",
        ),
    ] = None,
    band: Annotated[
        str | None, typer.Option("--band", help="Band of the radiance images (default: first).")
    ] = None,
    kind: Annotated[
        list[str] | None,
        typer.Option(
            "--kind",
            help="Figures to write: overview, chain, images, ranging (repeatable; default: all "
            "that the data can fill). OUTPUT is the first of them, the others go beside it.",
        ),
    ] = None,
    magnitude: Annotated[
        str,
        typer.Option(
            "--magnitude",
            help="Magnitudes of the overview: ab (at the aperture), exo (above the "
            "atmosphere), standard (above the atmosphere, at 1000 km) or vega (Vega V).",
        ),
    ] = "ab",
    force: Annotated[bool, typer.Option("--force", help="Overwrite existing figures.")] = False,
) -> None:
    """Plot a dataset: light curves, spectrogram and geometry in OUTPUT; the one-epoch chain,
    images and ranging figures beside it (OUTPUT-chain.png, ...). With --kind, OUTPUT holds
    the first figure asked for: `--kind chain -o chain.png` writes chain.png alone.

    OUTPUT is claimed as `simulate` claims its output; none of the figures may be DATASET.
    """

    def run() -> None:
        from speclight.io.output import FIELD, OutputClaim
        from speclight.plot import plot_files
        from speclight.plot.figures import KINDS, figure_paths

        chosen: int | str | None = epoch
        if epoch is not None and epoch.strip().lstrip("-").isdigit():
            chosen = int(epoch)
        kinds = kind or None
        with OutputClaim(output, force=force, inputs={"dataset": dataset}) as claim:
            for figure in figure_paths(claim.path, KINDS).values():
                if figure.exists() and figure.samefile(dataset):
                    raise InputError(
                        f"the figure {figure} would overwrite the dataset {dataset}; "
                        "choose another name",
                        field=FIELD,
                    )
            written = plot_files(
                dataset,
                claim.path,
                force=force,
                epoch=chosen,
                band=band,
                kinds=kinds,
                magnitude=magnitude,
            )
        for path in written:
            typer.echo(f"wrote {path}")

    _guarded(run)


def _measured_inputs(
    measured: Path, scenario: Path | None, endmembers: list[str] | None = None
) -> dict[str, Path | str]:
    """The input files of an estimation command, named for the output claim's checks."""
    inputs: dict[str, Path | str] = {"measured file": measured}
    if scenario is not None:
        inputs["scenario file"] = scenario
    for i, path in enumerate(endmembers or []):
        inputs[f"endmember file {i + 1}"] = path
    return inputs


def _optional_scenario(scenario: Path | None) -> Any:
    """The loaded scenario of an optional ``--scenario``, or None."""
    if scenario is None:
        return None
    from speclight.scenario import load_scenario

    return load_scenario(scenario)


@app.command()
def fit(
    scenario: Annotated[Path, typer.Argument(help="Scenario YAML file (the fit's start).")],
    measured: Annotated[
        Path, typer.Argument(help="Measured light curves: CSV (time, <band>...) or NetCDF.")
    ],
    output: Annotated[
        str, typer.Option("--output", "-o", metavar="FILE", help="Output FIT.json.")
    ] = "fit.json",
    free: Annotated[
        str, typer.Option("--free", help="Parameters to fit: albedo, roughness or both (a,b).")
    ] = "albedo",
    bin_s: Annotated[
        float | None, typer.Option("--bin-s", help="Average the measurements into S-second bins.")
    ] = None,
    plot_file: Annotated[
        str | None, typer.Option("--plot", metavar="FIG.png", help="Figure: rates and ratios.")
    ] = None,
    method: Annotated[
        str,
        typer.Option(
            "--method",
            help="Roughness fit: slsqp (central differences after a scan) or gradient "
            "(analytic derivatives; single-scattering render, beckmann/ggx materials).",
        ),
    ] = "slsqp",
    force: Annotated[bool, typer.Option("--force", help="Overwrite existing outputs.")] = False,
) -> None:
    """Fit per-band albedos (with --free albedo,roughness also the roughness of every rough
    material) so that the scenario's count rates match MEASURED; write FIT.json.

    The scenario is simulated at the measured epochs, starting from its own reflectance and
    roughness. Outputs are claimed as `simulate` claims its output. See docs/fit.md.
    """

    def run() -> None:
        from speclight.estimate.measured import read_measured
        from speclight.estimate.scenario_fit import fit_scenario, parse_free, parse_method
        from speclight.plot.figure_output import claim_outputs, write_outputs
        from speclight.scenario import load_scenario

        names = parse_free(free)
        chosen = parse_method(method)
        inputs = {"scenario file": scenario, "measurements": measured}
        with (
            claim_outputs(output, plot_file, force, inputs) as (claim, figure),
            _flag_names(bin_s="--bin-s"),
        ):
            result = fit_scenario(
                load_scenario(scenario), read_measured(measured), free=names, bin_s=bin_s,
                progress=sys.stderr.isatty(), method=chosen,
            )  # fmt: skip
            _raise_if_signalled()

            def draw() -> Any:
                from speclight.plot.fit_figure import fit_figure

                return fit_figure(
                    result.time_utc, result.measured_per_s, result.fitted_per_s, result.band_names
                )

            write_outputs(
                claim, (json.dumps(result.to_json(), indent=2) + "\n").encode(), figure, draw
            )
        if not result.converged:
            typer.echo(f"not converged: {result.message}", err=True)
        albedos = zip(result.band_names, result.albedo, strict=True)
        typer.echo("albedo: " + ", ".join(f"{b} {a:.4g}" for b, a in albedos))
        for name, (value, std) in result.roughness.items():
            spread = f"+- {std:.2g}" if std == std else "(not constrained)"  # NaN: unconstrained
            typer.echo(f"roughness {name}: {value:.4g} {spread}")
        typer.echo(f"wrote {output}" + (f" and {plot_file}" if plot_file else ""))

    _guarded(run)


@app.command()
def upsample(
    scenario: Annotated[Path, typer.Argument(help="Scenario YAML file: bands, optics, QE, grid.")],
    fit: Annotated[Path, typer.Argument(help="JSON with bands.BAND.albedo (`speclight fit`).")],
    output: Annotated[
        str, typer.Option("--output", "-o", metavar="FILE", help="Output CSV spectrum.")
    ] = "spectrum.csv",
    plot_file: Annotated[
        str | None, typer.Option("--plot", metavar="FIG", help="Figure (.png, .pdf, .svg).")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite existing outputs.")] = False,
) -> None:
    """Reflectance spectrum from band albedos: a sigmoid of a polynomial of order n-1 whose
    photon-weighted band averages (band x optics x QE) equal the albedos (paper eq. 3-4).

    Writes CSV wavelength_nm,reflectance on the scenario's wavelength grid.
    """

    def run() -> None:
        from speclight.estimate.upsample_io import read_fit_albedos, spectrum_csv
        from speclight.estimate.upsample_io import upsample_scenario as upsample_from
        from speclight.plot.figure_output import claim_outputs, write_outputs
        from speclight.scenario import load_scenario

        inputs = {"scenario file": scenario, "fit file": fit}
        with claim_outputs(output, plot_file, force, inputs) as (claim, figure):
            result = upsample_from(load_scenario(scenario), read_fit_albedos(fit), str(fit))

            def draw() -> Any:
                from speclight.plot.upsample_figure import upsample_figure

                return upsample_figure(result, scenario.stem)

            write_outputs(
                claim, spectrum_csv(result, str(scenario), str(fit)).encode(), figure, draw
            )
        if not result.spectrum.converged:
            typer.echo(
                "notice: the fit did not converge: the spectrum reproduces the albedos only to "
                f"{result.spectrum.max_band_error:.3g} (said in the CSV header)"
            )
        typer.echo(f"wrote {output}" + (f" and {plot_file}" if plot_file else ""))

    _guarded(run)


def _endmember_files(arguments: list[Path], endmembers: list[str] | None) -> list[str] | None:
    """``--endmembers E1.csv E2.csv ...``: the files after the first arrive as
    positional arguments after MEASURED; ``-e`` may also be repeated."""
    extra = [str(p) for p in arguments[1:]]
    if extra and not endmembers:
        raise InputError(
            f"unexpected argument(s) {' '.join(extra)}: give one MEASURED file (endmember "
            "files follow --endmembers)",
            field="MEASURED",
        )
    return None if not endmembers else [*endmembers, *extra]


@app.command()
def unmix(
    measured: Annotated[
        list[Path],
        typer.Argument(
            help="MEASURED first: a speclight NetCDF, or a CSV of count rates (with "
            "--scenario); any further arguments are more --endmembers files.",
            metavar="MEASURED [E2.csv ...]",
        ),
    ],
    endmembers: Annotated[
        list[str] | None,
        typer.Option(
            "--endmembers",
            "-e",
            metavar="FILE",
            help="Endmember spectrum CSV (wavelength_nm,reflectance; name = file stem); "
            "repeat for each, or 'scenario' for the scenario's materials.",
        ),
    ] = None,
    extract: Annotated[
        str | None,
        typer.Option("--extract", help="Extract endmembers from the data: atgp, pca or nfindr."),
    ] = None,
    n: Annotated[int | None, typer.Option("--n", help="Number of endmembers to extract.")] = None,
    method: Annotated[
        str, typer.Option("--method", help="ls, nnls, nnls-norm (default) or fcls.")
    ] = "nnls-norm",
    scenario: Annotated[
        Path | None,
        typer.Option(
            "--scenario",
            help="Scenario YAML (needed for a CSV; for a NetCDF default: the one it carries).",
        ),
    ] = None,
    bin_s: Annotated[
        float | None, typer.Option("--bin-s", help="Average epochs into bins of S seconds.")
    ] = None,
    source: Annotated[
        str | None,
        typer.Option(
            "--source",
            help="sun or laser: unmix the solar or the laser reflectance factors (default: "
            "the lasers' where the data have no solar ones).",
        ),
    ] = None,
    output: Annotated[
        str, typer.Option("--output", "-o", metavar="FILE", help="Output NetCDF (ABUND.nc).")
    ] = "abundance.nc",
    plot_file: Annotated[
        str | None, typer.Option("--plot", metavar="FIG", help="Figure (.png, .pdf, .svg).")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite existing outputs.")] = False,
) -> None:
    """Per-epoch material contributions from band reflectance factors: the linear mixing
    model x = S a (paper eq. 6) with endmember spectra (-e FILE ..., or -e scenario for the
    scenario's materials) or endmembers extracted from the data (--extract, --n). Spectra
    enter through band signatures weighted by the source at the aperture (Sun or lasers),
    per epoch. Writes ABUND.nc: abundance(time, endmember), residual(time),
    endmember_signature(endmember, band) and reflectance_factor(time, band); with ground
    truth in MEASURED, the confusion matrix.

    Example: speclight unmix out.nc -e gold.csv cell.csv paint.csv -o abund.nc --plot abund.png
    """

    def run() -> None:
        from speclight.estimate.unmix_io import check_unmix_options, unmix_measured
        from speclight.io.netcdf import dataset_bytes
        from speclight.plot.figure_output import claim_outputs, write_outputs

        members = _endmember_files(measured, endmembers)
        check_unmix_options(members, extract, n, method, source)
        inputs = _measured_inputs(measured[0], scenario, members)
        flags = _flag_names(bin_s="--bin-s")
        with claim_outputs(output, plot_file, force, inputs) as (claim, figure), flags:
            loaded = _optional_scenario(scenario)
            ds = unmix_measured(
                measured[0],
                endmembers=members,
                extract=extract,
                n=n,
                method=method,
                loaded=loaded,
                bin_s=bin_s,
                progress=sys.stderr.isatty(),
                light=source,
            )
            _raise_if_signalled()

            def draw() -> Any:
                from speclight.plot.unmix_figure import unmix_figure

                return unmix_figure(ds)

            write_outputs(claim, dataset_bytes(ds), figure, draw)
        if "mean_absolute_share_error" in ds.attrs:
            typer.echo(
                f"against the ground truth: mean absolute share error "
                f"{ds.attrs['mean_absolute_share_error']:.3f} (matched {ds.attrs['matching']})"
            )
        typer.echo(f"wrote {output}" + (f" and {plot_file}" if plot_file else ""))

    _guarded(run)


@app.command("reflection-map")
def reflection_map_cmd(
    measured: Annotated[
        list[Path],
        typer.Argument(
            help="MEASURED first: a speclight NetCDF, or a CSV of count rates (with "
            "--scenario); any further arguments are more --endmembers files.",
            metavar="MEASURED [E2.csv ...]",
        ),
    ],
    output: Annotated[
        str, typer.Option("--output", "-o", metavar="FILE", help="Output NetCDF (RMAP.nc).")
    ] = "reflection-map.nc",
    nside: Annotated[
        int, typer.Option("--nside", help="HEALPix resolution, a power of 2 (12 nside^2 pixels).")
    ] = 16,
    scenario: Annotated[
        Path | None,
        typer.Option(
            "--scenario",
            help="Scenario YAML: the geometry at the epochs of a CSV (or of a NetCDF without "
            "body-frame directions), the lasers' lines, -e scenario.",
        ),
    ] = None,
    source: Annotated[
        str | None,
        typer.Option(
            "--source",
            help="sun (map along the phase vector) or laser (coaxial lasers: along the "
            "observer direction); default: the lasers' where the data have no solar factors.",
        ),
    ] = None,
    endmembers: Annotated[
        list[str] | None,
        typer.Option(
            "--endmembers",
            "-e",
            metavar="FILE",
            help="Endmember spectrum CSV to unmix every pixel with (repeat for each), or "
            "'scenario' for the scenario's materials.",
        ),
    ] = None,
    method: Annotated[
        str, typer.Option("--method", help="Unmixing: ls, nnls, nnls-norm (default) or fcls.")
    ] = "nnls-norm",
    bin_s: Annotated[
        float | None, typer.Option("--bin-s", help="Average epochs into bins of S seconds.")
    ] = None,
    band: Annotated[
        str | None, typer.Option("--band", help="Band of the figure (default: most pixels).")
    ] = None,
    plot_file: Annotated[
        str | None, typer.Option("--plot", metavar="FIG", help="Figure (.png, .pdf, .svg).")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite existing outputs.")] = False,
) -> None:
    """Reflection map: each epoch's band reflectance factor placed on a HEALPix sphere (RING)
    in the body frame along its phase vector (the observer direction under coaxial lasers),
    averaged per pixel (Kucharski; paper section 5.3). Writes RMAP.nc:
    reflectance_factor(band, pixel), n_samples(pixel), range_offset(band, pixel) where the
    input has ranging, abundance(endmember, pixel) with --endmembers.

    Example: speclight reflection-map out.nc -o rmap.nc --nside 16 --plot rmap.png
    """

    def run() -> None:
        from speclight.estimate.reflection_map import check_nside
        from speclight.estimate.reflection_map_io import reflection_map_measured
        from speclight.estimate.source_spectrum import check_light
        from speclight.io.netcdf import dataset_bytes
        from speclight.plot.figure_output import claim_outputs, write_outputs

        members = _endmember_files(measured, endmembers)
        check_nside(nside)
        check_light(source)
        inputs = _measured_inputs(measured[0], scenario, members)
        flags = _flag_names(bin_s="--bin-s")
        with claim_outputs(output, plot_file, force, inputs) as (claim, figure), flags:
            loaded = _optional_scenario(scenario)
            ds = reflection_map_measured(
                measured[0],
                nside=nside,
                loaded=loaded,
                light=source,
                endmembers=members,
                method=method,
                bin_s=bin_s,
                progress=sys.stderr.isatty(),
            )
            _raise_if_signalled()

            def draw() -> Any:
                from speclight.plot.reflection_map_figure import reflection_map_figure

                return reflection_map_figure(ds, band)

            write_outputs(claim, dataset_bytes(ds), figure, draw)
        mapped = int((ds["n_samples"].values > 0).sum())
        typer.echo(
            f"{int(ds['n_samples'].values.sum())} epochs in {mapped} of "
            f"{ds.sizes['pixel']} pixels (nside {nside}, {ds.attrs['light']})"
        )
        typer.echo(f"wrote {output}" + (f" and {plot_file}" if plot_file else ""))

    _guarded(run)


def _phase_angles(text: str) -> list[float]:
    """``--phase-angles-deg 0,30,60,90``: comma-separated numbers."""
    try:
        return [float(x) for x in text.split(",") if x.strip()]
    except ValueError:
        raise InputError(
            f"--phase-angles-deg = {text!r} must be comma-separated numbers, e.g. 0,30,60,90",
            field="--phase-angles-deg",
        ) from None


@app.command("reflectivity-map")
def reflectivity_map(
    scenario: Annotated[
        Path, typer.Argument(help="Scenario YAML: target, materials, spectrum, render, bands.")
    ],
    output: Annotated[
        str, typer.Option("--output", "-o", metavar="MAP.zarr", help="Output Zarr store.")
    ] = "map.zarr",
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
    force: Annotated[bool, typer.Option("--force", help="Replace an existing store.")] = False,
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
        from speclight.estimate.reflectivity_map import check_map_options
        from speclight.estimate.reflectivity_map import reflectivity_map as build
        from speclight.scenario import load_scenario

        angles = _phase_angles(phase_angles_deg)
        check_map_options(directions, angles, rolls, chunk, workers)  # before loading
        result = build(
            load_scenario(scenario),
            output,
            directions=directions,
            phase_angles_deg=angles,
            rolls=rolls,
            chunk=chunk,
            force=force,
            progress=sys.stderr.isatty(),
            scheduler=scheduler,
            n_workers=workers,
            announce=True,
        )
        _raise_if_signalled()
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
            _fail(
                f"{len(result.failed)} chunk(s) failed (chunk {first[0]}: {first[1]}); "
                f"{output} is unfinished: rerun the same command to retry them",
                1,
            )
        typer.echo(f"wrote {output}")

    _guarded(run)


@app.command("spin-axis")
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
    output: Annotated[
        str, typer.Option("--output", "-o", metavar="FILE", help="Output NetCDF (AXIS.nc).")
    ] = "axis.nc",
    period_s: Annotated[
        float | None,
        typer.Option("--period-s", help="Rotation period [s] (default: the scenario's)."),
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
        bool,
        typer.Option("--free-period", help="Refine the period too, within --period-bound."),
    ] = False,
    period_bound: Annotated[
        float,
        typer.Option(
            "--period-bound", help="With --free-period: largest relative change of the period."
        ),
    ] = 0.05,
    source: Annotated[
        str | None,
        typer.Option(
            "--source",
            help="Light: sun or laser (coaxial, the map's phase-0 slice); default: what "
            "MEASURED has.",
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
    plot_file: Annotated[
        str | None, typer.Option("--plot", metavar="FIG", help="Figure (.png, .pdf, .svg).")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite existing outputs.")] = False,
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
        from speclight.estimate.source_spectrum import check_light
        from speclight.estimate.spin_axis import check_search_options
        from speclight.estimate.spin_axis_io import axis_dataset, spin_axis_measured
        from speclight.estimate.spin_axis_refine import check_refine_options
        from speclight.io.netcdf import dataset_bytes
        from speclight.plot.figure_output import claim_outputs, write_outputs
        from speclight.scenario import load_scenario

        flags = dict(
            grid_deg="--grid-deg", n_phases="--phases", period_s="--period-s", bands="--bands",
            refine_method="--refine", period_bound="--period-bound", y="MEASURED", bmap="--map",
            ranging_weight="--ranging-weight",
        )  # fmt: skip
        with _flag_names(**flags):
            check_search_options(grid_deg, phases)
            check_refine_options(refine_method, period_bound if free_period else None)
        check_light(source)
        names = [b.strip() for b in bands.split(",") if b.strip()] if bands else None
        inputs = {"scenario file": scenario, "measured file": measured, "map": map_file}
        with (
            claim_outputs(output, plot_file, force, inputs) as (claim, figure),
            _flag_names(**flags),
        ):
            loaded = load_scenario(scenario)
            result = spin_axis_measured(
                loaded,
                measured,
                map_file,
                period_s,
                grid_deg,
                phases,
                names,
                not no_refine,
                light=source,
                ranging_weight=ranging_weight,
                refine_method=refine_method,
                period_bound=period_bound if free_period else None,
            )
            ds = axis_dataset(result, str(map_file), str(scenario))
            _raise_if_signalled()

            def draw() -> Any:
                from speclight.plot.spin_axis_figure import spin_axis_figure

                return spin_axis_figure(ds)

            write_outputs(claim, dataset_bytes(ds), figure, draw)
        a = ds.attrs
        typer.echo(
            f"best axis RA {a['best_ra_deg']:.1f} Dec {a['best_dec_deg']:.1f} deg, phase "
            f"{a['best_phase_deg']:.1f} deg (misfit {a['best_error']:.4g}); mirror RA "
            f"{a['mirror_ra_deg']:.1f} Dec {a['mirror_dec_deg']:.1f} (misfit "
            f"{a['mirror_error']:.4g}); "
            + (
                f"refined RA {a['refined_ra_deg']:.2f} Dec {a['refined_dec_deg']:.2f} phase "
                f"{a['refined_phase_deg']:.1f} "
                + (f"period {a['refined_period_s']:.6g} s " if free_period else "")
                + f"by {a['refine_method']} with {a['refine_misfit_evaluations']} misfit and "
                f"{a['refine_gradient_evaluations']} gradient evaluations "
                if math.isfinite(float(a["refined_ra_deg"])) and not result.result.refine_note
                else f"refined RA {a['refined_ra_deg']:.2f} Dec {a['refined_dec_deg']:.2f}: "
                f"{result.result.refine_note} "
                if math.isfinite(float(a["refined_ra_deg"]))
                else "not refined (--no-refine) "
            )
            + f"({result.result.n_epochs} epochs, {result.light}, ranging weight "
            f"{result.ranging_weight:g}, {result.seconds:.1f} s)"
        )
        typer.echo(f"wrote {output}" + (f" and {plot_file}" if plot_file else ""))

    _guarded(run)


@app.command()
def period(
    measured: Annotated[
        Path, typer.Argument(help="Light curves: a speclight NetCDF or a CSV of count rates.")
    ],
    output: Annotated[
        str, typer.Option("--output", "-o", metavar="FILE", help="Output JSON (PERIOD.json).")
    ] = "period.json",
    scenario: Annotated[
        Path | None,
        typer.Option(
            "--scenario",
            help="Scenario YAML: geometry and spin axis for the synodic correction (for a "
            "NetCDF default: the one it carries).",
        ),
    ] = None,
    bands: Annotated[
        list[str] | None,
        typer.Option("--bands", help="Bands to use (repeatable; default: all)."),
    ] = None,
    min_period_s: Annotated[
        float | None,
        typer.Option("--min-period-s", help="Shortest period searched [s] (default 2 K dt)."),
    ] = None,
    max_period_s: Annotated[
        float | None,
        typer.Option("--max-period-s", help="Longest period searched [s] (default span/3)."),
    ] = None,
    harmonics: Annotated[
        int, typer.Option("--harmonics", help="Harmonics K of the periodogram's model.")
    ] = 2,
    bin_s: Annotated[
        float | None, typer.Option("--bin-s", help="Average epochs into bins of S seconds.")
    ] = None,
    draws: Annotated[
        int,
        typer.Option("--draws", help="Bootstrap draws for the false-alarm probability (1..10000)."),
    ] = 40,
    seed: Annotated[int, typer.Option("--seed", help="Seed of the bootstrap.")] = 0,
    if_symmetric: Annotated[
        str,
        typer.Option(
            "--if-symmetric",
            help="auto, double or keep: the rotation period when the halves of the 2P fold "
            "agree: double (the body looks alike after half a turn), keep, or auto (double "
            "when the light curve has one maximum per cycle); see docs/period.md.",
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
        typer.Option(
            "--source",
            help="sun (the count rates) or laser (a NetCDF's laser return rates, phase angle 0).",
        ),
    ] = "sun",
    plot_file: Annotated[
        str | None, typer.Option("--plot", metavar="FIG", help="Figure (.png, .pdf, .svg).")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite existing outputs.")] = False,
) -> None:
    """Rotation period from one or many bands: multi-band multi-harmonic Lomb-Scargle,
    bootstrap false-alarm probability, photometric or rotation period (the halves of the
    2P fold), synodic correction where the geometry is known. Writes PERIOD.json.

    Example: speclight period pass.nc -o period.json --plot period.png
    """

    def run() -> None:
        import json

        from speclight.estimate.period_decision import IfSymmetric
        from speclight.estimate.period_io import estimate_period
        from speclight.plot.figure_output import claim_outputs, write_outputs

        if if_symmetric not in ("auto", "double", "keep"):
            raise InputError(
                f"--if-symmetric = '{if_symmetric}' (choices: auto, double, keep)",
                field="--if-symmetric",
            )
        rule: IfSymmetric = (
            "double" if if_symmetric == "double" else "keep" if if_symmetric == "keep" else "auto"
        )
        inputs = _measured_inputs(measured, scenario)
        flags = _flag_names(
            min_period_s="--min-period-s", max_period_s="--max-period-s", draws="--draws",
            harmonics="--harmonics", seed="--seed", synodic="--synodic", bin_s="--bin-s",
        )  # fmt: skip
        with claim_outputs(output, plot_file, force, inputs) as (claim, figure), flags:
            loaded = _optional_scenario(scenario)
            result = estimate_period(
                measured,
                loaded=loaded,
                bands=bands,
                min_period_s=min_period_s,
                max_period_s=max_period_s,
                harmonics=harmonics,
                bin_s=bin_s,
                draws=draws,
                seed=seed,
                if_symmetric=rule,
                synodic=synodic,  # type: ignore[arg-type]  # checked by estimate_period
                source=source,
            )
            _raise_if_signalled()
            summary = result.to_json()

            def draw() -> Any:
                from speclight.plot.period_figure import period_figure

                return period_figure(result)

            write_outputs(claim, (json.dumps(summary, indent=2) + "\n").encode(), figure, draw)

        def shown(key: str, spec: str) -> str:  # null: not determined (PERIOD.json says)
            return "undetermined" if summary[key] is None else format(summary[key], spec)

        typer.echo(
            f"rotation period {shown('period_s', '.6g')} +- {shown('period_std_s', '.2g')} s "
            f"(photometric {shown('photometric_period_s', '.6g')} s, false-alarm probability "
            f"{shown('false_alarm_probability', '.2g')})"
        )
        typer.echo(f"wrote {output}" + (f" and {plot_file}" if plot_file else ""))

    _guarded(run)


@app.command()
def sweep(
    sweep_file: Annotated[
        Path, typer.Argument(metavar="SWEEP.yaml", help="Sweep file: base, vary, draws, seed.")
    ],
    output: Annotated[
        str, typer.Option("--output", "-o", metavar="RUNS.zarr", help="Output Zarr store.")
    ] = "runs.zarr",
    scheduler: Annotated[
        str,
        typer.Option(
            "--scheduler",
            metavar="ADDRESS",
            help="local (a Dask cluster on this machine), none (in this process) or the "
            "address of a running scheduler, tcp://HOST:PORT.",
        ),
    ] = "local",
    workers: Annotated[
        int | None, typer.Option("--workers", help="Workers of the local cluster (default: cores).")
    ] = None,
    spectra: Annotated[
        bool, typer.Option("--spectra", help="Store intensity and spectral flux too.")
    ] = False,
    append: Annotated[
        bool, typer.Option("--append", help="Add the cases after those of an existing store.")
    ] = False,
    force: Annotated[bool, typer.Option("--force", help="Replace an existing store.")] = False,
    quiet: Annotated[bool, typer.Option("--quiet", "-q", help="Print nothing but errors.")] = False,
) -> None:
    """Run many variants of a scenario (grids and seeded random draws of any of its fields)
    on a Dask cluster and store every case's light curves in one Zarr store with a `case`
    dimension (docs/sweep.md). Every case is validated before any runs. Rerunning the same
    command resumes an interrupted sweep (done cases are skipped, failed ones retried); a
    failed case is recorded in error(case) and the others go on (a warning says how many;
    exit code 0); exit code 1 when every case failed.

    Example: speclight sweep docs/examples/sweep-calsphere.yaml -o runs.zarr --workers 2
    """

    def run() -> None:
        import dataclasses

        from speclight.scale.sweep_cases import plan_sweep
        from speclight.scale.sweep_file import load_sweep
        from speclight.scale.sweep_run import run_sweep

        if workers is not None and workers < 1:
            raise InputError(f"--workers = {workers} must be >= 1", field="--workers")
        spec = load_sweep(sweep_file)
        if spectra and not spec.spectra:
            spec = dataclasses.replace(spec, spectra=True)
        plan = plan_sweep(spec)
        result = run_sweep(
            plan,
            output,
            scheduler=scheduler,
            n_workers=workers,
            force=force,
            append=append,
            progress=sys.stderr.isatty() and not quiet,
            announce=not quiet,
        )
        _raise_if_signalled()
        last = result.first_case + result.n_cases - 1
        if result.damaged:
            typer.echo(
                f"notice: {len(result.damaged)} case(s) marked done did not read back (case "
                f"{result.damaged[0]}: a file cut short): run again",
                err=True,
            )
        if not quiet:
            typer.echo(
                f"cases {result.first_case}..{last}: ran {result.ran}, skipped {result.skipped} "
                f"done before, in {result.seconds:.1f} s"
            )
        if result.failed:  # docs/sweep.md, "Failures": exit 1 if all failed, else 0
            index, message = next(iter(result.failed.items()))
            level = "error" if result.exit_code else "warning"
            typer.echo(
                f"{level}: {len(result.failed)} of {result.n_cases} case(s) failed (case {index}: "
                f"{message}); their rows are NaN and error(case) holds the message: rerun the "
                "same command to retry them",
                err=True,
            )
        if not quiet:
            typer.echo(f"wrote {output}")
        if result.exit_code:
            raise typer.Exit(result.exit_code)

    _guarded(run)


@app.command()
def compare(
    scenario: Annotated[
        Path, typer.Argument(help="Scenario YAML: target, attitude, orbit (or observed: true).")
    ],
    observations: Annotated[
        Path, typer.Argument(help="OBSERVATIONS CSV: time, site, magnitude, sigma, band.")
    ],
    output: Annotated[
        str, typer.Option("--output", "-o", metavar="FILE", help="Output NetCDF (CMP.nc).")
    ] = "compare.nc",
    plot_file: Annotated[
        str | None, typer.Option("--plot", metavar="FIG", help="Figure (.png, .pdf, .svg).")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite existing outputs.")] = False,
) -> None:
    """Simulate the scenario at every observed epoch and site (one run per site) and write
    observed, simulated and residual magnitudes with the geometry of each observation, and
    residual statistics (also printed). See docs/compare.md.

    Example: speclight compare calsphere.yaml observed.csv -o cmp.nc --plot cmp.png
    """

    def run() -> None:
        from speclight.estimate.compare import compare as run_compare
        from speclight.estimate.compare_stats import summary_lines
        from speclight.estimate.observations import read_observations
        from speclight.io.netcdf import dataset_bytes
        from speclight.plot.figure_output import claim_outputs, write_outputs
        from speclight.scenario import load_scenario

        inputs = {"scenario file": scenario, "observations file": observations}
        with claim_outputs(output, plot_file, force, inputs) as (claim, figure):
            result = run_compare(
                load_scenario(scenario), read_observations(observations), sys.stderr.isatty()
            )
            _raise_if_signalled()

            def draw() -> Any:
                from speclight.plot.compare_figure import compare_figure

                return compare_figure(result.dataset)

            write_outputs(claim, dataset_bytes(result.dataset), figure, draw)
        for line in [*result.notes, *summary_lines(result.dataset.attrs)]:
            typer.echo(line)
        typer.echo(f"wrote {output}" + (f" and {plot_file}" if plot_file else ""))

    _guarded(run)


@app.command("brdf-fit")
def brdf_fit(
    table: Annotated[
        str,
        typer.Argument(
            help="Measured in-plane BRDF table: a CSV (phi_i theta_i phi_o theta_o brdf, deg "
            "and sr-1) or a shipped table name."
        ),
    ],
    model: Annotated[
        str, typer.Option("--model", help="Analytic model: phong, abg, binomial or microfacet.")
    ],
    output: Annotated[
        str, typer.Option("--output", "-o", metavar="FILE", help="Material YAML.")
    ] = "material.yaml",
    distribution: Annotated[
        str, typer.Option("--distribution", help="microfacet: ggx or beckmann.")
    ] = "ggx",
    fresnel: Annotated[
        str, typer.Option("--fresnel", help="microfacet: schlick or exact (a dielectric).")
    ] = "schlick",
    min_brdf: Annotated[
        float,
        typer.Option("--min-brdf", help="Leave out samples at or below this BRDF [sr-1]."),
    ] = 0.0,
    plot_file: Annotated[
        str | None, typer.Option("--plot", metavar="FIG", help="Figure (.png, .pdf, .svg).")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite existing outputs.")] = False,
) -> None:
    """Fit an analytic BRDF model to a measured table in log space, print the residual per
    incidence angle and write the model as a material for a scenario's target.materials
    (its directional albedo held at most 1). See docs/brdf-models.md.

    Example: speclight brdf-fit starlink_v1p5_chassis_532nm --model binomial -o chassis.yaml
    """

    def run() -> None:
        from speclight.plot.figure_output import claim_outputs, write_outputs
        from speclight.target.brdf_fit.log_fit import fit_table_samples
        from speclight.target.brdf_fit.material_yaml import material_yaml, report_lines
        from speclight.target.brdf_samples import read_table_samples

        inputs = {"table": table} if Path(table).exists() else {}
        with claim_outputs(output, plot_file, force, inputs) as (claim, figure):
            samples = read_table_samples(table)
            flags = {
                "model": "--model",
                "distribution": "--distribution",
                "fresnel": "--fresnel",
                "min_brdf": "--min-brdf",
            }
            with _flag_names(**flags):
                fit = fit_table_samples(samples, model, distribution, fresnel, min_brdf)
            _raise_if_signalled()

            def draw() -> Any:
                from speclight.plot.brdf_fit_figure import brdf_fit_figure

                return brdf_fit_figure(samples, fit)

            write_outputs(claim, material_yaml(fit).encode(), figure, draw)
        for line in report_lines(fit):
            typer.echo(line)
        typer.echo(f"wrote {output}" + (f" and {plot_file}" if plot_file else ""))

    _guarded(run)


@app.command()
def passes(
    scenario: Annotated[Path, typer.Argument(help="Scenario YAML: its orbit and observer.")],
    output: Annotated[
        str | None,
        typer.Option("--output", "-o", metavar="FILE", help="Also write PASSES.csv or .json."),
    ] = None,
    start: Annotated[
        str | None,
        typer.Option(help="Search from this UTC time (ISO 8601); default the scenario's start."),
    ] = None,
    end: Annotated[
        str | None,
        typer.Option(help="Search until this UTC time (ISO 8601); default the scenario's stop."),
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite an existing output.")] = False,
) -> None:
    """Rise, culmination and set of every pass of the target above observer.min_elevation_deg,
    with the parts where it is sunlit, the sky is dark (the Sun at or below
    observer.max_sun_elevation_deg) and both (observable). See docs/passes.md.

    Example: speclight passes calsphere.yaml --start 2020-02-29T18:00Z --end 2020-03-01T06:00Z
    """

    def run() -> None:
        from speclight.io.output import OutputClaim
        from speclight.io.pass_table import check_passes_output, passes_file_bytes, print_passes
        from speclight.scenario import load_scenario
        from speclight.simulate.pass_search import parse_utc, scenario_passes

        start_utc = parse_utc(start, "--start") if start is not None else None
        end_utc = parse_utc(end, "--end") if end is not None else None
        if output is None:
            loaded = load_scenario(scenario)
            result = scenario_passes(loaded, start_utc, end_utc)
        else:
            suffix = check_passes_output(output)
            with OutputClaim(output, force=force, inputs={"scenario file": scenario}) as claim:
                loaded = load_scenario(scenario)
                result = scenario_passes(loaded, start_utc, end_utc)
                _raise_if_signalled()
                claim.write(passes_file_bytes(result, loaded.scenario.name, suffix))
        print_passes(result, f"passes of {loaded.scenario.name}")
        if output is not None:
            typer.echo(f"wrote {output}")

    _guarded(run)


@app.command()
def frames(
    dataset: Annotated[Path, typer.Argument(help="A dataset written by `speclight simulate`.")],
    output: Annotated[
        str, typer.Option("--output", "-o", metavar="DIR", help="Folder for the frames.")
    ] = "frames",
    imaging: Annotated[
        Path | None,
        typer.Option(
            "--imaging",
            metavar="FILE",
            help="YAML imaging section to use instead of the scenario's instrument.imaging.",
        ),
    ] = None,
    plot_file: Annotated[
        str | None,
        typer.Option("--plot", metavar="FIG", help="Figure of the first frames (.png, .pdf)."),
    ] = None,
    force: Annotated[
        bool, typer.Option("--force", help="Replace an earlier run's frames in DIR.")
    ] = False,
) -> None:
    """Detector frames of a simulated pass: FITS images with WCS (target streak or point,
    Hipparcos stars, sky, PSF, noise) and their truth (truth.json, frames.csv) in DIR.

    The camera is the scenario's instrument.imaging (or --imaging FILE). See docs/frames.md.

    Example: speclight frames pass.nc -o frames/ --plot frames.png
    """

    def run() -> None:
        from speclight.instrument.imaging import make_frame_files

        if plot_file is None:
            result = make_frame_files(dataset, output, imaging_file=imaging, force=force)
        else:
            from speclight.io.output import OutputClaim
            from speclight.plot.figure_output import FigureClaim, figure_format
            from speclight.plot.frames_figure import frames_figure

            fmt = figure_format(plot_file)
            with OutputClaim(plot_file, force=force, inputs={"dataset": dataset}) as claim:
                result = make_frame_files(dataset, output, imaging_file=imaging, force=force)
                _raise_if_signalled()
                FigureClaim(claim, fmt).write(frames_figure(result.frames, result.records))
        for note in result.notes:
            typer.echo(f"notice: {note}", err=True)
        typer.echo(
            f"wrote {len(result.records)} frames to {result.folder}"
            + (f" and {plot_file}" if plot_file else "")
        )

    _guarded(run)


@app.command()
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
    output: Annotated[
        str, typer.Option("--output", "-o", metavar="FILE", help="Output NetCDF (SHAPE.nc).")
    ] = "shape.nc",
    scenario: Annotated[
        Path | None,
        typer.Option(
            "--scenario",
            help="Scenario YAML: geometry and instrument (speclight "
            "input; a NetCDF's own by default).",
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
            help="Also fit torque-free (tumbling) states from "
            "this many random starts, the scenario's target as the EGI (0: off).",
        ),
    ] = 0,
    plot_file: Annotated[
        str | None, typer.Option("--plot", metavar="FIG", help="Figure (.png, .pdf, .svg).")
    ] = None,
    force: Annotated[bool, typer.Option("--force", help="Overwrite existing outputs.")] = False,
) -> None:
    """Convex shape (EGI), sidereal period and pole (ecliptic J2000) from light curves: period
    scan, pole map, Levenberg-Marquardt with analytic derivatives, uncertainties, the mirror
    pole; writes SHAPE.nc, SHAPE.obj beside it and the figure (docs/shape.md).

    Example: speclight shape asteroid.lc --format damit --period-range-h 5 8 -o shape.nc
    """

    def run() -> None:
        from speclight.estimate.shape.shape_files import shape_files
        from speclight.estimate.shape.shape_run import ShapeOptions

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
        ds, _ = shape_files(
            lc=lc,
            fmt=fmt,
            scenario=scenario,
            options=options,
            output=output,
            plot=plot_file,
            force=force,
            bands=names,
            tumbling_starts=tumbling_starts,
        )
        a = ds.attrs
        if "tumbling_families" in a:
            typer.echo(
                f"tumbling: {a['tumbling_families']} solution families (SHAPE.nc tumbling_*)"
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

    _guarded(run)


@app.command()
def info() -> None:
    """Versions of speclight and its engines, render variants, and data coverage."""

    def run() -> None:
        from speclight.info import info_report

        for section, entries in info_report().items():
            typer.echo(f"{section}:")
            width = max(len(k) for k in entries)
            for key, value in entries.items():
                typer.echo(f"  {key:<{width}}  {value}")

    _guarded(run)


@app.command("update-data")
def update_data(
    from_file: Annotated[
        Path | None,
        typer.Option("--from", metavar="FILE", help="Install this finals2000A.all (no network)."),
    ] = None,
    url: Annotated[
        str | None,
        typer.Option("--url", help="Download from here (default: the IERS Rapid Service)."),
    ] = None,
    timeout_s: Annotated[
        float, typer.Option("--timeout-s", help="Give up a download after this many seconds.")
    ] = 60.0,
) -> None:
    """Refresh the Earth-orientation and leap-second table (IERS finals2000A.all).

    Downloads it (or takes --from FILE), checks it and installs it in the user data folder
    ($SPECLIGHT_DATA_DIR, else ~/.local/share/speclight); runs use it from then on when it
    reaches further than the table shipped in skyfield-data. Nothing else downloads.
    """

    def run() -> None:
        from speclight.orbit.iers_update import DataUpdateError, update_from_file, update_from_url

        if from_file is not None and url is not None:
            raise InputError("give --from FILE or --url URL, not both", field="--from")
        if not 0 < timeout_s < float("inf"):
            raise InputError(f"--timeout-s = {timeout_s!r} must be > 0 s", field="--timeout-s")
        try:
            if from_file is not None:
                result = update_from_file(from_file)
            else:
                result = update_from_url(url, timeout_s)
        except DataUpdateError as exc:
            _fail(str(exc), 1)
        cov = result.coverage
        typer.echo(
            f"installed {result.installed} from {result.source}: Earth orientation measured "
            f"until {cov.measured_until}, predicted (and leap seconds known) until "
            f"{cov.predicted_until}"
        )
        if result.in_use != result.installed:
            typer.echo(f"notice: {result.in_use} reaches further and stays in use", err=True)

    _guarded(run)


def _one_line_notice(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    line: str | None = None,
) -> str:
    return f"notice: {message}\n"


#: Notices printed by this process: their text, or the category of those said once whatever
#: their text (the Earth-orientation table's).
_shown_notices: set[object] = set()


def _show_notice_once(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    file: Any = None,
    line: str | None = None,
) -> None:
    """Print a warning as a one-line notice, once per process (Python's own "once per
    place" starts over whenever a library changes the warning filters)."""
    from speclight.orbit.staleness import EarthOrientationWarning

    key = category if issubclass(category, EarthOrientationWarning) else (category, str(message))
    if key in _shown_notices:
        return
    _shown_notices.add(key)
    stream = sys.stderr if file is None else file
    try:
        stream.write(_one_line_notice(message, category, filename, lineno, line))
    except OSError:  # stderr closed: a notice is not worth failing for
        pass


def main() -> None:
    """Console-script entry point."""
    warnings.formatwarning = _one_line_notice  # fallbacks are notices, not tracebacks
    warnings.showwarning = _show_notice_once
    app(prog_name="speclight")


if __name__ == "__main__":
    main()
