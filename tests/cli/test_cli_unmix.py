"""``speclight unmix``: known synthetic mixtures recovered, ABUND.nc per SPEC, bad input refused.

The reference is the synthetic dataset of ``synthetic_mixture.py``: reflectance factors made
as ``a @ S`` from known contributions ``a`` and band signatures ``S`` computed there from
closed forms (not by speclight). Noise-free mixtures must come back to rounding; the noisy
unconstrained case is checked against the least-squares covariance ``sigma^2 (S S^T)^-1``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml
from synthetic_mixture import (
    mixture_dataset,
    random_mixture,
    signatures,
    write_spectra,
)
from typer.testing import CliRunner

from speclight.cli import app
from speclight.scenario import example_text

runner = CliRunner()
NAMES = ["gold", "cell", "paint"]
#: Noise-free unmixing is exact up to the solver's rounding (condition number of S ~ 10).
ROUNDING = 1e-9


def _write(ds: xr.Dataset, path: Path) -> Path:
    ds.to_netcdf(path, engine="h5netcdf")
    return path


def _unmix(*args: str) -> object:
    return runner.invoke(app, ["unmix", *args])


@pytest.fixture
def spectra(tmp_path: Path) -> dict[str, Path]:
    return write_spectra(tmp_path)


@pytest.mark.parametrize("method", ["ls", "nnls", "nnls-norm"])
def test_recovers_known_contributions(tmp_path: Path, spectra: dict, method: str) -> None:
    a = random_mixture(40, 3, seed=1, sum_to_one=False)
    measured = _write(mixture_dataset(a, NAMES), tmp_path / "m.nc")
    out = tmp_path / "ab.nc"
    files = [str(spectra[n]) for n in NAMES]
    result = _unmix(str(measured), "--endmembers", *files, "--method", method, "-o", str(out))
    assert result.exit_code == 0, result.output
    ds = xr.open_dataset(out)
    expected = a / a.sum(axis=1, keepdims=True) if method == "nnls-norm" else a
    lit = np.all(np.isfinite(a), axis=1)
    np.testing.assert_allclose(ds["abundance"].values[lit], expected[lit], atol=ROUNDING)
    assert np.all(np.isnan(ds["abundance"].values[~lit]))  # unlit rows kept, NaN
    assert np.all(np.isnan(ds["residual"].values[~lit]))
    assert np.all(ds["residual"].values[lit] < ROUNDING)
    np.testing.assert_allclose(ds["endmember_signature"].values, signatures(NAMES), rtol=1e-12)
    assert list(ds["endmember"].values) == NAMES
    assert ds["abundance"].attrs["units"] == ("1" if method == "nnls-norm" else "m2 sr-1")
    assert ds.attrs["method"] == method and "m.nc" in ds.attrs["source"]
    for name in ("abundance", "residual", "endmember_signature", "reflectance_factor"):
        assert ds[name].attrs["units"] and ds[name].attrs["long_name"]
    # matched by name with the ground truth: every epoch's dominant material found
    np.testing.assert_allclose(ds["confusion_matrix"].values, np.eye(3), atol=0)
    assert ds.attrs["mean_absolute_share_error"] < ROUNDING


def test_fcls_recovers_fractions_and_atgp_finds_the_pure_epochs(
    tmp_path: Path, spectra: dict
) -> None:
    a = random_mixture(40, 3, seed=2, sum_to_one=True)
    measured = _write(mixture_dataset(a, NAMES), tmp_path / "m.nc")
    files = [str(spectra[n]) for n in NAMES]
    out = tmp_path / "ab.nc"
    result = _unmix(str(measured), "-e", files[0], "-e", files[1], "-e", files[2],
                    "--method", "fcls", "-o", str(out))  # fmt: skip
    assert result.exit_code == 0, result.output
    lit = np.all(np.isfinite(a), axis=1)
    np.testing.assert_allclose(xr.open_dataset(out)["abundance"].values[lit], a[lit], atol=ROUNDING)
    # ATGP on data in a simplex picks its vertices, the pure epochs 0, 1, 2 (Ren & Chang
    # 2003): the extracted signatures are the true ones times the epochs' contributions
    out2 = tmp_path / "ab2.nc"
    result = _unmix(str(measured), "--extract", "atgp", "--n", "3", "-o", str(out2))
    assert result.exit_code == 0, result.output
    ds = xr.open_dataset(out2)
    assert sorted(ds["endmember_material"].values) == sorted(NAMES)
    np.testing.assert_allclose(ds["endmember_angle"].values, 0.0, atol=1e-6)
    assert ds["abundance"].attrs["units"] == "1"
    assert ds["endmember_signature"].attrs["units"] == "m2 sr-1"
    np.testing.assert_allclose(ds["confusion_matrix"].values, np.eye(3), atol=0)


def test_noisy_least_squares_matches_its_covariance(tmp_path: Path, spectra: dict) -> None:
    # x = a S + w, w ~ N(0, sigma^2): the LS error of a is N(0, sigma^2 (S S^T)^-1)
    # (Gauss-Markov); over 400 epochs its mean is within 4 standard errors of 0 and its
    # standard deviation within 4 standard errors (sd / sqrt(2 (n - 1))) of the prediction.
    n, sigma = 400, 2e-3
    a = np.random.default_rng(3).uniform(0.05, 0.5, size=(n, 3))
    ds = mixture_dataset(a, NAMES)
    noise = np.random.default_rng(4).normal(0.0, sigma, size=ds["reflectance_factor"].shape)
    ds["reflectance_factor"] = ds["reflectance_factor"] + noise
    measured = _write(ds, tmp_path / "m.nc")
    out = tmp_path / "ab.nc"
    files = [str(spectra[k]) for k in NAMES]
    result = _unmix(str(measured), "--endmembers", *files, "--method", "ls", "-o", str(out))
    assert result.exit_code == 0, result.output
    err = xr.open_dataset(out)["abundance"].values - a
    s = signatures(NAMES)
    predicted = sigma * np.sqrt(np.diag(np.linalg.inv(s @ s.T)))
    assert np.all(np.abs(err.mean(axis=0)) < 4 * predicted / np.sqrt(n))
    assert np.all(
        np.abs(err.std(axis=0, ddof=1) - predicted) < 4 * predicted / np.sqrt(2 * (n - 1))
    )


def test_plot_writes_a_png_with_the_confusion_panel(tmp_path: Path, spectra: dict) -> None:
    pytest.importorskip("matplotlib")
    a = random_mixture(30, 3, seed=5, sum_to_one=False)
    measured = _write(mixture_dataset(a, NAMES), tmp_path / "m.nc")
    out, fig = tmp_path / "ab.nc", tmp_path / "ab.png"
    files = [str(spectra[k]) for k in NAMES]
    result = _unmix(str(measured), "--endmembers", *files, "-o", str(out), "--plot", str(fig))
    assert result.exit_code == 0, result.output
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "mean absolute share error" in result.stdout


def _bad_spectrum(folder: Path, name: str, body: str) -> str:
    path = folder / f"{name}.csv"
    path.write_text("wavelength_nm,reflectance\n" + body)
    return str(path)


@pytest.mark.parametrize(
    ("case", "needle"),
    [
        ("method", "unknown method 'nnls_norm'; did you mean 'nnls-norm'?"),
        ("extract-no-n", "needs --n K"),
        ("n-above-bands", "--n = 7 endmembers is more than the 6 bands"),
        ("both", "one of them"),
        ("short-range", "covers 500-1100 nm"),
        ("nan", "not a finite number"),
        ("negative", "must be in [0, 1]"),
        ("csv-without-scenario", "give --scenario"),
        ("scenario-endmembers-without-scenario", "--endmembers scenario needs --scenario"),
        ("exists", "exists; choose another name or pass --force"),
        ("output-is-input", "is the measured file"),
        ("figure-format", "unknown figure format '.gif'"),
    ],
)
def test_bad_input_exits_2_and_writes_nothing(
    tmp_path: Path, spectra: dict, case: str, needle: str
) -> None:
    measured = _write(mixture_dataset(random_mixture(20, 3, 6, False), NAMES), tmp_path / "m.nc")
    files = [str(spectra[k]) for k in NAMES]
    out = tmp_path / "ab.nc"
    args = [str(measured), "--endmembers", *files]
    extra: list[str] = []
    if case == "method":
        extra = ["--method", "nnls_norm"]
    elif case == "extract-no-n":
        args = [str(measured), "--extract", "atgp"]
    elif case == "n-above-bands":
        args = [str(measured), "--extract", "pca", "--n", "7"]
    elif case == "both":
        extra = ["--extract", "atgp", "--n", "2"]
    elif case == "short-range":
        args = [str(measured), "-e", _bad_spectrum(tmp_path, "x", "500,0.5\n1100,0.5\n")]
    elif case == "nan":
        args = [str(measured), "-e", _bad_spectrum(tmp_path, "x", "300,nan\n1100,0.5\n")]
    elif case == "negative":
        args = [str(measured), "-e", _bad_spectrum(tmp_path, "x", "300,-0.1\n1100,0.5\n")]
    elif case == "csv-without-scenario":
        rates = tmp_path / "rates.csv"
        rates.write_text("time,B\n2020-02-29T21:16:00Z,100\n")
        args = [str(rates), "--endmembers", *files]
    elif case == "scenario-endmembers-without-scenario":
        args = [str(measured), "--endmembers", "scenario"]
    elif case == "exists":
        out.write_text("precious")
    elif case == "output-is-input":
        out = measured
    elif case == "figure-format":
        extra = ["--plot", str(tmp_path / "fig.gif")]
    before = measured.read_bytes()
    result = _unmix(*args, *extra, "-o", str(out))
    assert result.exit_code == 2, result.output
    assert needle in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert "Traceback" not in result.output
    if case == "exists":
        assert out.read_text() == "precious"
    elif case != "output-is-input":
        assert not out.exists()
    assert measured.read_bytes() == before
    assert not list(tmp_path.glob(".ab.nc*")) and not list(tmp_path.glob("*.gif"))


def test_csv_rates_with_scenario_give_the_grey_factor_in_every_band(
    tmp_path: Path, spectra: dict
) -> None:
    # SPEC section 5: for a target of constant spectral reflectance the reflectance factor
    # is the same in every band. The calsphere is a Lambertian sphere of reflectance 0.9;
    # its simulated rates, written as a MEASURED CSV, must come back as one factor per epoch
    # equal in all bands and equal to simulate's own reflectance_factor.
    from speclight.scenario import load_scenario
    from speclight.simulation import simulate

    data = yaml.safe_load(example_text("calsphere"))
    data["time"] = {"start": "2020-02-29T21:17:00Z", "stop": "2020-02-29T21:17:20Z", "step_s": 5.0}
    data["render"]["resolution_px"] = 32
    data["instrument"]["bands"] = [b for b in data["instrument"]["bands"] if "gaussian" in b]
    data["instrument"].pop("noise")
    scenario = tmp_path / "calsphere.yaml"
    scenario.write_text(yaml.safe_dump(data, sort_keys=False))
    ds = simulate(load_scenario(scenario)).dataset
    bands = [str(b) for b in ds["band"].values]
    rows = ["time," + ",".join(bands)]
    for t, rate in zip(ds["time"].values, ds["count_rate"].values, strict=True):
        stamp = np.datetime_as_string(t, unit="ms") + "Z"
        rows.append(stamp + "," + ",".join(repr(float(r)) for r in rate))
    rates = tmp_path / "rates.csv"
    rates.write_text("\n".join(rows) + "\n")
    out = tmp_path / "ab.nc"
    result = _unmix(
        str(rates), "-e", str(spectra["paint"]), "--scenario", str(scenario), "-o", str(out)
    )
    assert result.exit_code == 0, result.output
    got = xr.open_dataset(out)
    factor = got["reflectance_factor"].values
    assert np.all(np.isfinite(factor))
    np.testing.assert_allclose(factor, factor[:, :1] * np.ones((1, len(bands))), rtol=1e-9)
    np.testing.assert_allclose(factor, ds["reflectance_factor"].values, rtol=1e-9)
    np.testing.assert_allclose(got["abundance"].values, 1.0, atol=ROUNDING)
