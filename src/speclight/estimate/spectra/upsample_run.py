"""``speclight upsample``: band albedos from a FIT.json, a spectrum on the scenario's grid.

The albedos are read from ``bands.BAND.albedo`` of any JSON of that shape (``speclight fit``
writes one). They are upsampled (:func:`speclight.estimate.upsample`, the
reference paper's eq. 3-4) through the scenario's band responses: band curve x optics
transmission x detector QE
(:func:`speclight.estimate.inputs.band_responses.scenario_band_responses`), with the band
averages weighted as the measurement weighs them: by the mean Sun at the aperture over the
scenario's pass (:mod:`speclight.estimate.inputs.band_albedo`, the definition ``fit``'s albedos
share). ``bands.BAND.albedo_std`` (where the JSON has it; ``null``: not constrained) gives
the spectrum's standard deviation per wavelength.
"""

from __future__ import annotations

import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from speclight.errors import InputError, did_you_mean
from speclight.estimate.inputs.band_albedo import scenario_mean_source_W_m2_nm
from speclight.estimate.inputs.band_responses import BandResponses, scenario_band_responses
from speclight.estimate.spectra.upsampling import (
    NOISE_DRAWS,
    UpsampledSpectrum,
    photon_weights,
    upsample,
)
from speclight.input_files import read_user_text

if TYPE_CHECKING:
    from speclight.scenario import LoadedScenario

FIELD = "FIT.json"


@dataclass(frozen=True)
class ScenarioSpectrum:
    """A spectrum upsampled through a scenario's bands.

    Attributes
    ----------
    spectrum
        The upsampled spectrum (its ``albedo`` in the order of ``bands.band_names``).
    bands
        The scenario's band responses used.
    source_W_m2_nm
        The mean Sun at the aperture over the pass (L,) [W m-2 nm-1] that weighted the band
        averages; None: a flat source (no Sun in the scenario, or no lit observable epoch).
    """

    spectrum: UpsampledSpectrum
    bands: BandResponses
    source_W_m2_nm: np.ndarray | None = None

    @property
    def weights(self) -> np.ndarray:
        """The band averages' weights (B, L) [1] (rows sum to 1)."""
        return photon_weights(self.bands.response, self.bands.wavelength_nm, self.source_W_m2_nm)

    @property
    def band_centre_nm(self) -> np.ndarray:
        """Band centres ``sum w_j lambda`` [nm] (B,) with the band averages' weights."""
        return np.asarray(self.weights @ self.bands.wavelength_nm)

    @property
    def band_width_nm(self) -> np.ndarray:
        """Band widths: twice the weighted standard deviation [nm] (B,)."""
        w = self.weights
        wl = self.bands.wavelength_nm
        var = w @ wl**2 - (w @ wl) ** 2
        return np.asarray(2.0 * np.sqrt(np.maximum(var, 0.0)))


def _fit_bands(path: str | Path) -> dict[str, object]:
    """The ``bands`` mapping of a JSON file (``speclight fit``'s), checked to exist."""
    src = str(path)
    text = read_user_text(Path(path), FIELD, what="fit results")
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise InputError(f"not JSON: {exc}", source=src, field=FIELD) from None
    except RecursionError:
        raise InputError(
            "not a fit result: its lists or objects are nested deeper than Python's JSON "
            f"reader goes ({sys.getrecursionlimit()} levels)",
            source=src,
            field=FIELD,
        ) from None
    except ValueError:  # an integer of more digits than int() converts
        raise InputError(
            "not a fit result: it holds an integer of more than "
            f"{sys.get_int_max_str_digits()} digits",
            source=src,
            field=FIELD,
        ) from None
    bands = data.get("bands") if isinstance(data, dict) else None
    if not isinstance(bands, dict) or not bands:
        raise InputError(
            'no "bands" mapping; expected {"bands": {BAND: {"albedo": ...}, ...}} as '
            "`speclight fit` writes",
            source=src,
            field=FIELD,
        )
    return bands


