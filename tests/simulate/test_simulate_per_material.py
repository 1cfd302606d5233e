"""Per-material ground truth (render.per_material) and the laser reflectance factor.

* The per-material shares go through the same linear chain as the total, so they sum to
  ``reflectance_factor`` (and ``laser_reflectance_factor``) over the materials to rounding.
* Eq. 5 with the lasers' lines instead of the Sun (SPEC section 5): a Lambertian sphere of
  constant albedo rho and radius r lit by coaxial lasers (phase angle 0) has the same factor
  in every band that sees a line, ``F = (2/3) rho r^2``: the Lambert-sphere phase law
  ``(2 / (3 pi)) rho r^2 [sin a + (pi - a) cos a]`` (Russell 1916; Hapke 2012, eq. 6.6)
  at a = 0, the value the Sun's reflectance factor takes for the same geometry.
"""

import numpy as np
import pytest
import yaml

from speclight.errors import InputError
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate

#: Sums of 6 materials' shares against the total: float64 rounding of a few-term sum.
SUM_RTOL = 1e-12
#: Pixel quadrature of a 256 px sphere (tests/simulate/test_simulate_reflectance_factor.py).
SPHERE_RTOL = 5e-3


def _cube(name: str, **render):
    d = yaml.safe_load(example_text(name))
    d["time"] = {"start": "2019-08-30T02:21:00Z", "stop": "2019-08-30T02:23:00Z", "step_s": 4.0}
    d["render"].update({"resolution_px": 32, **render})
    return simulate(parse_scenario(yaml.safe_dump(d), source="test")).dataset


def test_material_shares_sum_to_the_reflectance_factor():
    ds = _cube("cube-materials")
    share = ds["reflectance_factor_material"]
    assert share.dims == ("time", "material", "band") and share.attrs["units"] == "m2 sr-1"
    assert list(ds["material"].values) == ["+x", "-x", "+y", "-y", "+z", "-z"]
    assert list(ds["material_reflectance"].values) == [
        "solar_cell",
        "solar_cell",
        "kapton_mli",
        "kapton_mli",
        "aluminium",
        "white_paint",
    ]
    total = ds["reflectance_factor"].values
    assert np.isfinite(total).all()
    np.testing.assert_allclose(share.sum("material").values, total, rtol=SUM_RTOL)
    assert np.all(share.values >= 0)
    assert "laser_reflectance_factor_material" not in ds


def test_laser_material_shares_sum_to_the_laser_reflectance_factor():
    ds = _cube("cube-materials-laser")
    total = ds["laser_reflectance_factor"].values
    assert np.isfinite(total).all() and np.all(total > 0)
    np.testing.assert_allclose(
        ds["laser_reflectance_factor_material"].sum("material").values, total, rtol=1e-10
    )
    # the Sun is off: no solar reflectance factor, no solar shares
    assert np.isnan(ds["reflectance_factor"].values).all()
    assert "reflectance_factor_material" not in ds


def test_per_material_needs_single_mode():
    d = yaml.safe_load(example_text("cube-materials"))
    d["render"].update({"mode": "path"})
    with pytest.raises(InputError, match="per_material: true needs mode: single"):
        parse_scenario(yaml.safe_dump(d), source="test")


def test_grey_sphere_under_coaxial_lasers_has_the_zero_phase_factor_in_every_band():
    d = yaml.safe_load(example_text("calsphere"))
    d["time"] = {"start": "2020-02-29T21:16:00Z", "stop": "2020-02-29T21:19:00Z", "step_s": 30.0}
    d["instrument"].pop("noise", None)
    site = {k: d["observer"][k] for k in ("latitude_deg", "longitude_deg", "altitude_m")}
    d["illumination"] = {
        "sun": False,
        "lasers": [
            {
                "name": f"l{w}",
                **site,
                "wavelength_nm": w,
                "linewidth_nm": 0.5,
                "power_w": 10.0,
                "repetition_rate_hz": 1000.0,
                "divergence_arcsec": 10.0,
            }
            for w in (450.0, 635.0, 1064.0)
        ],
    }
    ds = simulate(parse_scenario(yaml.safe_dump(d), source="test")).dataset
    f = ds["laser_reflectance_factor"]
    assert f.attrs["units"] == "m2 sr-1" and f.dims == ("time", "band")
    seen = ds["flags"].values == 0
    assert seen.sum() >= 5
    values = f.values[seen]
    # every band of calsphere (B, G, R, V and three SPADs) sees a line through its tails
    np.testing.assert_allclose(values, values[:, :1] * np.ones(values.shape[1]), rtol=1e-10)
    rho, r = 0.9, 0.18
    np.testing.assert_allclose(values, 2.0 / 3.0 * rho * r**2, rtol=SPHERE_RTOL)
