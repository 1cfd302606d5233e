"""Spectral efficiency curves of the instrument: optics transmission and detector QE.

A curve is given as a number (constant over wavelength), a table file (see
:mod:`speclight.instrument.tables` for the format and unit detection), inline
``(wavelength_nm, value)`` arrays, or the name of a shipped detector preset
(:data:`DETECTOR_PRESETS`). Tables are averaged over each wavelength bin of the grid
(piecewise-linear in between) and are 0 outside their wavelength range: a detector
datasheet that stops at 900 nm says nothing measured beyond it, and 0 is the safe choice
(no invented photons).
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError, did_you_mean
from speclight.instrument.tables import read_table, sort_unique, value_to_fraction, wavelength_to_nm
from speclight.wavelength_grid import bin_average, check_wavelength_grid


@dataclass(frozen=True)
class DetectorPreset:
    """A shipped efficiency curve: file in ``speclight/data/detectors`` and its units."""

    file: str
    value_scale: float  # multiply the file's values by this to get a fraction
    description: str


#: Shipped detector curves (see ``speclight/data/detectors/PROVENANCE.md``).
DETECTOR_PRESETS: dict[str, DetectorPreset] = {
    "hamamatsu-s13360-spad": DetectorPreset(
        "hamamatsu_S13360-6025CS_sipm_pde.csv",
        0.01,
        "Hamamatsu S13360-6025CS SiPM (SPAD array) photon detection efficiency, 279-897 nm",
    ),
    "hamamatsu-s10420-ccd": DetectorPreset(
        "hamamatsu_S10420-01_backthinned_CCD_QE.csv",
        1.0,
        "Hamamatsu S10420-01 back-thinned CCD quantum efficiency, 198-1197 nm",
    ),
    "sony-imx428-cmos": DetectorPreset(
        "sony_IMX428_mono_CMOS_QE_LUCID.csv",
        0.01,
        "Sony IMX428 monochrome CMOS quantum efficiency (LUCID), 319-1101 nm",
    ),
}

#: Folder of the shipped detector curves.
DATA_DIR = Path(__file__).resolve().parent.parent / "data" / "detectors"

CurveSpec = float | str | os.PathLike | tuple[ArrayLike, ArrayLike]


def load_preset(name: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Wavelength [nm] and efficiency [fraction] of a shipped detector preset.

    Data: manufacturer datasheet digitisations, see ``speclight/data/detectors/PROVENANCE.md``
    (Hamamatsu S13360-6025CS via petrstepanov/light-guides; Hamamatsu S10420-01 and Sony
    IMX428 via aphalo/photobiologySensors). Negative digitisation noise is clipped to 0.
    """
    key = name.strip().lower()
    if key not in DETECTOR_PRESETS:
        raise InputError(
            f"unknown detector preset {name!r}{did_you_mean(key, DETECTOR_PRESETS)} "
            f"(presets: {', '.join(DETECTOR_PRESETS)}; or give a table file path)",
            field="instrument.detector_qe",
        )
    preset = DETECTOR_PRESETS[key]
    path = DATA_DIR / preset.file
    _, data = read_table(str(path), "instrument.detector_qe")
    wl, value = sort_unique(data[:, 0], np.clip(data[:, 1] * preset.value_scale, 0.0, 1.0))
    return wl, value


def _looks_like_path(text: str) -> bool:
    return os.sep in text or "/" in text or Path(text).suffix != "" or Path(text).exists()


def spectral_curve(
    spec: CurveSpec, wavelength_nm: ArrayLike, field: str = "instrument.detector_qe"
) -> NDArray[np.float64]:
    """An efficiency curve on the wavelength grid.

    Parameters
    ----------
    spec
        A number in 0..1; a preset name (:data:`DETECTOR_PRESETS`, case-insensitive); a
        path to a CSV table (wavelength, value; units from the header or detected: um vs
        nm, percent vs fraction); or a ``(wavelength_nm, value)`` pair of arrays.
    wavelength_nm
        Grid (L,) [nm].
    field
        Scenario field named in error messages, e.g. ``instrument.optics_transmission``.

    Returns
    -------
    numpy.ndarray
        Bin-averaged efficiency (L,) [fraction]; 0 outside a table's wavelength range.
    """
    wl = check_wavelength_grid(wavelength_nm)
    if isinstance(spec, bool):
        raise InputError(f"{spec!r} is not an efficiency; give a number 0..1", field=field)
    if isinstance(spec, (int, float, np.floating, np.integer)):
        value = float(spec)
        if not (0.0 <= value <= 1.0):
            raise InputError(
                f"{spec!r} must be a fraction in 0..1 (write 0.85, not 85)", field=field
            )
        return np.full(wl.size, value)
    if isinstance(spec, tuple):
        x = np.asarray(spec[0], dtype=np.float64)
        y = value_to_fraction(np.asarray(spec[1], dtype=np.float64), "fraction", "inline", field)
        x, y = sort_unique(wavelength_to_nm(x, "wavelength_nm", "inline", field), y)
        return bin_average(x, y, wl, outside="zero")
    text = os.fspath(spec)
    if text.strip().lower() in DETECTOR_PRESETS:
        x, y = load_preset(text)
        return bin_average(x, y, wl, outside="zero")
    if not _looks_like_path(text):
        raise InputError(
            f"{text!r} is neither a number, a detector preset nor a table file"
            f"{did_you_mean(text.strip().lower(), DETECTOR_PRESETS)} "
            f"(presets: {', '.join(DETECTOR_PRESETS)}; a table path needs a suffix like .csv)",
            field=field,
        )
    header, data = read_table(text, field)
    if data.shape[1] != 2:
        raise InputError(
            f"an efficiency table needs exactly 2 columns (wavelength, value), found "
            f"{data.shape[1]}",
            source=text,
            field=field,
        )
    names: list[str | None] = list(header) if header else [None, None]
    x = wavelength_to_nm(data[:, 0], names[0], text, field)
    y = value_to_fraction(data[:, 1], names[1], text, field)
    x, y = sort_unique(x, y)
    return bin_average(x, y, wl, outside="zero")
