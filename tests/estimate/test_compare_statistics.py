"""compare's statistics beside the RMS (Pearson R, chi-square) at their edges, and the
per-object lines on the terminal for few and for many objects."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.stats
import xarray as xr

from speclight.estimate.comparison.compare_stats import (
    LISTED_OBJECTS,
    WORST_OBJECTS,
    chi_square,
    pearson_r,
    per_object,
    residual_statistics,
    summary_lines,
)

#: float64 sums of a few dozen magnitudes ~8 agree to ~1e-15 relative.
STAT_RTOL = 1e-12


def test_pearson_r_and_chi_square_against_their_definitions() -> None:
    rng = np.random.default_rng(7)
    obs = rng.uniform(5.0, 9.0, 40)
    sim = obs + rng.normal(0.3, 0.5, 40)
    sim[[3, 11]] = np.nan  # not observable: left out
    ok = np.isfinite(sim)
    r_ref = scipy.stats.pearsonr(obs[ok], sim[ok]).statistic  # Pearson 1896
    np.testing.assert_allclose(pearson_r(obs, sim), r_ref, rtol=STAT_RTOL)
    # docs/compare.md: sum((m_sim - m_obs)^2 / m_obs) / N, summed term by term
    chi_ref = sum((m - o) ** 2 / o for o, m in zip(obs[ok], sim[ok], strict=True)) / ok.sum()
    np.testing.assert_allclose(chi_square(obs, sim), chi_ref, rtol=STAT_RTOL)


@pytest.mark.parametrize(
    ("obs", "sim"),
    [
        ([8.0], [8.5]),  # one pair: no correlation
        ([8.0, 8.0, 8.0], [7.0, 8.0, 9.0]),  # constant observed
        ([8.0, np.nan], [np.nan, 8.0]),  # no finite pair
    ],
)
def test_pearson_r_is_nan_where_undefined(obs: list[float], sim: list[float]) -> None:
    assert np.isnan(pearson_r(np.array(obs), np.array(sim)))


def test_chi_square_is_nan_for_a_magnitude_not_above_zero() -> None:
    # a bright object (magnitude -1) has no positive "count"
    assert np.isnan(chi_square(np.array([-1.0, 8.0]), np.array([-0.5, 8.2])))
    assert np.isnan(chi_square(np.array([np.nan]), np.array([8.0])))


def _dataset(n_objects: int) -> xr.Dataset:
    """A CMP.nc-like dataset: object j has 3 rows with residual 0.1 (j + 1) mag, except the
    last object, which has none (not observable)."""
    rng = np.random.default_rng(3)
    index = np.repeat(np.arange(n_objects), 3)
    obs = rng.uniform(6.0, 9.0, index.size)
    sim = obs - 0.1 * (index + 1)
    sim[index == n_objects - 1] = np.nan
    ds = xr.Dataset()
    ds.attrs.update(residual_statistics(obs, sim, np.full(obs.size, 50.0), np.full(obs.size, 40.0)))
    ds = ds.assign_coords(object=("object", [f"sat{j}" for j in range(n_objects)]))
    stats = per_object(obs, sim, index, n_objects)
    for key in ("n", "mean", "rms", "median_abs", "pearson_r", "chi_square"):
        name = "n_per_object" if key == "n" else f"{key}_per_object"
        if key in ("mean", "rms", "median_abs"):
            name = f"residual_{name}"
        ds[name] = ("object", stats[key])
    return ds


def test_few_objects_one_line_each() -> None:
    lines = summary_lines(_dataset(3))
    assert lines[-3].startswith("object sat0: n 3, mean +0.100 mag, RMS 0.100 mag")
    assert lines[-2].startswith("object sat1: n 3, mean +0.200 mag")
    assert lines[-1] == "object sat2: no residual (not observable at any of its rows)"


def test_many_objects_their_spread_and_the_worst() -> None:
    n = LISTED_OBJECTS + 5
    lines = summary_lines(_dataset(n))
    # RMS of object j is 0.1 (j + 1); the last object has none
    rms = 0.1 * np.arange(1, n)
    lo, mid, hi = np.percentile(rms, [10, 50, 90])
    assert lines[-2].startswith(
        f"{n} objects, {n - 1} with residuals: RMS per object median {mid:.3f} mag "
        f"(10-90 %: {lo:.3f}-{hi:.3f})"
    )
    worst = [f"sat{j}" for j in range(n - 2, n - 2 - WORST_OBJECTS, -1)]
    assert lines[-1] == "largest RMS: " + ", ".join(
        f"{name} {0.1 * (int(name[3:]) + 1):.3f} mag (n 3)" for name in worst
    )
