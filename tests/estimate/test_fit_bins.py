"""``fit --bin-s``: measurements and model averaged over the same epochs
(estimate/fitting/fit_bins.py).

References: bin averages worked by hand; the reflectance a spinning cube was simulated with
(0.6), recovered from bins as long as a quarter turn, where the light curve goes through a
whole glint in every bin (the model at a bin's mean epoch is no stand-in for its mean
there); the bounds of ``bin_s`` (the epochs' time resolution, the data's span).
"""

from pathlib import Path

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.estimate import fit_scenario
from speclight.estimate.fitting.fit_bins import EpochBins
from speclight.estimate.inputs.measured import MeasuredLightCurve
from speclight.scenario import parse_scenario
from speclight.simulation import simulate

DATA = Path(__file__).parent / "data"
T0 = np.datetime64("2020-01-01T00:00:00", "ns")


def test_bins_average_the_used_entries_by_hand() -> None:
    t = T0 + np.array([0, 1, 2, 3, 10, 11], dtype="timedelta64[s]")
    use = np.array([[1, 1], [1, 0], [0, 0], [1, 1], [0, 1], [0, 0]], dtype=bool)
    bins = EpochBins.of(t, 5.0, use)
    # bin 0: epochs 0, 1, 3 used (epoch 2 has none): mean epoch 4/3 s; bin 1: epoch 10 only
    assert bins.n_bins == 2
    assert bins.time_utc[0] == T0 + np.timedelta64(1_333_333_333, "ns")
    assert bins.time_utc[1] == T0 + np.timedelta64(10, "s")
    v = np.array([[1.0, 10], [2, 99], [99, 99], [6, 30], [99, 7], [99, 99]])
    np.testing.assert_allclose(bins.mean(v), [[3.0, 20.0], [np.nan, 7.0]])
    # derivatives (K, N, B) along axis 1: the same averages per parameter
    twice = bins.mean(np.stack([v, 2 * v]), axis=1)[1]
    np.testing.assert_allclose(twice, [[6.0, 40.0], [np.nan, 14.0]])
    # sigma of a mean of n independent values: sqrt(sum sigma^2) / n
    s = np.array([[3.0, 1], [4, 1], [1, 1], [0, 2], [1, 5], [1, 1]])
    np.testing.assert_allclose(bins.sigma(s), [[5 / 3, np.sqrt(5) / 2], [np.nan, 5.0]])


def _cube(reflectance: float) -> str:
    text = (DATA / "spinning_cube.yaml").read_text()
    return text.replace("reflectance: 0.6", f"reflectance: {reflectance}")


def test_binned_fit_of_a_glinting_cube_recovers_its_reflectance() -> None:
    truth = simulate(parse_scenario(_cube(0.6), source="truth")).dataset
    rate = truth["count_rate_measured"].transpose("time", "band").values
    n = truth.sizes["time"]
    measured = MeasuredLightCurve(
        truth["time"].values, ["B", "R"], rate, None, np.ones(n, np.int64), "test"
    )
    start = parse_scenario(_cube(0.3), source="start")
    # 7.5 s: a quarter turn of the 30 s spin, one glint of the four per turn in every bin
    fit = fit_scenario(start, measured, bin_s=7.5)
    assert fit.converged, fit.message
    assert fit.n_epochs == 9  # 0..60 s (both ends) in 7.5 s bins: 8 full, the last epoch
    error = np.abs(fit.albedo - 0.6)
    assert np.all(error < 4 * fit.albedo_std), (fit.albedo, fit.albedo_std)
    assert np.all(error < 0.02 * 0.6), fit.albedo


@pytest.mark.filterwarnings("ignore::speclight.orbit.staleness.StaleInputWarning")
def test_bin_s_bounds_and_unusable_measurements() -> None:
    t = T0 + np.arange(30).astype("timedelta64[s]")
    lc = MeasuredLightCurve(t, ["B", "R"], np.ones((30, 2)), None, np.ones(30, np.int64), "lc")
    start = parse_scenario(_cube(0.3), source="start")
    with pytest.raises(InputError, match=r"bin_s = 100 s is not shorter than the 29 s"):
        fit_scenario(start, lc, bin_s=100.0)
    with pytest.raises(InputError, match=r"bin_s = 1e-12 must be a duration of at least 1e-09 s"):
        fit_scenario(start, lc, bin_s=1e-12)
    # 2020-01-01 00:00 UTC (half a year before the TLE's epoch, hence the filter): the cube's
    # orbit (LCS 1) is below the site's horizon at all 30 epochs
    with pytest.raises(InputError, match=r"no measured rate can be fitted.*below_min_elevation"):
        fit_scenario(start, lc)
