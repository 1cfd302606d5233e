"""Analytic derivatives of the spin-axis misfit and the gradient-based refinement.

References: the misfit of :func:`speclight.estimate.spin_axis.spin_axis_misfit.exact_misfit` (the
spin model
through the package's quaternions, not the tangent-plane parametrisation differentiated
here); central finite differences of the same misfit; and a pass made with a known axis,
phase and period on a map in closed form (tests/estimate/test_spin_axis.py), recovered from
a start 25 deg away with the period 2 % off.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from test_spin_axis import _body_directions, _closed_form_map, _rates
from test_spin_axis_grid import _geometry, _map

from speclight.errors import InputError
from speclight.estimate.spin_axis.spin_axis_core import (
    angular_distance_deg,
    exact_misfit,
    spin_axis_search,
)
from speclight.estimate.spin_axis.spin_axis_gradient import SpinMisfit
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry, spin_frame_map
from speclight.estimate.spin_axis.spin_axis_ranging import RangingTerm
from speclight.estimate.spin_axis.spin_axis_refine import check_refine_options, refine_candidate

BODY_AXES = [None, [0.0, 1.0, 0.0]]


def _central(model: SpinMisfit, x: np.ndarray, h: float = 1e-6) -> np.ndarray:
    e = np.eye(x.size)
    return np.array(
        [(model.misfit(x + h * e[k]) - model.misfit(x - h * e[k])) / (2 * h) for k in range(x.size)]
    )


@pytest.mark.parametrize("axis", BODY_AXES)
def test_misfit_is_the_spin_models_and_gradient_its_differences(axis) -> None:
    bmap = _map(8, [20.0, 50.0, 80.0, 110.0], 6, 3)
    rng = np.random.default_rng(11)
    geo = _geometry(rng)
    y = rng.uniform(1.0, 2.0, size=(geo.t_s.size, 3))
    rel = []
    for ra, dec, ph in ((30.0, 40.0, 70.0), (200.0, -80.0, 10.0), (10.0, 89.9999, 300.0)):
        model = SpinMisfit.around(bmap, geo, y, axis, ra, dec, free_period=True)
        x0 = np.array([0.0, 0.0, np.radians(ph), 0.0])
        assert model.misfit(x0) == pytest.approx(
            exact_misfit(bmap, geo, y, axis, ra, dec, ph), rel=1e-12
        )
        for _ in range(4):
            x = rng.normal(size=4) * [0.5, 0.5, 2.0, 0.3]
            # the parameters as the spin model's RA, Dec, phase and period give the same misfit
            ra2, dec2, ph2, period = model.to_spin_model(x)
            geo2 = dataclasses.replace(geo, period_s=period)
            e_ref = exact_misfit(bmap, geo2, y, axis, ra2, dec2, ph2)
            e, g = model.misfit_and_gradient(x)
            assert e == pytest.approx(e_ref, rel=1e-12)
            fd = _central(model, x)
            rel.append(np.max(np.abs(g - fd)) / np.max(np.abs(fd)))
    # smooth almost everywhere: a central difference of step 1e-6 rad is within ~1e-8 of
    # the derivative unless the step crosses a cell boundary (rare at 1e-6)
    assert np.median(rel) < 1e-6
    assert np.mean(np.asarray(rel) < 1e-4) >= 0.9


def test_ranging_term_gradient() -> None:
    """Coaxial light with range offsets: the offsets' residuals and their Jacobian."""
    rng = np.random.default_rng(5)
    lmap = _map(8, [0.0], 1, 4)  # channels [R0, R1, M0, M1]
    geo = _geometry(rng)
    geo = EpochGeometry(geo.observer_gcrs, geo.observer_gcrs, geo.t_s, geo.period_s)
    y = rng.uniform(1.0, 2.0, size=(geo.t_s.size, 2))
    meas = rng.normal(0.5, 0.2, size=(geo.t_s.size, 2))
    meas[::7, 1] = np.nan
    sub = dataclasses.replace(lmap, intensity_W_sr_nm=lmap.intensity_W_sr_nm[..., :2].copy())
    term = RangingTerm(lmap, spin_frame_map(lmap, None, 4), meas, 0.7, shares_rates=True)
    model = SpinMisfit.around(sub, geo, y, None, 120.0, 30.0, True, term)
    x0 = np.array([0.0, 0.0, 0.4, 0.0])
    ref = exact_misfit(sub, geo, y, None, 120.0, 30.0, np.degrees(0.4), term)
    assert model.misfit(x0) == pytest.approx(ref, rel=1e-12)
    for _ in range(4):
        x = rng.normal(size=4) * [0.4, 0.4, 2.0, 0.2]
        _, g = model.misfit_and_gradient(x)
        np.testing.assert_allclose(g, _central(model, x), rtol=1e-5, atol=1e-7)


