"""Laser ranging stage: link budget, bistatic geometry, horizon flag, bad input, Sun unchanged.

The link-budget reference is the standard laser-radar equation for the photo-electrons per
pulse from a target of optical cross-section sigma (Degnan 1993, "Millimeter accuracy
satellite laser ranging: a review", AGU Geodynamics Series 25, eq. 2.1 and 2.4,
doi:10.1029/GD025p0133), written out here, with the Lambertian sphere's cross-section at zero
phase sigma = 4 pi I/E = (8 pi / 3) rho r² (I = 2/3 rho E r², Hapke 2012, eq. 6.6).
"""

import numpy as np
import pytest
import yaml
from scipy import stats

from speclight.errors import InputError
from speclight.render import render_intensity
from speclight.render.session import RenderSession
from speclight.scenario import parse_scenario
from speclight.scenario.builtin_examples import example_text
from speclight.schema import FLAG_LASER_BELOW_HORIZON
from speclight.simulation.geometry_stage import scenario_geometry
from speclight.simulation.radiometry import (
    atmosphere_transmission,
    instrument_response,
    wavelength_grid_nm,
)
from speclight.simulation.ranging_stage import laser_ranging, prepare_ranging
from speclight.simulation.reflection import build_target

H, C = 6.62607015e-34, 299_792_458.0  # CODATA 2018, exact
STUTTGART = {"latitude_deg": 48.7822, "longitude_deg": 9.1967, "altitude_m": 355.0}
RADIUS_M, RHO = 0.18, 0.9
BAND_SIGMA_NM = 20.0
#: The band's response in the 1 nm bin at its centre is the bin average of the Gaussian.
BAND_AT_532 = float(
    np.sqrt(2 * np.pi) * BAND_SIGMA_NM * (2 * stats.norm.cdf(0.5 / BAND_SIGMA_NM) - 1)
)


def _laser(**kw):
    base = {"name": "slr", **STUTTGART, "wavelength_nm": 532.0, "linewidth_nm": 0.05}
    return base | {"power_w": 10.0, "repetition_rate_hz": 100.0, "divergence_arcsec": 10.0} | kw


def _scenario(lasers, sun=False):
    d = yaml.safe_load(example_text("calsphere"))
    d["time"] = {"start": "2020-02-29T21:17:00Z", "stop": "2020-02-29T21:17:02Z", "step_s": 1.0}
    d["illumination"] = {"sun": sun, "lasers": lasers}
    d["atmosphere"] = {"model": "none"}
    d["spectrum"] = {"min_nm": 400.0, "max_nm": 700.0, "step_nm": 1.0}
    d["render"] = {"mode": "single", "resolution_px": 128}
    d["instrument"] = {
        "optics_transmission": 1.0,
        "detector_qe": 1.0,
        "bands": [{"name": "wide", "gaussian": {"center_nm": 532.0, "sigma_nm": BAND_SIGMA_NM}}],
    }
    return parse_scenario(yaml.safe_dump(d), source="test")


def _run(loaded, variant=None):
    geo = scenario_geometry(loaded)
    wl = wavelength_grid_nm(loaded.scenario.spectrum)
    trans = atmosphere_transmission(loaded, wl, np.where(geo.observable, geo.elevation_deg, np.nan))
    rad = instrument_response(loaded, wl, np.zeros((geo.t_s.size, wl.size)), trans, geo.range_m)
    target = build_target(loaded)
    session = RenderSession.create("single", variant, target.materials)
    setup = prepare_ranging(loaded, geo, wl, target, session)
    assert setup is not None
    geo.flags = geo.flags | setup.flags  # as the pipeline merges the stages' flag bits
    return geo, laser_ranging(loaded, geo, setup, trans, rad)


def test_return_photons_per_pulse_match_the_laser_radar_equation():
    geo, res = _run(_scenario([_laser()]))
    assert np.all(geo.observable)
    r_up, r_down = res.laser_range_m[:, 0], geo.range_m
    # Degnan's link equation, monostatic, T = 1, eta = 1:
    energy_j = 10.0 / 100.0
    photons = energy_j * 532e-9 / (H * C)
    theta_t = 10.0 / 206264.80624709636 / 2  # 1/e² half-angle [rad]
    gain = 8.0 / theta_t**2
    sigma = 8.0 * np.pi / 3.0 * RHO * RADIUS_M**2
    area = np.pi * 0.43**2 / 4
    expected = photons * gain / (4 * np.pi * r_up**2) * sigma / (4 * np.pi * r_down**2) * area
    expected *= BAND_AT_532
    # pixel quadrature of the sphere's intensity at 128 px: 1.5e-4 (see the sphere tests)
    np.testing.assert_allclose(res.return_per_pulse[:, 0, 0], expected, rtol=1e-3)
    np.testing.assert_allclose(res.return_rate_per_s[:, 0], expected * 100.0, rtol=1e-3)
    # the transmitter at the receiver's site is seen at the receiver's range (same geometry)
    np.testing.assert_allclose(r_up, r_down, rtol=1e-9)
    # irradiance at the target: the beam's peak 2P/(pi w²), w = R theta/2
    w = r_up * 2 * theta_t / 2
    np.testing.assert_allclose(res.laser_irradiance_W_m2[:, 0], 2 * 10.0 / (np.pi * w**2))
    # range offset: the Lambertian sphere at zero phase, -3R/4 (see the sphere tests)
    np.testing.assert_allclose(res.range_offset_m[:, 0], -0.75 * RADIUS_M, rtol=1e-3)
    hist = res.range_histogram_per_s[:, 0]
    np.testing.assert_allclose(hist.sum(axis=1), res.return_rate_per_s[:, 0], rtol=1e-12)


