"""Reflectivity maps of a Lambertian sphere against the closed-form phase law; the store.

Lambert sphere of radius R and albedo rho under the irradiance E, phase angle a:
``I(a) = 2 / (3 pi) rho E R^2 [sin a + (pi - a) cos a]`` (Russell 1916, ApJ 43, 173,
doi:10.1086/142244; the same law as tests/render/test_render_single_closed_forms.py).
"""

import numpy as np
import pytest
from map_scenarios import SPHERE_TARGET, write_scenario

from speclight import instrument
from speclight.errors import InputError
from speclight.illumination import solar_irradiance_W_m2_nm
from speclight.maps.map_geometry import sun_observer
from speclight.maps.map_lookup import load_map, read_header
from speclight.maps.writer.reflectivity_map_run import reflectivity_map
from speclight.render import available_variants
from speclight.simulation import simulate
from speclight.simulation.radiometry import instrument_response, wavelength_grid_nm

RHO, RADIUS_M = 0.6, 1.7
#: 256 px: the single-mode sphere test's accuracy (0.5 %, pixel sampling < 0.2 %).
TOLERANCE = 0.005
PHASES_DEG = [0.0, 60.0, 120.0]


def lambert(a_rad):
    a = np.asarray(a_rad, dtype=float)
    return 2 / (3 * np.pi) * RHO * RADIUS_M**2 * (np.sin(a) + (np.pi - a) * np.cos(a))


@pytest.fixture(scope="module")
def sphere_map(tmp_path_factory):
    folder = tmp_path_factory.mktemp("sphere")
    _, loaded = write_scenario(
        folder, "sphere.yaml", resolution_px=256, step_nm=100, target=SPHERE_TARGET
    )
    run = reflectivity_map(
        loaded, folder / "m.zarr", directions=12, phase_angles_deg=PHASES_DEG, rolls=4, chunk=5
    )
    assert run.complete and not run.failed and run.n_chunks == 3
    return folder, loaded


def test_sphere_map_follows_the_lambert_phase_law(sphere_map):
    folder, loaded = sphere_map
    m = load_map(folder / "m.zarr")
    wl = wavelength_grid_nm(loaded.scenario.spectrum)
    e = solar_irradiance_W_m2_nm(wl, 1.0)  # the map is at 1 AU
    ref = lambert(np.radians(PHASES_DEG))[:, None] * e[None, :]  # (P, L)
    got = m.intensity_W_sr_nm  # (D, P, R, L): every direction and roll sees the same sphere
    assert got.shape == (12, 3, 4, wl.size)
    np.testing.assert_allclose(
        got, np.broadcast_to(ref[None, :, None, :], got.shape), rtol=TOLERANCE
    )


def test_sphere_count_rates_for_unit_range_and_aperture(sphere_map):
    folder, loaded = sphere_map
    import zarr

    rate = np.asarray(zarr.open_group(str(folder / "m.zarr"), mode="r")["count_rate"][...])
    wl = wavelength_grid_nm(loaded.scenario.spectrum)
    e = solar_irradiance_W_m2_nm(wl, 1.0)
    intensity = lambert(np.radians(PHASES_DEG))[:, None] * e[None, :]
    # the instrument chain at a range of 1 m and no atmosphere, per m2 of the scenario's aperture
    sc = loaded.scenario
    area = instrument.aperture_area_m2(sc.telescope.aperture_diameter_m)
    chain = instrument_response(loaded, wl, intensity, np.ones_like(intensity), np.ones(3))
    expected = chain.count_rate_per_s / area  # (P, B)
    assert rate.shape == (12, 3, 4, len(sc.instrument.bands))
    np.testing.assert_allclose(
        rate, np.broadcast_to(expected[None, :, None, :], rate.shape), rtol=TOLERANCE
    )


def test_lookup_between_stored_phase_angles_is_linear(sphere_map):
    folder, loaded = sphere_map
    m = load_map(folder / "m.zarr")
    wl = wavelength_grid_nm(loaded.scenario.spectrum)
    e = solar_irradiance_W_m2_nm(wl, 1.0)
    rng = np.random.default_rng(5)
    p = rng.normal(size=(50, 3))
    p /= np.linalg.norm(p, axis=1)[:, None]
    a = np.radians(rng.uniform(0, 150, 50))  # 120..150: clamped to 120
    s, o = sun_observer(p, a, rng.uniform(0, 2 * np.pi, 50))
    stored = np.radians(PHASES_DEG)
    expected = np.interp(a, stored, lambert(stored))[:, None] * e[None, :]
    np.testing.assert_allclose(m.intensity_1au(s, o), expected, rtol=TOLERANCE)


