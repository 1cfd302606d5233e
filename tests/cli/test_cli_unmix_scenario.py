"""``speclight unmix --endmembers scenario`` and ``--bin-s``.

The scenario's materials are given the tabulated spectra of ``synthetic_mixture``, so their
band signatures are known independently of speclight; two parts sharing one material become
one endmember named ``a,b``, and two grey materials (proportional signatures) are refused.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml
from synthetic_mixture import SPECTRA, mixture_dataset, random_mixture, signatures, write_spectra
from typer.testing import CliRunner

from speclight.cli import app
from speclight.scenario import example_text

runner = CliRunner()
ROUNDING = 1e-9
PARTS = {"bus": "gold", "wing_+y": "cell", "wing_-y": "cell", "antenna": "paint"}


def _scenario(tmp_path: Path, antenna: object = None) -> Path:
    data = yaml.safe_load(example_text("box-wing"))
    materials = {}
    for part, name in PARTS.items():
        x, y = SPECTRA[name]
        materials[part] = {"bsdf": "lambertian", "reflectance": {"wavelength_nm": x, "value": y}}
    if antenna is not None:
        materials["antenna"] = {"bsdf": "lambertian", "reflectance": antenna}
        materials["wing_-y"] = {"bsdf": "lambertian", "reflectance": 0.06}
    data["target"]["materials"] = materials
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _measured(tmp_path: Path) -> tuple[Path, np.ndarray]:
    """Mixture of gold, cell, paint; the cell's truth split 30/70 over the two wings."""
    a = random_mixture(30, 3, seed=7, sum_to_one=False)
    ds = mixture_dataset(a, ["gold", "cell", "paint"])
    truth = ds["reflectance_factor_material"].values
    split = np.stack([truth[:, 0], 0.3 * truth[:, 1], 0.7 * truth[:, 1], truth[:, 2]], axis=1)
    ds = ds.drop_vars(["reflectance_factor_material", "material"])
    ds = ds.assign_coords(material=list(PARTS))
    ds["reflectance_factor_material"] = (("time", "material", "band"), split)
    path = tmp_path / "m.nc"
    ds.to_netcdf(path, engine="h5netcdf")
    return path, a


def test_scenario_materials_are_the_endmembers(tmp_path: Path) -> None:
    measured, a = _measured(tmp_path)
    out = tmp_path / "ab.nc"
    args = [str(measured), "--endmembers", "scenario", "--scenario", str(_scenario(tmp_path))]
    result = runner.invoke(app, ["unmix", *args, "--method", "nnls", "-o", str(out)])
    assert result.exit_code == 0, result.output
    ds = xr.open_dataset(out)
    assert list(ds["endmember"].values) == ["bus", "wing_+y,wing_-y", "antenna"]
    np.testing.assert_allclose(
        ds["endmember_signature"].values, signatures(["gold", "cell", "paint"]), rtol=1e-12
    )
    lit = np.all(np.isfinite(a), axis=1)
    np.testing.assert_allclose(ds["abundance"].values[lit], a[lit], atol=ROUNDING)
    assert ds.attrs["matching"] == "by name"  # the wings' truth summed into their endmember
    np.testing.assert_allclose(ds["confusion_matrix"].values, np.eye(3), atol=0)


def test_proportional_scenario_materials_are_refused(tmp_path: Path) -> None:
    measured, _ = _measured(tmp_path)
    scenario = _scenario(tmp_path, antenna=0.8)  # grey 0.8 and grey 0.06: one shape
    out = tmp_path / "ab.nc"
    args = [str(measured), "-e", "scenario", "--scenario", str(scenario), "-o", str(out)]
    result = runner.invoke(app, ["unmix", *args])
    assert result.exit_code == 2
    assert "'wing_-y' and 'antenna' have proportional band signatures" in result.stderr
    assert not out.exists()


def test_binning_averages_the_factors(tmp_path: Path) -> None:
    # The model is linear: NNLS of the mean of positive mixtures is the mean of their
    # contributions; bins of 4 s from the first epoch, NaN (unlit) epochs left out.
    measured, a = _measured(tmp_path)
    spectra = write_spectra(tmp_path)
    files = [str(spectra[n]) for n in ("gold", "cell", "paint")]
    out = tmp_path / "ab.nc"
    args = [str(measured), "-e", *files, "--method", "nnls", "--bin-s", "4", "-o", str(out)]
    result = runner.invoke(app, ["unmix", *args])
    assert result.exit_code == 0, result.output
    ds = xr.open_dataset(out)
    expected = np.array([np.nanmean(a[i : i + 4], axis=0) for i in range(0, len(a), 4)])
    assert ds.sizes["time"] == len(expected)
    np.testing.assert_allclose(ds["abundance"].values, expected, atol=ROUNDING)


@pytest.mark.parametrize("bad", ["0", "-1", "nan"])
def test_bad_bin_is_refused(tmp_path: Path, bad: str) -> None:
    measured, _ = _measured(tmp_path)
    out = tmp_path / "ab.nc"
    result = runner.invoke(app, ["unmix", str(measured), "--extract", "atgp", "--n", "2",
                                 "--bin-s", bad, "-o", str(out)])  # fmt: skip
    assert result.exit_code == 2 and "--bin-s" in result.stderr
    assert not out.exists()
