"""Running sweeps: serial and on a real LocalCluster (2 workers, loopback), into the store.

References: a serial run in one process (the cluster must give identical arrays: the cases
are deterministic, noise included, since each case carries its noise seed); the plain
``simulate`` of a case's scenario; and a closed form: a Lambertian surface reflects in
proportion to its albedo (Lambert 1760) and the single-scattering render is linear in it, so
doubling the albedo doubles every count rate (to rounding) and lowers the AB magnitude by
2.5 log10(2). A sweep that is interrupted must resume where it stopped: counted task calls.
"""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from typer.testing import CliRunner

from speclight.cli import app
from speclight.errors import InputError
from speclight.scale import open_executor, worker_cache
from speclight.scale.sweep_cases import plan_sweep
from speclight.scale.sweep_file import load_sweep
from speclight.scale.sweep_run import run_case, run_sweep
from speclight.scenario import parse_scenario
from speclight.simulation import simulate

TLE = """CALSPHERE 4A
1 01520U 65065H   20058.86916325  .00000035  00000-0  49354-4 0  9992
2 01520  90.0403 128.7439 0072289 113.7399 336.8322 13.35807489655439
"""
TINY = """base: calsphere
set:
  render.resolution_px: 16
  time: {start: 2020-02-29T21:16:00Z, stop: 2020-02-29T21:16:20Z, step_s: 4.0}
"""
#: Relative rounding of float64 through a few hundred operations.
ROUNDING = 1e-12


def _plan(tmp_path: Path, vary: str, name: str = "sweep.yaml", extra: str = "", set_: str = ""):
    path = tmp_path / name
    path.write_text(TINY + set_ + extra + "vary:\n" + vary)
    return plan_sweep(load_sweep(path))


ALBEDO = "  target.materials.body.reflectance: [0.45, 0.9]\n"
FAILING = (
    ALBEDO + "  zip:\n    orbit.tle_file: [cs.tle, missing.tle]\n    orbit.norad_id: [1520, 1520]\n"
)
ORBIT_FROM_FILE = "  orbit: {tle_file: cs.tle}\n"  # set: the base's tle replaced by a file


@pytest.fixture(scope="module")
def cluster():
    with open_executor("local", n_workers=2) as ex:
        yield ex.client.scheduler.address


def _read(path: Path) -> xr.Dataset:
    return xr.open_zarr(path).load()


def test_cases_follow_the_albedo_law_and_xarray_reads_the_store(tmp_path):
    plan = _plan(tmp_path, ALBEDO)
    run = run_sweep(plan, tmp_path / "runs.zarr", scheduler="none")
    assert (run.ran, run.skipped, run.failed, run.complete) == (2, 0, {}, True)
    ds = _read(tmp_path / "runs.zarr")
    assert dict(ds.sizes) == {"case": 2, "time": 6, "band": 7}
    np.testing.assert_array_equal(ds["param_target__materials__body__reflectance"], [0.45, 0.9])
    assert list(ds["error"].values) == ["", ""]
    rate = ds["count_rate"].values
    lit = rate[0] > 0
    assert lit.sum() >= 30  # sunlit and above 10 deg
    np.testing.assert_allclose(rate[1][lit], 2 * rate[0][lit], rtol=ROUNDING)
    mag = ds["ab_magnitude"].values
    np.testing.assert_allclose(mag[0][lit] - mag[1][lit], 2.5 * math.log10(2), rtol=1e-9)
    # the case equals the plain simulate of its scenario (geometry from the worker cache)
    task = plan.tasks[1]
    alone = simulate(parse_scenario(task.yaml_text, base_dir=Path(task.base_dir))).dataset
    np.testing.assert_allclose(rate[1], alone["count_rate"].values, rtol=ROUNDING)
    np.testing.assert_allclose(
        ds["count_rate_measured"][1], alone["count_rate_measured"], rtol=ROUNDING
    )
    assert ds.attrs["fields"] == ["target.materials.body.reflectance"] and ds.attrs["complete"]


