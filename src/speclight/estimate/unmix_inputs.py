"""What ``speclight unmix`` reads: band reflectance factors and endmember signatures.

Band reflectance factors (eq. 5 of the reference paper, SPEC section 5), from

* a speclight NetCDF: its ``reflectance_factor(time, band)``; where the dataset also has
  ``count_rate_measured`` (noisy, as SPEC's MEASURED rule prefers), the factor of the
  measured rates, ``reflectance_factor x count_rate_measured / count_rate`` (eq. 5 is
  linear in the rate; NaN where ``count_rate`` is 0). Ground truth
  ``reflectance_factor_material(time, material, band)`` is kept where present;
* a CSV of count rates (:func:`speclight.estimate.read_measured`) with a scenario: the
  scenario is simulated at the measured epochs (:func:`speclight.simulate.simulate`) and the
  rates are turned into factors by :func:`speclight.instrument.reflectance_factor_m2_sr`
  with that simulation's range, solar irradiance x sunlit fraction x transmission and band
  responses, as ``speclight simulate`` does for its own rates.

Endmember signatures: reflectance spectra (CSV ``wavelength_nm,reflectance``, one material
per file, named by the file stem; or the scenario's materials) averaged over each band with
the photon weights of eq. 3 (:func:`speclight.estimate.upsampling.photon_weights`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.measured import MeasuredLightCurve, bin_light_curve, read_measured
from speclight.estimate.scenario_bands import BandResponses, dataset_band_responses
from speclight.estimate.upsampling import photon_weights

if TYPE_CHECKING:
    from speclight.scenario import LoadedScenario
    from speclight.target.materials import Material

F64 = NDArray[np.float64]
FIELD = "MEASURED"


@dataclass(frozen=True)
class ReflectanceFactors:
    """Band reflectance factors per epoch, with the bands that measured them.

    Attributes
    ----------
    time_utc
        (N,) epochs (UTC).
    factor
        (N, B) band reflectance factors [m2 sr-1]; NaN where unlit or unobservable.
    bands
        The band responses (band x optics x QE) on the wavelength grid.
    source
        What the factors were computed from, in words.
    material_contribution
        (N, M, B) ground truth: each material's part of ``factor`` [m2 sr-1], or None.
    material_names
        (M,) names of the ground-truth materials, or None.
    """

    time_utc: NDArray[np.datetime64]
    factor: F64
    bands: BandResponses
    source: str
    material_contribution: F64 | None = None
    material_names: list[str] | None = None


def _bin(time: NDArray[np.datetime64], values: F64, bin_s: float, src: str) -> tuple:
    """Average the rows of ``values`` (N, ...) into ``bin_s`` bins (bin_light_curve)."""
    flat = values.reshape(values.shape[0], -1)
    lc = MeasuredLightCurve(
        time, [str(i) for i in range(flat.shape[1])], flat, None, np.ones(time.size, np.int64), src
    )
    binned = bin_light_curve(lc, bin_s)
    return binned.time_utc, binned.rate_per_s.reshape((-1, *values.shape[1:]))


def read_reflectance_factors(
    path: str | Path,
    loaded: LoadedScenario | None = None,
    bin_s: float | None = None,
    progress: bool = False,
) -> ReflectanceFactors:
    """Band reflectance factors from a speclight NetCDF or a CSV of rates (module doc).

    Parameters
    ----------
    path
        MEASURED: a ``.nc`` dataset of ``speclight simulate`` or a CSV of count rates.
    loaded
        The scenario; required for a CSV (its bands, site, orbit and target are simulated at
        the measured epochs), ignored for a NetCDF.
    bin_s
        Average the epochs into bins of this many seconds (rates for a CSV, factors for a
        NetCDF), or None.
    progress
        Show the simulation's progress bar (CSV input).

    Raises
    ------
    InputError
        An unreadable file, a dataset without band reflectance factors, a CSV without a
        scenario, bands that do not match the scenario's, a bad ``bin_s``.
    """
    p = Path(path)
    src = str(p)
    if p.suffix.lower() not in (".nc", ".nc4", ".netcdf", ".h5"):
        if loaded is None:
            raise InputError(
                f"{src} is a CSV of count rates: give --scenario SCENARIO.yaml to turn them "
                "into reflectance factors (eq. 5 needs the geometry, Sun and instrument)",
                field="--scenario",
            )
        lc = read_measured(p)
        return _factors_from_rates(lc, loaded, bin_s, progress)
    read_measured(p)  # the file checks of every MEASURED reader (times, rates, sigmas)
    with xr.open_dataset(p, engine="h5netcdf") as ds:
        if "reflectance_factor" not in ds:
            raise InputError(
                "the dataset has no reflectance_factor(time, band) (simulate writes it for a "
                "sunlit target with bands); give a CSV of rates with --scenario instead",
                source=src,
                field=FIELD,
            )
        bands = dataset_band_responses(ds, src)
        factor = ds["reflectance_factor"].transpose("time", "band").values.astype(float)
        what = "reflectance_factor"
        if "count_rate_measured" in ds and "count_rate" in ds:
            rate = ds["count_rate"].transpose("time", "band").values.astype(float)
            measured = ds["count_rate_measured"].transpose("time", "band").values
            with np.errstate(invalid="ignore", divide="ignore"):
                factor = np.where(rate > 0, factor * measured / rate, np.nan)
            what = "reflectance_factor x count_rate_measured / count_rate (the noisy rates)"
        truth, names = None, None
        if "reflectance_factor_material" in ds:
            da = ds["reflectance_factor_material"].transpose("time", ..., "band")
            truth = da.values.astype(float)
            names = [str(m) for m in ds[da.dims[1]].values]
        time = ds["time"].values.astype("datetime64[ns]")
    if bin_s is not None:
        t0 = time
        time, factor = _bin(t0, factor, bin_s, src)
        if truth is not None:
            _, truth = _bin(t0, truth, bin_s, src)
    return ReflectanceFactors(time, factor, bands, f"{src}: {what}", truth, names)


def _factors_from_rates(
    lc: MeasuredLightCurve, loaded: LoadedScenario, bin_s: float | None, progress: bool
) -> ReflectanceFactors:
    from speclight import instrument
    from speclight.simulate import simulate

    names = [b.name for b in loaded.scenario.instrument.bands]
    lc = lc.select_bands(names)
    if bin_s is not None:
        lc = bin_light_curve(lc, bin_s)
    ds = simulate(loaded, progress=progress, time_utc=lc.time_utc).dataset
    bands = dataset_band_responses(ds, loaded.source)
    tel = loaded.scenario.telescope
    area = instrument.aperture_area_m2(tel.aperture_diameter_m, tel.obstruction_diameter_m)
    sunlit = ds["sunlit"].values if loaded.scenario.illumination.sun else np.zeros(lc.time_utc.size)
    light = ds["solar_irradiance"].values * sunlit[:, None] * ds["transmission"].values
    ones = np.ones(bands.wavelength_nm.size)
    factor = instrument.reflectance_factor_m2_sr(
        lc.rate_per_s,
        ds["range"].values,
        area,
        light,
        bands.wavelength_nm,
        ones,
        ones,
        bands.response,
    )
    return ReflectanceFactors(
        lc.time_utc, factor, bands, f"{lc.source}: count rates, scenario {loaded.source}"
    )


@dataclass(frozen=True)
class Endmembers:
    """Endmember reflectance spectra and their band signatures.

    Attributes
    ----------
    names
        (K,) endmember names.
    spectra
        (K, L) reflectance spectra on the bands' wavelength grid [1].
    signatures
        (K, B) photon-weighted band averages of the spectra (eq. 3) [1].
    """

    names: list[str]
    spectra: F64
    signatures: F64


def _signatures(names: list[str], spectra: F64, bands: BandResponses) -> Endmembers:
    weights = photon_weights(bands.response, bands.wavelength_nm)
    return Endmembers(names, spectra, spectra @ weights.T)


def endmembers_from_files(paths: list[str | Path], bands: BandResponses) -> Endmembers:
    """Endmembers from reflectance CSV files (``wavelength_nm,reflectance``), named by stem.

    Raises
    ------
    InputError
        A file that is not such a table (non-finite or negative values, values above 1, too
        few rows), one that does not cover the bands' wavelength grid, or two files with
        the same stem.
    """
    names = [Path(p).stem for p in paths]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise InputError(
            f"endmember name(s) {', '.join(twice)} given twice (names are the file stems)",
            field="--endmembers",
        )
    from speclight.target.reflectance import Reflectance

    spectra = [
        Reflectance.table_file(p, field="--endmembers").evaluate(bands.wavelength_nm) for p in paths
    ]
    return _signatures(names, np.array(spectra, dtype=float), bands)


def material_spectrum(material: Material, wavelength_nm: F64) -> F64:
    """A material's reflectance spectrum for unmixing [1] (L,).

    The normal-incidence reflectance (:meth:`Reflectance.evaluate`: the albedo of a
    Lambertian surface, the Fresnel reflectance of a conductor at normal incidence, a table);
    for ``plastic`` the diffuse base's reflectance (the coat's few-percent Fresnel
    reflection is left out: it is nearly grey and seen only in glints).
    """
    if material.bsdf == "plastic" and material.diffuse_reflectance is not None:
        return material.diffuse_reflectance.evaluate(wavelength_nm)
    return material.reflectance.evaluate(wavelength_nm)


def endmembers_from_scenario(loaded: LoadedScenario, bands: BandResponses) -> Endmembers:
    """The scenario's materials as endmembers; materials of identical spectrum are one
    endmember named by their names joined with ``,``.

    Raises
    ------
    InputError
        A scenario without a target.
    """
    from speclight.simulate.reflection import build_target

    if loaded.scenario.target is None:
        raise InputError("the scenario has no target materials", field="--endmembers")
    target = build_target(loaded)
    names: list[str] = []
    spectra: list[F64] = []
    for m in target.materials:
        spectrum = material_spectrum(m, bands.wavelength_nm)
        same = [i for i, s in enumerate(spectra) if np.array_equal(s, spectrum)]
        if same:
            names[same[0]] += f",{m.name}"
        else:
            names.append(m.name)
            spectra.append(spectrum)
    return _signatures(names, np.array(spectra, dtype=float), bands)
