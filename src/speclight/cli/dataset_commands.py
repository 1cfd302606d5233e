"""Commands that draw from a simulated dataset: ``plot`` (speclight.plot) and ``frames``
(speclight.instrument.imaging)."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from speclight.cli.guard import guarded, raise_if_signalled
from speclight.cli.options import force_option, output_option, plot_option
from speclight.errors import InputError

#: The DATASET argument of the commands that read a simulated dataset.
Dataset = Annotated[Path, typer.Argument(help="A dataset written by `speclight simulate`.")]


def plot(
    dataset: Dataset,
    output: Annotated[str, output_option("FILE", "Figure file (.png, .pdf).")] = "speclight.png",
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
    force: Annotated[bool, force_option("Overwrite existing figures.")] = False,
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

    guarded(run)


def frames(
    dataset: Dataset,
    output: Annotated[str, output_option("DIR", "Folder for the frames.")] = "frames",
    imaging: Annotated[
        Path | None,
        typer.Option(
            "--imaging",
            metavar="FILE",
            help="YAML imaging section to use instead of the scenario's instrument.imaging.",
        ),
    ] = None,
    plot_file: Annotated[
        str | None, plot_option("Figure of the first frames (.png, .pdf).")
    ] = None,
    force: Annotated[bool, force_option("Replace an earlier run's frames in DIR.")] = False,
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
                raise_if_signalled()
                FigureClaim(claim, fmt).write(frames_figure(result.frames, result.records))
        for note in result.notes:
            typer.echo(f"notice: {note}", err=True)
        typer.echo(
            f"wrote {len(result.records)} frames to {result.folder}"
            + (f" and {plot_file}" if plot_file else "")
        )

    guarded(run)