def test_cluster_gives_the_serial_store_and_a_failing_case_is_flagged(tmp_path, cluster):
    (tmp_path / "cs.tle").write_text(TLE)
    plan = _plan(tmp_path, FAILING, set_=ORBIT_FROM_FILE)
    serial = run_sweep(plan, tmp_path / "serial.zarr", scheduler="none")
    dask = run_sweep(plan, tmp_path / "dask.zarr", scheduler=cluster)
    assert "Dask cluster" in dask.where and serial.where.endswith("(serial)")
    assert sorted(dask.failed) == sorted(serial.failed) == [1, 3]  # missing.tle
    assert "missing.tle" in dask.failed[1] and dask.complete
    a, b = _read(tmp_path / "serial.zarr"), _read(tmp_path / "dask.zarr")
    for name in ("count_rate", "ab_magnitude", "count_rate_measured"):
        assert np.array_equal(a[name].values, b[name].values, equal_nan=True), name
        assert np.all(np.isnan(b[name].values[[1, 3]])) and not np.any(np.isnan(b[name][0]))
    assert list(a["error"].values) == list(b["error"].values)
    np.testing.assert_array_equal(b["param_orbit__norad_id"], [1520] * 4)
    assert list(b["param_orbit__tle_file"].values) == ["cs.tle", "missing.tle"] * 2


def test_set_then_vary_inside_a_set_section(tmp_path):
    # written as a test of the parser too: set orbit (a mapping), vary orbit.tle_file in it
    (tmp_path / "cs.tle").write_text(TLE)
    plan = _plan(tmp_path, FAILING, set_=ORBIT_FROM_FILE)
    assert len(plan.tasks) == 4


_calls: list[int] = []


def _counting(task):
    _calls.append(task.index)
    if len(_calls) == 3 and _interrupt:
        raise KeyboardInterrupt  # as Ctrl-C would, mid-run
    if task.index == 2:
        raise RuntimeError("case 2 fails once")
    return run_case(task)


_interrupt = True


def test_resume_skips_done_cases_and_retries_failed_ones(tmp_path):
    global _interrupt
    plan = _plan(tmp_path, "  target.materials.body.reflectance: [0.2, 0.4, 0.6, 0.8]\n")
    out = tmp_path / "runs.zarr"
    _calls.clear()
    _interrupt = True
    with pytest.raises(KeyboardInterrupt):
        run_sweep(plan, out, scheduler="none", task=_counting)
    assert _calls == [0, 1, 2]  # 0 and 1 done; 2 interrupted before it ran
    _calls.clear()
    _interrupt = False
    run = run_sweep(plan, out, scheduler="none", task=_counting)
    assert _calls == [2, 3] and (run.ran, run.skipped) == (2, 2)
    assert list(run.failed) == [2] and "case 2 fails once" in run.failed[2]
    _calls.clear()
    run = run_sweep(plan, out, scheduler="none", task=run_case)  # the failed one, again
    assert (run.ran, run.skipped, run.failed) == (1, 3, {})
    rate = _read(out)["count_rate"].values
    lit = rate[0] > 0
    for k, albedo in enumerate([0.2, 0.4, 0.6, 0.8]):
        np.testing.assert_allclose(rate[k][lit], rate[0][lit] * albedo / 0.2, rtol=ROUNDING)


