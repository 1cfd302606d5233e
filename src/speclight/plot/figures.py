"""``speclight plot``: which figures a dataset gets, and writing them safely.

``plot_file(pass.nc, pass.png)`` writes the overview ``pass.png`` (light curves,
spectrogram, geometry: all on one UTC time axis) and, beside it, one file per other
figure the dataset can fill: ``pass-chain.png`` (one epoch through the radiometric
chain, on a wavelength axis), ``pass-images.png`` (saved images) and
``pass-ranging.png`` (range histograms and offsets). The file named always holds the
first figure written: with ``kinds=["chain"]`` the chain goes to ``pass.png`` itself.
Every file is rendered to a temporary name first and moved into place only when all
have rendered; none is written if any target exists and ``force`` is not set.

To add a figure, append a :class:`FigureKind` to :data:`FIGURES`.
"""

from __future__ import annotations

import os
import secrets
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import xarray as xr

from speclight.errors import InputError, did_you_mean
from speclight.io.output import OutputWriteError, create_new_file
from speclight.plot.chain import chain_figure
from speclight.plot.images import images_figure
from speclight.plot.lightcurve import MAGNITUDES
from speclight.plot.overview import overview_figure
from speclight.plot.ranging import has_ranging, ranging_figure
from speclight.plot.selection import (
    check_dataset,
    has_images,
    has_spectra,
    resolve_band,
    resolve_epoch,
)
from speclight.plot.style import DPI


@dataclass(frozen=True)
class Choices:
    """Resolved plot options: the epoch to follow and the band of the images."""

    epoch: int | None
    epoch_reason: str
    band: str | None
    epoch_given: bool = False
    magnitude: str = "ab"


@dataclass(frozen=True)
class FigureKind:
    """One figure: its name, file-name suffix, when it applies and how it is built."""

    name: str
    suffix: str
    applies: Callable[[xr.Dataset, Choices], bool]
    build: Callable[[xr.Dataset, Choices], Any]


FIGURES: tuple[FigureKind, ...] = (
    FigureKind(
        "overview", "", lambda ds, c: True, lambda ds, c: overview_figure(ds, c.epoch, c.magnitude)
    ),
    FigureKind(
        "chain",
        "-chain",
        lambda ds, c: has_spectra(ds) and c.epoch is not None,
        lambda ds, c: chain_figure(ds, c.epoch or 0, c.epoch_reason),
    ),
    FigureKind(
        "images", "-images", lambda ds, c: has_images(ds), lambda ds, c: images_figure(ds, c.band)
    ),
    FigureKind(
        "ranging",
        "-ranging",
        lambda ds, c: has_ranging(ds),
        lambda ds, c: ranging_figure(ds, c.epoch if c.epoch_given else None),
    ),
)
KINDS = tuple(f.name for f in FIGURES)


def _require_matplotlib() -> None:
    """An :class:`InputError` saying how to install matplotlib, before any work, if missing."""
    from speclight.engine_packages import require_engine

    require_engine("matplotlib", "plot", "drawing figures")


def _choices(
    ds: xr.Dataset, epoch: int | str | None, band: str | None, magnitude: str = "ab"
) -> Choices:
    index = resolve_epoch(ds, epoch)
    reason = "brightest observable epoch" if epoch is None else "chosen with --epoch"
    band = resolve_band(ds, band) if has_images(ds) else band
    if magnitude not in MAGNITUDES:
        raise InputError(
            f"--magnitude = '{magnitude}' (choices: {', '.join(MAGNITUDES)})", field="--magnitude"
        )
    name = MAGNITUDES[magnitude][0]
    if magnitude != "ab" and name not in ds:
        raise InputError(
            f"--magnitude {magnitude}: the dataset has no {name} (written by speclight "
            "0.1 since the CF/magnitudes update, and Vega V only where the grid covers V)",
            field="--magnitude",
        )
    return Choices(index, reason, band, epoch_given=epoch is not None, magnitude=magnitude)


