"""The tumbling fit's light models (tumbling_light.py): a reflectivity map in memory against
closed forms, and a map store's band rates turned into the light curves' reflectance factor."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import WHITE
from speclight.estimate.shape.egi import mesh_facets
from speclight.estimate.shape.scattering import scattering_law
from speclight.estimate.shape.tumbling_light import (
    ConvexLight,
    MapLight,
    band_map_light,
    tabulated_map,
)
from speclight.maps.map_geometry import healpix_directions, sun_observer
from speclight.target import shapes

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # tests/estimate: map_scenarios
F32_EPS = float(np.finfo(np.float32).eps)


def test_map_light_at_its_nodes_is_the_tabulated_model():
    """A map of the box-wing's convex model (Lambert) read at its own nodes gives the convex
    model back, to float32 rounding: the nodes' directions, phase angles and rolls are laid
    out as the lookup reads them (an anisotropic body: any mix-up of direction or roll shows)."""
    tgt = shapes.box_wing(WHITE, dish=False)
    convex = ConvexLight(
        *mesh_facets([(p.vertices_m, p.faces) for p in tgt.parts]), scattering_law("lambert")
    )
    phases = np.array([30.0, 60.0, 90.0])
    rmap = tabulated_map(
        lambda s, o: convex(s, o, np.sqrt(0.5 * (1 + np.sum(s * o, axis=1)))),
        nside=2,
        phase_angle_deg=phases,
        n_rolls=8,
    )
    p = healpix_directions(2)
    k = np.arange(len(p))
    sun, obs = sun_observer(p, np.deg2rad(phases[k % 3]), 2 * np.pi * (k % 8) / 8)
    expected = convex(sun, obs, np.sqrt(0.5 * (1 + np.sum(sun * obs, axis=1))))
    got = MapLight(rmap)(sun, obs, np.zeros(len(p)))
    # float32 storage, then a weighted sum of 16 values (weights summing to 1)
    assert np.max(np.abs(got - expected)) <= 16 * F32_EPS * np.max(expected)
    assert np.ptp(expected) > 0.5 * np.max(expected)  # the test can see a mix-up


def test_map_light_of_a_lambert_sphere_follows_its_phase_function():
    """A Lambertian sphere of radius 1 m and albedo 1: its intensity per unit irradiance is
    ``(2 / (3 pi)) (sin a + (pi - a) cos a)`` [m2 sr-1] at phase angle ``a`` (Russell 1916,
    ApJ 43, 173). Its map (the convex model of an equal-area 768-facet sphere, phase angles
    every 10 deg) read at random directions, rolls and phase angles between the stored ones
    is within linear interpolation's bound ``h^2 / 8 max |f''|`` (``f'' = sin a - (pi - a)
    cos a``, ``|f''| <= pi``) plus the faceting's error (the facets' model at a node)."""
    normals = healpix_directions(8)
    areas = np.full(len(normals), 4 * np.pi / len(normals))
    convex = ConvexLight(normals, areas, scattering_law("lambert"))
    phases = np.arange(0.0, 181.0, 10.0)[:-1]  # 0..170 deg (a map stops at 179)
    rmap = tabulated_map(
        lambda s, o: convex(s, o, np.ones(len(s))), nside=2, phase_angle_deg=phases, n_rolls=4
    )
    rng = np.random.default_rng(3)
    n = 200
    p = rng.normal(size=(n, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    a = np.deg2rad(rng.uniform(5.0, 165.0, n))
    sun, obs = sun_observer(p, a, rng.uniform(0, 2 * np.pi, n))
    got = MapLight(rmap)(sun, obs, np.ones(n))
    closed = 2 / (3 * np.pi) * (np.sin(a) + (np.pi - a) * np.cos(a))
    # the map is a weighted mean (weights summing to 1) of its nodes, each off the closed
    # form by the faceting at most; the closed form depends on the phase angle alone, so
    # the weighted mean of its node values is its linear interpolation in phase angle
    nodes = np.deg2rad(phases)
    node_closed = 2 / (3 * np.pi) * (np.sin(nodes) + (np.pi - nodes) * np.cos(nodes))
    faceting = np.max(np.abs(rmap.intensity_W_sr_nm[..., 0] - node_closed[None, :, None]))
    h = np.deg2rad(10.0)
    bound = h**2 / 8 * np.pi * 2 / (3 * np.pi) + faceting
    assert np.max(np.abs(got - closed)) <= bound
    assert faceting < 0.01 * closed.max()  # a fine sphere: the bound is a real one


@pytest.fixture(scope="module")
def box_wing_map(tmp_path_factory):
    """A coarse reflectivity map of the box-wing example (12 directions, 2 phase angles,
    4 rolls, 24 px, 100 nm bins) written by speclight reflectivity-map."""
    from map_scenarios import write_scenario

    from speclight.maps.writer.reflectivity_map_run import reflectivity_map

    folder = tmp_path_factory.mktemp("tumbling_map")
    _, loaded = write_scenario(folder, "map.yaml", resolution_px=24, step_nm=100)
    reflectivity_map(
        loaded, folder / "m.zarr", directions=12, phase_angles_deg=[40, 70], rolls=4, chunk=12
    )
    return folder / "m.zarr", loaded


def test_band_map_light_is_the_mean_band_reflectance_factor(box_wing_map):
    """The map's band count rates turned into the mean reflectance factor of two bands equal,
    at the nodes, the factor computed from the map's spectral intensity instead (eq. 5 of
    Nussbaum et al. 2022: ``sum_L I k_b / sum_L E k_b``, ``k_b`` the band's photon kernel,
    ``E`` the Sun at 1 AU): the rates' normalisation (range 1 m, aperture 1 m2) undone."""
    from speclight.estimate.inputs.band_responses import scenario_band_responses
    from speclight.illumination import solar_irradiance_W_m2_nm
    from speclight.instrument.photometry import photon_kernel
    from speclight.maps.map_lookup import load_map

    path, loaded = box_wing_map
    bands = scenario_band_responses(loaded)
    chosen = bands.band_names[:2]
    response = bands.response[:2]
    light = band_map_light(path, chosen, response, bands.wavelength_nm)
    rmap = load_map(path)
    p = rmap.direction_body
    sun, obs = sun_observer(p, np.deg2rad(70.0), np.deg2rad(90.0))
    got = light(sun, obs, np.zeros(len(p)))
    ones = np.ones(bands.wavelength_nm.size)
    kernel = photon_kernel(bands.wavelength_nm, ones, ones, response)  # (2, L)
    intensity = rmap.intensity_W_sr_nm[:, 1, 1].astype(float)  # (D, L): 70 deg, roll 90 deg
    sun_e = solar_irradiance_W_m2_nm(bands.wavelength_nm)
    expected = np.mean((intensity @ kernel.T) / (kernel @ sun_e), axis=1)
    assert np.all(expected > 0)
    # float32 rates and intensities (the map stores both): a few float32 roundings
    assert np.allclose(got, expected, rtol=8 * F32_EPS, atol=0.0)