def read_fit_albedos(path: str | Path) -> dict[str, float]:
    """``{band: albedo}`` from ``bands.BAND.albedo`` of a JSON file (``speclight fit``'s).

    Raises
    ------
    InputError
        If the file is not JSON (or nested too deep, or holds an integer of more digits than
        Python converts), has no ``bands`` mapping, or a band lacks a numeric ``albedo`` in
        (0, 1].
    """
    src = str(path)
    out: dict[str, float] = {}
    for name, entry in _fit_bands(path).items():
        value = entry.get("albedo") if isinstance(entry, dict) else None
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            raise InputError(
                f"bands.{name}.albedo = {value!r} must be a number in (0, 1]",
                source=src,
                field=FIELD,
            )
        if not (math.isfinite(value) and 0.0 < value <= 1.0):
            raise InputError(
                f"bands.{name}.albedo = {value!r} must be in (0, 1] (a reflectance; 0 and "
                "NaN have no sigmoid-polynomial spectrum)",
                source=src,
                field=FIELD,
            )
        out[str(name)] = float(value)
    return out


def read_fit_albedo_std(path: str | Path) -> dict[str, float] | None:
    """``{band: albedo_std}`` [1] from ``bands.BAND.albedo_std`` of a JSON file, ``inf`` where
    it is ``null`` (``speclight fit``: not constrained); None where no band has one.

    Raises
    ------
    InputError
        As :func:`read_fit_albedos`, or an ``albedo_std`` that is not a number >= 0 or null.
    """
    bands = _fit_bands(path)
    if not any(isinstance(e, dict) and "albedo_std" in e for e in bands.values()):
        return None
    out: dict[str, float] = {}
    for name, entry in bands.items():
        value = entry.get("albedo_std", None) if isinstance(entry, dict) else None
        if value is None:
            out[str(name)] = math.inf
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not value >= 0:
            raise InputError(
                f"bands.{name}.albedo_std = {value!r} must be a number >= 0 (or null: not "
                "constrained)",
                source=str(path),
                field=FIELD,
            )
        out[str(name)] = float(value)
    return out


def upsample_scenario(
    loaded: LoadedScenario,
    albedos: dict[str, float],
    source: str = FIELD,
    albedo_std: dict[str, float] | None = None,
) -> ScenarioSpectrum:
    """Upsample band albedos through the scenario's band responses (eq. 3-4), the band
    averages weighted by the mean Sun at the aperture over the scenario's pass.

    Parameters
    ----------
    loaded
        The scenario: its bands (with optics and QE), wavelength grid and pass.
    albedos
        ``{band: albedo}`` [1], exactly the scenario's bands (any order).
    source
        Where the albedos came from, for messages.
    albedo_std
        ``{band: standard deviation}`` [1] of the albedos (``inf``: not constrained), or
        None: no ``reflectance_std``.

    Raises
    ------
    InputError
        A band of ``albedos`` that the scenario lacks, or a scenario band that ``albedos``
        lacks (with a did-you-mean), or an albedo outside (0, 1].
    """
    bands = scenario_band_responses(loaded)
    names = bands.band_names
    for name in albedos:
        if name not in names:
            raise InputError(
                f"band '{name}' is not a band of the scenario{did_you_mean(name, names)} "
                f"(scenario bands: {', '.join(names)})",
                source=source,
                field=FIELD,
            )
    missing = [n for n in names if n not in albedos]
    if missing:
        hint = did_you_mean(missing[0], [a for a in albedos if a not in names])
        raise InputError(
            f"no albedo for the scenario band(s) {', '.join(missing)}{hint}; give one per "
            f"scenario band ({', '.join(names)})",
            source=source,
            field=FIELD,
        )
    rho = np.array([albedos[n] for n in names], dtype=float)
    bad = np.flatnonzero(~((rho > 0) & (rho <= 1)))
    if bad.size:
        raise InputError(
            f"albedo of band '{names[bad[0]]}' = {rho[bad[0]]!r} must be in (0, 1]",
            source=source,
            field=FIELD,
        )
    std = None if albedo_std is None else np.array([albedo_std.get(n, np.inf) for n in names])
    sun = scenario_mean_source_W_m2_nm(loaded)
    spectrum = upsample(
        rho, bands.response, bands.wavelength_nm, source_W_m2_nm=sun, albedo_std=std
    )
    return ScenarioSpectrum(spectrum, bands, sun)