def _kinds(kinds: Sequence[str] | None) -> list[FigureKind]:
    if kinds is None:
        return list(FIGURES)
    for k in kinds:
        if k not in KINDS:
            raise InputError(
                f"unknown figure {k!r}{did_you_mean(k, KINDS)} (choices: {', '.join(KINDS)})",
                field="--kind",
            )
    if not kinds:
        raise InputError(f"no figure asked for (choices: {', '.join(KINDS)})", field="--kind")
    return [f for f in FIGURES if f.name in kinds]


def figure_names(
    ds: xr.Dataset, *, epoch: int | str | None = None, band: str | None = None
) -> list[str]:
    """Names of the figures :func:`plot_files` writes for ``ds`` (main one first)."""
    check_dataset(ds)
    choices = _choices(ds, epoch, band)
    return [f.name for f in FIGURES if f.applies(ds, choices)]


def plot_dataset(ds: xr.Dataset, *, epoch: int | str | None = None) -> Any:
    """Build the overview figure of a dataset (a :class:`matplotlib.figure.Figure`).

    Parameters
    ----------
    ds
        A dataset written by ``speclight simulate``.
    epoch
        Epoch marked as the one followed through the chain: an index, a UTC time, or
        None for the brightest observable epoch.
    """
    _require_matplotlib()
    check_dataset(ds)
    return overview_figure(ds, resolve_epoch(ds, epoch))


def figure_paths(output: Path, names: Sequence[str]) -> dict[str, Path]:
    """File of each figure: ``output`` itself for the first of ``names``, and
    ``<stem><suffix><ext>`` beside it for the others (``pass-chain.png``...)."""
    by_name = {f.name: f for f in FIGURES}
    return {
        n: output
        if i == 0
        else output.with_name(f"{output.stem}{by_name[n].suffix}{output.suffix}")
        for i, n in enumerate(names)
    }


def _check_output(output: Path) -> None:
    from matplotlib.backend_bases import FigureCanvasBase

    formats = FigureCanvasBase.get_supported_filetypes()
    ext = output.suffix.lstrip(".").lower()
    if ext not in formats:
        raise InputError(
            f"cannot write a figure as {output.name!r}{did_you_mean(ext, formats)}; "
            f"use one of the extensions {', '.join(sorted(formats))}, e.g. pass.png",
            field="--output",
        )
    if not output.parent.is_dir():
        raise InputError(f"folder {output.parent} does not exist", field="--output")


def _load(dataset: Path) -> xr.Dataset:
    from speclight.io.user_dataset import read_user_dataset

    ds = read_user_dataset(dataset, None, what="dataset", require_time=False)
    check_dataset(ds, source=str(dataset))
    return ds


#: Why a dataset cannot fill a figure, and what gives it the data.
_MISSING = {
    "images": "has no saved images (a scenario saves them with render.save_images_at)",
    "ranging": "has no laser ranging (a scenario has it with illumination.lasers)",
}


def _refuse_missing(dataset: Path, ds: xr.Dataset, missing: list[str], choices: Choices) -> None:
    """An :class:`InputError` for figures asked for with ``--kind`` that ``ds`` cannot fill."""
    reasons = []
    for name in missing:
        if name != "chain":
            reasons.append(f"asked for {name}, but the dataset {_MISSING[name]}")
        elif not has_spectra(ds):
            reasons.append("asked for chain, but the dataset has no spectra (a run without target)")
        else:
            reasons.append("asked for chain, but no epoch is observable and sunlit; give --epoch")
    fillable = [f.name for f in FIGURES if f.applies(ds, choices)]
    raise InputError(
        f"{'; '.join(reasons)}; figures this dataset can fill: {', '.join(fillable)}",
        source=str(dataset),
        field="--kind",
    )


