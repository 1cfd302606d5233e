"""Options of ``speclight period`` checked before any work, the searched period range and
the cost of the periodogram and its bootstrap."""

from __future__ import annotations

import warnings

import numpy as np

from speclight.errors import InputError
from speclight.estimate.period.period_decision import MIN_CYCLES
from speclight.estimate.period.period_fap import DRAWS
from speclight.estimate.period.periodogram import BandSeries

#: Frequencies per peak width ``1/span`` of the grid.
SAMPLES_PER_PEAK = 5
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
#: How the false-alarm probability is computed (docs/period.md).
FAP_METHODS = ("auto", "analytic", "bootstrap")


def check_period_options(
    *,
    min_period_s: float | None,
    max_period_s: float | None,
    harmonics: int,
    draws: int,
    seed: int,
    synodic: str,
    fap_method: str = "auto",
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
    fap_method
        ``auto``, ``analytic`` or ``bootstrap``.
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
    if fap_method not in FAP_METHODS:
        raise InputError(
            f"fap_method = '{fap_method}' (choices: {', '.join(FAP_METHODS)})",
            field="fap_method",
        )


def period_range(
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