def test_map_mode_pass_scales_by_sun_distance(sphere_map):
    folder, _ = sphere_map
    _, loaded = write_scenario(
        folder,
        "sphere-map.yaml",
        resolution_px=256,
        step_nm=100,
        target=SPHERE_TARGET,
        render="render: {mode: map, map_file: m.zarr}",
    )
    ds = simulate(loaded).dataset
    assert ds.attrs["render_mode"] == "map"
    stored = np.radians(PHASES_DEG)
    a = np.radians(ds["phase_angle"].values)
    lit = np.isfinite(ds["intensity"].values[:, 0]) & (ds["sunlit"].values > 0)
    assert lit.sum() > 100
    expected = (
        np.interp(a, stored, lambert(stored))[:, None]
        * ds["solar_irradiance"].values
        * ds["sunlit"].values[:, None]
    )
    np.testing.assert_allclose(ds["intensity"].values[lit], expected[lit], rtol=TOLERANCE)


def test_resume_after_an_interruption_gives_the_uninterrupted_map(tmp_path):
    _, loaded = write_scenario(tmp_path, "bw.yaml", resolution_px=16, step_nm=100)
    full = reflectivity_map(loaded, tmp_path / "full.zarr", directions=48, chunk=10)
    part = reflectivity_map(loaded, tmp_path / "part.zarr", directions=48, chunk=10, max_chunks=2)
    assert full.complete and not part.complete and part.rendered == 2
    with pytest.raises(InputError, match="unfinished"):
        read_header(tmp_path / "part.zarr")
    again = reflectivity_map(loaded, tmp_path / "part.zarr", directions=48, chunk=10)
    assert again.complete and again.skipped == 2 and again.rendered == 3
    a = load_map(tmp_path / "full.zarr").intensity_W_sr_nm
    b = load_map(tmp_path / "part.zarr").intensity_W_sr_nm
    np.testing.assert_array_equal(a, b)
    with pytest.raises(InputError, match="other parameters"):  # an unfinished map, other N
        reflectivity_map(loaded, tmp_path / "part2.zarr", directions=48, chunk=10, max_chunks=1)
        reflectivity_map(loaded, tmp_path / "part2.zarr", directions=200, chunk=10)


def test_failed_chunk_is_recorded_and_retried(tmp_path, monkeypatch):
    import speclight.render as render

    _, loaded = write_scenario(tmp_path, "bw.yaml", resolution_px=16, step_nm=100)
    real = render.render_intensity
    calls = []

    def flaky(*args, **kwargs):
        calls.append(1)
        if len(calls) == 2:
            raise RuntimeError("simulated render failure")
        return real(*args, **kwargs)

    monkeypatch.setattr(render, "render_intensity", flaky)
    run = reflectivity_map(loaded, tmp_path / "m.zarr", directions=48, chunk=20)
    assert run.rendered == 2 and not run.complete  # the failed chunk is not counted
    assert run.failed == {"1": "RuntimeError: simulated render failure"}
    monkeypatch.setattr(render, "render_intensity", real)
    again = reflectivity_map(loaded, tmp_path / "m.zarr", directions=48, chunk=20)
    assert again.complete and again.rendered == 1 and again.failed == {}
    assert np.all(np.isfinite(load_map(tmp_path / "m.zarr").intensity_W_sr_nm))


