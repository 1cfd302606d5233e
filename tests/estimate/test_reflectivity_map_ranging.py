"""Coaxial range histograms of a reflectivity map: a Lambertian sphere's closed form, the
consistency with the stored mean offsets, resume, and their absence without lasers.

Lambertian sphere of radius R and albedo rho, lit and seen along the same axis (phase 0): the
pixel at projected radius r sees the surface at one-way offset d = -R mu from the centre
(mu = sqrt(1 - r^2 / R^2)) with intensity ~ mu dA, dA = 2 pi r dr = -2 pi R^2 mu dmu; the
returned power per offset is ~ mu^2 dmu, so the offsets d in [-R, 0] have the density
3 (d/R)^2 / R, the cumulative fraction 1 - (-d/R)^3 below d, and the mean -3R/4 (the same
sphere as the range_offset test of test_reflectivity_map.py). The total is the sphere's
phase-0 intensity (Russell 1916, ApJ 43, 173: I(0) = 2/3 rho E R^2) times the photon kernel.
"""

import numpy as np
import pytest
import zarr
from map_scenarios import SPHERE_TARGET, write_scenario

from speclight.errors import InputError
from speclight.illumination import solar_irradiance_W_m2_nm
from speclight.instrument.photometry import photon_kernel
from speclight.maps.map_lookup import load_map
from speclight.maps.writer.reflectivity_map_run import reflectivity_map
from speclight.simulation.radiometry import instrument_response, wavelength_grid_nm

RHO, RADIUS_M = 0.6, 1.7


def _kernel(loaded):
    wl = wavelength_grid_nm(loaded.scenario.spectrum)
    k = instrument_response(loaded, wl, np.zeros((1, wl.size)), np.ones((1, wl.size)), np.ones(1))
    return wl, photon_kernel(wl, k.optics, np.ones(wl.size), k.band_response * k.qe)


@pytest.fixture(scope="module")
def sphere_laser_map(tmp_path_factory):
    folder = tmp_path_factory.mktemp("sphere-laser")
    _, loaded = write_scenario(
        folder,
        "sphere-laser.yaml",
        resolution_px=128,
        step_nm=100,
        target=SPHERE_TARGET,
        example="box-wing-laser",
    )
    run = reflectivity_map(loaded, folder / "m.zarr", directions=12, chunk=12)
    assert run.complete
    return folder / "m.zarr", loaded


def test_sphere_histogram_against_the_closed_form(sphere_laser_map):
    path, loaded = sphere_laser_map
    group = zarr.open_group(str(path), mode="r")
    hist = np.asarray(group["range_histogram"][...], dtype=float)  # (D, B, bins)
    bounds = np.asarray(group["range_bin_bounds"][...])
    centres = np.asarray(group["range_bin"][...])
    np.testing.assert_allclose(centres, bounds.mean(axis=1))
    assert hist.shape == (12, len(group.attrs["band_names"]), len(centres))
    # total: I(0) for 1 W m-2 nm-1 per bin, range 1 m, area 1 m2 -> counts = I k summed
    _, k = _kernel(loaded)
    expected_total = 2 / 3 * RHO * RADIUS_M**2 * k.sum(axis=1)
    # 128 px: the disk's pixel sampling is well under 1 % (0.5 % at 256 px in the phase-law test)
    np.testing.assert_allclose(
        hist.sum(axis=2), np.broadcast_to(expected_total, hist.shape[:2]), rtol=0.01
    )
    # shape: the cumulative fraction at each bin's upper edge against 1 - (-d/R)^3
    d = np.clip(bounds[:, 1] / RADIUS_M, -1.0, 0.0)
    cdf = 1.0 - (-d) ** 3
    got = np.cumsum(hist, axis=2) / hist.sum(axis=2, keepdims=True)
    # a pixel (2R/128) shifts an offset near the limb by up to a bin: 1 % of the total
    assert np.max(np.abs(got - cdf)) < 0.01
    assert np.all(hist[..., bounds[:, 0] > 1e-9] == 0)  # nothing behind the centre
    mean = (hist * centres).sum(axis=2) / hist.sum(axis=2)
    np.testing.assert_allclose(mean, -0.75 * RADIUS_M, rtol=0.01)


