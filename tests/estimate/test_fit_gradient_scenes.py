"""``fit --method gradient`` on articulated targets and with Earthshine (issue 15, item 2).

References, as in test_fit_gradient.py:

* the pass's count rates against ``simulate``'s ``count_rate`` on the same geometry (the
  pipeline's own pose grouping and Earthshine cells: a pose rounded differently, or the
  Earthshine rendered on the posed target, changes the rates by far more than 1e-12);
* the derivatives against central differences of the full ``simulate`` at steps h and h/2
  (the truncation bound of test_fit_gradient.py's module doc);
* the fit: recovery of the roughness the noisy data were simulated with (Poisson draws,
  fixed seed), from a start a factor 4 away, to within 3 of the fit's standard deviations.

Scenes: the ``starlink-v1.5`` example (a Sun-tracking array about the nadir axis, 0.25 deg
pose steps) with its array made GGX (its shipped materials are lab-measured tables, which
have no roughness), and the spinning Beckmann cube of test_fit_gradient.py with Earthshine.
"""

from pathlib import Path

import numpy as np
import pytest
import yaml

from speclight.estimate import fit_scenario
from speclight.estimate.fitting.roughness_gradient import RoughnessRates
from speclight.estimate.inputs.measured import MeasuredLightCurve
from speclight.render.articulated import pose_groups
from speclight.scenario import example_text, parse_scenario
from speclight.scenario.overrides import replace_fields
from speclight.simulation import simulate

DATA = Path(__file__).parent / "data"
ARRAY = {"bsdf": "ggx", "roughness": 0.1, "reflectance": 0.3}


def _starlink(earthshine=False, noise=False):
    d = yaml.safe_load(example_text("starlink-v1.5"))
    d["render"]["resolution_px"] = 32
    d["target"]["materials"]["array"] = dict(ARRAY)
    if earthshine:
        d["illumination"]["earthshine"] = {"albedo": 0.3, "samples": 16}
    if noise:
        d["instrument"]["noise"] = {"seed": 5}
    return d


def _cube_earthshine(sun=True):
    d = yaml.safe_load((DATA / "spinning_cube.yaml").read_text())
    del d["instrument"]["noise"]
    d["time"]["step_s"] = 1.0
    d["illumination"] = {"sun": sun, "earthshine": {"albedo": 0.3, "samples": 16}}
    return d


SCENES = {
    "articulated": (_starlink, "array", 0.1),
    "articulated+earthshine": (lambda: _starlink(earthshine=True), "array", 0.1),
    "earthshine": (_cube_earthshine, "*", 0.12),
    "earthshine-only": (lambda: _cube_earthshine(sun=False), "*", 0.12),
}


def _setup(scene):
    make, material, alpha = SCENES[scene]
    loaded = parse_scenario(yaml.safe_dump(make()), source=scene)
    base = simulate(loaded)
    ref = base.dataset["count_rate"].transpose("time", "band").values
    return loaded, base, ref, material, alpha


@pytest.mark.parametrize("scene", list(SCENES))
def test_rates_equal_simulate(scene):
    loaded, base, ref, material, alpha = _setup(scene)
    n = ref.shape[0]
    rates = RoughnessRates(loaded, base.geometry, [material], np.ones(n, bool))
    refl = rates.reflection
    if "articulated" in scene:
        poses = pose_groups(refl.angles, refl.step_deg)[0]
        assert len(poses) > 10  # the array turns through many poses over the pass
    if "earthshine" in scene:
        assert refl.cells is not None and refl.cells.epoch.size > refl.n  # > 1 cell an epoch
    c, _ = rates(np.array([alpha]))
    np.testing.assert_array_equal(np.isfinite(c), np.isfinite(ref))
    assert np.count_nonzero(ref > 0) > 60
    np.testing.assert_allclose(c, ref, rtol=1e-12, atol=0)
    # a subset of the epochs (the fit's usable ones) gives the same rates there, NaN elsewhere
    use = np.random.default_rng(1).random(n) < 0.5
    part, _ = RoughnessRates(loaded, base.geometry, [material], use)(np.array([alpha]))
    np.testing.assert_allclose(part[use], ref[use], rtol=1e-12, atol=0)
    assert np.all(np.isnan(part[~use]))


@pytest.mark.parametrize("scene", ["articulated", "earthshine-only"])
def test_derivatives_match_central_differences_of_simulate(scene):
    loaded, base, ref, material, alpha = _setup(scene)
    rates = RoughnessRates(loaded, base.geometry, [material], np.ones(ref.shape[0], bool))
    _, jac = rates(np.array([alpha]))

    def sim(a):
        run = simulate(
            replace_fields(loaded, {f"target.materials.{material}.roughness": a}),
            geometry=base.geometry,
        )
        return run.dataset["count_rate"].transpose("time", "band").values

    fd = [(sim(alpha + h) - sim(alpha - h)) / (2 * h) for h in (2e-3, 1e-3)]
    size = np.nanmax(np.abs(jac[0]))
    assert size > 0
    error = np.nanmax(np.abs(jac[0] - fd[1]))
    # max-norm truncation bound, rounding 1e-13 of the rates over h (test_fit_gradient.py)
    assert error <= 0.5 * np.nanmax(np.abs(fd[0] - fd[1])) + 1e-13 * np.nanmax(ref) / 1e-3
    assert error < 1e-3 * size


def test_gradient_fit_recovers_the_array_roughness_of_starlink_from_four_times_off():
    d = _starlink(noise=True)
    truth = simulate(parse_scenario(yaml.safe_dump(d), source="truth")).dataset
    bands = [b["name"] for b in d["instrument"]["bands"]]
    rate = truth["count_rate_measured"].transpose("time", "band").values
    n = truth.sizes["time"]
    lc = MeasuredLightCurve(truth["time"].values, bands, rate, None, np.ones(n, np.int64), "t")
    d["target"]["materials"]["array"]["roughness"] = 0.4
    start = parse_scenario(yaml.safe_dump(d), source="start")
    fit = fit_scenario(start, lc, free=("albedo", "roughness"), method="gradient")
    assert fit.converged, fit.message
    value, std = fit.roughness["array"]
    assert abs(value - 0.1) < 3 * std, (value, std)
    assert std < 1e-3
    # the truth's scale is 1: its albedo is the scenario's own band reflectance
    rho = np.array([fit.extra["band_reflectance_of_scenario"][b] for b in bands])
    assert np.all(np.abs(fit.albedo - rho) < 3 * fit.albedo_std), (fit.albedo, rho)
    assert fit.extra["n_simulations"] < 25
