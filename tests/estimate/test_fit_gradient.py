"""Analytic roughness derivatives and ``fit --method gradient`` (issue 15, item 2).

References:

* the derivatives against central finite differences (of the numpy BRDF formulas, and of
  the full ``simulate`` on a fixed geometry), with the tolerance the difference's own
  truncation error sets: a central difference of step h errs by c h^2, so D(h/2) errs by
  |D(h) - D(h/2)| / 3; the analytic value must lie within half of |D(h) - D(h/2)| of D(h/2);
* the fit: recovery of the roughness the noisy data were simulated with (Poisson draws,
  fixed seed) from a start a factor 10 away, to within 3 of the fit's own standard deviations;
  on a closed-form glint model, the spread of the fitted roughness over many noise draws
  (Monte Carlo) against the reported standard deviation, and the projected residuals'
  Jacobian against central differences of the projected residuals.
"""

from pathlib import Path

import numpy as np
import pytest
import yaml

from speclight.errors import InputError
from speclight.estimate import fit_scenario
from speclight.estimate.fitting.gradient_fit import fit_roughness_gradient, projected_residuals
from speclight.estimate.fitting.roughness_gradient import RoughnessRates
from speclight.estimate.inputs.measured import MeasuredLightCurve
from speclight.render.brdf_gradient import (
    microfacet_d_dalpha,
    microfacet_weight_dalpha,
    smith_g1_dalpha,
)
from speclight.scenario import example_text, parse_scenario
from speclight.scenario.overrides import replace_fields
from speclight.simulation import simulate
from speclight.target.microfacet_terms import microfacet_d, microfacet_weight, smith_g1

DATA = Path(__file__).parent / "data"
ONE = '"*": {bsdf: beckmann, roughness: 0.12, reflectance: 0.6}'
TWO = (
    '"+x": {bsdf: beckmann, roughness: 0.12, reflectance: 0.6}\n'
    '    "*": {bsdf: ggx, roughness: 0.2, reflectance: 0.5}'
)


def _within_truncation(analytic, fd_h, fd_half, floor):
    """|analytic - D(h/2)| <= |D(h) - D(h/2)| / 2 + floor, elementwise (module doc)."""
    bound = 0.5 * np.abs(fd_h - fd_half) + floor
    return np.abs(analytic - fd_half) <= bound


@pytest.mark.parametrize("kind", ["beckmann", "ggx"])
@pytest.mark.parametrize("alpha", [0.03, 0.12, 0.5, 0.9])
def test_microfacet_derivatives_match_central_differences_of_the_formulas(kind, alpha):
    rng = np.random.default_rng(7)
    ci, co, ch = rng.uniform(0.05, 1.0, (3, 4000))
    h = 1e-3 * alpha

    def smooth(cos):
        # Beckmann's rational G1 has a kink at 1 / (alpha tan) = 1.6: differences across it
        # measure the kink, not the derivative
        if kind == "ggx":
            return np.ones(cos.shape, bool)
        tan = np.sqrt(1 - cos**2) / cos
        return np.sign(1 / ((alpha - h) * tan) - 1.6) == np.sign(1 / ((alpha + h) * tan) - 1.6)

    pairs = [
        (lambda a: microfacet_d(ch, a, kind), microfacet_d_dalpha(ch, alpha, kind), ch > 0),
        (lambda a: smith_g1(ci, a, kind), smith_g1_dalpha(ci, alpha, kind), smooth(ci)),
        (
            lambda a: microfacet_weight(ci, co, ch, a, kind),
            microfacet_weight_dalpha(ci, co, ch, alpha, kind),
            smooth(ci) & smooth(co),
        ),
    ]
    for f, analytic, ok_here in pairs:
        assert ok_here.mean() > 0.95
        fd_h = (f(alpha + h) - f(alpha - h)) / (2 * h)
        fd_half = (f(alpha + h / 2) - f(alpha - h / 2)) / h
        floor = 1e-12 * np.abs(f(alpha)).max() / h  # rounding of the differences
        ok = _within_truncation(analytic, fd_h, fd_half, floor)
        assert np.all(ok | ~ok_here), np.abs(analytic - fd_half)[~ok & ok_here].max()


T = np.linspace(-1.0, 1.0, 201)
GAIN = np.array([1000.0, 400.0])


def _glint(alpha):
    """A Gaussian glint of width alpha on a baseline in two bands (N, 2), and d/dalpha."""
    g = np.exp(-0.5 * (T / alpha[0]) ** 2)
    c = (g + 0.05)[:, None] * GAIN[None, :]
    dc = (g * T**2 / alpha[0] ** 3)[:, None] * GAIN[None, :]
    return c, dc[None]