def test_sphere_histogram_lookup_at_any_direction(sphere_laser_map):
    # A sphere's histogram is the same from every direction: the interpolation between the
    # four nearest pixels must return it unchanged, in between nodes too.
    path, _ = sphere_laser_map
    m = load_map(path)
    assert m.range_histogram_per_s is not None and m.range_bin_edges_m is not None
    rng = np.random.default_rng(7)
    obs = rng.normal(size=(20, 3))
    got = m.coaxial_range_histogram(np.vstack([obs, [np.nan, 0, 0]]))
    assert np.all(np.isnan(got[-1]))
    ref = m.range_histogram_per_s.astype(float).mean(axis=0)
    scale = ref.sum(axis=1)[None, :, None]
    # the stored directions agree to 2e-9 of the total (measured); float32 storage: 1e-6
    assert np.max(np.abs(got[:-1] - ref[None]) / scale) < 1e-5


def test_histogram_mean_is_the_stored_offset_and_resume_is_identical(tmp_path):
    _, loaded = write_scenario(tmp_path, "bwl.yaml", resolution_px=16, example="box-wing-laser")
    full = reflectivity_map(loaded, tmp_path / "full.zarr", directions=48, chunk=10)
    part = reflectivity_map(loaded, tmp_path / "part.zarr", directions=48, chunk=10, max_chunks=2)
    again = reflectivity_map(loaded, tmp_path / "part.zarr", directions=48, chunk=10)
    assert full.complete and not part.complete and again.complete and again.skipped == 2
    a = zarr.open_group(str(tmp_path / "full.zarr"), mode="r")
    b = zarr.open_group(str(tmp_path / "part.zarr"), mode="r")
    for name in ("range_histogram", "range_offset", "range_bin_bounds"):
        np.testing.assert_array_equal(a[name][...], b[name][...])
    # the lookup at the stored directions returns their own histograms (weights 1 there)
    m = load_map(tmp_path / "full.zarr")
    stored = np.asarray(a["range_histogram"][...], dtype=float)
    np.testing.assert_allclose(
        m.coaxial_range_histogram(m.direction_body), stored, rtol=1e-5, atol=1e-6 * stored.max()
    )
    hist = np.asarray(a["range_histogram"][...], dtype=float)
    bounds = np.asarray(a["range_bin_bounds"][...])
    centres = bounds.mean(axis=1)
    # the stored per-wavelength offsets, weighted by each band's counts per wavelength
    # (unit-irradiance intensity at phase 0 = the Sun's intensity / the solar irradiance)
    wl, k = _kernel(loaded)
    unit = np.asarray(a["intensity"][:, 0, 0, :], dtype=float) / solar_irradiance_W_m2_nm(wl, 1.0)
    offset = np.asarray(a["range_offset"][...], dtype=float)
    w = unit[:, None, :] * k[None]  # (D, B, L)
    expected = np.nansum(w * offset[:, None, :], axis=2) / w.sum(axis=2)
    got = (hist * centres).sum(axis=2) / hist.sum(axis=2)
    # binning moves each return by at most half a bin
    half_bin = 0.5 * (bounds[0, 1] - bounds[0, 0])
    assert np.all(np.isfinite(got))
    assert np.max(np.abs(got - expected)) <= half_bin


def test_map_without_lasers_has_no_histogram(tmp_path):
    _, loaded = write_scenario(tmp_path, "bw.yaml", resolution_px=16, step_nm=100)
    assert reflectivity_map(loaded, tmp_path / "m.zarr", directions=12, chunk=12).complete
    group = zarr.open_group(str(tmp_path / "m.zarr"), mode="r")
    assert "range_histogram" not in group and "range_bin" not in group
    m = load_map(tmp_path / "m.zarr")
    assert m.range_histogram_per_s is None
    with pytest.raises(InputError, match="no range_histogram"):
        m.coaxial_range_histogram([[1.0, 0.0, 0.0]])
