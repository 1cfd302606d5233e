"""Continuation of the gradient refinement: the coarsened map, the smoothed misfit, and a
far start from which only the continuation converges.

References: HEALPix nesting computed independently of :func:`coarsen_map`'s NESTED
indexing (astropy-healpix ``vec2pix`` of each fine pixel centre at the coarse ``nside``:
a fine pixel lies inside its parent); the closed-form response of the ``[1/4, 1/2, 1/4]``
filter to a sinusoid of the roll (``(1 + cos(2 pi / R)) / 2`` per halving); central
differences of the smoothed misfit; a pass simulated on a synthetic map with a known axis
and phase (tests/estimate/test_spin_axis_grid.py), with starts 60 and 90 deg away found by
``bench/bench_spin_continuation.py``-style draws (seeded) where plain L-BFGS-B stops in
another minimum.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from astropy_healpix import healpy as hp
from test_spin_axis import _body_directions
from test_spin_axis_grid import _geometry, _map

from speclight.estimate.spin_axis.spin_axis_continuation import (
    SmoothedMisfit,
    Stage,
    coarsen_map,
    continuation_stages,
    gaussian_smoother,
    stage_model,
)
from speclight.estimate.spin_axis.spin_axis_core import angular_distance_deg, spin_axis_search
from speclight.estimate.spin_axis.spin_axis_gradient import SpinMisfit
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry, spin_frame_map
from speclight.estimate.spin_axis.spin_axis_ranging import RangingTerm
from speclight.estimate.spin_axis.spin_axis_refine import refine_candidate, refine_staged
from speclight.maps.map_geometry import healpix_directions


def test_coarsened_map_averages_the_children() -> None:
    fine = _map(8, [20.0, 50.0], 4, 2)
    # values that depend only on the parent pixel at nside 2 (found from the pixel centres)
    parent = hp.vec2pix(2, *fine.direction_body.T, nest=False)
    values = np.arange(48.0)[parent][:, None, None, None] * np.ones((1, 2, 4, 2))
    m = coarsen_map(
        type(fine)(fine.header, fine.direction_body, values.astype(np.float32)), 2, None
    )
    assert m.header.nside == 2
    np.testing.assert_allclose(m.direction_body, healpix_directions(2))
    np.testing.assert_array_equal(
        m.intensity_W_sr_nm, np.arange(48.0)[:, None, None, None] + 0 * m.intensity_W_sr_nm
    )
    # a mean: a constant stays itself, the sum over the sphere is kept (equal-area pixels)
    mean = coarsen_map(fine, 4, None).intensity_W_sr_nm.mean(axis=0)
    np.testing.assert_allclose(mean, fine.intensity_W_sr_nm.mean(axis=0), rtol=1e-6)
    with pytest.raises(ValueError):
        coarsen_map(fine, 3, None)
    with pytest.raises(ValueError):
        coarsen_map(fine, None, 3)


def test_fewer_rolls_filter_a_sinusoid_by_the_closed_form() -> None:
    fine = _map(2, [20.0], 8, 1)
    roll = np.radians(fine.header.roll_deg)
    values = np.broadcast_to(np.cos(2 * roll + 0.3)[None, None, :, None], (48, 1, 8, 1))
    m = coarsen_map(
        type(fine)(fine.header, fine.direction_body, values.astype(np.float32)), None, 2
    )
    np.testing.assert_allclose(m.header.roll_deg, [0.0, 180.0])
    # 8 -> 4 -> 2 rolls: the filter's gain on cos(2 r) at steps 45 deg and then 90 deg
    gain = (1 + np.cos(2 * np.radians(45.0))) / 2 * (1 + np.cos(2 * np.radians(90.0))) / 2
    expect = gain * np.cos(2 * np.radians([0.0, 180.0]) + 0.3)
    np.testing.assert_allclose(m.intensity_W_sr_nm[0, 0, :, 0], expect, atol=1e-6)


def test_smoothed_misfit_gradient_is_its_differences() -> None:
    bmap = _map(8, [20.0, 50.0, 80.0, 110.0], 8, 3)
    rng = np.random.default_rng(4)
    geo = _geometry(rng)
    y = rng.uniform(1.0, 2.0, size=(geo.t_s.size, 3))
    base = SpinMisfit.around(bmap, geo, y, None, 30.0, 40.0, free_period=True)
    s = gaussian_smoother(geo.t_s, 3.0)
    np.testing.assert_allclose(s.sum(axis=1), 1.0)
    model = stage_model(base, Stage(4, 4, 3.0))
    assert isinstance(model, SmoothedMisfit) and model.bmap.header.nside == 4
    rel = []
    for _ in range(6):
        x = rng.normal(size=4) * [0.4, 0.4, 2.0, 0.2]
        e, g = model.misfit_and_gradient(x)
        r, _ = SpinMisfit.residuals(model, x, jacobian=False)
        n = y.size
        assert e == pytest.approx(np.sum((s @ r[:n].reshape(y.shape)) ** 2), rel=1e-12)
        h, eye = 1e-6, np.eye(4)
        fd = [
            (model.misfit(x + h * eye[k]) - model.misfit(x - h * eye[k])) / (2 * h)
            for k in range(4)
        ]
        rel.append(np.max(np.abs(g - fd)) / np.max(np.abs(fd)))
    assert np.median(rel) < 1e-6


def _pass():
    bmap = _map(8, [20.0, 50.0, 80.0, 110.0], 8, 3)
    geo = _geometry(np.random.default_rng(11))
    truth = (30.0, 40.0, 70.0)
    sun = _body_directions(geo.sun_gcrs, *truth, geo.t_s, geo.period_s)
    obs = _body_directions(geo.observer_gcrs, *truth, geo.t_s, geo.period_s)
    return bmap, geo, bmap.intensity_1au(sun, obs), truth


# starts 60 and 90 deg from the truth where plain L-BFGS-B stops elsewhere (seeded draws)
FAR_STARTS = [
    (13.154784446169032, -17.90818367104905, 63.75935847963553),
    (348.61242322543325, -6.358874623219029, 60.89917719316371),
    (78.83781938992101, -38.1107605740016, 60.06961933981259),
]


@pytest.mark.parametrize("start", FAR_STARTS)
def test_continuation_converges_where_plain_gradient_does_not(start) -> None:
    bmap, geo, y, (ra, dec, phase) = _pass()
    assert angular_distance_deg(start[0], start[1], ra, dec) > 55.0

    def at_truth(r) -> bool:
        d_phase = abs((r.phase_deg - phase + 180.0) % 360.0 - 180.0)
        return angular_distance_deg(r.ra_deg, r.dec_deg, ra, dec) < 0.1 and d_phase < 0.1

    plain = refine_candidate(bmap, geo, y, None, start, 2.5, "gradient")
    assert not at_truth(plain)
    cont = refine_candidate(bmap, geo, y, None, start, 2.5, "gradient-continuation")
    # the pass is the map's own interpolation: its minimum (misfit 0) is the truth
    assert at_truth(cont)
    assert cont.error < 1e-8 < plain.error
    assert cont.n_gradient > 0 and cont.n_misfit == 0
    direct = refine_staged(bmap, geo, y, None, start, [Stage(2, 8), Stage(4, 8)])
    assert direct.answer == pytest.approx(cont.answer)


def test_stage_coarsens_the_ranging_map_too() -> None:
    rng = np.random.default_rng(5)
    lmap = _map(8, [0.0], 1, 4)  # coaxial channels [R0, R1, M0, M1]
    geo = _geometry(rng)
    geo = EpochGeometry(geo.observer_gcrs, geo.observer_gcrs, geo.t_s, geo.period_s)
    y = rng.uniform(1.0, 2.0, size=(geo.t_s.size, 2))
    meas = rng.normal(0.5, 0.2, size=(geo.t_s.size, 2))
    sub = dataclasses.replace(lmap, intensity_W_sr_nm=lmap.intensity_W_sr_nm[..., :2].copy())
    term = RangingTerm(lmap, spin_frame_map(lmap, None, 4), meas, 0.7, shares_rates=True)
    base = SpinMisfit.around(sub, geo, y, None, 120.0, 30.0, False, term)
    model = stage_model(base, Stage(2, None, 0.0))
    assert model.ranging is not None and model.ranging.bmap.header.nside == 2
    # the stage is the misfit on the coarsened maps, built directly
    coarse = dataclasses.replace(term, bmap=coarsen_map(lmap, 2, None))
    direct = SpinMisfit.around(coarsen_map(sub, 2, None), geo, y, None, 120.0, 30.0, False, coarse)
    x = np.array([0.1, -0.2, 0.4])
    assert model.misfit(x) == pytest.approx(direct.misfit(x), rel=1e-12)
    assert model.misfit(x) != pytest.approx(base.misfit(x), rel=1e-3)


def test_search_with_continuation_records_it() -> None:
    bmap, geo, y, (ra, dec, phase) = _pass()
    sfm = spin_frame_map(bmap, None, 18)
    res = spin_axis_search(
        bmap, sfm, geo, y, ["b0", "b1", "b2"], 20.0, refine_method="gradient-continuation"
    )
    assert res.refine_method == "gradient-continuation" and res.refine_n_gradient > 0
    assert angular_distance_deg(res.refined[0], res.refined[1], ra, dec) < 0.1
    assert abs((res.refined[2] - phase + 180.0) % 360.0 - 180.0) < 0.1
    assert continuation_stages(8) == [Stage(2), Stage(4)]
    assert continuation_stages(2) == [] and continuation_stages(32)[-1] == Stage(16)
