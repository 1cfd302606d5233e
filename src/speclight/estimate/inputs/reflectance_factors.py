"""What ``speclight unmix`` reads: band reflectance factors and the source spectrum.

Band reflectance factors (eq. 5 of the reference paper), from

* a speclight NetCDF. Under the Sun (``light="sun"``): its ``reflectance_factor(time,
  band)``; where the dataset also has ``count_rate_measured`` (noisy, as read_measured
  also prefers), the factor of the measured rates, ``reflectance_factor x
  count_rate_measured / count_rate`` (eq. 5 is linear in the rate; NaN where
  ``count_rate`` is 0). Under lasers (``light="laser"``): ``laser_reflectance_factor``.
  The default is the lasers where the dataset has laser factors and no finite solar ones
  (the Sun off), else the Sun. Ground truth ``reflectance_factor_material`` (or
  ``laser_reflectance_factor_material``) with the ``material_reflectance`` labels is kept
  where present;
* a CSV of count rates (:func:`speclight.estimate.read_measured`) with a scenario: the
  scenario is simulated at the measured epochs (:func:`speclight.simulation.simulate`) and the
  rates are turned into factors by :func:`speclight.instrument.reflectance_factor_m2_sr`
  with that simulation's range, source spectrum at the aperture and band responses, as
  ``speclight simulate`` does for its own rates (the Sun where the scenario has it on, else
  its lasers).

With them comes the source spectrum at the aperture of every epoch
(:mod:`speclight.estimate.inputs.source_spectrum`), which weights the endmembers' band signatures
(:mod:`speclight.estimate.spectra.endmember_spectra`).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.inputs.band_responses import BandResponses, dataset_band_responses
from speclight.estimate.inputs.cost_limits import check_bin_s
from speclight.estimate.inputs.measured import (
    NETCDF_VARIABLES,
    MeasuredLightCurve,
    bin_light_curve,
    measured_from_dataset,
    read_measured,
)
from speclight.estimate.inputs.measured_checks import check_rates, dataset_namers, no_usable_epochs
from speclight.estimate.inputs.source_spectrum import (
    Light,
    check_light,
    default_light,
    laser_source_W_m2_nm,
    sun_source_W_m2_nm,
)
from speclight.io.user_dataset import read_user_dataset, values

if TYPE_CHECKING:
    from speclight.scenario import LoadedScenario

F64 = NDArray[np.float64]
FIELD = "MEASURED"
#: What :func:`read_reflectance_factors` reads of a dataset (factors, band responses, the
#: source spectrum, ground truth), besides the rates of the MEASURED checks.
DATASET_VARIABLES = (
    *NETCDF_VARIABLES,
    "reflectance_factor",
    "reflectance_factor_material",
    "laser_reflectance_factor_material",
    "material_reflectance",
    "band_response",
    "optics_transmission",
    "detector_qe",
    "solar_irradiance",
    "transmission",
    "sunlit",
    "laser_irradiance",
)


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
    source_W_m2_nm
        (N, L) source spectrum at the aperture [W m-2 nm-1] (the Sun's or the lasers'), or
        None where unknown.
    light
        ``"sun"`` or ``"laser"``: which factors these are.
    material_labels
        (M,) the materials' reflectance labels (``material_reflectance``), or None.
    """

    time_utc: NDArray[np.datetime64]
    factor: F64
    bands: BandResponses
    source: str
    material_contribution: F64 | None = None
    material_names: list[str] | None = None
    source_W_m2_nm: F64 | None = None
    light: str = "sun"
    material_labels: list[str] | None = None