def test_gradient_refinement_recovers_axis_phase_and_period() -> None:
    bmap = _closed_form_map(16)
    ra, dec, phase0, period = 40.0, 25.0, 50.0, 37.0
    n = 200
    t = np.linspace(0.0, 150.0, n)
    ang = np.radians(np.linspace(-30, 30, n))
    los = np.stack([np.cos(ang) * 0.8, np.sin(ang) * 0.8, np.full(n, 0.6)], -1)
    y = _rates(_body_directions(los, ra, dec, phase0, t, period))
    geo = EpochGeometry(los, los, t, period * 1.02)  # the given period 2 % off
    start = (ra + 25.0 / np.cos(np.radians(dec)) * 0.8, dec - 15.0, phase0 + 20.0)
    assert angular_distance_deg(start[0], start[1], ra, dec) > 20.0
    r = refine_candidate(bmap, geo, y, None, start, 5.0, "gradient", period_bound=0.05)
    # the map is interpolated (HEALPix nside 16: 3.7 deg pixels), so the minimum is near,
    # not at, the truth; the period's error shifts the phase by 360 t / P
    assert angular_distance_deg(r.ra_deg, r.dec_deg, ra, dec) < 1.0
    assert abs((r.phase_deg - phase0 + 180.0) % 360.0 - 180.0) < 1.0
    assert r.period_s == pytest.approx(period, rel=1e-3)
    assert r.n_gradient > 0 and r.n_misfit == 0
    e_start = exact_misfit(bmap, geo, y, None, *start)
    assert r.error < e_start / 100


def test_search_records_the_method_and_the_period() -> None:
    bmap = _closed_form_map(8)
    n, period = 120, 37.0
    t = np.linspace(0.0, 150.0, n)
    ang = np.radians(np.linspace(-30, 30, n))
    los = np.stack([np.cos(ang) * 0.8, np.sin(ang) * 0.8, np.full(n, 0.6)], -1)
    y = _rates(_body_directions(los, 250.0, -60.0, 300.0, t, period))
    geo = EpochGeometry(los, los, t, period * 1.005)
    sfm = spin_frame_map(bmap, None, 18)
    kw = {"refine_method": "gauss-newton", "period_bound": 0.02}
    res = spin_axis_search(bmap, sfm, geo, y, ["b0", "b1"], 20.0, None, **kw)
    assert res.refine_method == "gauss-newton" and res.refine_n_gradient > 0
    assert res.refined_period_s == pytest.approx(period, rel=2e-3)
    assert angular_distance_deg(res.refined[0], res.refined[1], 250.0, -60.0) < 7.3  # a pixel


def test_refine_options() -> None:
    for method, bound in (
        ("newton", None),
        ("gradient", 0.0),
        ("slsqp", 0.7),
        ("gradient", np.nan),
    ):
        with pytest.raises(InputError):
            check_refine_options(method, bound)
    check_refine_options("slsqp", 0.05)
