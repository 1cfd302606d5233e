"""Measured light curves in: a CSV of count rates per band, or a speclight NetCDF dataset.

CSV (:mod:`.measured_csv`): a ``time`` column (ISO 8601 UTC), then count rates [s-1] per
band named exactly as the scenario's bands, optionally ``<band>_sigma`` columns (the rates'
standard deviations [s-1]); ``#`` lines are comments. NetCDF: a speclight dataset (read by
:func:`speclight.io.user_dataset.read_user_dataset`, which refuses damaged files, other
dimensions and times without CF units); its ``count_rate_measured`` is used where present,
else ``count_rate``, and ``count_rate_sigma`` where present; with ``source="laser"`` its
laser reflectance factors per band, ``laser_reflectance_factor`` (the returns normalised by
the range and the laser irradiance, which the returns fall with as ``range^-4``; the Sun's
light left out, as a range-gated detector sees it), with the shot noise of ``return_rate``
over one epoch spacing as sigma.

What is refused (an :class:`~speclight.errors.InputError` naming the file and line or
time index, the column or band and the value) and what is kept:

* unreadable files, a missing ``time`` column, an empty or repeated column name, a
  ``_sigma`` column of no band, a row with fewer cells than the header or a value in a
  column without a name, unparseable numbers or times, a time with another UTC offset,
  duplicate times (NetCDF: unsorted ones too): refused; CSV rows out of time order are
  sorted, with a notice;
* epochs outside the Sun ephemeris, infinite, subnormal or huge rates, sigmas that are
  not above 0, below the rate's rounding or huge, a band without any rate above 0:
  refused (:mod:`.measured_checks` says why each);
* a column that is not a band of the scenario, where a scenario gives the bands (``fit``,
  ``unmix``, ``reflection-map``, ``spin-axis``): refused by
  :meth:`MeasuredLightCurve.select_bands` (extra bands of a NetCDF are ignored);
* an empty cell or ``nan``: kept as NaN (no measurement of that band at that epoch; fits
  skip it);
* negative rates: kept. Measured rates are background-subtracted (as speclight's own
  ``count_rate_measured``), so noise makes faint epochs negative.

:func:`bin_light_curve` averages a fast detector (a SPAD at 1 kHz) to a slower cadence (a
camera's exposures), as the reference paper did (Nussbaum et al. 2022, section 4).
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError, did_you_mean
from speclight.estimate.inputs.measured_checks import (
    MAX_RATE_PER_S,
    check_epochs,
    check_order,
    check_rates,
    check_sigmas,
    check_signal,
    dataset_namers,
)
from speclight.estimate.inputs.measured_csv import read_csv_columns

if TYPE_CHECKING:
    import xarray as xr

F64 = NDArray[np.float64]
FIELD = "MEASURED"


@dataclass
class MeasuredLightCurve:
    """Count rates per band at the measured epochs.

    Attributes
    ----------
    time_utc
        (N,) epochs, UTC ``datetime64[ns]``, strictly increasing.
    band_names
        (B,) band names, as in the scenario.
    rate_per_s
        (N, B) count rates [s-1] (NaN: no measurement).
    sigma_per_s
        (N, B) their standard deviations [s-1], or ``None`` when the file gives none (a fit
        then uses the shot noise of the rates).
    n_samples
        (N,) measurements averaged into each epoch (1 unless binned).
    source
        Where the data came from (a file name).
    extra_bands_refused
        Whether :meth:`select_bands` refuses bands that it is not asked for (a CSV's columns
        are all the user's; a NetCDF holds every band of its scenario).
    """

    time_utc: NDArray[np.datetime64]
    band_names: list[str]
    rate_per_s: F64
    sigma_per_s: F64 | None
    n_samples: NDArray[np.int64]
    source: str
    extra_bands_refused: bool = False

    def select_bands(self, band_names: list[str], *, subset: bool = False) -> MeasuredLightCurve:
        """The same light curve with its bands in the order of ``band_names`` (e.g. the
        scenario's), checked: a band that is not measured is an error with a did-you-mean,
        and so is a measured band that is not asked for where ``extra_bands_refused`` (a CSV
        column that is no band of the scenario), unless ``subset`` (a choice of bands)."""
        index = []
        for name in band_names:
            if name not in self.band_names:
                raise InputError(
                    f"band '{name}' of the scenario is not in the measurements"
                    f"{did_you_mean(name, self.band_names)} (measured: "
                    f"{', '.join(self.band_names)})",
                    source=self.source,
                    field=FIELD,
                )
            index.append(self.band_names.index(name))
        if self.extra_bands_refused and not subset:
            extra = [b for b in self.band_names if b not in band_names]
            if extra:
                raise InputError(
                    f"column '{extra[0]}' is not a band of the scenario"
                    f"{did_you_mean(extra[0], band_names)} (bands: {', '.join(band_names)}); "
                    "give one column per scenario band, named as in the scenario, and "
                    "optionally '<band>_sigma'",
                    source=self.source,
                    field=FIELD,
                )
        sigma = None if self.sigma_per_s is None else self.sigma_per_s[:, index]
        return replace(
            self,
            band_names=list(band_names),
            rate_per_s=self.rate_per_s[:, index],
            sigma_per_s=sigma,
        )


def read_measured(path: str | Path, source: str = "sun") -> MeasuredLightCurve:
    """Read measured light curves from a CSV or a speclight NetCDF file (module doc).

    ``source``: ``"sun"`` (the count rates) or ``"laser"`` (a NetCDF's laser return rates).
    A CSV's rows out of time order are sorted (with a warning), not refused.
    """
    p = Path(path)
    if source not in ("sun", "laser"):
        raise InputError(f"source = '{source}' (choices: sun, laser)", field="source")
    if p.suffix.lower() in (".nc", ".nc4", ".netcdf", ".h5"):
        return _read_netcdf(p, source)
    if source == "laser":
        raise InputError(
            "source='laser' reads the laser return rates of a speclight NetCDF; a CSV holds "
            "count rates only (use source='sun')",
            source=str(p),
            field="source",
        )
    c = read_csv_columns(p)
    ones = np.ones(c.time_utc.size, np.int64)
    return MeasuredLightCurve(
        c.time_utc,
        c.band_names,
        c.rate_per_s,
        c.sigma_per_s,
        ones,
        str(p),
        extra_bands_refused=True,
    )


#: What the NetCDF reader reads of a dataset.
NETCDF_VARIABLES = (
    "count_rate_measured",
    "count_rate",
    "count_rate_sigma",
    "laser_reflectance_factor",
    "return_rate",
)


def _read_netcdf(path: Path, source: str = "sun") -> MeasuredLightCurve:
    from speclight.io.user_dataset import read_user_dataset

    ds = read_user_dataset(path, FIELD, what="measurements", variables=NETCDF_VARIABLES)
    return measured_from_dataset(ds, str(path), source)


def measured_from_dataset(ds: xr.Dataset, src: str, source: str = "sun") -> MeasuredLightCurve:
    """The light curve of a dataset read by :func:`speclight.io.user_dataset.read_user_dataset`
    (module docstring: which variables; every check of the CSV reader)."""
    from speclight.io.user_dataset import values

    name = "count_rate_measured" if "count_rate_measured" in ds else "count_rate"
    if source == "laser":
        if "return_rate" not in ds:
            raise InputError(
                "source='laser': no laser return rates (return_rate) in it: the scenario "
                "had no lasers (use source='sun')",
                source=src,
                field="source",
            )
        name = "laser_reflectance_factor"
    if name not in ds or "band" not in ds.coords:
        raise InputError(
            "not a speclight dataset with band count rates (count_rate_measured or "
            "count_rate on (time, band))",
            source=src,
            field=FIELD,
        )
    if ds.sizes["time"] == 0:
        raise InputError("the dataset holds no epochs ('time' is empty)", source=src, field=FIELD)
    bands = [str(b) for b in ds["band"].values]
    _check_band_names(bands, src)
    t_in = ds["time"].values
    row, column = dataset_namers(t_in, bands)
    t = check_epochs(t_in, row, src, FIELD)
    check_order(t, row, src, FIELD)
    rate = values(ds, name, ("time", "band"), src, FIELD)
    laser = source == "laser"
    what = "laser reflectance factor" if laser else "rate"
    check_rates(rate, row, column, src, FIELD, max_abs=None if laser else MAX_RATE_PER_S, what=what)
    sigma = None
    if "count_rate_sigma" in ds and not laser:
        sigma = values(ds, "count_rate_sigma", ("time", "band"), src, FIELD)
        check_sigmas(sigma, rate, row, column, src, FIELD)
    if laser:
        returns = values(ds, "return_rate", ("time", "band"), src, FIELD)
        sigma = _laser_sigma(rate, returns, t)
    check_signal(rate, bands, src, FIELD, what)
    return MeasuredLightCurve(t, bands, rate, sigma, np.ones(t.size, np.int64), src)


def _check_band_names(bands: list[str], src: str) -> None:
    for j, b in enumerate(bands):
        if not b.strip() or b in bands[:j]:
            what = "an empty name" if not b.strip() else f"the name '{b}' of an earlier band"
            raise InputError(
                f"band {j + 1} of the band coordinate has {what}; give each band a name, once",
                source=src,
                field=FIELD,
            )


def _laser_sigma(factor: F64, returns: F64, t: np.ndarray) -> F64:
    """Shot-noise sigmas of laser reflectance factors: the factor times the relative shot
    noise ``1 / sqrt(N)`` of the returns counted in one epoch spacing ``dt``
    (``N = return_rate * dt``; the factor is the rate times geometric terms known exactly)."""
    dt = float(np.median(np.diff(t) / np.timedelta64(1, "s"))) if t.size > 1 else 1.0
    with np.errstate(invalid="ignore", divide="ignore"):
        counts = np.asarray(returns, dtype=float) * dt
        return np.where(counts > 0, np.abs(factor) / np.sqrt(counts), np.nan)


def bin_light_curve(lc: MeasuredLightCurve, bin_s: float) -> MeasuredLightCurve:
    """Average a light curve into bins of ``bin_s`` seconds from its first epoch.

    Each bin's epoch is the mean of its epochs, its rate the mean of its finite rates per
    band, its sigma ``sqrt(sum sigma^2) / n`` (the standard error of the mean of independent
    measurements), ``n_samples`` the number of epochs averaged. Empty bins are left out.
    """
    if not (np.isfinite(bin_s) and bin_s > 0):
        raise InputError(f"bin_s = {bin_s!r} must be a duration > 0 s", field="bin_s")
    dt = (lc.time_utc - lc.time_utc[0]) / np.timedelta64(1, "s")
    key = np.floor(dt / bin_s).astype(np.int64)
    uniq, counts = np.unique(key, return_counts=True)
    slot = np.searchsorted(uniq, key)
    n_bins, n_b = uniq.size, len(lc.band_names)
    finite = np.isfinite(lc.rate_per_s)
    n_finite = np.zeros((n_bins, n_b))
    np.add.at(n_finite, slot, finite)
    total = np.zeros((n_bins, n_b))
    np.add.at(total, slot, np.where(finite, lc.rate_per_s, 0.0))
    with np.errstate(invalid="ignore", divide="ignore"):
        rate = np.where(n_finite > 0, total / n_finite, np.nan)
    sigma = None
    if lc.sigma_per_s is not None:
        var = np.zeros((n_bins, n_b))
        np.add.at(var, slot, np.where(finite, lc.sigma_per_s**2, 0.0))
        with np.errstate(invalid="ignore", divide="ignore"):
            sigma = np.where(n_finite > 0, np.sqrt(var) / n_finite, np.nan)
    offset_ns = (lc.time_utc - lc.time_utc[0]).astype(np.int64)
    mean_ns = np.zeros(n_bins)
    np.add.at(mean_ns, slot, offset_ns.astype(float))
    times = lc.time_utc[0] + np.rint(mean_ns / counts).astype("timedelta64[ns]")
    n = np.zeros(n_bins, np.int64)
    np.add.at(n, slot, lc.n_samples)
    return MeasuredLightCurve(times, list(lc.band_names), rate, sigma, n, lc.source)