def plot_files(
    dataset: str | Path,
    output: str | Path,
    force: bool = False,
    *,
    epoch: int | str | None = None,
    band: str | None = None,
    kinds: Sequence[str] | None = None,
    dpi: int = DPI,
    magnitude: str = "ab",
) -> list[Path]:
    """Read a dataset file and write all its figures; returns the files, main one first.

    Parameters
    ----------
    dataset
        NetCDF file written by ``speclight simulate``.
    output
        Main figure file (``.png``, ``.pdf``, ``.svg``...): the first figure written (the
        overview, unless ``kinds`` leaves it out); the others go beside it as
        ``<stem>-chain``, ``<stem>-images``, ``<stem>-ranging`` with the same extension.
    force
        Overwrite existing files; otherwise an existing target is an error and nothing is
        written.
    epoch
        Epoch followed through the chain: index, UTC time (ISO 8601), or None for the
        brightest observable epoch.
    band
        Band of the radiance images (default: the first band; the whole wavelength grid
        when the dataset has no bands).
    kinds
        Figures to write (names in :data:`KINDS`, written in that order); None for all that
        apply. A figure asked for that the dataset cannot fill (images of a run that saved
        none...) is an error.
    dpi
        Resolution of raster formats [dots per inch].
    magnitude
        The overview's magnitudes: ``ab`` (at the aperture), ``exo`` (above the
        atmosphere), ``standard`` (above the atmosphere, at 1000 km) or ``vega`` (Vega V).

    Raises
    ------
    InputError
        Bad options or dataset, an existing figure without ``force``, or matplotlib not
        installed (checked first).
    OutputWriteError
        A figure could not be written (full disk...); none was written.
    """
    _require_matplotlib()
    dataset, output = Path(dataset), Path(output)
    _check_output(output)
    wanted = _kinds(kinds)
    ds = _load(dataset)
    choices = _choices(ds, epoch, band, magnitude)
    todo = [f for f in wanted if f.applies(ds, choices)]
    if kinds is not None and len(todo) < len(wanted):
        _refuse_missing(dataset, ds, [f.name for f in wanted if f not in todo], choices)
    paths = figure_paths(output, [f.name for f in todo])
    existing = [str(p) for p in paths.values() if p.exists()]
    if existing and not force:
        raise InputError(
            f"{', '.join(existing)} exist{'s' if len(existing) == 1 else ''}; "
            "choose another name or pass --force to overwrite",
            field="--output",
        )
    temporaries: list[tuple[Path, Path]] = []
    try:
        for kind in todo:
            target = paths[kind.name]
            fig = kind.build(ds, choices)
            temp = target.with_name(f".{target.name}.{secrets.token_hex(4)}{target.suffix}")
            try:
                fd = create_new_file(temp)  # mode 0666 less the umask, like any new file
                temporaries.append((temp, target))
                with os.fdopen(fd, "wb") as f:
                    fig.savefig(f, dpi=dpi, format=target.suffix.lstrip(".").lower())
            except OSError as exc:  # a full disk, a quota, an I/O error
                raise OutputWriteError(
                    f"cannot write {target}: {exc.strerror or exc}; no figure was written"
                ) from exc
        for temp, target in temporaries:
            os.replace(temp, target)
    finally:
        for temp, _ in temporaries:
            temp.unlink(missing_ok=True)
    return [paths[f.name] for f in todo]


def plot_file(
    dataset: str | Path,
    output: str | Path,
    force: bool = False,
    *,
    epoch: int | str | None = None,
    band: str | None = None,
    kinds: Sequence[str] | None = None,
    dpi: int = DPI,
) -> Path:
    """Read a dataset file and write its figures (see :func:`plot_files`).

    Returns
    -------
    Path
        The main figure file, ``output`` (the overview unless ``kinds`` leaves it out).
    """
    return plot_files(dataset, output, force, epoch=epoch, band=band, kinds=kinds, dpi=dpi)[0]
