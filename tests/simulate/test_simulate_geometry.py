"""The geometry stage of the pipeline, end to end from scenario text to dataset."""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from speclight.errors import InputError
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate
from speclight.simulation.geometry_stage import time_grid


def _scenario(name: str = "lcs1", **changes: object) -> str:
    """A built-in scenario without its target: geometry only, nothing rendered."""
    data = yaml.safe_load(example_text(name))
    data.pop("target")
    data.update(changes)
    return yaml.safe_dump(data, sort_keys=False)


def test_time_grid_includes_stop_on_grid_only() -> None:
    loaded = parse_scenario(example_text("lcs1"))
    grid = time_grid(loaded.scenario.time)
    assert grid.size == 21 * 60 // 2 + 1
    assert str(grid[-1]) == "2020-07-18T01:38:00.000000000"


@pytest.mark.parametrize(
    "attitude",
    [
        {
            "model": "fixed",
            "z_axis_ra_deg": 10,
            "z_axis_dec_deg": 20,
            "x_axis_ra_deg": 100,
            "x_axis_dec_deg": 0,
        },
        {"model": "spin", "spin_axis_ra_deg": 30, "spin_axis_dec_deg": 45, "period_s": 12},
        {
            "model": "torque_free",
            "inertia_kg_m2": [1.0, 2.0, 3.0],
            "initial_attitude": {"quaternion": [1, 0, 0, 0]},
            "angular_velocity_body_rad_s": [0.1, 0.3, 0.05],
        },
    ],
)
def test_body_frame_preserves_the_phase_angle(attitude: dict[str, object]) -> None:
    # A rotation preserves angles: the angle between the body-frame Sun and observer
    # directions must equal the phase angle computed in GCRS, for any attitude model.
    ds = simulate(parse_scenario(_scenario(attitude=attitude))).dataset
    sun = ds["sun_direction_body"].values
    obs = ds["observer_direction_body"].values
    angle = np.degrees(np.arccos(np.clip(np.sum(sun * obs, axis=1), -1, 1)))
    np.testing.assert_allclose(angle, ds["phase_angle"].values, atol=1e-8)
    bisector = (sun + obs) / np.linalg.norm(sun + obs, axis=1, keepdims=True)
    np.testing.assert_allclose(ds["phase_vector_body"].values, bisector, atol=1e-12)


def test_shadow_flags_follow_sunlit_fraction() -> None:
    ds = simulate(parse_scenario(_scenario("calsphere"))).dataset
    sunlit, flags = ds["sunlit"].values, ds["flags"].values
    assert np.any(sunlit == 0) and np.any(sunlit == 1), "the example crosses the shadow edge"
    np.testing.assert_array_equal((flags & 4) > 0, sunlit <= 0)
    np.testing.assert_array_equal((flags & 8) > 0, (sunlit > 0) & (sunlit < 1))


def test_tle_checksum_error_names_scenario_field() -> None:
    text = example_text("lcs1").replace("0  9994", "0  9995")
    with pytest.raises(InputError, match=r"orbit\.tle.*checksum"):
        simulate(parse_scenario(text, source="my.yaml"))


def test_orbit_sources_agree_through_the_pipeline(tmp_path) -> None:
    # The shipped CPF sample was generated from the same LCS 1 element set that the lcs1
    # example uses (src/speclight/data/cpf/README.md), so ranges through both readers must
    # agree to the CPF's 1 mm rounding plus its interpolation error (< 1 cm, tests/orbit).
    from importlib.resources import files

    cpf = files("speclight") / "data" / "cpf" / "lcs1_20201127_speclight_sgp4.cpf"
    tle = files("speclight") / "data" / "tle" / "calibration_spheres.tle"
    window = {"start": "2020-11-27T17:30:00Z", "stop": "2020-11-27T17:40:00Z", "step_s": 20.0}
    ranges = []
    for orbit in ({"cpf_file": str(cpf)}, {"tle_file": str(tle), "norad_id": 1361}):
        text = _scenario(time=window, orbit=orbit)
        ranges.append(simulate(parse_scenario(text, base_dir=tmp_path)).dataset["range"].values)
    np.testing.assert_allclose(ranges[0], ranges[1], rtol=0, atol=0.05)


def test_light_time_range_solves_the_light_time_equation(tmp_path) -> None:
    # A target moving on a straight line in GCRS, r(t) = r0 + v t: the one-way light time
    # tau of a signal received at t solves |r0 + v (t - tau) - o(t)| = c tau, a quadratic
    # (v.v - c^2) tau^2 - 2 (v.d) tau + d.d = 0 with d = r0 + v t - o(t) (Montenbruck & Gill
    # 2000, sec. 6.2.1). The reported range must be c tau.
    from speclight import orbit
    from speclight.orbit.timescale import time_from_utc

    c = 299_792_458.0
    r0 = np.array([2.0e6, 5.0e6, 4.5e6])
    v = np.array([-6.0e3, 2.5e3, 3.0e3])  # 7 km/s, LEO-like speed
    t0 = np.datetime64("2020-07-18T01:00:00", "ns")
    rows = ["# frame: GCRS", "time_utc,x_m,y_m,z_m"]
    for k in range(-20, 81):
        r = r0 + v * 10.0 * k
        rows.append(
            f"{np.datetime_as_string(t0 + np.timedelta64(10 * k, 's'))}Z,"
            f"{r[0]:.6f},{r[1]:.6f},{r[2]:.6f}"
        )
    eph = tmp_path / "line.csv"
    eph.write_text("\n".join(rows) + "\n")
    window = {"start": "2020-07-18T01:00:00Z", "stop": "2020-07-18T01:10:00Z", "step_s": 60.0}
    observer = {
        "latitude_deg": 48.7822,
        "longitude_deg": 9.1967,
        "altitude_m": 355,
        "min_elevation_deg": -90,
    }
    text = _scenario(time=window, orbit={"ephemeris_file": str(eph)}, observer=observer)
    ds = simulate(parse_scenario(text)).dataset
    times = ds["time"].values
    t_s = (times - t0) / np.timedelta64(1, "s")
    o = orbit.site_position_gcrs_m(orbit.Site(48.7822, 9.1967, 355.0), time_from_utc(times))
    d = r0 + v * t_s[:, None] - o
    a, b, cc = v @ v - c**2, -2 * d @ v, np.sum(d * d, axis=1)
    tau = (-b - np.sqrt(b * b - 4 * a * cc)) / (2 * a)  # the positive root (a < 0)
    # 1 mm: the fixed-point iteration leaves < 0.3 mm, the 1 ns time rounding 7 um
    np.testing.assert_allclose(ds["range"].values, c * tau, rtol=0, atol=1e-3)
    # and it differs from the geometric range by about the radial speed times tau
    no_delay = _scenario(
        time=window,
        orbit={"ephemeris_file": str(eph)},
        observer={**observer, "light_time": False},
    )
    geometric = simulate(parse_scenario(no_delay)).dataset["range"].values
    assert np.all(np.abs(ds["range"].values - geometric) > 1.0)


def test_geometry_only_run_allocates_no_spectra() -> None:
    # issue 9 (fuzz/0019): a run without a target built (N, 189) solar irradiance and
    # transmission arrays; 2e6 such epochs died with MemoryError
    loaded = parse_scenario(_scenario(), source="test")
    result = simulate(loaded)
    ds = result.dataset
    assert "wavelength" not in ds.dims and "solar_irradiance" not in ds and "transmission" not in ds
    assert {"range", "elevation", "phase_angle", "sunlit", "flags"} <= set(ds.data_vars)
    assert ds.sizes["time"] == result.geometry.t_s.size
