"""Path mode in a scalar variant (the fallback without libLLVM 16-19): the scene's mesh
buffers are Dr.Jit dynamic arrays there, not ``mi.Float`` (a single number in scalar
variants), and building the scene failed for every mesh."""

from __future__ import annotations

import numpy as np
import pytest

from speclight.render import available_variants, render_intensity
from speclight.target import Material, Reflectance, plate

pytestmark = pytest.mark.skipif(
    "scalar_spectral" not in available_variants(), reason="Mitsuba's scalar_spectral variant"
)
#: Standard errors of path mode's Monte Carlo estimate allowed (a z-test at 4 sigma).
Z_MAX = 4.0


def test_lambertian_plate_in_scalar_spectral_path_mode() -> None:
    rho = 0.5
    target = plate(1.0, 1.0, Material("p", "lambertian", Reflectance.constant(rho)))
    sun = np.array([[0.0, 0.0, 1.0]])
    obs = np.array([[0.3, 0.0, 1.0]]) / np.hypot(0.3, 1.0)
    wl = np.array([450.0, 650.0])
    res = render_intensity(
        target, sun, obs, np.ones((1, 2)), wl, mode="path", resolution_px=16,
        samples_per_pixel=8, variant="scalar_spectral", seed=1,
    )  # fmt: skip
    # Lambert: I = rho / pi * A * cos_i * cos_o * E (area 1 m2, E = 1 W m-2 nm-1)
    expected = rho / np.pi * 1.0 * 1.0 * float(obs[0, 2])
    err = res.intensity_std_W_sr_nm[0]
    assert np.all(err > 0)
    assert np.all(np.abs(res.intensity_W_sr_nm[0] - expected) <= Z_MAX * err)