@pytest.mark.skipif(
    not any(v.endswith("_spectral") and not v.startswith("scalar") for v in available_variants()),
    reason="path mode needs a vectorised Mitsuba spectral variant",
)
def test_path_mode_sphere_map_is_unbiased(tmp_path):
    # Each direction and roll of a sphere's map is an independent Monte Carlo estimate of
    # the same Lambert intensity (chunks use seed + chunk): their mean must agree with the
    # closed form within 4 standard errors of the mean (z-test; 6e-5 false alarms, seeded).
    render = "render: {mode: path, resolution_px: 32, samples_per_pixel: 16, seed: 3}"
    _, loaded = write_scenario(
        tmp_path, "sphere.yaml", step_nm=100, target=SPHERE_TARGET, render=render
    )
    run = reflectivity_map(
        loaded, tmp_path / "p.zarr", directions=12, phase_angles_deg=[0, 60], rolls=2, chunk=6
    )
    assert run.complete and load_map(tmp_path / "p.zarr").header.attrs["render_mode"] == "path"
    got = load_map(tmp_path / "p.zarr").intensity_W_sr_nm.astype(float).sum(axis=-1)  # (D, P, R)
    wl = wavelength_grid_nm(loaded.scenario.spectrum)
    e_sum = solar_irradiance_W_m2_nm(wl, 1.0).sum()
    for j, phase in enumerate([0.0, 60.0]):
        samples = got[:, j, 0] if phase == 0 else got[:, j, :].ravel()  # phase 0: one per dir
        ref = lambert(np.radians(phase)) * e_sum
        sem = samples.std(ddof=1) / np.sqrt(samples.size)
        assert sem > 0  # distinct samples per direction and chunk
        assert abs(samples.mean() - ref) < 4 * sem, (samples.mean(), ref, sem)
        assert sem < 0.01 * ref  # a test that can tell 60 from 0 deg (and a 4 % bias)


def test_coaxial_range_offset_of_a_lambertian_sphere(tmp_path):
    # Coaxial (phase 0) Lambert sphere: a pixel at projected radius rho sees the surface at
    # depth -R cos(t) (cos(t) = sqrt(1 - rho^2 / R^2)) with intensity ~ cos(t); the mean over
    # the disk is -R (int mu^2 dA) / (int mu dA) = -R (pi R^2 / 2) / (2 pi R^2 / 3) = -3R/4.
    # Pixel sampling at 128 px: well under 1 % of R (tolerance 1 %).
    _, loaded = write_scenario(
        tmp_path,
        "sphere-laser.yaml",
        resolution_px=128,
        step_nm=100,
        target=SPHERE_TARGET,
        example="box-wing-laser",
    )
    run = reflectivity_map(loaded, tmp_path / "m.zarr", directions=12, chunk=12)
    assert run.complete
    import zarr

    offset = np.asarray(zarr.open_group(str(tmp_path / "m.zarr"), mode="r")["range_offset"][...])
    assert offset.shape == (12, wavelength_grid_nm(loaded.scenario.spectrum).size)
    np.testing.assert_allclose(offset, -0.75 * RADIUS_M, rtol=0.01)


@pytest.mark.skipif(
    not any(v.startswith(("llvm_", "cuda_")) for v in available_variants()),
    reason="a Mitsuba ray caster needs a vectorised variant",
)
def test_single_mode_map_after_a_path_mode_map_in_the_same_process(tmp_path):
    # The single-mode engine (a Mitsuba caster in an *_rgb variant) is kept per process; a
    # path-mode map in between sets a *_spectral variant process-wide. The third map must
    # render every chunk (the closed form at phase 0) and count only rendered chunks.
    single = write_scenario(tmp_path, "s.yaml", resolution_px=64, step_nm=100, target=SPHERE_TARGET)
    render = "render: {mode: path, resolution_px: 16, samples_per_pixel: 4}"
    path = write_scenario(tmp_path, "p.yaml", step_nm=100, target=SPHERE_TARGET, render=render)
    for k, (_, loaded) in enumerate([single, path, single]):
        run = reflectivity_map(loaded, tmp_path / f"m{k}.zarr", directions=12, chunk=6)
        assert run.failed == {} and run.rendered == 2 and run.complete
    m = load_map(tmp_path / "m2.zarr")
    e = solar_irradiance_W_m2_nm(wavelength_grid_nm(single[1].scenario.spectrum), 1.0)
    got = m.intensity_W_sr_nm[:, 0, 0, :]
    # 64 px: pixel sampling within 1 % (0.2 % at 256 px, TOLERANCE's source)
    np.testing.assert_allclose(got, np.broadcast_to(lambert(0.0) * e, got.shape), rtol=0.01)
