"""``speclight period``: rotation period of a measured or simulated pass (PERIOD.json).

Steps (``docs/period.md``):

1. detrended magnitudes per band and pass (:mod:`.period_inputs`); a CSV's rows out of
   time order are sorted (a notice says so);
2. the multi-band multi-harmonic periodogram (:mod:`.periodogram`) on a regular frequency
   grid from ``1/max_period_s`` (default: a third of the span: a light curve that changes
   over the pass is fitted by a few harmonics of any period longer than that, so at least 3
   cycles are asked for) to ``1/min_period_s`` (default: ``2 K dt``, so that the K-th
   harmonic stays below the Nyquist frequency of the median spacing ``dt``), 5 samples per
   peak width ``1/span``; the best peak refined;
3. outliers (:mod:`.outliers`): single points far off the fit in one band are left out and
   steps 2-3 run again without them, first about the periodogram's model, then about the
   model the refinement chooses;
4. false-alarm probability of the best peak at the noise level beside it: analytic
   (:mod:`.analytic_fap`) or by permutation bootstrap (:mod:`.period_fap`); a period is
   detected below 1 % and when the best peak is not the longest period searched with the
   power rising beyond it; otherwise no period, and where the light curve varies slowly a
   lower bound (:mod:`.period_result`);
5. photometric or rotation period (:mod:`.period_decision`), then the two-frequency test
   of a tumbler (:mod:`.two_frequencies`);
6. synodic correction where the geometry is known (:mod:`.synodic`): from the dataset's
   ``attitude_quaternion`` and ``phase_vector_body`` or the scenario's geometry at the
   measured epochs; the spin axis from a scenario with ``attitude.model: spin``. Applied
   to ``period_s`` with ``synodic="bisector"``, reported only with ``"report"``, and by
   default (``"auto"``) applied where the bisector stands for the geometry: when the
   median phase angle of the pass is at most :data:`AUTO_MAX_PHASE_DEG` (always for
   coaxial lasers, phase angle 0). Where it is not applied, its size enters
   ``period_std_s``.
"""

from __future__ import annotations

import warnings
from pathlib import Path
from typing import Literal

import numpy as np

from speclight.errors import InputError
from speclight.estimate.inputs.measured import bin_light_curve, read_measured
from speclight.estimate.period.analytic_fap import AnalyticFap, analytic_fap
from speclight.estimate.period.outliers import Outliers, combined, find_outliers, without
from speclight.estimate.period.peak_refinement import Peak, refine_with_model
from speclight.estimate.period.period_decision import ALPHA, IfSymmetric, rotation_period
from speclight.estimate.period.period_fap import DRAWS, bootstrap_maxima
from speclight.estimate.period.period_inputs import magnitude_series
from speclight.estimate.period.period_options import (
    SAMPLES_PER_PEAK,
    check_period_options,
    check_periodogram_cost,
    period_range,
)
from speclight.estimate.period.period_result import PeriodResult
from speclight.estimate.period.periodogram import (
    F64,
    BandSeries,
    frequency_grid,
    local_maxima,
    multiband_power,
)
from speclight.estimate.period.search_edge import search_edge
from speclight.estimate.period.synodic import sidereal_period
from speclight.estimate.period.two_frequencies import tumbling_test
from speclight.scenario import LoadedScenario

SynodicMode = Literal["auto", "report", "bisector"]
FapMethod = Literal["auto", "analytic", "bootstrap"]
#: ``synodic="auto"`` applies the correction up to this median phase angle [deg]. The
#: light curve is a function of the phase-angle bisector's body-frame direction only in the
#: limit of small phase angles (Harris et al. 1984, Icarus 57, 251, section II: the PAB
#: approximation); at large ones a faceted body's light depends on the Sun's and the
#: observer's directions separately, and the box-wing of docs/period.md (55-117 deg) shows
#: the fit in the bisector's frame then does not help. 30 deg is speclight's choice.
AUTO_MAX_PHASE_DEG = 30.0
#: Fewest epochs accepted.
MIN_EPOCHS = 20
N_CANDIDATES = 5
#: ``fap_method="auto"`` takes the analytic false-alarm probability when every band has at
#: least this many points per parameter of its model (Baluev's approximation is
#: asymptotic in the number of points; speclight's choice), else the bootstrap.
ANALYTIC_POINTS_PER_PARAMETER = 10