def test_band_map_light_refuses_other_bands(box_wing_map):
    from speclight.errors import InputError
    from speclight.estimate.inputs.band_responses import scenario_band_responses

    path, loaded = box_wing_map
    bands = scenario_band_responses(loaded)
    with pytest.raises(InputError, match="bands") as err:
        band_map_light(path, ["nope"], bands.response[:1], bands.wavelength_nm)
    assert err.value.field == "map_path"


def test_tumbling_run_uses_the_map_for_the_chosen_bands(box_wing_map):
    """``speclight shape --map``'s light model (tumbling_run.py) is the map's mean factor
    over the light curves' own bands (the ShapeInput's chosen ones, here the second band
    alone); without bands (a DAMIT file) the map is refused, naming ``map_path``."""
    from dataclasses import replace

    from speclight.errors import InputError
    from speclight.estimate.inputs.band_responses import scenario_band_responses
    from speclight.estimate.shape.inversion_data import build_inversion_data
    from speclight.estimate.shape.shape_inputs import ShapeInput
    from speclight.estimate.shape.tumbling_run import tumbling_light

    path, loaded = box_wing_map
    bands = scenario_band_responses(loaded)
    second = replace(bands, band_names=bands.band_names[1:2], response=bands.response[1:2])
    one, three = np.ones((3, 3)), np.ones(3)
    data = build_inversion_data(
        np.arange(3.0), three, three, one, one, np.zeros(3, int), np.array([True]), "x"
    )  # the light model does not read the points
    inputs = ShapeInput(data, second.band_names, None, None, "m2 sr-1", "x", loaded, second)
    light = tumbling_light(inputs, scattering_law("lambert"), map_path=path).model
    alone = band_map_light(path, second.band_names, second.response, bands.wavelength_nm)
    both = band_map_light(path, bands.band_names[:2], bands.response[:2], bands.wavelength_nm)
    sun, obs = sun_observer(healpix_directions(1), np.deg2rad(55.0), 0.4)
    got = light(sun, obs, np.zeros(12))
    assert np.array_equal(got, alone(sun, obs, np.zeros(12)))
    assert not np.allclose(got, both(sun, obs, np.zeros(12)), rtol=1e-3)  # bands differ
    with pytest.raises(InputError) as err:
        tumbling_light(replace(inputs, bands=None), scattering_law("lambert"), map_path=path)
    assert err.value.field == "map_path"
