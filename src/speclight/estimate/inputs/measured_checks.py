"""The checks every measured light curve passes, from a CSV or a NetCDF dataset alike.

Epochs, rates and sigmas that no estimation can use are refused here, with the line (CSV) or
the time index (NetCDF), the column or band and the value, so that a fit, a periodogram or a
spin-axis search never sees them:

* an epoch outside what the shipped Sun ephemeris (JPL DE421) covers (every estimation
  places the Sun and the target at the epochs; ``simulate`` refuses such scenarios too). It
  is checked before the conversion to ``datetime64[ns]``, which wraps years outside
  1678-2262 around silently;
* a rate that is infinite, subnormal (below 2.2e-308 in size: its arithmetic loses every
  digit) or larger than :data:`MAX_RATE_PER_S` in size;
* a sigma that is infinite, not above 0, smaller than the rate's own rounding
  (:data:`SIGMA_FLOOR` times the rate: such a weight is infinite in effect) or larger than
  :data:`MAX_RATE_PER_S`; a NaN sigma is "not given" for that cell;
* a band with no rate above 0 at any epoch: it measured nothing (all empty, zero or
  negative), and no fit, period or axis can come from it.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.scenario.sections_geometry import FIRST_EPOCH_UTC, LAST_EPOCH_UTC

F64 = NDArray[np.float64]
#: Largest count rate accepted [s-1]. The Sun itself through a 10 m aperture gives about
#: 3e23 photons per second (1361 W m-2 x 78 m2 / 3.6e-19 J per photon at 550 nm); a rate
#: far above that is a unit or a parsing error, and its squares overflow.
MAX_RATE_PER_S = 1e30
#: Smallest sigma accepted, relative to the rate: the relative rounding of float64 (2.2e-16).
SIGMA_FLOOR = float(np.finfo(np.float64).eps)
TINY = float(np.finfo(np.float64).tiny)
FIRST_EPOCH = np.datetime64(FIRST_EPOCH_UTC.replace(tzinfo=None), "s")
LAST_EPOCH = np.datetime64(LAST_EPOCH_UTC.replace(tzinfo=None), "s")
#: Names a row (``"line 5"``, ``"time index 3"``) and a column (``"column 'B'"``).
Namer = Callable[[int], str]


def dataset_namers(t: NDArray[np.datetime64], bands: list[str]) -> tuple[Namer, Namer]:
    """How the checks name a row and a column of a dataset's (time, band) array."""

    def row(i: int) -> str:
        return f"time index {i} ({t[i]})"

    def column(j: int) -> str:
        return f"band '{bands[j]}'"

    return row, column


def check_epoch(t: np.datetime64, where: str, text: str, src: str, field: str) -> np.datetime64:
    """``t`` (any unit) as ``datetime64[ns]`` if it lies within the ephemeris span.

    Parameters
    ----------
    t
        The epoch (UTC).
    where
        The place in the file, for the message (``"line 5"``).
    text
        The time as given.
    src, field
        The file and the field the error names.
    """
    if not FIRST_EPOCH <= t.astype("datetime64[s]") <= LAST_EPOCH:
        raise InputError(
            f"{where}: {text} is outside what the shipped Sun ephemeris (JPL DE421) "
            f"covers; accepted: {FIRST_EPOCH_UTC.date()} to {LAST_EPOCH_UTC.date()} UTC",
            source=src,
            field=field,
        )
    return t.astype("datetime64[ns]")


def check_epochs(
    t: NDArray[np.datetime64], row: Namer, src: str, field: str
) -> NDArray[np.datetime64]:
    """Every epoch of ``t`` (any unit) checked as :func:`check_epoch`; ``datetime64[ns]``."""
    seconds = t.astype("datetime64[s]")
    bad = np.flatnonzero((seconds < FIRST_EPOCH) | (seconds > LAST_EPOCH))
    if bad.size:
        k = int(bad[0])
        check_epoch(t[k], row(k), str(t[k]), src, field)
    return t.astype("datetime64[ns]")


def check_order(t: NDArray[np.datetime64], row: Namer, src: str, field: str) -> None:
    """Refuse repeated or decreasing epochs."""
    step = np.diff(t)
    bad = np.flatnonzero(step <= np.timedelta64(0, "ns"))
    if bad.size:
        k = int(bad[0])
        what = "repeats" if step[k] == np.timedelta64(0, "ns") else "comes before"
        raise InputError(
            f"{row(k + 1)}: time {t[k + 1]} {what} the time of {row(k)}; give each epoch "
            "once, in increasing order",
            source=src,
            field=field,
        )


