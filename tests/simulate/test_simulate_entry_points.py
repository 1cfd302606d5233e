"""Entering the pipeline where estimation needs it: given epochs, reused geometry, and each
material's contribution to the intensity.

References: the pipeline's own full runs (what a fit would otherwise recompute), and two
closed forms: a Lambertian surface reflects in proportion to its albedo (Lambert 1760), and
the sum of the materials' contributions is the rendered intensity (superposition: the
single-scattering render is linear in the light each pixel reflects).
"""

import numpy as np
import pytest
import yaml

from speclight.render import material_contributions, render_intensity
from speclight.scenario import parse_scenario
from speclight.scenario.builtin_examples import example_text
from speclight.simulation import simulate
from speclight.target import Material, Reflectance, target_from_spec

GEOMETRY_VARS = ("range", "elevation", "phase_angle", "sunlit", "observer_direction_body")
#: Relative rounding of float64 through a few hundred operations; epochs computed in arrays of
#: other lengths may take other SIMD/BLAS paths, so equal values may differ in the last bits.
ROUNDING = 1e-12


def assert_rounding_equal(got: np.ndarray, expected: np.ndarray, name: str) -> None:
    scale = float(np.nanmax(np.abs(expected))) if np.size(expected) else 0.0
    np.testing.assert_allclose(got, expected, rtol=ROUNDING, atol=ROUNDING * scale, err_msg=name)


def _calsphere(albedo=0.9, **render):
    d = yaml.safe_load(example_text("calsphere"))
    d["time"] = {"start": "2020-02-29T21:16:00Z", "stop": "2020-02-29T21:16:20Z", "step_s": 2.0}
    d["target"]["materials"]["body"]["reflectance"] = albedo
    d["render"] = {"mode": "single", "resolution_px": 64, **render}
    d["atmosphere"] = {"model": "none"}
    d["instrument"].pop("noise", None)
    return parse_scenario(yaml.safe_dump(d), source="test")


def test_simulate_at_given_epochs_equals_the_grid_run_there():
    loaded = _calsphere()
    full = simulate(loaded).dataset
    picked = full["time"].values[[1, 4, 7]]
    part = simulate(loaded, time_utc=picked).dataset
    np.testing.assert_array_equal(part["time"].values, picked)
    np.testing.assert_array_equal(part["flags"].values, full["flags"].values[[1, 4, 7]])
    for name in (*GEOMETRY_VARS, "attitude_quaternion"):
        assert_rounding_equal(part[name].values, full[name].values[[1, 4, 7]], name)
    np.testing.assert_allclose(
        part["count_rate"].values, full["count_rate"].values[[1, 4, 7]], rtol=1e-12
    )


def test_given_epochs_keep_the_attitude_clock_of_time_start():
    # a spinning target: its attitude at a given epoch is that of the grid run at the same
    # epoch (the clock starts at time.start, not at the first epoch given)
    d = yaml.safe_load(example_text("box-wing"))
    d["time"] = {"start": "2019-08-30T02:20:00Z", "stop": "2019-08-30T02:21:30Z", "step_s": 30.0}
    d["render"] = {"mode": "single", "resolution_px": 32}
    loaded = parse_scenario(yaml.safe_dump(d), source="test")
    grid = simulate(loaded).dataset
    given = simulate(loaded, time_utc=grid["time"].values[2:]).dataset
    for name in ("attitude_quaternion", "sun_direction_body", "observer_direction_body"):
        assert_rounding_equal(given[name].values, grid[name].values[2:], name)
    assert not np.array_equal(
        grid["attitude_quaternion"].values[0], given["attitude_quaternion"].values[0]
    )


def test_reused_geometry_reruns_only_reflection_and_radiometry():
    first = simulate(_calsphere(albedo=0.9))
    again = simulate(_calsphere(albedo=0.45), geometry=first.geometry)
    for name in GEOMETRY_VARS:
        np.testing.assert_array_equal(again.dataset[name].values, first.dataset[name].values)
    # Lambertian: intensity and count rates proportional to the albedo
    np.testing.assert_allclose(
        again.dataset["intensity"].values, 0.5 * first.dataset["intensity"].values, rtol=1e-12
    )
    np.testing.assert_allclose(
        again.dataset["count_rate"].values, 0.5 * first.dataset["count_rate"].values, rtol=1e-12
    )
    with pytest.raises(ValueError, match="not both"):
        simulate(_calsphere(), geometry=first.geometry, time_utc=first.dataset["time"].values)


def _box_wing(bus_albedo):
    shape = {"builtin": "box_wing", "bus_size_m": [1.0, 1.0, 1.5], "wing_span_m": 3.0,
             "wing_width_m": 1.2}  # fmt: skip
    materials = {
        "bus": {"bsdf": "lambertian", "reflectance": bus_albedo},
        "wing_+y": {"bsdf": "beckmann", "roughness": 0.2, "reflectance": 0.4},
        "wing_-y": {"bsdf": "beckmann", "roughness": 0.2, "reflectance": 0.4},
        "antenna": {
            "bsdf": "lambertian",
            "reflectance": {"wavelength_nm": [400, 900], "value": [0.2, 0.8]},
        },
    }
    return target_from_spec(shape, materials)


def test_material_contributions_sum_to_the_intensity_and_scale_with_albedo():
    rng = np.random.default_rng(5)
    sun = rng.normal(size=(6, 3))
    obs = sun + rng.normal(scale=0.8, size=(6, 3))
    wl = np.linspace(400.0, 900.0, 11)
    e = np.ones((6, wl.size))
    target = _box_wing(0.3)
    c = material_contributions(target, sun, obs, e, wl, resolution_px=64, variant="numpy")
    names = [m.name for m in target.materials]
    assert c.shape == (6, len(names), wl.size)
    total = render_intensity(target, sun, obs, e, wl, resolution_px=64, variant="numpy")
    np.testing.assert_allclose(c.sum(axis=1), total.intensity_W_sr_nm, rtol=1e-12, atol=1e-300)
    # doubling the bus albedo doubles its contribution and leaves the others alone: the
    # design matrix of an albedo fit
    doubled = render_intensity(_box_wing(0.6), sun, obs, e, wl, resolution_px=64, variant="numpy")
    k = names.index("bus")
    expected = c.sum(axis=1) + c[:, k]
    np.testing.assert_allclose(doubled.intensity_W_sr_nm, expected, rtol=1e-12, atol=1e-300)
    assert np.any(c[:, k] > 0)  # the bus is seen and lit: the check is not vacuous


def test_material_contributions_mark_bad_epochs_nan():
    grey = Material("grey", "lambertian", Reflectance.constant(0.5))
    from speclight.target import sphere

    c = material_contributions(
        sphere(1.0, grey), [[0, 0, 1], [np.nan, 0, 0]], [[0, 0, 1], [0, 0, 1]], [1.0, 1.0],
        [500.0, 600.0], resolution_px=16, variant="numpy",
    )  # fmt: skip
    assert np.all(np.isfinite(c[0])) and np.all(np.isnan(c[1]))
    # the Lambert sphere at zero phase: I = (2/3) rho E R^2 (Russell 1916), pixel error at 16 px
    np.testing.assert_allclose(c[0, 0], 2 / 3 * 0.5, rtol=0.03)
