"""``speclight period``: rotation period of a measured or simulated pass (PERIOD.json).

Steps (``docs/period.md``):

1. the count rates of the chosen bands become magnitudes ``-2.5 log10(rate)`` with
   ``sigma_mag = 2.5 / ln 10 * sigma / rate`` (the measured sigmas, else the shot noise
   ``sqrt(rate / t)`` with ``t`` the scenario's exposure or the median epoch spacing); points
   with ``rate <= 2 sigma`` are left out; a weighted polynomial in time (degree 3) is
   subtracted per band: the slow change of range, phase angle and airmass over the pass;
2. the multi-band multi-harmonic periodogram (:mod:`.periodogram`) on a regular frequency
   grid from ``1/max_period_s`` (default: a third of the span: a light curve that changes
   over the pass is fitted by a few harmonics of any period longer than that, so at least 3
   cycles are asked for) to ``1/min_period_s`` (default:
   ``2 K dt``, so that the K-th harmonic stays below the Nyquist frequency of the median
   spacing ``dt``), 5 samples per peak width ``1/span``; the best peak refined;
3. false-alarm probability by permutation bootstrap (:mod:`.period_fap`);
4. photometric or rotation period (:mod:`.period_decision`);
5. synodic correction where the geometry is known (:mod:`.synodic`): from the dataset's
   ``attitude_quaternion`` and ``phase_vector_body`` or the scenario's geometry at the
   measured epochs; the spin axis from a scenario with ``attitude.model: spin``. Applied
   to ``period_s`` with ``synodic="bisector"``, reported only with ``"report"``, and by
   default (``"auto"``) applied where the bisector stands for the geometry: when the
   median phase angle of the pass is at most :data:`AUTO_MAX_PHASE_DEG` (always for
   coaxial lasers, phase angle 0).
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.inputs.measured import MeasuredLightCurve, bin_light_curve, read_measured
from speclight.estimate.period.period_decision import (
    ALPHA,
    MIN_CYCLES,
    IfSymmetric,
    RotationDecision,
    rotation_period,
)
from speclight.estimate.period.period_fap import DRAWS, BootstrapMaxima, bootstrap_maxima
from speclight.estimate.period.periodogram import (
    F64,
    BandSeries,
    Peak,
    frequency_grid,
    local_maxima,
    multiband_power,
    refine_peak,
)
from speclight.estimate.period.synodic import SynodicCorrection, sidereal_period
from speclight.scenario import LoadedScenario

SynodicMode = Literal["auto", "report", "bisector"]
#: ``synodic="auto"`` applies the correction up to this median phase angle [deg]. The
#: light curve is a function of the phase-angle bisector's body-frame direction only in the
#: limit of small phase angles (Harris et al. 1984, Icarus 57, 251, section II: the PAB
#: approximation); at large ones a faceted body's light depends on the Sun's and the
#: observer's directions separately, and the box-wing of docs/period.md (55-117 deg) shows
#: the fit in the bisector's frame then does not help. 30 deg is speclight's choice.
AUTO_MAX_PHASE_DEG = 30.0

#: Fewest epochs accepted, and the polynomial degree of the trend removed per band.
MIN_EPOCHS = 20
DETREND_DEGREE = 3
N_CANDIDATES = 5
SAMPLES_PER_PEAK = 5
LN10 = float(np.log(10.0))
#: Smallest magnitude sigma accepted [mag]: one part per million, far below what any
#: photometry reaches (scintillation alone is ~1e-3 mag in 1 s). A smaller sigma (a sigma
#: column of ~0, or a rate so huge that its shot noise vanishes) would weigh ``1/sigma^2``
#: over every other epoch together, or overflow.
MIN_SIGMA_MAG = 1e-6
#: Brightest rate accepted, as a factor over its band's median usable rate: 1e6, 15 mag.
#: Glints of flat panels reach 8-10 mag above a satellite's diffuse level; a rate a million
#: times the median is a broken value, and it alone would set the periodogram.
MAX_RATE_OVER_MEDIAN = 1e6
#: Largest bootstrap ``draws``: the Gumbel fit of the false-alarm probability is stable with
#: tens of draws (:mod:`.period_fap`); 10 000 draws pin it far beyond what a decision needs.
MAX_DRAWS = 10_000
#: Seconds per frequency and band of astropy's chi2 periodogram, and per frequency, band and
#: point times (2 harmonics + 1)^2 (measured: 300-20 000 points, 1-10 harmonics, within 20 %
#: or above; BENCHMARKS.md "Estimator limits", bench/bench_estimator_limits.py).
SECONDS_PER_BAND_FREQUENCY = 60e-6
SECONDS_PER_TERM = 10e-9
#: Bytes per frequency of the grid: the grid, the power, the sum over bands and astropy's
#: own arrays per call (float64).
BYTES_PER_FREQUENCY = 8 * 8


def magnitude_series(
    lc: MeasuredLightCurve, exposure_s: float | None = None
) -> tuple[BandSeries, F64, F64]:
    """Detrended magnitudes of all bands (module docstring, step 1).

    Returns
    -------
    series
        The finite points, flattened.
    t_s
        (N,) time of each epoch since the first [s].
    weight
        (N,) information of each epoch, ``sum_b 1/sigma_mag^2`` (0 where none is usable).
    """
    t_s = (lc.time_utc - lc.time_utc[0]) / np.timedelta64(1, "s")
    rate = lc.rate_per_s
    if lc.sigma_per_s is not None:
        sigma = lc.sigma_per_s
    else:
        t_exp = exposure_s if exposure_s else float(np.median(np.diff(t_s)))
        sigma = np.sqrt(np.abs(rate) / (t_exp * lc.n_samples[:, None]))
    with np.errstate(invalid="ignore", divide="ignore", over="ignore"):
        ok = np.isfinite(rate) & np.isfinite(sigma) & (sigma > 0) & (rate > 2 * sigma)
        mag = np.where(ok, -2.5 * np.log10(np.where(ok, rate, 1.0)), np.nan)
        dmag = np.where(ok, 2.5 / LN10 * sigma / np.where(ok, rate, 1.0), np.nan)
    _check_usable_points(lc, ok, dmag)
    span = max(float(t_s[-1]), 1e-9)
    for b in range(rate.shape[1]):
        m = ok[:, b]
        if m.sum() > DETREND_DEGREE + 1:
            x = t_s[m] / span
            c = np.polynomial.polynomial.polyfit(x, mag[m, b], DETREND_DEGREE, w=1 / dmag[m, b])
            mag[m, b] -= np.polynomial.polynomial.polyval(x, c)
    tt = np.broadcast_to(t_s[:, None], rate.shape)
    bb = np.broadcast_to(np.arange(rate.shape[1])[None, :], rate.shape)
    series = BandSeries(
        t_s=tt[ok].astype(float),
        y=mag[ok],
        dy=dmag[ok],
        band=bb[ok].astype(np.int64),
        n_bands=rate.shape[1],
    )
    weight = np.where(ok, 1.0 / np.where(ok, dmag, 1.0) ** 2, 0.0).sum(axis=1)
    return series, t_s, weight


def _check_usable_points(lc: MeasuredLightCurve, ok: NDArray[np.bool_], dmag: F64) -> None:
    """Refuse a usable rate far above its band's median (:data:`MAX_RATE_OVER_MEDIAN`) or
    with a sigma below :data:`MIN_SIGMA_MAG`, naming the first such point."""
    rate = lc.rate_per_s
    for b, name in enumerate(lc.band_names):
        m = ok[:, b]
        if not m.any():
            continue
        median = float(np.median(rate[m, b]))
        bright = np.flatnonzero(m & (rate[:, b] > MAX_RATE_OVER_MEDIAN * median))
        if bright.size:
            i = int(bright[0])
            raise InputError(
                f"band '{name}' at {lc.time_utc[i]}: rate {rate[i, b]:.3g} s-1 is "
                f"{rate[i, b] / median:.3g} times the band's median {median:.3g} s-1 "
                f"({bright.size} such epoch(s)); no light curve varies by more than "
                f"{MAX_RATE_OVER_MEDIAN:.0e} (15 mag): check the file",
                source=lc.source,
                field="MEASURED",
            )
        fine = np.flatnonzero(m & (dmag[:, b] < MIN_SIGMA_MAG))
        if fine.size:
            i = int(fine[0])
            sigma = dmag[i, b] * rate[i, b] * LN10 / 2.5
            raise InputError(
                f"band '{name}' at {lc.time_utc[i]}: sigma {sigma:.3g} s-1 of the rate "
                f"{rate[i, b]:.3g} s-1 is {dmag[i, b]:.3g} mag ({fine.size} such epoch(s)); "
                f"accepted: at least {MIN_SIGMA_MAG:g} mag (no photometry is more precise): "
                "check the sigma columns",
                source=lc.source,
                field="MEASURED",
            )


@dataclass
class PeriodResult:
    """Everything ``speclight period`` found (``to_json`` gives PERIOD.json)."""

    series: BandSeries
    band_names: list[str]
    frequency_hz: F64
    power: F64
    candidates: list[tuple[float, float]]
    peak: Peak
    harmonics: int
    bootstrap: BootstrapMaxima
    decision: RotationDecision
    synodic: SynodicCorrection | None
    n_epochs: int
    source: str

    @property
    def period_s(self) -> float:
        """The rotation period: sidereal where corrected, else synodic."""
        if self.synodic is not None and self.synodic.sidereal_period_s is not None:
            return self.synodic.sidereal_period_s
        return self.decision.rotation_period_s

    @property
    def period_std_s(self) -> float:
        """Standard deviation of the rotation period, ``factor P^2 sigma_f`` [s] (the
        sidereal fit's where applied)."""
        if self.synodic is not None and self.synodic.sidereal_std_s is not None:
            return self.synodic.sidereal_std_s
        f = self.peak.frequency_hz
        return float(self.decision.factor * self.peak.frequency_std_hz / f**2)

    def to_json(self) -> dict[str, Any]:
        """PERIOD.json (keys documented in docs/period.md); a number that could not be
        determined (NaN) is written ``null`` and its key listed in ``undetermined``."""
        out = self._summary()
        missing: list[str] = []
        out = _nulls_for_nan(out, "", missing)
        if missing:
            out["undetermined"] = missing
        return out

    def _summary(self) -> dict[str, Any]:
        best_power = float(np.nanmax(self.power))
        fap = self.bootstrap.false_alarm_probability(best_power)
        perm, upper = self.bootstrap.permutation_p_value(best_power)
        syn = self.synodic
        return {
            "period_s": self.period_s,
            "period_std_s": self.period_std_s,
            "false_alarm_probability": fap,
            "permutation_p_value": perm,
            "permutation_p_value_is_upper_bound": upper,
            "method": (
                "multi-band Lomb-Scargle (astropy LombScargle per band, nterms = "
                f"{self.harmonics}, chi2-weighted sum; VanderPlas & Ivezic 2015) on detrended "
                f"magnitudes; FAP from a Gumbel law fitted to the maximum powers of "
                f"{self.bootstrap.draws} permutation draws (seed {self.bootstrap.seed}; the "
                "(value, sigma) pairs shuffled among the epochs of each band, same grid; "
                "Suveges 2014); period_std_s from "
                "the curvature of chi2(f) at its minimum (harmonics and a cubic trend per "
                "band), delta chi2 = 1 after scaling by "
                "the reduced chi2, times the coloured-noise factor sqrt(sum w_k / sum "
                "(w_k / R_k)) (w_k = k^2 A_k^2, R_k the residuals' Lomb-Scargle power beside "
                "harmonic k over their mean power; Kay 1993 ch. 3; never below 1); residuals' "
                f"lag-1 correlation rho = {self.peak.residual_correlation:.3f}"
            ),
            "candidates": [{"period_s": p, "power": w} for p, w in self.candidates],
            "photometric_period_s": self.decision.photometric_period_s,
            "synodic_period_s": self.decision.rotation_period_s,
            "decision": self.decision.decision,
            "halves_tests": [
                {
                    "fold_period_s": t.period_s,
                    "f_statistic": t.f_statistic,
                    "p_value": t.p_value,
                    "halves_differ": t.differ,
                }
                for t in self.decision.tests
            ],
            "alpha": ALPHA,
            "synodic_correction_s": None if syn is None else syn.correction_s,
            "synodic_bound_s": None if syn is None else syn.bound_s,
            "synodic_linear_period_s": None if syn is None else syn.linear_period_s,
            "bisector_fit_period_s": None if syn is None else syn.bisector_fit_period_s,
            "bisector_rate_rad_s": None if syn is None else syn.bisector_rate_rad_s,
            "synodic_method": (
                "geometry unknown (a CSV without --scenario): no correction"
                if syn is None
                else syn.method
            ),
            "best_power": best_power,
            "power_at_fap_1_percent": self.bootstrap.power_at(0.01),
            "harmonics": self.harmonics,
            "frequency_grid_hz": {
                "min": float(self.frequency_hz[0]),
                "max": float(self.frequency_hz[-1]),
                "n": int(self.frequency_hz.size),
            },
            "n_epochs": self.n_epochs,
            "bands": self.band_names,
            "source": self.source,
        }


def check_period_options(
    *,
    min_period_s: float | None,
    max_period_s: float | None,
    harmonics: int,
    draws: int,
    seed: int,
    synodic: str,
) -> None:
    """Refuse options outside their ranges (before any file is read).

    Parameters
    ----------
    min_period_s, max_period_s
        The period range searched [s], or None (the defaults).
    harmonics
        Harmonics of the periodogram's model, 1..20.
    draws
        Bootstrap draws of the false-alarm probability, 1..:data:`MAX_DRAWS`.
    seed
        Seed of the bootstrap, >= 0.
    synodic
        ``auto``, ``report`` or ``bisector``.
    """
    if not 1 <= harmonics <= 20:
        raise InputError(f"harmonics = {harmonics} must be 1..20", field="harmonics")
    for name, v in (("min_period_s", min_period_s), ("max_period_s", max_period_s)):
        if v is not None and not (np.isfinite(v) and v > 0):
            raise InputError(f"{name} = {v!r} must be a duration > 0 s", field=name)
    if min_period_s is not None and max_period_s is not None and min_period_s >= max_period_s:
        raise InputError(
            f"min_period_s = {min_period_s:g} must be below max_period_s = {max_period_s:g}",
            field="min_period_s",
        )
    if not 1 <= draws <= MAX_DRAWS:
        raise InputError(
            f"draws = {draws} must be 1..{MAX_DRAWS} (the false-alarm probability's Gumbel "
            "fit is stable with a few tens)",
            field="draws",
        )
    if seed < 0:
        raise InputError(f"seed = {seed} must be an integer >= 0", field="seed")
    if synodic not in ("auto", "report", "bisector"):
        raise InputError(
            f"synodic = '{synodic}' (choices: auto, report, bisector)", field="synodic"
        )


def _period_range(
    series: BandSeries,
    min_period_s: float | None,
    max_period_s: float | None,
    harmonics: int,
) -> tuple[float, float]:
    """The searched period range [s] (module docstring, step 2), checked against the data:
    a period is measured from repeated cycles, so none longer than the span is searched."""
    span = series.span_s
    dt = float(np.median(np.diff(np.unique(series.t_s))))
    min_p = min_period_s if min_period_s is not None else 2 * harmonics * dt
    max_p = max_period_s if max_period_s is not None else span / MIN_CYCLES
    for name, value in (("max_period_s", max_p), ("min_period_s", min_p)):
        if value > span:
            raise InputError(
                f"{name} = {value:g} s is longer than the {span:g} s the usable epochs span: "
                "a period is measured from repeated cycles, and the light curve of less than "
                f"one cycle fits every longer period alike; give at most {span:g} s "
                f"(default {MIN_CYCLES:g} cycles: {span / MIN_CYCLES:g} s)",
                field=name,
            )
    if min_p >= max_p:
        raise InputError(
            f"the period range {min_p:g} .. {max_p:g} s is empty (span {span:g} s, spacing "
            f"{dt:g} s, {harmonics} harmonics): give min_period_s below max_period_s",
            field="min_period_s",
        )
    return float(min_p), float(max_p)


def check_periodogram_cost(
    series: BandSeries, *, min_p: float, max_p: float, harmonics: int, draws: int
) -> None:
    """Refuse a frequency grid and bootstrap that cannot finish
    (:mod:`speclight.estimate.inputs.cost_limits`).

    Parameters
    ----------
    series
        The light curves.
    min_p, max_p
        The period range searched [s].
    harmonics
        Harmonics of the periodogram's model.
    draws
        Bootstrap draws.
    """
    from speclight.estimate.inputs.cost_limits import (
        ANNOUNCE_SECONDS,
        MAX_SECONDS,
        check_cost,
        duration,
    )
    from speclight.simulation.memory import memory_limit_bytes

    n_freq = SAMPLES_PER_PEAK * series.span_s * (1.0 / min_p - 1.0 / max_p) + 1
    points = np.bincount(series.band, minlength=series.n_bands)
    per_grid = n_freq * np.sum(
        SECONDS_PER_BAND_FREQUENCY + SECONDS_PER_TERM * points * (2 * harmonics + 1) ** 2
    )
    seconds = float((1 + draws) * per_grid)
    what = (
        f"the periodogram of {n_freq:.3g} frequencies ({min_p:g} .. {max_p:g} s, "
        f"{SAMPLES_PER_PEAK} per peak width over {series.span_s:g} s) x {series.n_bands} "
        f"band(s) x {series.t_s.size} points x {harmonics} harmonics, once and for "
        f"{draws} bootstrap draws,"
    )
    reduce = "give fewer draws, a larger min_period_s or a smaller max_period_s"
    n_bytes = n_freq * BYTES_PER_FREQUENCY
    # name what the user made large: the draws where the grid alone (with the default
    # draws) would finish, else the grid's shortest period
    grid_fits = n_bytes <= memory_limit_bytes() and seconds / (1 + draws) * (1 + DRAWS) <= (
        MAX_SECONDS
    )
    if grid_fits:
        check_cost("draws", draws, what, n_bytes, seconds, reduce)
    else:
        check_cost("min_period_s", f"{min_p:g}", what, n_bytes, seconds, reduce)
    if seconds > ANNOUNCE_SECONDS:
        warnings.warn(f"period: {what.rstrip(',')}: about {duration(seconds)}", stacklevel=2)


def estimate_period(
    measured: str | Path,
    *,
    loaded: LoadedScenario | None = None,
    bands: list[str] | None = None,
    min_period_s: float | None = None,
    max_period_s: float | None = None,
    harmonics: int = 2,
    bin_s: float | None = None,
    draws: int = DRAWS,
    seed: int = 0,
    if_symmetric: IfSymmetric = "auto",
    synodic: SynodicMode = "auto",
    source: str = "sun",
) -> PeriodResult:
    """Rotation period of the light curves in ``measured`` (module docstring).

    Errors name the Python parameters (``min_period_s``, ``draws``, ...).

    Parameters
    ----------
    measured
        Light curves: a speclight NetCDF or a CSV of count rates
        (:func:`speclight.estimate.read_measured`).
    loaded
        The scenario of the geometry, for the synodic correction (for a NetCDF default: the
        one it carries); one given here is checked against the measurements
        (:func:`speclight.estimate.inputs.geometry_match.check_scenario_sees`).
    bands
        Bands to use (default: all).
    min_period_s, max_period_s
        The period range searched [s] (default ``2 K dt`` and a third of the span).
    harmonics
        Harmonics ``K`` of the periodogram's model.
    bin_s
        Average the epochs into bins of this many seconds.
    draws
        Bootstrap draws of the false-alarm probability.
    seed
        Seed of the bootstrap.
    if_symmetric
        ``auto``, ``double`` or ``keep``: the rotation period when the halves of the 2P fold
        agree (docs/period.md).
    synodic
        ``auto``, ``report`` or ``bisector``: the synodic correction applied, only reported,
        or applied where the median phase angle is at most 30 deg.
    source
        ``sun`` (the count rates) or ``laser`` (a NetCDF's laser return rates).

    Returns
    -------
    PeriodResult
        The periods, their uncertainties and the decisions; ``.to_json()`` is PERIOD.json.
    """
    from speclight.estimate.inputs.cost_limits import check_bin_s
    from speclight.estimate.period.period_geometry import pass_geometry

    check_period_options(
        min_period_s=min_period_s, max_period_s=max_period_s, harmonics=harmonics,
        draws=draws, seed=seed, synodic=synodic,
    )  # fmt: skip
    lc = read_measured(measured, source)
    if bands:
        lc = lc.select_bands(list(bands), subset=True)
    if bin_s is not None:
        check_bin_s(bin_s, lc.time_utc)
        lc = bin_light_curve(lc, bin_s)
    given = loaded
    loaded = loaded if loaded is not None else _carried_scenario(measured)
    exposure = loaded.scenario.instrument.exposure_s if loaded is not None else None
    series, t_s, weight = magnitude_series(lc, exposure)
    n_epochs = int(np.sum(weight > 0))
    if n_epochs < MIN_EPOCHS:
        raise InputError(
            f"{n_epochs} epochs with a usable rate (> 2 sigma); at least {MIN_EPOCHS} are "
            "needed for a period",
            source=lc.source,
            field="MEASURED",
        )
    if given is not None:
        from speclight.estimate.inputs.geometry_match import check_scenario_sees

        check_scenario_sees(given, measured, lc.time_utc[weight > 0], source)
    min_p, max_p = _period_range(series, min_period_s, max_period_s, harmonics)
    check_periodogram_cost(series, min_p=min_p, max_p=max_p, harmonics=harmonics, draws=draws)
    freq = frequency_grid(series.span_s, min_p, max_p, SAMPLES_PER_PEAK)
    power = multiband_power(series, freq, harmonics)
    if not np.any(np.isfinite(power)):
        raise InputError(
            "the periodogram is undefined at every frequency (no band has enough usable "
            f"points for {harmonics} harmonics)",
            source=lc.source,
            field="MEASURED",
        )
    top = local_maxima(power, N_CANDIDATES)
    candidates = [(float(1 / freq[k]), float(power[k])) for k in top]
    orders = list(range(1, harmonics + 1))
    peak = refine_peak(series, float(freq[top[0]]), orders, within=(freq[0], freq[-1]))
    decision = rotation_period(series, 1 / peak.frequency_hz, harmonics, min_p, if_symmetric)
    boot = bootstrap_maxima(series, freq, harmonics, draws, seed)
    correction = None
    geometry = pass_geometry(measured, lc, loaded, source)
    if geometry is not None:
        pab, axis, phase_deg = geometry
        apply, why = _apply_synodic(synodic, phase_deg[weight > 0])
        correction = sidereal_period(
            series,
            decision.rotation_period_s,
            harmonics,
            t_s,
            pab,
            weight,
            axis,
            apply=apply,
            not_applied_why=why,
        )
    return PeriodResult(
        series,
        list(lc.band_names),
        freq,
        power,
        candidates,
        peak,
        harmonics,
        boot,
        decision,
        correction,
        n_epochs,
        lc.source,
    )


def _nulls_for_nan(value: Any, key: str, missing: list[str]) -> Any:
    """``value`` with every non-finite float replaced by None (its key path added to
    ``missing``): JSON has no NaN."""
    if isinstance(value, dict):
        return {k: _nulls_for_nan(v, f"{key}.{k}" if key else k, missing) for k, v in value.items()}
    if isinstance(value, list):
        return [_nulls_for_nan(v, f"{key}[{i}]", missing) for i, v in enumerate(value)]
    if isinstance(value, float | np.floating) and not np.isfinite(value):
        missing.append(key)
        return None
    return value


def _apply_synodic(mode: str, phase_deg: F64) -> tuple[bool, str]:
    """Whether the bisector correction is applied, and why not where it is not."""
    if mode == "bisector":
        return True, ""
    if mode == "report":
        return False, "not asked for (--synodic report)"
    median = float(np.nanmedian(phase_deg)) if np.isfinite(phase_deg).any() else np.nan
    if median <= AUTO_MAX_PHASE_DEG:
        return True, ""
    return False, (
        f"--synodic auto: the pass's median phase angle {median:.0f} deg is above "
        f"{AUTO_MAX_PHASE_DEG:g} deg, where the light curve depends on the Sun's and the "
        "observer's directions separately (--synodic bisector applies it anyway)"
    )


def _carried_scenario(measured: str | Path) -> LoadedScenario | None:
    if Path(measured).suffix.lower() not in (".nc", ".nc4", ".netcdf", ".h5"):
        return None
    from speclight.io.user_dataset import read_user_dataset
    from speclight.scenario import parse_scenario

    ds = read_user_dataset(measured, "MEASURED", what="measurements", variables=())
    text = ds.attrs.get("scenario_yaml")
    if text is None:
        return None
    return parse_scenario(str(text), source=f"{measured} (scenario_yaml)")
