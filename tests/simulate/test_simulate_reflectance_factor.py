"""The band reflectance factor of the simulate output (Nussbaum et al. 2022, eq. 5).

For a grey target (one constant reflectance) the intensity is ``I(lambda) = F E(lambda)`` with
a factor ``F`` that does not depend on wavelength, so every band's reflectance factor is the
same ``F``; for a Lambertian sphere of albedo rho and radius r it is the closed form
``F = (2 / (3 pi)) rho r^2 [sin a + (pi - a) cos a]`` at phase angle a (Russell 1916).
"""

import numpy as np
import yaml

from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate

#: Pixel quadrature of a 256 px sphere for phase angles up to ~120 deg (the sphere tests of
#: tests/render: worst 0.19 % at 150 deg).
SPHERE_RTOL = 5e-3


def test_grey_sphere_has_one_reflectance_factor_in_every_band():
    d = yaml.safe_load(example_text("calsphere"))
    d["time"] = {"start": "2020-02-29T21:13:00Z", "stop": "2020-02-29T21:19:00Z", "step_s": 20.0}
    d["instrument"].pop("noise", None)
    ds = simulate(parse_scenario(yaml.safe_dump(d), source="test")).dataset
    f = ds["reflectance_factor"]
    assert f.attrs["units"] == "m2 sr-1" and f.dims == ("time", "band")
    lit = (ds["flags"].values == 0) & (ds["sunlit"].values == 1.0)
    assert lit.sum() >= 5
    values = f.values[lit]
    # the same in every band (SPECTRL2 attenuation and the band curves cancel exactly)
    np.testing.assert_allclose(values, values[:, :1] * np.ones(values.shape[1]), rtol=1e-10)
    a = np.radians(ds["phase_angle"].values[lit])
    rho, r = 0.9, 0.18
    law = 2 / (3 * np.pi) * rho * r**2 * (np.sin(a) + (np.pi - a) * np.cos(a))
    np.testing.assert_allclose(values[:, 0], law, rtol=SPHERE_RTOL)
    # no light, no factor: epochs in the Earth's shadow or below the horizon are NaN
    dark = ds["sunlit"].values == 0
    assert dark.sum() >= 3  # the window starts in the Earth's shadow
    assert np.all(np.isnan(f.values[dark]))
