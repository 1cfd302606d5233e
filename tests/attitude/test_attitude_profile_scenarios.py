"""The attitude profiles in scenario files and through the whole pipeline.

References: Lambert's cosine law for a flat plate, I = (rho / pi) A E cos(theta_i)
cos(theta_o) (Lambert 1760, *Photometria*), with the angles built from skyfield's
satellite, Sun (JPL DE421) and site positions and its WGS84 subpoint, not from speclight's
geometry; the yaw-steering law (Sun in the body x-z plane).
"""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
import yaml
from profile_pass import pass_scenario, skyfield_pass, unit
from skyfield.api import wgs84
from typer.testing import CliRunner

from speclight.cli import app
from speclight.errors import InputError
from speclight.orbit import load_ephemeris
from speclight.scenario import parse_scenario
from speclight.scenario.builtin_examples import example_text
from speclight.schema import FLAG_ATTITUDE_UNDEFINED, NOT_OBSERVABLE
from speclight.simulation import simulate

RES_PX = 256


@pytest.mark.parametrize(
    ("attitude", "message"),
    [
        ({"model": "nadir", "yaw_steer": True}, "did you mean 'yaw_steering'"),
        ({"model": "nadir", "nadir_type": "geodetc"}, "'geodetic' or 'geocentric'"),
        ({"model": "nadir", "yaw_sun_side": "x"}, "'\\+x' or '-x'"),
        ({"model": "sun_pointing", "constraint": "sun"}, "cannot fix the rotation"),
        ({"model": "sun_pointing", "constraint_axis_body": [0, 0, 3]}, "parallel"),
        ({"model": "sun_pointing", "pointing_axis_body": [0, 0, 0]}, "non-zero"),
        ({"model": "sun_pointing", "constraint_ra_deg": 3.0}, "only with constraint: radec"),
        ({"model": "inertial_pointing", "target_ra_deg": 1.0}, "target_dec_deg"),
        (
            {"model": "inertial_pointing", "target_ra_deg": 1, "target_dec_deg": 2,
             "constraint": "radec"},
            "needs constraint_ra_deg and constraint_dec_deg",
        ),
        ({"model": "target_pointing", "site_latitude_deg": 95, "site_longitude_deg": 0},
         "site_latitude_deg"),
        ({"model": "table"}, "missing required field 'file'"),
        ({"model": "nadri"}, "'nadir'"),
    ],
)  # fmt: skip
def test_profile_errors_name_the_field(attitude, message):
    with pytest.raises(InputError, match=message):
        parse_scenario(yaml.safe_dump(pass_scenario(attitude)), source="test")


def test_nadir_plate_follows_lamberts_law_with_skyfield_angles():
    # A Lambertian plate (normal along body z, both faces alike) on a nadir-pointing bus:
    # its face is the nadir direction, so I / E = (rho / pi) A |cos i cos o| where the Sun
    # and the site are on the same side of the plate.
    rho, w, h = 0.5, 2.0, 1.0
    d = pass_scenario({"model": "nadir"})
    d["target"] = {
        "shape": {"builtin": "plate", "width_m": w, "height_m": h},
        "materials": {"*": {"bsdf": "lambertian", "reflectance": rho}},
    }
    d["render"] = {"mode": "single", "resolution_px": RES_PX}
    d["spectrum"] = {"min_nm": 500, "max_nm": 600, "step_nm": 50}
    d["atmosphere"] = {"model": "none"}
    d["instrument"] = {"bands": [{"name": "G-550", "gaussian": {"center_nm": 550, "sigma_nm": 10}}]}
    result = simulate(parse_scenario(yaml.safe_dump(d), source="test"))
    ds, geo = result.dataset, result.geometry
    use = (ds["flags"].values & (NOT_OBSERVABLE | 8)) == 0  # observable, fully sunlit
    assert use.sum() >= 10
    sat, t = skyfield_pass(geo)
    g = sat.at(t)
    r = g.position.m.T
    nadir = unit(wgs84.subpoint_of(g).at(t).position.m.T - r)
    eph = load_ephemeris()
    sun = unit((eph["sun"] - eph["earth"]).at(t).position.m.T - r)
    site = wgs84.latlon(d["observer"]["latitude_deg"], d["observer"]["longitude_deg"],
                        elevation_m=d["observer"]["altitude_m"])  # fmt: skip
    obs = unit(site.at(t).position.m.T - r)
    cos_i, cos_o = np.sum(sun * nadir, axis=1), np.sum(obs * nadir, axis=1)
    expected = rho / np.pi * w * h * np.clip(cos_i * cos_o, 0.0, None)
    ratio = ds["intensity"].values / ds["solar_irradiance"].values
    # pixel-centre sampling: relative error <= perimeter * pitch / projected area (as in
    # tests/render/test_render_single_closed_forms.py); the Sun's aberration (apparent in
    # speclight, geometric here, 1e-4 rad) is far below it
    pitch = 2 * np.hypot(w / 2, h / 2) / RES_PX
    bound = 2 * (w + h) * pitch / (w * h * np.abs(cos_o))
    for k in np.flatnonzero(use):
        assert np.all(expected[k] > 0.0)
        np.testing.assert_allclose(ratio[k], expected[k], rtol=bound[k])
    # culmination: the site is seen near the plate's normal (the face is toward the site)
    top = int(np.nanargmax(geo.elevation_deg))
    assert ds["observer_direction_body"].values[top, 2] == pytest.approx(cos_o[top], abs=1e-6)
    assert cos_o[top] > np.cos(np.radians(10.0))


def test_cli_simulates_a_yaw_steered_box_wing_pass(tmp_path):
    d = yaml.safe_load(example_text("box-wing"))
    d["time"] = {"start": "2019-08-30T02:20:00Z", "stop": "2019-08-30T02:29:00Z", "step_s": 60.0}
    d["attitude"] = {"model": "nadir", "yaw_steering": True}
    d["render"] = {"mode": "single", "resolution_px": 16}
    d["atmosphere"] = {"model": "none"}
    d["instrument"].pop("noise")
    scenario, out = tmp_path / "nadir.yaml", tmp_path / "nadir.nc"
    scenario.write_text(yaml.safe_dump(d))
    result = CliRunner().invoke(app, ["simulate", str(scenario), "-o", str(out)])
    assert result.exit_code == 0, result.output
    with xr.open_dataset(out) as ds:
        assert "attitude_undefined" in ds["flags"].attrs["flag_meanings"]
        assert not np.any(ds["flags"].values & FLAG_ATTITUDE_UNDEFINED)
        observable = (ds["flags"].values & NOT_OBSERVABLE) == 0
        assert observable.sum() >= 8
        np.testing.assert_allclose(ds["sun_direction_body"].values[:, 1], 0.0, atol=1e-13)
        assert np.all(ds["intensity"].values[observable] > 0.0)
