"""SPECTRL2 transmission: Rayleigh optical depth, Beer-Lambert scaling, horizon rows."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from speclight.atmosphere import airmass, transmission

GRID_NM = np.arange(300.0, 1241.0, 5.0)
RAYLEIGH_TOLERANCE = 0.03  # issue 4: Rayleigh optical depth within 3 % of Bucholtz 1995


# Wavelengths on SPECTRL2's own grid away from its O2 / mixed-gas bands (Bird & Riordan
# 1986, Table 1: absorption coefficients a_u are zero there).
CLEAN_NM = np.array([350.0, 400.0, 450.0, 500.0, 550.0, 600.0, 650.0, 800.0, 860.0, 1050.0])


def test_spectrl2_rayleigh_optical_depth_matches_bucholtz(bucholtz: Callable) -> None:
    t = transmission(
        "spectrl2", GRID_NM, [90.0], 0.0, water_vapour_cm=0.0, ozone_atm_cm=0.0, aod_500nm=0.0
    )[0]
    tau = -np.log(t) / airmass(90.0)
    idx = np.searchsorted(GRID_NM, CLEAN_NM)
    ref = bucholtz(CLEAN_NM)
    assert np.all(np.abs(tau[idx] / ref - 1) < RAYLEIGH_TOLERANCE)


def test_spectrl2_continuum_follows_beer_lambert() -> None:
    # At 550 nm extinction is Rayleigh + aerosol + ozone Chappuis continuum, so
    # -ln T is proportional to the airmass. SPECTRL2 uses a separate ozone airmass (layer
    # at 22 km) whose ratio to Kasten-Young's differs by < 1 % above 20 deg; ozone is ~15 %
    # of the optical depth at 550 nm, so the ratio must match to 0.3 %.
    el = np.array([90.0, 45.0, 30.0, 20.0])
    t = transmission("spectrl2", GRID_NM, el, 0.0)[:, np.searchsorted(GRID_NM, 550.0)]
    ratio = np.log(t) / np.log(t[0])
    assert np.allclose(ratio, airmass(el) / airmass(90.0), rtol=3e-3)


def test_spectrl2_rows_nan_below_horizon_and_pressure_lowers_extinction() -> None:
    t0 = transmission("spectrl2", GRID_NM, [45.0, -1.0, np.nan], 0.0)
    assert np.isfinite(t0[0]).all() and np.isnan(t0[1:]).all()
    assert np.all((t0[0] >= 0) & (t0[0] <= 1))
    # A site at 2 km has 21.5 % less air above it (U.S. Std. Atm. 1976): Rayleigh only.
    kw = {"water_vapour_cm": 0.0, "ozone_atm_cm": 0.0, "aod_500nm": 0.0}
    low = transmission("spectrl2", GRID_NM, [90.0], 0.0, **kw)[0, 20]
    high = transmission("spectrl2", GRID_NM, [90.0], 2000.0, **kw)[0, 20]
    assert np.isclose(np.log(high) / np.log(low), 79495.2 / 101325.0, rtol=1e-3)
