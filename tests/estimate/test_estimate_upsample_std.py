"""Upsampling with a source spectrum and with the albedos' standard deviations (issue 25 item 6).

References the code did not produce:

* the band averages weighted by the source (Nussbaum et al. 2022, eq. 5: the detected photons
  ``E R_j lambda dlambda``), written out here as bin sums;
* Monte Carlo (Mitsuba-style statistical test): the spread of the spectra upsampled from
  albedos drawn here with the given standard deviations (other draws than the code's) must
  match ``reflectance_std`` within the standard error of the ratio of two sample standard
  deviations, ``sqrt(1 / (2 (n1 - 1)) + 1 / (2 (n2 - 1)))``.
"""

from __future__ import annotations

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.estimate.spectra.upsampling import NOISE_DRAWS, upsample

WL_NM = np.arange(400.0, 1000.0 + 2.5, 5.0)
CENTRES_NM = np.linspace(450.0, 950.0, 5)
#: A non-flat source [W m-2 nm-1]: a smooth Sun-like hump times a rising transmission.
SOURCE = 1.9 * np.exp(-(((WL_NM - 480.0) / 380.0) ** 2)) * np.linspace(0.35, 0.95, WL_NM.size)
#: Monte Carlo draws here and the bound on |sample std / reflectance_std - 1|: four standard
#: errors of the ratio of two sample standard deviations.
DRAWS = 300
STD_TOLERANCE = 4.0 * np.sqrt(0.5 / (DRAWS - 1) + 0.5 / (NOISE_DRAWS - 1))


def _bands() -> np.ndarray:
    return np.exp(-0.5 * ((WL_NM[None, :] - CENTRES_NM[:, None]) / 45.0) ** 2)


def test_band_averages_weighted_by_the_source_are_reproduced() -> None:
    rho = np.array([0.2, 0.35, 0.5, 0.45, 0.6])
    response = _bands()
    result = upsample(rho, response, WL_NM, source_W_m2_nm=SOURCE)
    assert result.converged
    w = response * SOURCE * WL_NM * 5.0  # uniform grid: every bin 5 nm wide
    np.testing.assert_allclose((w @ result.reflectance) / w.sum(axis=1), rho, atol=1e-8)
    flat = upsample(rho, response, WL_NM).reflectance
    assert np.max(np.abs((w @ flat) / w.sum(axis=1) - rho)) > 1e-3  # the weighting matters


@pytest.mark.parametrize("rho", [[0.2, 0.35, 0.5, 0.45, 0.6], [0.4] * 5])
def test_reflectance_std_is_the_spread_over_albedo_noise(rho: list[float]) -> None:
    rho_a, std = np.array(rho), np.full(5, 0.004)
    result = upsample(rho_a, _bands(), WL_NM, source_W_m2_nm=SOURCE, albedo_std=std)
    assert result.reflectance_std is not None
    rng = np.random.default_rng(2025)
    spectra = np.array(
        [
            upsample(
                rho_a + rng.normal(0.0, std), _bands(), WL_NM, source_W_m2_nm=SOURCE
            ).reflectance
            for _ in range(DRAWS)
        ]
    )
    ratio = spectra.std(axis=0, ddof=1) / result.reflectance_std
    assert np.max(np.abs(ratio - 1.0)) < STD_TOLERANCE


def test_zero_std_gives_zero_and_bad_std_is_refused() -> None:
    rho = np.array([0.2, 0.35, 0.5, 0.45, 0.6])
    result = upsample(rho, _bands(), WL_NM, albedo_std=np.zeros(5))
    assert result.reflectance_std is not None and np.all(result.reflectance_std == 0.0)
    assert upsample(rho, _bands(), WL_NM).reflectance_std is None
    for bad in ([0.01] * 4, [0.01, -0.01, 0.01, 0.01, 0.01], [np.nan] * 5):
        with pytest.raises(InputError) as err:
            upsample(rho, _bands(), WL_NM, albedo_std=np.array(bad))
        assert err.value.field == "albedo_std"
    with pytest.raises(InputError) as err:
        upsample(rho, _bands(), WL_NM, source_W_m2_nm=-SOURCE)
    assert err.value.field == "source_W_m2_nm"
