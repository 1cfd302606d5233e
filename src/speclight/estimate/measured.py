"""Measured light curves in: a CSV of count rates per band, or a speclight NetCDF dataset.

CSV: the first column is ``time`` (ISO 8601, UTC: ``2020-02-29T21:16:00Z``, a ``+00:00``
offset or no offset), the others are count rates [s-1] named exactly as the scenario's
bands, optionally with ``<band>_sigma`` columns (the rates' standard deviations [s-1]);
lines starting with ``#`` are comments. NetCDF: a speclight dataset; its
``count_rate_measured`` is used where present, else ``count_rate``, and ``count_rate_sigma``
where present; with ``source="laser"`` its laser reflectance factors per band,
``laser_reflectance_factor`` (the returns normalised by the range and the laser irradiance,
which the returns fall with as ``range^-4``; the Sun's light left out, as a range-gated
detector sees it), with the shot noise of ``return_rate`` over one epoch spacing as sigma.

What is refused (an :class:`~speclight.errors.InputError` naming the file and line or
column) and what is kept:

* unreadable files, a missing ``time`` column, a column that is neither a band nor a band's
  sigma, unparseable numbers or times, a time with another UTC offset, duplicate or
  unsorted times, negative or non-finite sigmas: refused;
* an empty cell or ``nan``: kept as NaN (no measurement of that band at that epoch; fits
  skip it);
* negative rates: kept. Measured rates are background-subtracted (as speclight's own
  ``count_rate_measured``), so noise makes faint epochs negative.

:func:`bin_light_curve` averages a fast detector (a SPAD at 1 kHz) to a slower cadence (a
camera's exposures), as the reference paper did (Nussbaum et al. 2022, section 4).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError, did_you_mean
from speclight.input_files import read_user_text

F64 = NDArray[np.float64]
FIELD = "MEASURED"
_OFFSET = re.compile(r"(Z|[+-]\d\d:?\d\d)$")


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
    """

    time_utc: NDArray[np.datetime64]
    band_names: list[str]
    rate_per_s: F64
    sigma_per_s: F64 | None
    n_samples: NDArray[np.int64]
    source: str

    def select_bands(self, band_names: list[str]) -> MeasuredLightCurve:
        """The same light curve with its bands in the order of ``band_names`` (e.g. the
        scenario's), checked: a band that is not measured is an error with a did-you-mean."""
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
    """
    p = Path(path)
    if source not in ("sun", "laser"):
        raise InputError(f"--source = '{source}' (choices: sun, laser)", field="--source")
    if p.suffix.lower() in (".nc", ".nc4", ".netcdf", ".h5"):
        return _read_netcdf(p, source)
    if source == "laser":
        raise InputError(
            "--source laser reads the laser return rates of a speclight NetCDF; a CSV holds "
            "count rates only (use --source sun)",
            source=str(p),
            field="--source",
        )
    return _read_csv(p)


def _read_csv(path: Path) -> MeasuredLightCurve:
    src = str(path)
    lines = [
        (k, line.strip())
        for k, line in enumerate(read_user_text(path, FIELD, what="measurements").splitlines(), 1)
        if line.strip() and not line.lstrip().startswith("#")
    ]
    if not lines:
        raise InputError("the file holds no header and no rows", source=src, field=FIELD)
    header_line, header = lines[0]
    columns = [c.strip() for c in header.split(",")]
    if columns[0] != "time":
        raise InputError(
            f"line {header_line}: the first column must be 'time' (ISO 8601 UTC), got "
            f"'{columns[0]}'",
            source=src,
            field=FIELD,
        )
    names = columns[1:]
    bands = [c for c in names if not c.endswith("_sigma")]
    if not bands or len(set(names)) != len(names):
        raise InputError(
            f"line {header_line}: give one column per band (and optionally '<band>_sigma'), "
            f"each once; got {', '.join(names) or 'none'}",
            source=src,
            field=FIELD,
        )
    for c in names:
        if c.endswith("_sigma") and c.removesuffix("_sigma") not in bands:
            raise InputError(
                f"line {header_line}: column '{c}' is the sigma of no band column "
                f"(bands: {', '.join(bands)})",
                source=src,
                field=FIELD,
            )
    if len(lines) < 2:
        raise InputError("the file holds a header but no rows", source=src, field=FIELD)
    times, values = [], []
    for k, line in lines[1:]:
        cells = [c.strip() for c in line.split(",")]
        if len(cells) != len(columns):
            raise InputError(
                f"line {k}: {len(cells)} cells, the header names {len(columns)}",
                source=src,
                field=FIELD,
            )
        times.append(_time(cells[0], k, src))
        values.append([_number(c, k, col, src) for c, col in zip(cells[1:], names, strict=True)])
    t = np.array(times, dtype="datetime64[ns]")
    _check_order(t, [k for k, _ in lines[1:]], src)
    data = np.array(values, dtype=float).reshape(len(times), len(names))
    rate = data[:, [names.index(b) for b in bands]]
    sigma = None
    if any(f"{b}_sigma" in names for b in bands):
        sigma = np.full(rate.shape, np.nan)
        for j, b in enumerate(bands):
            if f"{b}_sigma" in names:
                sigma[:, j] = data[:, names.index(f"{b}_sigma")]
        _check_sigma(sigma, src)
    return MeasuredLightCurve(t, bands, rate, sigma, np.ones(len(t), np.int64), src)


def _time(text: str, line: int, src: str) -> np.datetime64:
    m = _OFFSET.search(text)
    body = text
    if m:
        if m.group(1) not in ("Z", "+00:00", "+0000", "-00:00"):
            raise InputError(
                f"line {line}: time '{text}' has the UTC offset {m.group(1)}; give UTC "
                "(a 'Z' or '+00:00' suffix, or none)",
                source=src,
                field=FIELD,
            )
        body = text[: m.start()]
    try:
        t = np.datetime64(body, "ns")
    except ValueError:
        raise InputError(
            f"line {line}: '{text}' is not an ISO 8601 time (e.g. 2020-02-29T21:16:00Z)",
            source=src,
            field=FIELD,
        ) from None
    if np.isnat(t):
        raise InputError(f"line {line}: time '{text}' is not a time", source=src, field=FIELD)
    return t


def _number(text: str, line: int, column: str, src: str) -> float:
    if text == "" or text.lower() == "nan":
        return np.nan
    try:
        x = float(text)
    except ValueError:
        raise InputError(
            f"line {line}: '{text}' in column '{column}' is not a number", source=src, field=FIELD
        ) from None
    if np.isinf(x):
        raise InputError(
            f"line {line}: '{text}' in column '{column}' is infinite", source=src, field=FIELD
        )
    return x


def _check_order(t: NDArray[np.datetime64], lines: list[int], src: str) -> None:
    step = np.diff(t)
    bad = np.flatnonzero(step <= np.timedelta64(0, "ns"))
    if bad.size:
        k = int(bad[0])
        what = "repeats" if step[k] == np.timedelta64(0, "ns") else "comes before"
        raise InputError(
            f"line {lines[k + 1]}: time {t[k + 1]} {what} the time of line {lines[k]}; "
            "give each epoch once, in increasing order",
            source=src,
            field=FIELD,
        )


def _check_sigma(sigma: F64, src: str) -> None:
    bad = np.isfinite(sigma) & (sigma < 0)
    if np.any(bad):
        i, j = np.argwhere(bad)[0]
        raise InputError(
            f"row {i + 1}, band {j + 1}: sigma {sigma[i, j]:g} is negative",
            source=src,
            field=FIELD,
        )


def _read_netcdf(path: Path, source: str = "sun") -> MeasuredLightCurve:
    import xarray as xr

    src = str(path)
    try:
        ds = xr.open_dataset(path, engine="h5netcdf")
    except (OSError, ValueError) as exc:
        raise InputError(f"cannot read it as NetCDF: {exc}", source=src, field=FIELD) from None
    with ds:
        name = "count_rate_measured" if "count_rate_measured" in ds else "count_rate"
        if source == "laser":
            if "return_rate" not in ds:
                raise InputError(
                    "--source laser: no laser return rates (return_rate) in it: the scenario "
                    "had no lasers (use --source sun)",
                    source=src,
                    field="--source",
                )
            name = "laser_reflectance_factor"
        if name not in ds or "band" not in ds.coords:
            raise InputError(
                "not a speclight dataset with band count rates (count_rate_measured or "
                "count_rate on (time, band))",
                source=src,
                field=FIELD,
            )
        t = ds["time"].values.astype("datetime64[ns]")
        _check_order(t, list(range(1, t.size + 1)), src)
        rate = ds[name].transpose("time", "band").values.astype(float)
        sigma = None
        if "count_rate_sigma" in ds and source == "sun":
            sigma = ds["count_rate_sigma"].transpose("time", "band").values.astype(float)
            _check_sigma(sigma, src)
        if source == "laser":
            sigma = _laser_sigma(rate, ds["return_rate"].transpose("time", "band").values, t)
        bands = [str(b) for b in ds["band"].values]
    return MeasuredLightCurve(t, bands, rate, sigma, np.ones(t.size, np.int64), src)


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
        raise InputError(f"--bin-s = {bin_s!r} must be a duration > 0 s", field="--bin-s")
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
