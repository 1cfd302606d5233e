"""Spin-axis search: inputs it cannot use, sizes that cannot finish, a refinement that fails.

References: a curve of mean 0 cannot be divided by its mean (the misfit's normalisation);
a map band of zeros predicts no light for any candidate; the spin-frame map's size from its
layout (polar x azimuth cells x phase angles x rolls x bands, float32); the fallback rule
(the refined answer is the grid's best cell where no refinement ends finite and below it).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.estimate.spin_axis.spin_axis_answer import refined_or_best
from speclight.estimate.spin_axis.spin_axis_core import check_measured_curves, spin_axis_search
from speclight.estimate.spin_axis.spin_axis_limits import check_search_cost, search_cost
from speclight.estimate.spin_axis.spin_axis_lookup import (
    EpochGeometry,
    cell_deg_for,
    spin_frame_map,
)
from speclight.estimate.spin_axis.spin_axis_ranging import check_ranging_weight
from speclight.estimate.spin_axis.spin_axis_refine import Refined
from speclight.maps.map_geometry import healpix_directions
from speclight.maps.map_lookup import MapHeader, ReflectivityMap


def _map(zero_band: bool = False) -> ReflectivityMap:
    """Coaxial closed-form rates on nside 4: band 0 brighter towards +x, band 1 towards +z
    (or 0 everywhere)."""
    d = healpix_directions(4)
    rates = np.stack([2.0 + d[:, 0], 0.0 * d[:, 2] if zero_band else 2.0 + d[:, 2]], axis=-1)
    header = MapHeader(Path("synthetic"), 4, np.array([500.0]), ["b0", "b1"], np.array([0.0]),
                       np.array([0.0]), {})  # fmt: skip
    return ReflectivityMap(header, d, rates.astype(np.float32)[:, None, None, :])


def _pass(n: int = 60) -> tuple[EpochGeometry, np.ndarray]:
    ang = np.radians(np.linspace(-30, 30, n))
    los = np.stack([np.cos(ang) * 0.8, np.sin(ang) * 0.8, np.full(n, 0.6)], -1)
    t = np.linspace(0.0, 120.0, n)
    y = np.stack([2.0 + np.cos(2 * np.pi * t / 37), 2.0 + np.sin(2 * np.pi * t / 37)], -1)
    return EpochGeometry(los, los, t, 37.0), y


def test_a_curve_without_positive_mean_is_refused() -> None:
    y = np.array([[1.0, 0.0], [2.0, 0.0], [3.0, 0.0]])
    with pytest.raises(InputError, match=r"band\(s\) 'G' \(0\)") as err:
        check_measured_curves(y, ["B", "G"])
    assert err.value.field == "y"
    check_measured_curves(y[:, :1], ["B"])  # a positive mean: fine


def test_a_map_that_predicts_no_light_is_refused() -> None:
    bmap = _map(zero_band=True)
    geo, y = _pass()
    with pytest.raises(InputError, match="no candidate of the grid has a finite misfit"):
        spin_axis_search(bmap, spin_frame_map(bmap, None, 12), geo, y, ["b0", "b1"], 30.0)


def test_a_refinement_that_ends_non_finite_falls_back_to_the_best_cell(monkeypatch) -> None:
    import speclight.estimate.spin_axis.spin_axis_refine as refine

    def broken(*args, **kwargs) -> Refined:
        return Refined(np.nan, np.nan, np.nan, np.nan, np.nan, 7, 0)

    monkeypatch.setattr(refine, "refine_candidate", broken)
    bmap = _map()
    geo, y = _pass()
    res = spin_axis_search(bmap, spin_frame_map(bmap, None, 12), geo, y, ["b0", "b1"], 30.0)
    assert res.refined[:3] == res.best[:3] and np.isfinite(res.refined[3])
    assert res.refined_period_s == geo.period_s
    assert "no finite misfit" in res.refine_note


def test_fallback_rule_by_hand() -> None:
    geo, _ = _pass()
    best = (10.0, 20.0, 30.0, 0.5)
    good = Refined(11.0, 21.0, 31.0, 0.1, 37.0, 5, 0)
    worse = Refined(50.0, 60.0, 70.0, 0.9, 37.0, 5, 0)
    nan = Refined(np.nan, 1.0, 1.0, np.nan, 37.0, 5, 0)
    assert refined_or_best([nan, good], best, 0.4, geo.period_s) == (good.answer, 37.0, "")
    answer, period, note = refined_or_best([worse], best, 0.4, geo.period_s)
    assert answer == (10.0, 20.0, 30.0, 0.4) and "above the grid's best" in note
    assert period == geo.period_s
    answer, _, note = refined_or_best([nan], best, np.inf, geo.period_s)
    assert answer == best and "no finite misfit" in note  # the grid's own misfit then


def test_search_cost_from_the_layout() -> None:
    # nside 8: cell 2.44 deg -> 74 polar cells; 72 phases of 5 deg -> 3 azimuth cells each
    cell = cell_deg_for(8)
    n_polar, m = int(np.ceil(180 / cell)), int(np.ceil(5.0 / cell))
    map_bytes, _, grid_bytes, _ = search_cost(8, 4, 8, 2.0, 72, 300, 10)
    values = n_polar * 72 * m * 4 * 8 * 10 * 4  # float32 cells x geometries x bands
    assert map_bytes == pytest.approx(5 * values + n_polar * 72 * m * (320 + 160))
    assert grid_bytes >= 4 * 8 * 180 * 90 * 72  # the misfits, float64


@pytest.mark.parametrize(
    ("grid_deg", "n_phases", "field"), [(2.0, 10**9, "n_phases"), (0.001, 72, "grid_deg")]
)
def test_searches_that_cannot_finish_name_their_option(grid_deg, n_phases, field) -> None:
    with pytest.raises(InputError, match="GiB of memory") as err:
        check_search_cost(8, 4, 8, grid_deg, n_phases, 300, 10)
    assert err.value.field == field
    check_search_cost(8, 4, 8, 10.0, 36, 300, 10)  # the tests' search: fine


def test_ranging_weight_bounded() -> None:
    offsets = np.zeros((3, 2))
    with pytest.raises(InputError, match="from 0 to 1e"):
        check_ranging_weight(1e300, offsets)
    assert check_ranging_weight(1e6, offsets) == 1e6
