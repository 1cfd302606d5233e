"""``estimate_period`` on broken points and options that cannot finish (issue 22, items 3 and 10).

References: the searched range is the option's contract (the answer lies in it); a light
curve of less than one cycle cannot tell periods apart, so no period longer than the span
is searched; a band with no more points than its model's parameters adds nothing to the
periodogram, whose other band's power is then astropy's own ``LombScargle`` of that band
(VanderPlas & Ivezic 2015: the standard power of one band); worked-by-hand values.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from astropy.timeseries import LombScargle

from speclight.errors import InputError
from speclight.estimate import estimate_period
from speclight.estimate.period.period_run import _nulls_for_nan
from speclight.estimate.period.periodogram import BandSeries, multiband_power

START = np.datetime64("2020-02-29T21:16:00", "s")


def _csv(path: Path, n: int = 240, period_s: float = 37.0, huge_at: int | None = None,
         sigma_scale: float = 1.0) -> Path:  # fmt: skip
    """Two bands of a two-harmonic light curve (1e5, 5e4 s-1), fixed noise, sigma columns."""
    rng = np.random.default_rng(1)
    t = np.arange(n, dtype=float)
    x = 2 * np.pi * t / period_s
    mag = 0.3 * np.cos(x) + 0.1 * np.cos(2 * x + 0.5)
    rows = ["time,B1,B1_sigma,B2,B2_sigma"]
    for i in range(n):
        cells = [f"{START + np.timedelta64(i, 's')}Z"]
        for scale in (1e5, 5e4):
            rate = scale * 10 ** (-0.4 * mag[i])
            sigma = np.sqrt(rate)
            value = 1e20 if i == huge_at and scale == 1e5 else rate + rng.normal(0, sigma)
            sigma = np.sqrt(value) if i == huge_at and scale == 1e5 else sigma  # its shot noise
            cells += [f"{value:.6g}", f"{sigma * sigma_scale:.6g}"]
        rows.append(",".join(cells))
    path.write_text("\n".join(rows) + "\n")
    return path


def test_the_answer_lies_in_the_searched_range(tmp_path: Path) -> None:
    data = _csv(tmp_path / "lc.csv")
    # a range without the true 37 s: the best peak of 50..60 s is found at or inside its edges
    result = estimate_period(data, min_period_s=50.0, max_period_s=60.0, draws=3,
                             if_symmetric="keep")  # fmt: skip
    assert 50.0 <= result.decision.photometric_period_s <= 60.0
    out = result.to_json()
    assert all(np.isfinite(v) for v in (out["period_s"], out["best_power"]))


@pytest.mark.parametrize(
    ("kwargs", "field", "words"),
    [
        ({"max_period_s": 1e7, "min_period_s": 1e6}, "max_period_s", "longer than the 239 s"),
        ({"min_period_s": 300.0, "max_period_s": 400.0}, "max_period_s", "239 s"),
        ({"draws": 10**9}, "draws", "must be 1..10000"),
        ({"seed": -1}, "seed", ">= 0"),
        ({"min_period_s": 1e-6}, "min_period_s", "GiB of memory"),
        ({"bin_s": 1e9}, "bin_s", "not shorter than the 239 s"),
        ({"bin_s": 1e-300}, "bin_s", "at least 1e-09 s"),
    ],
)
def test_options_that_cannot_work_name_the_parameter(tmp_path: Path, kwargs, field, words) -> None:
    data = _csv(tmp_path / "lc.csv")
    with pytest.raises(InputError, match=words) as err:
        estimate_period(data, **kwargs)
    assert err.value.field == field


def test_broken_points_are_refused_with_their_epoch(tmp_path: Path) -> None:
    # 1e20: below the reader's 1e30 s-1 ceiling, 1e15 times the band's median
    with pytest.raises(InputError, match=r"band 'B1' at 2020-02-29T21:16:07.*times the band's"):
        estimate_period(_csv(tmp_path / "huge.csv", huge_at=7))
    # sigmas of ~1e-12 of the rate (the shot noise sqrt(1e5) times 1e-12 sqrt(1e5)): ~1e-12
    # mag, which no photometry reaches (weights 1/sigma^2 of 1e24 would drown the rest)
    with pytest.raises(InputError, match=r"accepted: at least 1e-06 mag"):
        estimate_period(_csv(tmp_path / "tiny.csv", sigma_scale=1e-12 * np.sqrt(1e5)))


def test_a_band_with_too_few_points_adds_nothing() -> None:
    rng = np.random.default_rng(2)
    t = np.sort(rng.uniform(0, 200, 150))
    y = np.sin(2 * np.pi * t / 23.0) + rng.normal(0, 0.1, t.size)
    dy = np.full(t.size, 0.1)
    series = BandSeries(
        np.concatenate([t, t[:3]]), np.concatenate([y, [1.0, 2.0, 0.5]]),
        np.concatenate([dy, [0.1, 0.1, 0.1]]), np.repeat([0, 1], [t.size, 3]), 2,
    )  # fmt: skip
    f = np.linspace(0.01, 0.2, 50)
    power = multiband_power(series, f, harmonics=2)  # 3 points, 5 parameters: band 1 out
    expected = LombScargle(t, y, dy, nterms=2).power(f, method="chi2", normalization="standard")
    np.testing.assert_allclose(power, expected, rtol=1e-9)
    alone = BandSeries(t[:3], y[:3], dy[:3], np.zeros(3, np.int64), 1)
    assert np.all(np.isnan(multiband_power(alone, f, harmonics=2)))


def test_nan_in_the_summary_becomes_null_and_is_listed() -> None:
    missing: list[str] = []
    summary = {"a": 1.0, "b": float("nan"), "c": [{"d": np.float64("inf")}]}
    out = _nulls_for_nan(summary, "", missing)
    assert out == {"a": 1.0, "b": None, "c": [{"d": None}]}
    assert missing == ["b", "c[0].d"]
