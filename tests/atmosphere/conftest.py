"""Fixtures of the atmosphere tests: a per-session 6S cache and a 6S availability check."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from speclight.atmosphere import SixSUnavailable, sixs_executable


@pytest.fixture(scope="session")
def sixs_cache(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A fresh 6S cache folder for this test session (never the user's cache)."""
    try:
        sixs_executable()
    except SixSUnavailable as exc:
        pytest.skip(f"6S executable cannot run here: {exc}")
    return tmp_path_factory.mktemp("sixs-cache")


def bucholtz_rayleigh_tau(wavelength_nm: np.ndarray) -> np.ndarray:
    """Rayleigh optical depth of the U.S. 1962 standard atmosphere at sea level.

    A. Bucholtz, "Rayleigh-scattering calculations for the terrestrial atmosphere",
    Appl. Opt. 34, 2765-2773 (1995), doi:10.1364/AO.34.002765, eq. 9 with the Table 5
    fit coefficients (separate fits below and above 0.5 um).
    """
    lam = wavelength_nm / 1000.0
    short = lam <= 0.5
    a = np.where(short, 6.50362e-3, 8.64627e-3)
    b = np.where(short, 3.55212, 3.99668)
    c = np.where(short, 1.35579, 1.10298e-2)
    d = np.where(short, 0.11563, 2.71393e-2)
    return a * lam ** -(b + c * lam + d / lam)


@pytest.fixture(scope="session")
def bucholtz() -> Callable[[np.ndarray], np.ndarray]:
    """Bucholtz (1995) Rayleigh optical depth at sea level as a function of wavelength [nm]."""
    return bucholtz_rayleigh_tau