def bin_factors(time: NDArray[np.datetime64], values: F64, bin_s: float, src: str) -> tuple:
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
    *,
    bin_s: float | None = None,
    progress: bool = False,
    light: str | None = None,
) -> ReflectanceFactors:
    """Band reflectance factors from a speclight NetCDF or a CSV of rates (module doc).

    Parameters
    ----------
    path
        MEASURED: a ``.nc`` dataset of ``speclight simulate`` or a CSV of count rates.
    loaded
        The scenario; required for a CSV (its bands, site, orbit and target are simulated at
        the measured epochs). For a NetCDF under lasers it gives the lines (default: the
        scenario the dataset was simulated from, its ``scenario_yaml``).
    bin_s
        Average the epochs into bins of this many seconds (rates for a CSV, factors for a
        NetCDF), from 1 ns to less than the epochs' span
        (:func:`speclight.estimate.inputs.cost_limits.check_bin_s`), or None.
    progress
        Show the simulation's progress bar (CSV input).
    light
        ``"sun"`` or ``"laser"``: which factors to unmix; None: what the data have.

    Raises
    ------
    InputError
        An unreadable file, a dataset without band reflectance factors, a CSV without a
        scenario, bands that do not match the scenario's, a bad ``bin_s`` or ``light``.
    """
    check_light(light)
    p = Path(path)
    src = str(p)
    if p.suffix.lower() not in (".nc", ".nc4", ".netcdf", ".h5"):
        if loaded is None:
            raise InputError(
                f"{src} is a CSV of count rates: give loaded=SCENARIO to turn them "
                "into reflectance factors (eq. 5 needs the geometry, Sun and instrument)",
                field="loaded",
            )
        lc = read_measured(p)
        return _factors_from_rates(lc, loaded, bin_s, progress, light)
    ds = read_user_dataset(p, FIELD, what="measurements", variables=DATASET_VARIABLES)
    chosen: Light = default_light(ds) if light is None else light  # type: ignore[assignment]
    var = "laser_reflectance_factor" if chosen == "laser" else "reflectance_factor"
    if var not in ds:
        raise InputError(
            f"the dataset has no {var}(time, band) (simulate writes it for a "
            f"{'laser-lit' if chosen == 'laser' else 'sunlit'} target with bands); "
            "give a CSV of rates with loaded=SCENARIO instead",
            source=src,
            field=FIELD,
        )
    bands = dataset_band_responses(ds, src)
    factor = values(ds, var, ("time", "band"), src, FIELD)
    if not np.any(np.isfinite(factor)):
        other = "sun" if chosen == "laser" else "laser"
        raise InputError(
            f"{var} is NaN at every epoch (no {'laser' if chosen == 'laser' else 'Sun'} "
            f"light); try light='{other}'",
            source=src,
            field="light",
        )
    checked = measured_from_dataset(ds, src, chosen)  # the checks of every MEASURED reader
    row, column = dataset_namers(checked.time_utc, checked.band_names)
    check_rates(factor, row, column, src, FIELD, max_abs=None, what=var)
    what = var
    if chosen == "sun":
        source = sun_source_W_m2_nm(ds)
        if "count_rate_measured" in ds and "count_rate" in ds:
            rate = values(ds, "count_rate", ("time", "band"), src, FIELD)
            measured = values(ds, "count_rate_measured", ("time", "band"), src, FIELD)
            with np.errstate(invalid="ignore", divide="ignore"):
                factor = np.where(rate > 0, factor * measured / rate, np.nan)
            what = "reflectance_factor x count_rate_measured / count_rate (the noisy rates)"
    else:
        source = laser_source_W_m2_nm(ds, loaded or dataset_scenario(ds, src))
    truth, names, labels = None, None, None
    if f"{var}_material" in ds:
        da = ds[f"{var}_material"].transpose("time", ..., "band")
        truth = da.values.astype(float)
        names = [str(m) for m in ds[da.dims[1]].values]
        if "material_reflectance" in ds:
            labels = [str(m) for m in ds["material_reflectance"].values]
    time = checked.time_utc
    if bin_s is not None:
        check_bin_s(bin_s, time)
        t0 = time
        time, factor = bin_factors(t0, factor, bin_s, src)
        _, source = bin_factors(t0, source, bin_s, src)
        if truth is not None:
            _, truth = bin_factors(t0, truth, bin_s, src)
    return ReflectanceFactors(
        time, factor, bands, f"{src}: {what}", truth, names, source, chosen, labels
    )


def dataset_scenario(ds: xr.Dataset, src: str) -> LoadedScenario:
    """The scenario a simulate dataset was made from (its ``scenario_yaml`` attribute)."""
    if "scenario_yaml" not in ds.attrs:
        raise InputError(
            "the dataset does not carry its scenario (attribute scenario_yaml): give "
            "loaded=SCENARIO",
            source=src,
            field="loaded",
        )
    from speclight.scenario import parse_scenario

    return parse_scenario(str(ds.attrs["scenario_yaml"]), source=f"{src} (scenario_yaml)")


def _factors_from_rates(
    lc: MeasuredLightCurve,
    loaded: LoadedScenario,
    bin_s: float | None,
    progress: bool,
    light: str | None,
) -> ReflectanceFactors:
    from speclight import instrument
    from speclight.simulation import simulate

    names = [b.name for b in loaded.scenario.instrument.bands]
    lc = lc.select_bands(names)
    if bin_s is not None:
        check_bin_s(bin_s, lc.time_utc)
        lc = bin_light_curve(lc, bin_s)
    ds = simulate(loaded, progress=progress, time_utc=lc.time_utc).dataset
    bands = dataset_band_responses(ds, loaded.source)
    tel = loaded.scenario.telescope
    area = instrument.aperture_area_m2(tel.aperture_diameter_m, tel.obstruction_diameter_m)
    if light is None:
        light = "sun" if loaded.scenario.illumination.sun else "laser"
    if light == "sun":
        if not loaded.scenario.illumination.sun:
            raise InputError("light='sun' but the scenario has the Sun off", field="light")
        source = sun_source_W_m2_nm(ds)
    else:
        source = laser_source_W_m2_nm(ds, loaded)
    ones = np.ones(bands.wavelength_nm.size)
    factor = instrument.reflectance_factor_m2_sr(
        lc.rate_per_s,
        ds["range"].values,
        area,
        source,
        bands.wavelength_nm,
        ones,
        ones,
        bands.response,
    )
    if not np.any(np.isfinite(factor)):
        raise no_usable_epochs(lc.time_utc.size, loaded.source, lc.source)
    return ReflectanceFactors(
        lc.time_utc,
        factor,
        bands,
        f"{lc.source}: count rates ({light}), scenario {loaded.source}",
        source_W_m2_nm=source,
        light=light,
    )