def test_laser_below_its_horizon_flags_the_epoch_and_the_run_goes_on():
    antipode = _laser(name="far", latitude_deg=-48.78, longitude_deg=-170.8)
    geo, res = _run(_scenario([_laser(), antipode]))
    assert np.all(geo.flags & FLAG_LASER_BELOW_HORIZON)
    assert np.all(res.laser_elevation_deg[:, 1] < 0)
    assert np.all(res.laser_irradiance_W_m2[:, 1] == 0)
    assert np.all(res.return_per_pulse[:, 1, 0] == 0)
    assert np.all(res.return_per_pulse[:, 0, 0] > 0)  # the other laser still ranges
    assert any("below the transmitter's horizon" in n for n in res.notes)
    # with only the hidden laser there is no return: rate 0, offset undefined (NaN)
    _, alone = _run(_scenario([antipode]))
    assert np.all(alone.return_rate_per_s == 0) and np.all(np.isnan(alone.range_offset_m))


def test_bistatic_transmitter_lights_the_sphere_at_its_own_phase_angle():
    # a transmitter 300 km east: its direction differs from the receiver's
    east = _laser(name="east", longitude_deg=13.2, altitude_m=600.0)
    geo, res = _run(_scenario([east]))
    from speclight.orbit import Site
    from speclight.orbit.timescale import time_from_utc
    from speclight.ranging import transmitter_geometry

    t = time_from_utc(geo.time_utc)
    tx = transmitter_geometry(
        Site(48.7822, 13.2, 600.0), t, geo.r_target_gcrs_m, geo.quaternion_body_to_gcrs
    )
    a = np.arccos(np.einsum("nk,nk->n", tx.direction_body, geo.observer_direction_body))
    assert np.all(a > np.radians(5))
    irr = res.laser_irradiance_W_m2[:, 0]
    law = 2 / 3 * RHO * irr * RADIUS_M**2 * (np.sin(a) + (np.pi - a) * np.cos(a)) / np.pi
    # Lambert-sphere phase law (Hapke 2012, eq. 6.6); the terminator's pixel sampling <1e-2
    np.testing.assert_allclose(res.laser_intensity_W_sr_nm.sum(axis=1), law, rtol=1e-2)


@pytest.mark.parametrize(
    ("field", "value", "match"),
    [
        ("power_w", 0.0, "power_w"),
        ("power_w", -3.0, "power_w"),
        ("divergence_arcsec", 4.85e-5, "radians or degrees"),
        ("wavelength_nm", 1064.0, "spectrum grid"),
    ],
)
def test_bad_laser_inputs_are_refused(field, value, match):
    # the scenario model refuses the physics at load time, the stage the line outside the grid
    with pytest.raises(InputError, match=match) as err:
        _run(_scenario([_laser(**{field: value})]))
    assert field in str(err.value)


def test_sun_only_render_is_unchanged_by_the_ranging_hook():
    loaded = _scenario([], sun=True)
    geo = scenario_geometry(loaded)
    wl = wavelength_grid_nm(loaded.scenario.spectrum)
    target = build_target(loaded)
    session = RenderSession.create("single", None, target.materials)
    assert prepare_ranging(loaded, geo, wl, target, session) is None  # no lasers: nothing to do
    args = (
        build_target(loaded),
        geo.sun_direction_body,
        geo.observer_direction_body,
        np.ones((geo.t_s.size, wl.size)),
        wl,
    )
    plain = render_intensity(*args, resolution_px=64, variant="numpy")
    calls = []
    hooked = render_intensity(
        *args, resolution_px=64, variant="numpy", on_hits=lambda *a: calls.append(a[0])
    )
    assert calls and np.array_equal(np.concatenate(calls), np.arange(geo.t_s.size))
    np.testing.assert_array_equal(hooked.intensity_W_sr_nm, plain.intensity_W_sr_nm)


def test_outputs_have_units_and_write_to_netcdf(tmp_path):
    import xarray as xr

    loaded = _scenario([_laser()])
    geo, res = _run(loaded)
    wl = wavelength_grid_nm(loaded.scenario.spectrum)
    ds = xr.Dataset(coords={"time": geo.time_utc, "wavelength": wl, "band": ["wide"]})
    ds = res.add_to(ds)
    for name in (
        "range_histogram",
        "range_offset",
        "laser_irradiance",
        "laser_intensity",
        "return_photons_per_pulse",
        "return_rate",
        "range_bin",
    ):
        assert ds[name].attrs["units"] and ds[name].attrs["long_name"]
    assert ds["range_histogram"].dims == ("time", "band", "range_bin")
    assert ds["range_offset"].dims == ("time", "band")
    ds.to_netcdf(tmp_path / "r.nc", engine="h5netcdf")
    back = xr.open_dataset(tmp_path / "r.nc", engine="h5netcdf")
    np.testing.assert_array_equal(back["range_offset"].values, res.range_offset_m)


def test_path_mode_ranging_of_a_convex_sphere_equals_single_scattering():
    # a sphere has no interreflection: the multi-bounce tracer adds nothing (convexity)
    loaded = _scenario([_laser()])
    d = yaml.safe_load(loaded.yaml_text)
    d["render"] = {"mode": "path", "resolution_px": 64, "samples_per_pixel": 2}
    _, path = _run(parse_scenario(yaml.safe_dump(d), source="test"))
    d["render"] = {"mode": "single", "resolution_px": 64}
    _, single = _run(parse_scenario(yaml.safe_dump(d), source="test"))
    np.testing.assert_allclose(path.range_offset_m, single.range_offset_m, rtol=1e-12)
    np.testing.assert_allclose(path.return_rate_per_s, single.return_rate_per_s, rtol=1e-12)
