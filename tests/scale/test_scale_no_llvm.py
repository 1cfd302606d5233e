"""The documented fallback (no libLLVM 16-19) inside Dask workers, and the exit-code rule.

``SPECLIGHT_HIDE_LLVM=1`` makes a process, and the workers of a local cluster it starts,
behave as on a machine without libLLVM 16-19: ``scalar_*`` variants and the numpy ray caster,
which must not start processes inside a (daemonic) Dask worker. One worker per run, so that
the worker's share of the cores (``SPECLIGHT_RENDER_THREADS``) is all of them and the numpy
caster would use a process pool if it were allowed to. Each command runs in a fresh
interpreter: Dr.Jit chooses its libLLVM once per process, at its first import.

References: a Lambertian sphere's single-scattering intensity at phase angle 0,
``I = 2/3 rho E R^2`` (Russell 1916, ApJ 43, 173, doi:10.1086/142244); a Lambertian surface
reflects in proportion to its albedo (Lambert 1760), so doubling it doubles every count rate.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import zarr

from speclight.illumination import solar_irradiance_W_m2_nm
from speclight.render.variant import HIDE_LLVM_ENV, mitsuba_installed
from speclight.scenario.builtin_examples import example_text

SWEEP = """base: calsphere
set:
  render.resolution_px: 16
  time: {start: 2020-02-29T21:16:00Z, stop: 2020-02-29T21:16:08Z, step_s: 4.0}
vary:
  target.materials.body.reflectance: [0.3, 0.6]
"""
#: The calsphere example's sphere (radius 0.18 m, albedo 0.9) on a coarse grid.
RHO, RADIUS_M = 0.9, 0.18
#: Pixel sampling of a sphere at 64 px (the disk's rim pixels, weighted by cos^2): the
#: single-mode sphere test measures < 0.2 % at 256 px, about 4x that at 64 px.
PIXEL_SAMPLING = 0.01
#: Relative rounding of float64 through a few hundred operations.
ROUNDING = 1e-12


def _speclight(*args: str | Path, cwd: Path) -> subprocess.CompletedProcess[str]:
    env = {**os.environ, HIDE_LLVM_ENV: "1"}
    return subprocess.run(
        [sys.executable, "-m", "speclight", *map(str, args)],
        capture_output=True,
        text=True,
        cwd=cwd,
        env=env,
        timeout=300,
    )


def test_hidden_llvm_leaves_the_fallback_variants():
    code = "from speclight.render import choose_variant as c; print(c(None, spectral=False))"
    env = {**os.environ, HIDE_LLVM_ENV: "1"}
    out = subprocess.run(
        [sys.executable, "-W", "ignore", "-c", code], capture_output=True, text=True, env=env
    )
    chosen = out.stdout.strip()
    assert chosen in ("scalar_rgb", "numpy") and not chosen.startswith("llvm_"), out


def test_sweep_and_map_on_a_local_cluster_without_llvm(tmp_path):
    (tmp_path / "sweep.yaml").write_text(SWEEP)
    sweep = _speclight("sweep", "sweep.yaml", "-o", "runs.zarr", "--workers", "1", cwd=tmp_path)
    assert sweep.returncode == 0, sweep.stderr
    runs = xr.open_zarr(tmp_path / "runs.zarr").load()
    assert list(runs.case_state.values) == [1, 1] and list(runs.error.values) == ["", ""]
    rate = runs.count_rate.values  # (case, time, band): albedo 0.6 is twice 0.3
    assert np.all(np.isfinite(rate)) and np.all(rate > 0)
    np.testing.assert_allclose(rate[1], 2 * rate[0], rtol=ROUNDING)

    text = example_text("calsphere").replace("resolution_px: 256", "resolution_px: 64")
    (tmp_path / "sphere.yaml").write_text(text.replace("step_nm: 5", "step_nm: 100"))
    args = ("--directions", "12", "--chunk", "6", "--scheduler", "local", "--workers", "1")
    made = _speclight("reflectivity-map", "sphere.yaml", "-o", "m.zarr", *args, cwd=tmp_path)
    assert made.returncode == 0, made.stderr
    group = zarr.open_group(str(tmp_path / "m.zarr"), mode="r")
    want = "scalar_rgb" if mitsuba_installed() else "numpy"
    assert group.attrs["render_variant"] == want and group.attrs["complete"]
    wl = np.asarray(group["wavelength"][...])
    ref = 2 / 3 * RHO * RADIUS_M**2 * solar_irradiance_W_m2_nm(wl, 1.0)  # at 1 AU
    got = np.asarray(group["intensity"][...], dtype=float)[:, 0, 0, :]  # (direction, bin)
    np.testing.assert_allclose(got, np.broadcast_to(ref, got.shape), rtol=PIXEL_SAMPLING)


@pytest.mark.parametrize(("albedos", "code"), [("[0.3, 0.6]", 0), ("[0.6]", 1)])
def test_a_sweep_with_failed_cases_warns_and_with_all_failed_exits_1(tmp_path, albedos, code):
    # The second albedo's case reads a TLE file that does not exist: it fails when it runs.
    (tmp_path / "cs.tle").write_text(
        "CALSPHERE 4A\n"
        "1 01520U 65065H   20058.86916325  .00000035  00000-0  49354-4 0  9992\n"
        "2 01520  90.0403 128.7439 0072289 113.7399 336.8322 13.35807489655439\n"
    )
    tle = "[cs.tle, missing.tle]" if code == 0 else "[missing.tle]"
    norad = "[1520, 1520]" if code == 0 else "[1520]"
    (tmp_path / "sweep.yaml").write_text(
        SWEEP.replace("vary:\n  target.materials.body.reflectance: [0.3, 0.6]\n", "")
        + "  orbit: {tle_file: cs.tle}\n"
        + f"vary:\n  zip:\n    orbit.tle_file: {tle}\n    orbit.norad_id: {norad}\n"
        + f"    target.materials.body.reflectance: {albedos}\n"
    )
    from typer.testing import CliRunner

    from speclight.cli import app

    args = ["sweep", str(tmp_path / "sweep.yaml"), "-o", str(tmp_path / "r.zarr")]
    result = CliRunner().invoke(app, [*args, "--scheduler", "none"])
    assert result.exit_code == code, result.output
    assert "case(s) failed" in result.stderr and "missing.tle" in result.stderr
    assert result.stderr.startswith("warning:" if code == 0 else "error:")