#: Wavelengths where the bands' summed photon weight is below this fraction of its peak
#: are extrapolated (no band sees them).
MEASURED_WEIGHT_FRACTION = 0.01


def measured_range_nm(result: ScenarioSpectrum) -> tuple[float, float]:
    """First and last wavelength [nm] where the bands' summed photon weight (each band's
    normalised to one) reaches ``MEASURED_WEIGHT_FRACTION`` of its peak."""
    wl = result.bands.wavelength_nm
    total = result.weights.sum(axis=0)
    seen = np.flatnonzero(total >= MEASURED_WEIGHT_FRACTION * total.max())
    return float(wl[seen[0]]), float(wl[seen[-1]])


def spectrum_csv(result: ScenarioSpectrum, scenario_source: str, fit_source: str) -> str:
    """The CSV ``wavelength_nm,reflectance[,reflectance_std]`` with ``#`` lines saying what
    it is (``reflectance_std`` where the albedos came with standard deviations)."""
    s = result.spectrum
    state = (
        "converged (the band albedos are reproduced)"
        if s.converged
        else "NOT converged (the spectrum is the best found)"
    )
    low, high = measured_range_nm(result)
    albedos = ", ".join(
        f"{n}={a:.6g}" for n, a in zip(result.bands.band_names, s.albedo, strict=True)
    )
    weighting = (
        "the band albedos are averages weighted by the detected photons of the mean Sun at the "
        "aperture over the scenario's pass (Sun x atmosphere x band x optics x QE x "
        "wavelength), as speclight fit's"
        if result.source_W_m2_nm is not None
        else "the band albedos are photon-weighted averages with a flat source (band x optics "
        "x QE x wavelength): the scenario has no Sun or no lit observable epoch"
    )
    if s.reflectance_std is None:
        spread = "reflectance_std: none (the albedos came without albedo_std)"
    else:
        spread = (
            f"reflectance_std: the spread of the spectra upsampled from {NOISE_DRAWS} albedo "
            "sets drawn with the albedos' standard deviations (inf where a band is not "
            "constrained); it is the spread over the albedos' noise, not the error between "
            "the bands"
        )
    lines = [
        "# reflectance spectrum upsampled from band albedos by speclight upsample",
        "# model: sigmoid of a polynomial of order n-1 (Jakob & Hanika 2019; Nussbaum et al. "
        "2022, eq. 3-4)",
        f"# weighting: {weighting}",
        f"# scenario: {scenario_source}",
        f"# albedos: {fit_source}: {albedos}",
        f"# fit: {state}; largest band error |fit - albedo| = {s.max_band_error:.3g}",
        f"# underdetermined: {len(s.albedo)} band albedos fix {len(s.albedo)} numbers of the "
        "spectrum; between them it is the smoothest sigmoid polynomial through them, not a "
        "measurement (its shape error is not bounded by the albedos' errors)",
        f"# measured range: {low:.6g}-{high:.6g} nm (where the bands' summed weight "
        f"reaches {100 * MEASURED_WEIGHT_FRACTION:g} % of its peak); the spectrum outside it is "
        "extrapolated",
        f"# {spread}",
    ]
    if s.reflectance_std is None:
        lines.append("wavelength_nm,reflectance")
        lines += [f"{w:.6g},{r:.9f}" for w, r in zip(s.wavelength_nm, s.reflectance, strict=True)]
    else:
        lines.append("wavelength_nm,reflectance,reflectance_std")
        lines += [
            f"{w:.6g},{r:.9f},{e:.6g}"
            for w, r, e in zip(s.wavelength_nm, s.reflectance, s.reflectance_std, strict=True)
        ]
    return "\n".join(lines) + "\n"
