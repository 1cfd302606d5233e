"""Interpolation error of a box-wing reflectivity map against direct renders.

A small map (HEALPix nside 4: 192 directions, ~15 deg apart; phase angles 0, 30, 60, 90 deg;
8 rolls; 32 px, 100 nm bins) is interpolated at 300 random geometries (seed 1) and compared
with renders of the same geometries at the same settings; the error is
``|I_map / I_render - 1|`` of the intensity summed over wavelength. Measured (BENCHMARKS.md
and docs/reflectivity-map.md; seeds 1, 2, 3 of this draw):

* active (phase angle 0, coaxial laser geometry): median 0.046, 0.037, 0.051; 95th
  percentile 0.209, 0.226, 0.232;
* passive (phase angle uniform in 0..90 deg): median 0.068, 0.057, 0.071; 95th percentile
  0.384, 0.330, 0.477.

The bounds below are the largest of the three seeds plus 25 % (a different caster, numpy or
Mitsuba, changes a few edge pixels); a wrong roll or phase convention, or a lookup in the
wrong pixel, gives a 95th percentile of order 1 (tested below: the roll turned by 90 deg).
"""

import numpy as np
import pytest
from map_scenarios import write_scenario

from speclight.illumination import solar_irradiance_W_m2_nm
from speclight.maps.map_geometry import sun_observer
from speclight.maps.map_lookup import load_map
from speclight.maps.writer.reflectivity_map_run import reflectivity_map
from speclight.render import render_intensity
from speclight.simulation.radiometry import wavelength_grid_nm
from speclight.simulation.reflection import build_target

N, RES_PX = 300, 32
BOUNDS = {  # (median, 95th percentile): measured maximum over seeds x 1.25
    "active": (0.051 * 1.25, 0.232 * 1.25),
    "passive": (0.071 * 1.25, 0.477 * 1.25),
}


@pytest.fixture(scope="module")
def box_wing_map(tmp_path_factory):
    folder = tmp_path_factory.mktemp("bwmap")
    _, loaded = write_scenario(folder, "bw.yaml", resolution_px=RES_PX, step_nm=100)
    reflectivity_map(
        loaded, folder / "m.zarr", directions=192, phase_angles_deg=[0, 30, 60, 90], chunk=96
    )
    return load_map(folder / "m.zarr"), loaded


def _errors(the_map, loaded, kind, roll_offset=0.0):
    rng = np.random.default_rng(1)
    p = rng.normal(size=(N, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    a_passive = np.radians(rng.uniform(0, 90, N))  # the draws of the documented measurement
    r_active = rng.uniform(0, 2 * np.pi, N)
    r_passive = rng.uniform(0, 2 * np.pi, N)
    a, r = (np.zeros(N), r_active) if kind == "active" else (a_passive, r_passive)
    wl = wavelength_grid_nm(loaded.scenario.spectrum)
    solar = solar_irradiance_W_m2_nm(wl, 1.0)
    s, o = sun_observer(p, a, r)
    direct = render_intensity(build_target(loaded), s, o, solar, wl, resolution_px=RES_PX)
    s2, o2 = sun_observer(p, a, r + roll_offset)
    got = the_map.intensity_1au(s2, o2).sum(axis=1)
    return np.abs(got / direct.intensity_W_sr_nm.sum(axis=1) - 1)


@pytest.mark.parametrize("kind", ["active", "passive"])
def test_interpolation_error_against_direct_renders(box_wing_map, kind):
    e = _errors(*box_wing_map, kind)
    median, p95 = BOUNDS[kind]
    assert np.median(e) < median
    assert np.percentile(e, 95) < p95


def test_a_wrong_roll_is_detected(box_wing_map):
    # the same check fails when the lookup uses the roll turned by 90 deg
    e = _errors(*box_wing_map, "passive", roll_offset=np.pi / 2)
    assert np.percentile(e, 95) > BOUNDS["passive"][1]  # measured: 0.82


def test_lookup_at_stored_nodes_returns_the_stored_values(box_wing_map):
    # at a pixel centre, a stored phase angle and a stored roll every weight but one is 0
    the_map, _ = box_wing_map
    pixels = np.array([0, 5, 100, 191])  # 0 and 191: next to the poles
    for j, k in [(1, 0), (2, 3), (3, 7)]:
        a = np.radians(the_map.header.phase_angle_deg[j])
        r = np.radians(the_map.header.roll_deg[k])
        s, o = sun_observer(the_map.direction_body[pixels], a, r)
        np.testing.assert_allclose(
            the_map.intensity_1au(s, o), the_map.intensity_W_sr_nm[pixels, j, k], rtol=1e-5
        )
