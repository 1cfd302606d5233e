"""``speclight unmix`` end to end on the cube-materials examples (Sun and lasers).

The reference is the ground truth of ``render: {per_material: true}``: each material's share
``F_k(t, j)`` of the band reflectance factor. Every BRDF of the cube is its tabulated
reflectance times a geometric factor and a single-mode render has no interreflections, so
``F_k(t) = g_k(t) s_k(t)`` with ``s_k(t)`` the band average of the table weighted by the
detected photons of that epoch's source at the aperture (SPEC section 5, eq. 5;
docs/cube-materials.md). The true fractions are ``g / sum(g)`` with ``g_k = F_k . s_k /
|s_k|^2``, computed here from the shipped tables and the dataset's source spectrum.

Noise-free, the command unmixes every epoch with that epoch's signatures, so (as
tests/estimate/test_estimate_cube_materials.py derives) it recovers the fractions to float64
rounding (``EXACT``; the signature matrix has a condition number ~120): the dominant material
is right in every epoch whose true lead exceeds ``2 EXACT``, the 100 % of
docs/cube-materials.md. Low resolution and a short pass keep it a few seconds.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml
from typer.testing import CliRunner

from speclight.cli import app
from speclight.estimate import spectral_angle_rad
from speclight.estimate.inputs.source_spectrum import (
    coaxial_laser_source_W_m2_nm,
    laser_lines_per_nm,
)
from speclight.estimate.spectra.ground_truth import (
    fractions,
    material_signatures,
    true_contributions,
)
from speclight.scenario import example_text, parse_scenario
from speclight.target import Reflectance
from speclight.target.material_tables import MATERIAL_TABLES, material_table_path

runner = CliRunner()
NAMES = list(MATERIAL_TABLES)
EXACT = 1e-9


@pytest.fixture(scope="module")
def simulated(tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, xr.Dataset]]:
    """Each example simulated once for the module (the slow part)."""
    folder = tmp_path_factory.mktemp("cube")
    return {n: _simulate(folder, n) for n in ("cube-materials", "cube-materials-laser")}


def _simulate(tmp_path: Path, name: str) -> tuple[Path, xr.Dataset]:
    d = yaml.safe_load(example_text(name))
    d["time"] = {"start": "2019-08-30T02:20:00Z", "stop": "2019-08-30T02:25:00Z", "step_s": 5.0}
    d["render"]["resolution_px"] = 32
    d["instrument"].pop("noise", None)
    scenario = tmp_path / f"{name}.yaml"
    scenario.write_text(yaml.safe_dump(d, sort_keys=False))
    out = tmp_path / f"{name}.nc"
    result = runner.invoke(app, ["simulate", str(scenario), "-o", str(out)])
    assert result.exit_code == 0, result.output
    return out, xr.open_dataset(out)


def _truth(ds: xr.Dataset, laser: bool) -> tuple[np.ndarray, np.ndarray]:
    """True fractions (N, 4) and per-epoch signatures (N, 4, B) of the tables (NAMES)."""
    wl = ds["wavelength"].values
    response = (
        ds["band_response"].values * ds["detector_qe"].values * ds["optics_transmission"].values
    )
    tables = np.stack([Reflectance.table_file(material_table_path(n)).evaluate(wl) for n in NAMES])
    t = ds["transmission"].values
    if laser:
        loaded = parse_scenario(ds.attrs["scenario_yaml"], source="laser")
        lines = laser_lines_per_nm(loaded, wl)
        source = coaxial_laser_source_W_m2_nm(ds["laser_irradiance"].values, lines, t, wl)
        shares = ds["laser_reflectance_factor_material"].values
    else:
        source = ds["solar_irradiance"].values * ds["sunlit"].values[:, None] * t
        shares = ds["reflectance_factor_material"].values
    signatures = material_signatures(tables, response, wl, source)
    labels = [str(v) for v in ds["material_reflectance"].values]
    return fractions(true_contributions(shares, labels, NAMES, signatures)), signatures


@pytest.mark.parametrize("name", ["cube-materials", "cube-materials-laser"])
def test_unmix_recovers_the_cube_materials(tmp_path: Path, simulated: dict, name: str) -> None:
    laser = name.endswith("laser")
    measured, ds = simulated[name]
    truth, _ = _truth(ds, laser)
    out = tmp_path / "ab.nc"
    if laser:  # the shipped tables as files: matched by the materials' reflectance labels
        files = [str(material_table_path(n)) for n in NAMES]
        args = [str(measured), "-e", *files, "-o", str(out)]
    else:  # the scenario's materials, from the scenario the dataset carries
        args = [str(measured), "-e", "scenario", "-o", str(out)]
    result = runner.invoke(app, ["unmix", *args])
    assert result.exit_code == 0, result.output
    ab = xr.open_dataset(out)
    assert ab.attrs["light"] == ("laser" if laser else "sun")
    est = ab["abundance"].values
    if not laser:  # endmembers +x,-x (solar cell), +y,-y (kapton), +z (aluminium), -z (paint)
        assert list(ab["endmember"].values) == ["+x,-x", "+y,-y", "+z", "-z"]
        est = est[:, [2, 1, 0, 3]]  # into NAMES order
    else:
        assert list(ab["endmember"].values) == NAMES
        assert ab.attrs["matching"] == "by reflectance label"
    lit = np.all(np.isfinite(truth), axis=1)
    assert lit.sum() >= 40
    np.testing.assert_allclose(est[lit], truth[lit], atol=EXACT)
    top2 = np.sort(truth[lit], axis=1)[:, -2:]
    clear = top2[:, 1] - top2[:, 0] > 2 * EXACT
    assert clear.sum() >= lit.sum() - 1
    right = np.argmax(est[lit][clear], axis=1) == np.argmax(truth[lit][clear], axis=1)
    assert np.all(right)
    count = ab["confusion_count"].values
    assert count.sum() == lit.sum() and np.trace(count) >= clear.sum()
    assert ab.attrs["mean_absolute_share_error"] < EXACT


def test_extracted_laser_signatures_against_the_truth(tmp_path: Path, simulated: dict) -> None:
    # ATGP picks epochs: each extracted signature is one epoch's reflectance factors. Where
    # that epoch sees one material alone (true fraction 1), it is that material's signature
    # of the epoch, s_m(t), times a contribution, so it must be matched to m, at the angle
    # between s_m(t) and the true signature of the pass (the truth summed over the epochs,
    # which the atmosphere's change along the pass turns by a few tenths of a degree). The
    # paper's Figure 14 compares them; the figure is written.
    pytest.importorskip("matplotlib")
    measured, ds = simulated["cube-materials-laser"]
    truth, per_epoch = _truth(ds, laser=True)
    out, fig = tmp_path / "ab.nc", tmp_path / "ab.png"
    args = [str(measured), "--extract", "atgp", "--n", "4", "-o", str(out), "--plot", str(fig)]
    result = runner.invoke(app, ["unmix", *args])
    assert result.exit_code == 0, result.output
    ab = xr.open_dataset(out)
    assert ab.attrs["matching"] == "by spectral angle"
    assert sorted(ab["class"].values) == sorted(NAMES)
    classes = [str(c) for c in ab["class"].values]
    x = ab["reflectance_factor"].values
    pure = 0
    for k, sig in enumerate(ab["endmember_signature"].values):
        t = int(np.nanargmin(np.abs(x - sig).sum(axis=1)))
        np.testing.assert_array_equal(x[t], sig)  # an epoch of the data
        if np.nanmax(truth[t]) > 1.0 - EXACT:
            pure += 1
            m = int(np.argmax(truth[t]))
            assert ab["endmember_material"].values[k] == NAMES[m]
            true_sig = ab["true_signature"].values[classes.index(NAMES[m])]
            expected = np.degrees(spectral_angle_rad(per_epoch[t, m], true_sig))[0, 0]
            assert ab["endmember_angle"].values[k] == pytest.approx(expected, abs=1e-6)
    assert pure >= 1
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


@pytest.mark.parametrize(
    ("name", "source", "needle"),
    [
        ("cube-materials-laser", "sun", "NaN at every epoch (no Sun light); try --source laser"),
        ("cube-materials", "laser", "has no laser_reflectance_factor(time, band)"),
        ("cube-materials", "lazer", "--source = 'lazer': unknown source (choices: sun, laser)"),
    ],
)
def test_a_source_the_data_lack_is_refused(
    tmp_path: Path, simulated: dict, name: str, source: str, needle: str
) -> None:
    out = tmp_path / "ab.nc"
    measured, _ = simulated[name]
    args = [str(measured), "-e", "scenario", "--source", source, "-o", str(out)]
    result = runner.invoke(app, ["unmix", *args])
    assert result.exit_code == 2
    assert needle in result.stderr and len(result.stderr.strip().splitlines()) == 1
    assert not out.exists()


def test_laser_rates_as_csv_give_simulates_laser_factors(tmp_path: Path, simulated: dict) -> None:
    # eq. 5 with the lasers' lines (SPEC section 5): the laser return rates written as a
    # MEASURED CSV, with the scenario, must come back as simulate's own
    # laser_reflectance_factor (the same range, lines, transmission and bands), to rounding
    measured, ds = simulated["cube-materials-laser"]
    bands = [str(b) for b in ds["band"].values]
    rows = ["time," + ",".join(bands)]
    for t, rate in zip(ds["time"].values, ds["return_rate"].values, strict=True):
        rows.append(
            np.datetime_as_string(t, unit="ms") + "Z," + ",".join(repr(float(r)) for r in rate)
        )
    rates = tmp_path / "returns.csv"
    rates.write_text("\n".join(rows) + "\n")
    out = tmp_path / "ab.nc"
    scenario = str(measured.with_suffix(".yaml"))
    args = [str(rates), "--scenario", scenario, "-e", "scenario", "-o", str(out)]
    result = runner.invoke(app, ["unmix", *args])
    assert result.exit_code == 0, result.output
    ab = xr.open_dataset(out)
    assert ab.attrs["light"] == "laser"
    np.testing.assert_allclose(
        ab["reflectance_factor"].values, ds["laser_reflectance_factor"].values, rtol=1e-9
    )
