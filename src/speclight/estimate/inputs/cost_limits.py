"""Up-front limits of the estimation commands: sizes a user controls, checked before any work.

``speclight simulate`` refuses a run that cannot fit in memory (:mod:`speclight.simulation.
memory`); the estimators do the same for what their options and inputs make large: the
period's frequency grid and bootstrap draws, the spin-axis grid, phases and map resampling,
the bins of ``--bin-s``. Each check raises an :class:`~speclight.errors.InputError` naming
the **Python parameter** (``n_phases``, ``draws``...; the command line says its flag) with
the estimate, the limit and what to reduce.

* **Memory**: the estimate against :func:`speclight.simulation.memory.memory_limit_bytes`
  (half the physical memory, or the process limit).
* **Time**: the estimate against :data:`MAX_SECONDS`, one day, the limit ``simulate`` puts
  on a path-mode render: the output is written only at the end, so a longer run risks
  losing everything to one interruption. The rates behind the estimates were measured on
  the development machine (2 cores shared with other jobs; BENCHMARKS.md, "Estimator
  limits", ``bench/bench_estimator_limits.py``), within about 20 % there; against a limit of
  a day only their order of magnitude matters.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError

#: Longest estimated run accepted [s]: one day (module docstring).
MAX_SECONDS = 86_400.0
#: Estimated runs longer than this [s] are announced before they start.
ANNOUNCE_SECONDS = 60.0
#: Shortest bin accepted [s]: the time resolution of the epochs (``datetime64[ns]``).
MIN_BIN_S = 1e-9


def gib(n_bytes: float) -> str:
    """``n_bytes`` in GiB, 3 significant digits."""
    return f"{n_bytes / 1024**3:.3g} GiB"


def duration(seconds: float) -> str:
    """A duration in s, min, h or days, 3 significant digits."""
    for unit, size in (("days", 86_400.0), ("h", 3600.0), ("min", 60.0)):
        if seconds >= 2 * size:
            return f"{seconds / size:.3g} {unit}"
    return f"{seconds:.3g} s"


def check_cost(
    field: str, value: object, what: str, n_bytes: float, seconds: float, reduce: str
) -> None:
    """Refuse a run whose memory or time estimate is over the limit (module docstring).

    Parameters
    ----------
    field
        The Python parameter that makes it large (the error's field).
    value
        Its value, as given.
    what
        What is large, with its sizes in words (e.g. ``"the frequency grid of 1e9 x 2
        bands"``).
    n_bytes, seconds
        The estimates [bytes], [s].
    reduce
        What to reduce, in words.
    """
    from speclight.simulation.memory import memory_limit_bytes

    limit = memory_limit_bytes()
    if n_bytes > limit:
        raise InputError(
            f"{field} = {value}: {what} needs about {gib(n_bytes)} of memory, more than the "
            f"limit of {gib(limit)} (half the physical memory, or the process limit); "
            f"{reduce}",
            field=field,
        )
    if seconds > MAX_SECONDS:
        raise InputError(
            f"{field} = {value}: {what} would take about {duration(seconds)}, more than the "
            f"limit of {duration(MAX_SECONDS)}; {reduce}",
            field=field,
        )


def check_bin_s(bin_s: float, time_utc: NDArray[np.datetime64], field: str = "bin_s") -> None:
    """Refuse a bin that is not a duration from :data:`MIN_BIN_S` to the data's time span.

    A shorter bin is below the epochs' time resolution; a bin as long as the span averages
    the whole pass into one value, which no estimator can use (the light curve's shape is
    what they fit).

    Parameters
    ----------
    bin_s
        The bin [s].
    time_utc
        (N,) the epochs to bin.
    field
        The parameter's name in the message.
    """
    if not (np.isfinite(bin_s) and bin_s >= MIN_BIN_S):
        raise InputError(
            f"{field} = {bin_s!r} must be a duration of at least {MIN_BIN_S:g} s", field=field
        )
    t = np.asarray(time_utc, dtype="datetime64[ns]")
    span_s = float((t.max() - t.min()) / np.timedelta64(1, "s")) if t.size else 0.0
    if bin_s >= span_s:
        raise InputError(
            f"{field} = {bin_s:g} s is not shorter than the {span_s:g} s that the {t.size} "
            "epochs span: every epoch would fall in one bin, and the light curve's shape, "
            f"which the estimate needs, would be lost; give a bin shorter than {span_s:g} s",
            field=field,
        )


def time_span_text(time_utc: NDArray[np.datetime64]) -> str:
    """``"2020-02-29T21:15:00 .. 2020-02-29T21:17:00 UTC (61 epochs)"``."""
    t = np.asarray(time_utc, dtype="datetime64[s]")
    if t.size == 0:
        return "no epochs"
    return f"{t.min()} .. {t.max()} UTC ({t.size} epochs)"


__all__ = [
    "ANNOUNCE_SECONDS",
    "MAX_SECONDS",
    "MIN_BIN_S",
    "check_bin_s",
    "check_cost",
    "duration",
    "gib",
    "time_span_text",
]
