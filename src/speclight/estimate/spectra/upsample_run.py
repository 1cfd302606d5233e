"""``speclight upsample``: band albedos from a FIT.json, a spectrum on the scenario's grid.

The albedos are read from ``bands.BAND.albedo`` of any JSON of that shape (``speclight fit``
writes one). They are upsampled (:func:`speclight.estimate.upsample`, the
reference paper's eq. 3-4) through the scenario's band responses: band curve x optics
transmission x detector QE
(:func:`speclight.estimate.inputs.band_responses.scenario_band_responses`).
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
from speclight.estimate.inputs.band_responses import BandResponses, scenario_band_responses
from speclight.estimate.spectra.upsampling import UpsampledSpectrum, photon_weights, upsample
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
    """

    spectrum: UpsampledSpectrum
    bands: BandResponses

    @property
    def band_centre_nm(self) -> np.ndarray:
        """Photon-weighted band centres ``sum w_j lambda`` [nm] (B,)."""
        w = photon_weights(self.bands.response, self.bands.wavelength_nm)
        return np.asarray(w @ self.bands.wavelength_nm)

    @property
    def band_width_nm(self) -> np.ndarray:
        """Photon-weighted band widths: twice the weighted standard deviation [nm] (B,)."""
        w = photon_weights(self.bands.response, self.bands.wavelength_nm)
        wl = self.bands.wavelength_nm
        var = w @ wl**2 - (w @ wl) ** 2
        return np.asarray(2.0 * np.sqrt(np.maximum(var, 0.0)))


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
    out: dict[str, float] = {}
    for name, entry in bands.items():
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


def upsample_scenario(
    loaded: LoadedScenario, albedos: dict[str, float], source: str = FIELD
) -> ScenarioSpectrum:
    """Upsample band albedos through the scenario's band responses (eq. 3-4).

    Parameters
    ----------
    loaded
        The scenario: its bands (with optics and QE) and wavelength grid.
    albedos
        ``{band: albedo}`` [1], exactly the scenario's bands (any order).
    source
        Where the albedos came from, for messages.

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
    return ScenarioSpectrum(upsample(rho, bands.response, bands.wavelength_nm), bands)


def spectrum_csv(result: ScenarioSpectrum, scenario_source: str, fit_source: str) -> str:
    """The CSV ``wavelength_nm,reflectance`` with ``#`` lines saying what it is."""
    s = result.spectrum
    state = "converged" if s.converged else "NOT converged (the spectrum is the best found)"
    albedos = ", ".join(
        f"{n}={a:.6g}" for n, a in zip(result.bands.band_names, s.albedo, strict=True)
    )
    lines = [
        "# reflectance spectrum upsampled from band albedos by speclight upsample",
        "# model: sigmoid of a polynomial of order n-1 (Jakob & Hanika 2019; Nussbaum et al. "
        "2022, eq. 3-4), photon-weighted band averages through band x optics x QE",
        f"# scenario: {scenario_source}",
        f"# albedos: {fit_source}: {albedos}",
        f"# fit: {state}; largest band error |fit - albedo| = {s.max_band_error:.3g}",
        "wavelength_nm,reflectance",
    ]
    lines += [f"{w:.6g},{r:.9f}" for w, r in zip(s.wavelength_nm, s.reflectance, strict=True)]
    return "\n".join(lines) + "\n"
