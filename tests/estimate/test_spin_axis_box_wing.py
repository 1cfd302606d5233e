"""Spin axes of simulated box-wing passes recovered against a map of the same target, and the
``speclight spin-axis`` command line (a run; bad input refused with exit code 2 and one line).

The passes are rendered (``render.mode: single``, 24 px, 100 nm bins, 150 epochs, the
example's noise: the search reads the noisy rates' reflectance factors); the map is a
separate, coarse one (HEALPix nside 4, ~15 deg between directions, phase angles 40-130 deg,
8 rolls). The reference cases of Nussbaum et al. 2022, Fig. 18: the spin about the antenna
(body z) and about the wingspan (body y, ``spin_body_axis: [0, 1, 0]``). Pass criterion (the
issue's): the truth lies in the best cell or one of its 8 neighbours (within sqrt(2) grid
steps), or so does it for the reported mirror minimum (a box-wing is nearly symmetric about
its equatorial plane, so the reversed axis fits almost as well; Fig. 18a).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from map_scenarios import map_scenario_text
from typer.testing import CliRunner

from speclight.cli import app
from speclight.estimate.spin_axis.spin_axis_core import angular_distance_deg
from speclight.estimate.spin_axis.spin_axis_run import spin_axis_measured
from speclight.io.netcdf import dataset_bytes
from speclight.maps.writer.reflectivity_map_run import reflectivity_map
from speclight.scenario import example_text, load_scenario
from speclight.simulation import simulate

GRID_DEG, PHASES = 10.0, 36
runner = CliRunner()


def _pass_text(body_axis: str = "", ra: float = 30.0, dec: float = 45.0) -> str:
    text = map_scenario_text(resolution_px=24, step_nm=100).replace("step_s: 1.0", "step_s: 4.0")
    text = text.replace("spin_axis_ra_deg: 30.0", f"spin_axis_ra_deg: {ra}")
    text = text.replace("spin_axis_dec_deg: 45.0", f"spin_axis_dec_deg: {dec}")
    if body_axis:
        text = text.replace(
            "initial_phase_deg: 0.0", f"initial_phase_deg: 0.0\n  spin_body_axis: {body_axis}"
        )
    return text


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("spin")
    (folder / "map.yaml").write_text(_pass_text())
    reflectivity_map(
        load_scenario(folder / "map.yaml"),
        folder / "m.zarr",
        directions=192,
        phase_angles_deg=[40, 70, 100, 130],
        rolls=8,
        chunk=192,
    )
    return folder


def _simulated(folder: Path, name: str, text: str) -> Path:
    (folder / f"{name}.yaml").write_text(text)
    out = folder / f"{name}.nc"
    if not out.exists():
        out.write_bytes(dataset_bytes(simulate(load_scenario(folder / f"{name}.yaml")).dataset))
    return folder / f"{name}.yaml"


@pytest.mark.parametrize(
    ("name", "body_axis", "ra", "dec"),
    [("antenna", "", 30.0, 45.0), ("wingspan", "[0, 1, 0]", 200.0, -20.0)],
)
def test_box_wing_axis_recovered(folder, name, body_axis, ra, dec) -> None:
    scenario = _simulated(folder, name, _pass_text(body_axis, ra, dec))
    run = spin_axis_measured(
        load_scenario(scenario),
        scenario.with_suffix(".nc"),
        folder / "m.zarr",
        grid_deg=GRID_DEG,
        n_phases=PHASES,
    )
    r = run.result
    assert run.scenario_axis == (ra, dec)
    assert run.spin_body_axis == ([0.0, 1.0, 0.0] if body_axis else [0.0, 0.0, 1.0])
    near = [angular_distance_deg(a[0], a[1], ra, dec) for a in (r.best, r.mirror)]
    assert min(near) <= np.sqrt(2) * GRID_DEG, (r.best, r.mirror)
    # the mirror is the second minimum far from the best: the reversed axis, roughly
    assert angular_distance_deg(r.best[0], r.best[1], r.mirror[0], r.mirror[1]) > 90
    # refinement from the best cells does not end worse than they are
    assert r.refined[3] <= min(r.best[3], r.mirror[3])


def _one_line_error(result, *words: str) -> None:
    assert result.exit_code == 2, result.output
    lines = [line for line in result.output.splitlines() if line.startswith("error:")]
    assert len(lines) == 1, result.output
    for word in words:
        assert word in lines[0], lines[0]


def test_cli_run_and_bad_input(folder) -> None:
    scenario = _simulated(folder, "antenna", _pass_text())
    measured, out = scenario.with_suffix(".nc"), folder / "axis.nc"
    base = ["spin-axis", str(scenario), str(measured), "--map", str(folder / "m.zarr")]
    args = [*base, "-o", str(out), "--grid-deg", "30", "--phases", "12", "--no-refine"]
    ok = runner.invoke(app, [*args, "--plot", str(folder / "axis.png")])
    assert ok.exit_code == 0, ok.output
    assert "best axis RA" in ok.output
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds["error"].dims == ("ra", "dec") and ds["error"].shape == (12, 6)
        assert ds["best_phase"].shape == (12, 6)
        for key in ("best", "mirror", "refined"):
            assert f"{key}_ra_deg" in ds.attrs and f"{key}_dec_deg" in ds.attrs
        assert np.isnan(ds.attrs["refined_ra_deg"])  # --no-refine
        assert ds.attrs["scenario_ra_deg"] == 30.0
        assert ds.attrs["period_s"] == 120.0
        # the true track is the simulation's own phase vector in the body frame
        with xr.open_dataset(measured, engine="h5netcdf") as sim:
            p = sim["phase_vector_body"].transpose("time", ...).values
        lat = ds["track_lat"].sel(solution="scenario").values
        np.testing.assert_allclose(lat, np.degrees(np.arcsin(p[:, 2])), atol=1e-9)
    assert (folder / "axis.png").stat().st_size > 0
    # the gradient refinement with a free period: method, evaluations and period recorded
    grad = [*base, "-o", str(folder / "grad.nc"), *args[7:11], "--refine", "gradient"]
    run = runner.invoke(app, [*grad, "--free-period"])
    assert run.exit_code == 0, run.output
    assert "by gradient with 0 misfit and " in run.output and "period " in run.output
    with xr.open_dataset(folder / "grad.nc", engine="h5netcdf") as ds:
        a = ds.attrs
        assert a["refine_method"] == "gradient" and a["period_free"] == 1
        assert a["refine_gradient_evaluations"] > 0 and a["refine_misfit_evaluations"] == 0
        assert abs(a["refined_period_s"] / 120.0 - 1) <= a["period_bound"] == 0.05
        assert a["period_check"] == "not run"  # a free period
    with xr.open_dataset(out, engine="h5netcdf") as ds:
        assert ds.attrs["refine_method"] == "none" and ds.attrs["period_free"] == 0
        assert ds.attrs["period_check"] == "not run"  # no refinement
    cont = [*base, "-o", str(folder / "cont.nc"), *args[7:11]]
    run = runner.invoke(app, [*cont, "--refine", "gradient-continuation"])
    assert run.exit_code == 0, run.output
    assert "by gradient-continuation with 0 misfit and " in run.output
    with xr.open_dataset(folder / "cont.nc", engine="h5netcdf") as ds:
        assert ds.attrs["refine_method"] == "gradient-continuation"
        assert ds.attrs["refine_gradient_evaluations"] > 0
        # the map (192 directions, 15 deg apart) against the rendered truth: the answer is
        # ~6 deg off the scenario's axis, and the sigmas count the map's error (the
        # jackknife-shrunk ones alone were ~2.2 deg: 3 sigma off), so the truth is within
        # the 95 % ellipse's 2.45 sigma of the largest axis; the region is then wide
        # (> 5 % of the sphere: not constrained) and the period check is not run (the true
        # period passing it: test_spin_axis.py)
        a = ds.attrs
        err = angular_distance_deg(a["refined_ra_deg"], a["refined_dec_deg"], 30.0, 45.0)
        assert err <= 2.45 * a["sigma_axis_deg"], (err, a["sigma_axis_deg"])
        assert a["period_check"] == "not run" and a["axis_constrained"] == 0, a["axis_note"]
        assert a["sigma_method"] == "jackknife-warp"  # the default, recorded
    # the same noisy rates as a CSV (eq. 5 applied to them with the scenario's geometry, the
    # scenario run on the map): the same misfits, to the CSV's 7 significant digits
    with xr.open_dataset(measured, engine="h5netcdf") as sim:
        rate = sim["count_rate_measured"].transpose("time", "band").values
        rows = [f"time,{','.join(str(b) for b in sim['band'].values)}"]
        for t, r in zip(sim["time"].values, rate, strict=True):
            rows.append(
                f"{np.datetime_as_string(t, unit='ms')}Z," + ",".join(f"{x:.7g}" for x in r)
            )
    (folder / "pass.csv").write_text("\n".join(rows) + "\n")
    csv_args = [base[0], str(scenario), str(folder / "pass.csv"), *base[3:]]
    csv_run = runner.invoke(app, [*csv_args, *args[7:], "-o", str(folder / "csv.nc")])
    assert csv_run.exit_code == 0, csv_run.output
    with xr.open_dataset(out, engine="h5netcdf") as a, xr.open_dataset(folder / "csv.nc") as b:
        np.testing.assert_allclose(b["error"].values, a["error"].values, rtol=1e-5)
    _one_line_error(runner.invoke(app, args), "exists")
    new = ["-o", str(folder / "new.nc")]
    _one_line_error(runner.invoke(app, [*base, *new, "--grid-deg", "0"]), "--grid-deg")
    _one_line_error(runner.invoke(app, [*base, *new, "--grid-deg", "91"]), "--grid-deg")
    _one_line_error(runner.invoke(app, [*base, *new, "--phases", "0"]), "--phases")
    _one_line_error(runner.invoke(app, [*base, *new, "--period-s", "-3"]), "--period-s")
    _one_line_error(runner.invoke(app, [*base, *new, "--bands", "G-999/1"]), "G-999/1")
    _one_line_error(runner.invoke(app, [*base, *new, "--refine", "newton"]), "--refine")
    _one_line_error(runner.invoke(app, [*base, *new, "--period-kind", "solar"]), "--period-kind")
    bad_bound = ["--free-period", "--period-bound", "0.9"]
    _one_line_error(runner.invoke(app, [*base, *new, *bad_bound]), "--period-bound")
    # no period: a fixed attitude and no --period-s
    fixed = scenario.read_text().replace(
        "  model: spin\n", "  model: fixed\n  quaternion: [1, 0, 0, 0]\n"
    )
    for key in ("spin_axis_ra_deg", "spin_axis_dec_deg", "period_s", "initial_phase_deg"):
        fixed = "\n".join(ln for ln in fixed.splitlines() if key not in ln) + "\n"
    (folder / "fixed.yaml").write_text(fixed)
    base_fixed = [base[0], str(folder / "fixed.yaml"), *base[2:]]
    _one_line_error(runner.invoke(app, [*base_fixed, *new]), "--period-s")
    # a map of other bands than the scenario's
    fewer = scenario.read_text().replace(
        "    - {name: G-420/26, gaussian: {center_nm: 420, sigma_nm: 26}}\n", ""
    )
    (folder / "fewer.yaml").write_text(fewer)
    base_fewer = [base[0], str(folder / "fewer.yaml"), *base[2:]]
    _one_line_error(runner.invoke(app, [*base_fewer, *new]), "instrument.bands")
    assert not (folder / "new.nc").exists()


def test_cli_refuses_what_cannot_be_searched(folder) -> None:
    """Sizes that cannot finish, curves without a mean, another satellite (issue 22)."""
    scenario = _simulated(folder, "antenna", _pass_text())
    measured = scenario.with_suffix(".nc")
    base = ["spin-axis", str(scenario), str(measured), "--map", str(folder / "m.zarr")]
    new = ["-o", str(folder / "refused.nc")]
    _one_line_error(runner.invoke(app, [*base, *new, "--phases", "1000000000"]),
                    "--phases = 1000000000 must be 1..36000")  # fmt: skip
    # within the bounds but over the memory or time limit (which, depends on the machine)
    _one_line_error(runner.invoke(app, [*base, *new, "--phases", "36000"]),
                    "--phases = 36000: the search of 180 x 90 axes x 36000 phases")  # fmt: skip
    _one_line_error(runner.invoke(app, [*base, *new, "--grid-deg", "0.01"]),
                    "--grid-deg = 0.01: the search of 36000 x 18000 axes")  # fmt: skip
    _one_line_error(runner.invoke(app, [*base, *new, "--period-s", "1e-9"]), "--period-s")
    # a band of zero rates (a CSV of the pass): the reader refuses it (it measured nothing)
    with xr.open_dataset(measured, engine="h5netcdf") as sim:
        rate = sim["count_rate_measured"].transpose("time", "band").values
        bands = [str(b) for b in sim["band"].values]
        times = sim["time"].values
    rate[:, 2] = 0.0
    rows = [f"time,{','.join(bands)}"] + [
        f"{np.datetime_as_string(t, unit='ms')}Z," + ",".join(f"{x:.7g}" for x in r)
        for t, r in zip(times, rate, strict=True)
    ]
    (folder / "zero.csv").write_text("\n".join(rows) + "\n")
    zero = [base[0], str(scenario), str(folder / "zero.csv"), *base[3:]]
    _one_line_error(runner.invoke(app, [*zero, *new, "--grid-deg", "30", "--phases", "12"]),
                    "MEASURED", f"band '{bands[2]}' has no rate above 0")  # fmt: skip

    # the scenario of another satellite (the calsphere's orbit) for the box-wing's pass
    def orbit(text: str) -> str:
        return text[text.index("orbit:") : text.index("attitude:")]

    other = _pass_text().replace(orbit(_pass_text()), orbit(example_text("calsphere")))
    (folder / "other.yaml").write_text(other)
    _one_line_error(
        runner.invoke(app, [base[0], str(folder / "other.yaml"), *base[2:], *new]),
        "catalogue number 1520",
    )
    assert not (folder / "refused.nc").exists()
    # a run that passes: finite refined axis, and AXIS.nc says how it was refined
    ok = runner.invoke(app, [*base, "-o", str(folder / "ok.nc"), "--grid-deg", "30",
                             "--phases", "12"])  # fmt: skip
    assert ok.exit_code == 0, ok.output
    with xr.open_dataset(folder / "ok.nc", engine="h5netcdf") as ds:
        assert all(np.isfinite(ds.attrs[f"refined_{k}"]) for k in ("ra_deg", "dec_deg", "error"))
        assert ds.attrs["refine_note"] and ds.attrs["mirror_note"]