def test_projected_jacobian_is_the_derivative_of_the_projected_residuals():
    rng = np.random.default_rng(3)
    clean = _glint(np.array([0.12]))[0] * np.array([0.8, 1.3])
    sigma = np.sqrt(clean)
    m = clean + sigma * rng.standard_normal(clean.shape)
    alpha, h = 0.2, 1e-4
    _, jac, _ = projected_residuals(*_glint(np.array([alpha])), m, sigma, True)
    fd = []
    for step in (h, h / 2):
        up = projected_residuals(*_glint(np.array([alpha + step])), m, sigma, True)[0]
        down = projected_residuals(*_glint(np.array([alpha - step])), m, sigma, True)[0]
        fd.append((up - down) / (2 * step))
    assert np.all(_within_truncation(jac[:, 0], fd[0], fd[1], 1e-9 * np.abs(jac).max()))


def test_gradient_fit_std_matches_the_monte_carlo_spread():
    truth_alpha, truth_scale = 0.12, np.array([0.8, 1.3])
    clean = _glint(np.array([truth_alpha]))[0] * truth_scale
    sigma = np.sqrt(clean)
    rng = np.random.default_rng(7)
    alphas, stds = [], []
    for _ in range(40):
        m = clean + sigma * rng.standard_normal(clean.shape)
        fit = fit_roughness_gradient(_glint, m, sigma, np.array([0.6]), (0.01, 1.0))
        assert fit.success, fit.message
        alphas.append(fit.roughness[0])
        stds.append(fit.roughness_std[0])
        assert np.all(np.abs(fit.scales.scale - truth_scale) < 5 * fit.scales.scale_std)
    alphas, stds = np.array(alphas), np.array(stds)
    spread = alphas.std(ddof=1)
    assert abs(alphas.mean() - truth_alpha) < 4 * spread / np.sqrt(40)  # 4 standard errors
    # the sample std of 40 draws is uncertain by 1/sqrt(2 * 39) = 11 %: 3 of those bound it
    assert np.median(stds) / spread == pytest.approx(1.0, abs=0.35)


def _measured(ds):
    rate = ds["count_rate_measured"].transpose("time", "band").values
    n = ds.sizes["time"]
    return MeasuredLightCurve(ds["time"].values, ["B", "R"], rate, None, np.ones(n, np.int64), "t")


def _cube(text=ONE):
    return (DATA / "spinning_cube.yaml").read_text().replace(ONE, text)


CASES = [(ONE, ["*"], [0.12]), (TWO, ["+x", "*"], [0.12, 0.2])]


@pytest.mark.parametrize(("materials", "rough", "alpha"), CASES)
def test_count_rate_derivatives_match_central_differences_of_simulate(materials, rough, alpha):
    loaded = replace_fields(
        parse_scenario(_cube(materials), source="t"), {"instrument.noise": None}
    )
    base = simulate(loaded)
    rates = RoughnessRates(loaded, base.geometry, rough, np.ones(base.geometry.t_s.size, bool))
    c, jac = rates(np.array(alpha))
    ref = base.dataset["count_rate"].transpose("time", "band").values
    np.testing.assert_array_equal(np.isfinite(c), np.isfinite(ref))
    lit = np.isfinite(ref) & (ref > 0)
    assert lit.sum() > 100
    np.testing.assert_allclose(c[lit], ref[lit], rtol=1e-12)  # the same chain, same sums

    def sim(a):
        values = {
            f"target.materials.{n}.roughness": float(v) for n, v in zip(rough, a, strict=True)
        }
        run = simulate(replace_fields(loaded, values), geometry=base.geometry)
        return run.dataset["count_rate"].transpose("time", "band").values

    for k in range(len(rough)):
        fd = []
        for h in (2e-3, 1e-3):
            up, down = np.array(alpha), np.array(alpha)
            up[k] += h
            down[k] -= h
            fd.append((sim(up) - sim(down)) / (2 * h))
        size = np.nanmax(np.abs(jac[k]))
        assert size > 0
        # max-norm form of the truncation bound (rounding: 1e-13 of the rates over h)
        error = np.nanmax(np.abs(jac[k] - fd[1]))
        assert error <= 0.5 * np.nanmax(np.abs(fd[0] - fd[1])) + 1e-13 * np.nanmax(ref) / 1e-3
        assert error < 1e-3 * size


def test_gradient_fit_recovers_the_roughness_from_ten_times_too_small():
    truth = simulate(parse_scenario(_cube(), source="truth")).dataset
    start = parse_scenario(_cube(ONE.replace("0.12", "0.012")), source="start")
    fit = fit_scenario(start, _measured(truth), free=("albedo", "roughness"), method="gradient")
    assert fit.converged, fit.message
    value, std = fit.roughness["*"]
    assert abs(value - 0.12) < 3 * std, (value, std)
    assert std < 1e-3
    assert np.all(np.abs(fit.albedo - 0.6) < 3 * fit.albedo_std), (fit.albedo, fit.albedo_std)
    assert fit.to_json()["method"].startswith("gradient")
    assert fit.extra["n_simulations"] < 25