def check_rates(
    rate: F64,
    row: Namer,
    column: Namer,
    src: str,
    field: str,
    *,
    max_abs: float | None = MAX_RATE_PER_S,
    what: str = "rate",
) -> None:
    """Refuse infinite, subnormal and (above ``max_abs``) huge values of ``rate`` (N, B);
    NaN is "no measurement".

    Parameters
    ----------
    rate
        The values (N, B) [s-1].
    row, column
        Name an entry's row (``"line 5"``) and column for the message.
    src, field
        The file and the field the error names.
    max_abs
        Largest magnitude accepted [s-1]; None: no upper bound.
    what
        What the values are, for the message (``"rate"``).
    """
    size = np.abs(rate)
    bad = np.isinf(rate) | ((size > 0) & (size < TINY))
    if max_abs is not None:
        bad |= size > max_abs
    if np.any(bad):
        i, j = (int(k) for k in np.argwhere(bad)[0])
        x = rate[i, j]
        if np.isinf(x):
            why = "is infinite"
        elif size[i, j] < TINY:
            why = f"is subnormal (below {TINY:.3g} in size: no digit of it survives arithmetic)"
        else:
            why = f"is above {max_abs:g} in size (the Sun through a 10 m telescope gives 3e23 s-1)"
        raise InputError(f"{row(i)}, {column(j)}: {what} {x:g} {why}", source=src, field=field)


def check_sigmas(sigma: F64, rate: F64, row: Namer, column: Namer, src: str, field: str) -> None:
    """Refuse sigmas (N, B) that are infinite, not above 0, below ``SIGMA_FLOOR x |rate|`` or
    above :data:`MAX_RATE_PER_S`; NaN is "not given".

    Parameters
    ----------
    sigma, rate
        The standard deviations and the rates they belong to (N, B) [s-1].
    row, column
        Name an entry's row and column for the message.
    src, field
        The file and the field the error names.
    """
    given = ~np.isnan(sigma)
    with np.errstate(invalid="ignore"):
        floor = SIGMA_FLOOR * np.where(np.isfinite(rate), np.abs(rate), 0.0)
        bad = given & ~((sigma > 0) & (sigma >= floor) & (sigma <= MAX_RATE_PER_S))
    if not np.any(bad):
        return
    i, j = (int(k) for k in np.argwhere(bad)[0])
    s = sigma[i, j]
    if s < 0:
        why = "is negative; a standard deviation is > 0"
    elif s == 0:
        why = "is 0; give it > 0 (a measurement without uncertainty would weigh infinitely)"
    elif np.isinf(s) or s > MAX_RATE_PER_S:
        why = f"is above {MAX_RATE_PER_S:g}: no measurement is that uncertain"
    else:
        why = (
            f"is below the rounding of the rate {rate[i, j]:g} itself ({SIGMA_FLOOR:.2g} of "
            "it): it would weigh infinitely"
        )
    raise InputError(f"{row(i)}, {column(j)}: sigma {s:g} {why}", source=src, field=field)


def check_signal(rate: F64, names: list[str], src: str, field: str, what: str = "rate") -> None:
    """Refuse a band (column ``j`` of ``rate``) without any value above 0.

    Parameters
    ----------
    rate
        The values (N, B) [s-1].
    names
        The band names (B,).
    src, field
        The file and the field the error names.
    what
        What the values are, for the message.
    """
    with np.errstate(invalid="ignore"):
        some = np.any(rate > 0, axis=0)
    if not np.all(some):
        j = int(np.flatnonzero(~some)[0])
        raise InputError(
            f"band '{names[j]}' has no {what} above 0 at any epoch (every value empty, nan, "
            "zero or negative): it measured nothing; leave it out or check the file",
            source=src,
            field=field,
        )


def no_usable_epochs(
    n_epochs: int, scenario: str, src: str, field: str = "MEASURED", what: str = "measured"
) -> InputError:
    """The error for measurements none of whose epochs the scenario can model.

    Parameters
    ----------
    n_epochs
        Epochs measured.
    scenario
        The scenario's source, for the message.
    src, field
        The file and the field the error names.
    what
        What the epochs are (``"measured"``).
    """
    return InputError(
        f"none of the {n_epochs} {what} epochs is usable: the scenario {scenario} has the "
        "target below the minimum elevation, in daylight, unlit or without an orbit at every "
        "one of them; check the file's times against the scenario's orbit and site",
        source=src,
        field=field,
    )