def _search(
    series: BandSeries, freq: F64, harmonics: int, source: str
) -> tuple[F64, list[tuple[float, float]], Peak, bool]:
    """Periodogram, candidates, refined best peak, and whether the best peak is the longest
    period searched with the power still rising beyond it."""
    power = multiband_power(series, freq, harmonics)
    if not np.any(np.isfinite(power)):
        raise InputError(
            "the periodogram is undefined at every frequency (no band has enough usable "
            f"points for {harmonics} harmonics)",
            source=source,
            field="MEASURED",
        )
    top = local_maxima(np.where(np.isfinite(power), power, -np.inf), N_CANDIDATES)
    candidates = [(float(1 / freq[k]), float(power[k])) for k in top]
    peak = refine_with_model(series, float(freq[top[0]]), harmonics, within=(freq[0], freq[-1]))
    return power, candidates, peak, bool(top[0] == 0)


def _use_bootstrap(method: str, series: BandSeries, harmonics: int) -> bool:
    if method != "auto":
        return method == "bootstrap"
    counts = np.bincount(series.band, minlength=series.n_bands)
    counts = counts[counts > 2 * harmonics + 1]
    return bool(np.any(counts < ANALYTIC_POINTS_PER_PARAMETER * (2 * harmonics + 1)))


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
    fap_method: FapMethod = "auto",
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
        Bootstrap draws of the false-alarm probability (where the bootstrap runs).
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
    fap_method
        ``auto`` (analytic where valid, see :data:`ANALYTIC_POINTS_PER_PARAMETER`),
        ``analytic`` or ``bootstrap``.

    Returns
    -------
    PeriodResult
        The periods, their uncertainties and the decisions; ``.to_json()`` is PERIOD.json.
    """
    from speclight.estimate.inputs.cost_limits import check_bin_s
    from speclight.estimate.period.period_geometry import pass_geometry

    check_period_options(
        min_period_s=min_period_s, max_period_s=max_period_s, harmonics=harmonics,
        draws=draws, seed=seed, synodic=synodic, fap_method=fap_method,
    )  # fmt: skip
    notices: list[str] = []
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        lc = read_measured(measured, source)
    for w in caught:
        notices.append(str(w.message))
        warnings.warn(str(w.message), stacklevel=2)
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
    min_p, max_p = period_range(series, min_period_s, max_period_s, harmonics)
    boot_wanted = _use_bootstrap(fap_method, series, harmonics)
    check_periodogram_cost(
        series, min_p=min_p, max_p=max_p, harmonics=harmonics, draws=draws if boot_wanted else 0
    )
    freq = frequency_grid(series.span_s, min_p, max_p, SAMPLES_PER_PEAK)
    power, candidates, peak, rising = _search(series, freq, harmonics, lc.source)
    # outliers about the periodogram's model first (one point far off drives the choice of
    # the model: a cosmic ray took a trend of degree 20), then about the model chosen without
    # them (harmonics and trend left in the residuals hide smaller ones)
    n_points = series.t_s.size
    first = find_outliers(series, peak.frequency_hz, list(range(1, harmonics + 1)))
    if first.index.size:
        series = without(series, first.index)
        power, candidates, peak, rising = _search(series, freq, harmonics, lc.source)
    second = find_outliers(
        series, peak.frequency_hz, peak.orders, peak.trend_degree, peak.amplitude_change
    )
    if second.index.size:
        series = without(series, second.index)
        power, candidates, peak, rising = _search(series, freq, harmonics, lc.source)
    outliers: Outliers | None = combined(first, second, n_points)
    analytic: AnalyticFap = analytic_fap(series, freq, harmonics, peak.frequency_hz)
    boot = bootstrap_maxima(series, freq, harmonics, draws, seed) if boot_wanted else None
    decision = rotation_period(series, 1 / peak.frequency_hz, harmonics, min_p, if_symmetric)
    if decision.ambiguous:
        notices.append(decision.decision)
    tumbling = tumbling_test(series, freq, 1 / decision.rotation_period_s, harmonics, ALPHA)
    correction = None
    geometry = pass_geometry(measured, lc, loaded, source)
    if geometry is not None:
        pab, axis, phase_deg = geometry
        apply, why = _apply_synodic(synodic, phase_deg[weight > 0])
        correction = sidereal_period(
            series, decision.rotation_period_s, harmonics, t_s, pab, weight, axis,
            apply=apply, not_applied_why=why,
        )  # fmt: skip
    return PeriodResult(
        series, list(lc.band_names), freq, power, candidates, peak, harmonics, analytic,
        boot, decision, correction, n_epochs, lc.source, outliers=outliers,
        tumbling=tumbling, rising=rising, notices=notices,
        edge=search_edge(series, peak, freq, harmonics, decision),
    )  # fmt: skip


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