def test_gradient_fit_recovers_two_materials_from_five_times_off():
    truth = simulate(parse_scenario(_cube(TWO), source="truth")).dataset
    text = TWO.replace("0.12", "0.024").replace("0.2,", "0.04,")
    start = parse_scenario(_cube(text), source="start")
    fit = fit_scenario(start, _measured(truth), free=("albedo", "roughness"), method="gradient")
    assert fit.converged, fit.message
    for name, true in (("+x", 0.12), ("*", 0.2)):
        value, std = fit.roughness[name]
        assert abs(value - true) < 3 * std, (name, value, std)


def test_gradient_method_refusals_name_the_reason():
    truth = simulate(parse_scenario(_cube(), source="truth")).dataset
    lc = _measured(truth)
    loaded = parse_scenario(_cube(), source="start")
    with pytest.raises(InputError, match=r"method = 'newton': give one of slsqp, gradient"):
        fit_scenario(loaded, lc, free=("albedo", "roughness"), method="newton")
    path = replace_fields(loaded, {"render.mode": "path"})
    with pytest.raises(InputError, match="single-scattering render only"):
        fit_scenario(path, lc, free=("albedo", "roughness"), method="gradient")
    plastic = {"bsdf": "plastic", "roughness": 0.12, "reflectance": {"dielectric": "SiO2"},
               "diffuse_reflectance": 0.5}  # fmt: skip
    d = yaml.safe_load(_cube())
    d["target"]["materials"]["*"] = plastic
    with pytest.raises(InputError, match=r"plastic.*quadrature table"):
        fit_scenario(parse_scenario(yaml.safe_dump(d), source="p"), lc,
                     free=("albedo", "roughness"), method="gradient")  # fmt: skip


def test_gradient_fit_reports_a_polished_sphere_roughness_unconstrained():
    # as the SLSQP test in test_estimate_fit_scenario.py: a Beckmann sphere's light curve
    # barely changes shape with roughness, so roughness and albedo are degenerate
    d = yaml.safe_load(example_text("lcs1"))
    d["time"].update(stop="2020-07-18T01:20:00Z", step_s=4.0)
    d["render"]["resolution_px"] = 64
    d["target"]["materials"]["body"]["reflectance"] = 0.8
    truth = simulate(parse_scenario(yaml.safe_dump(d), source="truth")).dataset
    d["target"]["materials"]["body"]["roughness"] = 0.3
    bands = [b["name"] for b in d["instrument"]["bands"]]
    rate = truth["count_rate_measured"].transpose("time", "band").values
    n = truth.sizes["time"]
    lc = MeasuredLightCurve(truth["time"].values, bands, rate, None, np.ones(n, np.int64), "t")
    start = parse_scenario(yaml.safe_dump(d), source="start")
    fit = fit_scenario(start, lc, free=("albedo", "roughness"), method="gradient")
    assert not fit.converged
    assert "roughness of material 'body' is not constrained" in fit.message
    # the albedo's std covers the roughness values the solver met that fit as well: the true
    # albedo (the constant reflectance 0.8) lies within 3 of it, and it is not the useless
    # joint std of a degenerate pair (hundreds)
    assert np.all(np.abs(fit.albedo - 0.8) < 3 * fit.albedo_std), (fit.albedo, fit.albedo_std)
    assert np.all(fit.albedo_std < 0.1)


def test_rates_equal_simulate_in_penumbra_and_shadow():
    # the calsphere pass leaves the Earth's shadow through 12 penumbra epochs: the pass scales
    # them by the sunlit fraction as the pipeline does, and shadowed epochs are 0
    d = yaml.safe_load(example_text("calsphere"))
    d["render"]["resolution_px"] = 32
    d["target"]["materials"]["body"] = {"bsdf": "ggx", "roughness": 0.3, "reflectance": 0.7}
    loaded = replace_fields(
        parse_scenario(yaml.safe_dump(d), source="x"), {"instrument.noise": None}
    )
    base = simulate(loaded)
    flags = base.dataset["flags"].values
    assert np.count_nonzero(flags & 8) > 0 and np.count_nonzero(flags & 4) > 0
    rates = RoughnessRates(loaded, base.geometry, ["body"], np.ones(flags.size, bool))
    c, _ = rates(np.array([0.3]))
    ref = base.dataset["count_rate"].transpose("time", "band").values
    np.testing.assert_array_equal(np.isfinite(c), np.isfinite(ref))
    np.testing.assert_allclose(c, ref, rtol=1e-12, atol=0)