def test_append_adds_cases_and_another_sweep_is_refused(tmp_path):
    first = _plan(tmp_path, "  target.materials.body.reflectance: [0.3]\n", "a.yaml")
    more = _plan(tmp_path, "  target.materials.body.reflectance: [0.6, 0.9]\n", "b.yaml")
    other = _plan(tmp_path, "  telescope.aperture_diameter_m: [0.5]\n", "c.yaml")
    out = tmp_path / "runs.zarr"
    run_sweep(first, out, scheduler="none")
    with pytest.raises(InputError, match=r"holds 1 cases of another sweep.*--append"):
        run_sweep(more, out, scheduler="none")
    run = run_sweep(more, out, scheduler="none", append=True)
    assert (run.first_case, run.ran) == (1, 2)
    again = run_sweep(more, out, scheduler="none", append=True)  # resumes, adds nothing
    assert (again.first_case, again.ran, again.skipped) == (1, 0, 2)
    with pytest.raises(InputError, match=r"cannot append.*its fields are"):
        run_sweep(other, out, scheduler="none", append=True)
    ds = _read(out)
    np.testing.assert_array_equal(ds["case"], [0, 1, 2])
    np.testing.assert_array_equal(ds["param_target__materials__body__reflectance"], [0.3, 0.6, 0.9])
    assert len(ds.attrs["segments"]) == 2
    rate = ds["count_rate"].values
    lit = rate[0] > 0
    np.testing.assert_allclose(rate[2][lit], 3 * rate[0][lit], rtol=ROUNDING)
    fresh = run_sweep(other, out, scheduler="none", force=True)
    assert fresh.first_case == 0 and _read(out).sizes["case"] == 1


def test_spectra_are_stored_when_asked(tmp_path):
    plan = _plan(tmp_path, ALBEDO, extra="spectra: true\n")
    run_sweep(plan, tmp_path / "runs.zarr", scheduler="none")
    ds = _read(tmp_path / "runs.zarr")
    assert ds["intensity"].dims == ("case", "time", "wavelength") and ds["wavelength"].size == 189
    lit = ds["intensity"].values[0] > 0
    np.testing.assert_allclose(
        ds["intensity"].values[1][lit], 2 * ds["intensity"].values[0][lit], rtol=1e-6
    )  # float32 in the store


def test_cli_runs_a_sweep_and_reports_file_errors_with_exit_2(tmp_path):
    runner = CliRunner()
    sweep = tmp_path / "sweep.yaml"
    sweep.write_text(TINY + "vary:\n  target.materials.body.reflectanse: [0.5]\n")
    result = runner.invoke(app, ["sweep", str(sweep), "-o", str(tmp_path / "r.zarr")])
    assert result.exit_code == 2
    assert f"{sweep}: line 6: vary.target.materials.body.reflectanse" in result.output
    assert "did you mean 'reflectance'" in result.output
    sweep.write_text(TINY + "vary:\n  target.materials.body.reflectance: [0.5]\n")
    args = ["sweep", str(sweep), "-o", str(tmp_path / "r.zarr"), "--scheduler", "none"]
    result = runner.invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "ran 1, skipped 0" in result.output and "wrote" in result.output
    assert runner.invoke(app, args).output.count("skipped 1 done before") == 1


def test_the_geometry_is_built_once_per_worker_for_unchanged_sections(tmp_path):
    plan = _plan(tmp_path, ALBEDO)
    worker_cache.clear()
    run_case(plan.tasks[0])
    assert len(worker_cache._CACHE) == 1
    run_case(dataclasses.replace(plan.tasks[1]))
    assert len(worker_cache._CACHE) == 1  # the albedo does not change the geometry
    worker_cache.clear()


def test_polarised_cases_keep_dolp_and_aolp(tmp_path):
    metal = "  target.materials.body: {bsdf: ggx, roughness: 0.3, reflectance: {conductor: Al}}\n"
    plan = _plan(tmp_path, "  render.polarization: [false, true]\n", set_=metal)
    assert plan.polarization
    run_sweep(plan, tmp_path / "runs.zarr", scheduler="none")
    ds = _read(tmp_path / "runs.zarr")
    assert ds["dolp"].dims == ("case", "time", "band") and ds["aolp"].attrs["units"] == "degree"
    assert np.isnan(ds["dolp"].values[0]).all()  # the unpolarised case writes no polarisation
    reference = simulate(parse_scenario(plan.tasks[1].yaml_text)).dataset
    lit = np.isfinite(reference["dolp"].values)
    assert lit.any() and (reference["dolp"].values[lit] > 0.01).all()  # Al at phase ~100 deg
    for name in ("dolp", "aolp"):
        np.testing.assert_allclose(ds[name].values[1], reference[name].values, rtol=ROUNDING)
