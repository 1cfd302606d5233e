"""``speclight upsample``: the spectrum reproduces the JSON albedos through the scenario's bands.

The band responses are computed here independently of speclight (``synthetic_mixture``: the
Gaussian bands bin-averaged with the normal CDF, times the scenario's constant optics
transmission and a linear QE table, whose bin averages are its values at the bin centres),
and the photon-weighted band averages of eq. 3 (Nussbaum et al. 2022) of the written CSV
must equal the albedos to 1e-3, the accuracy upsampling promises (ALBEDO_CLIP and the fit
tolerance are far below it). A grey input must give the flat spectrum.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from synthetic_mixture import CENTRES_NM, SIGMA_NM, WL, band_average, gaussian_responses
from typer.testing import CliRunner

from speclight.cli import app
from speclight.scenario import example_text

runner = CliRunner()
OPTICS = 0.8
#: What upsampling promises to reproduce
#: (speclight.estimate.spectra.upsampling.ALBEDO_CLIP is 1e-4).
ALBEDO_TOLERANCE = 1e-3
BANDS = [f"G-{c:g}/{SIGMA_NM:g}" for c in CENTRES_NM]


def _qe(wl: np.ndarray) -> np.ndarray:
    return 0.4 + 0.5 * (wl - 300.0) / 800.0  # the table below: linear from 300 to 1100 nm


@pytest.fixture
def scenario(tmp_path: Path) -> Path:
    (tmp_path / "qe.csv").write_text("wavelength_nm,qe\n300,0.4\n1100,0.9\n")
    data = yaml.safe_load(example_text("calsphere"))
    data["spectrum"] = {"min_nm": float(WL[0]), "max_nm": float(WL[-1]), "step_nm": 5.0}
    data["instrument"]["optics_transmission"] = OPTICS
    data["instrument"]["detector_qe"] = "qe.csv"
    data["instrument"]["bands"] = [
        {"name": b, "gaussian": {"center_nm": c, "sigma_nm": SIGMA_NM}}
        for b, c in zip(BANDS, CENTRES_NM, strict=True)
    ]
    path = tmp_path / "scenario.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def _fit(tmp_path: Path, albedo: dict[str, float], name: str = "fit.json") -> Path:
    path = tmp_path / name
    payload = {
        "bands": {b: {"albedo": a, "albedo_std": 0.01, "scale": 1.0} for b, a in albedo.items()}
    }
    path.write_text(json.dumps(payload))
    return path


def _read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    lines = path.read_text().splitlines()
    comments = [line for line in lines if line.startswith("#")]
    body = [line for line in lines if not line.startswith("#")]
    assert body[0] == "wavelength_nm,reflectance"
    return comments, np.array([[float(v) for v in line.split(",")] for line in body[1:]])


def test_spectrum_reproduces_the_albedos(tmp_path: Path, scenario: Path) -> None:
    albedo = dict(zip(BANDS, [0.35, 0.55, 0.62, 0.58, 0.48, 0.40], strict=True))
    out = tmp_path / "spectrum.csv"
    result = runner.invoke(
        app, ["upsample", str(scenario), str(_fit(tmp_path, albedo)), "-o", str(out)]
    )
    assert result.exit_code == 0, result.output
    comments, table = _read_csv(out)
    np.testing.assert_allclose(table[:, 0], WL)  # the scenario's grid
    response = gaussian_responses() * OPTICS * _qe(WL)
    got = band_average(table[:, 1], response)
    np.testing.assert_allclose(got, list(albedo.values()), atol=ALBEDO_TOLERANCE)
    assert np.all((table[:, 1] >= 0) & (table[:, 1] <= 1))
    assert any("fit: converged" in c for c in comments)
    assert "notice" not in result.stdout


def test_grey_albedos_give_a_flat_spectrum(tmp_path: Path, scenario: Path) -> None:
    out = tmp_path / "spectrum.csv"
    fit = _fit(tmp_path, dict.fromkeys(BANDS, 0.42))
    result = runner.invoke(app, ["upsample", str(scenario), str(fit), "-o", str(out)])
    assert result.exit_code == 0, result.output
    _, table = _read_csv(out)
    np.testing.assert_allclose(table[:, 1], 0.42, atol=1e-9)  # 9 decimals in the CSV


def test_plot_is_written(tmp_path: Path, scenario: Path) -> None:
    pytest.importorskip("matplotlib")
    albedo = dict(zip(BANDS, [0.3, 0.4, 0.5, 0.6, 0.6, 0.6], strict=True))
    out, fig = tmp_path / "s.csv", tmp_path / "s.png"
    args = ["upsample", str(scenario), str(_fit(tmp_path, albedo)), "-o", str(out)]
    result = runner.invoke(app, [*args, "--plot", str(fig)])
    assert result.exit_code == 0, result.output
    assert fig.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and out.exists()


@pytest.mark.parametrize(
    ("case", "needle"),
    [
        ("unknown-band", "band 'G-430/52' is not a band of the scenario; did you mean 'G-430/25'?"),
        ("missing-band", "no albedo for the scenario band(s) G-900/25"),
        ("zero", "must be in (0, 1]"),
        ("nan", "must be in (0, 1]"),
        ("above-one", "must be in (0, 1]"),
        ("not-json", "not JSON"),
        ("no-bands", 'no "bands" mapping'),
        ("deep", "nested deeper than Python's JSON reader goes"),
        ("digits", "an integer of more than 4300 digits"),
        ("exists", "exists; choose another name or pass --force"),
        ("output-is-fit", "is the fit file"),
        ("plot-is-output", "is the output"),
    ],
)
def test_bad_input_exits_2_and_writes_nothing(
    tmp_path: Path, scenario: Path, case: str, needle: str
) -> None:
    albedo = dict.fromkeys(BANDS, 0.5)
    out = tmp_path / "spectrum.csv"
    extra: list[str] = []
    if case == "unknown-band":
        albedo["G-430/52"] = albedo.pop("G-430/25")
    elif case == "missing-band":
        albedo.pop("G-900/25")
    elif case == "zero":
        albedo["G-520/25"] = 0.0
    elif case == "nan":
        albedo["G-520/25"] = float("nan")  # json writes NaN, which Python's reader accepts
    elif case == "above-one":
        albedo["G-520/25"] = 1.2
    fit = _fit(tmp_path, albedo)
    if case == "not-json":
        fit.write_text("{bands: R 0.5}")
    elif case == "no-bands":
        fit.write_text('{"albedo": 0.5}')
    elif case == "deep":
        fit.write_text("[" * 100_000 + "]" * 100_000)
    elif case == "digits":
        fit.write_text('{"bands": {"G-520/25": {"albedo": ' + "1" * 5001 + "}}}")
    elif case == "exists":
        out.write_text("precious")
    elif case == "output-is-fit":
        out = fit
    elif case == "plot-is-output":
        extra = ["--plot", str(out.with_suffix(".png"))]
        out = out.with_suffix(".png")
    before = fit.read_bytes()
    result = runner.invoke(app, ["upsample", str(scenario), str(fit), "-o", str(out), *extra])
    assert result.exit_code == 2, result.output
    assert needle in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    assert fit.read_bytes() == before
    if case == "exists":
        assert out.read_text() == "precious"
    elif case != "output-is-fit":
        assert not out.exists()
    assert not list(tmp_path.glob(".spectrum*"))


def test_unreachable_albedos_are_written_with_a_notice(tmp_path: Path) -> None:
    # Two Gaussian bands on one centre, sigma 20 and 120 nm, albedos 0.9 and 0.1: with two
    # bands p is a line, S(p) is monotonic, and the wide band's average cannot fall that far
    # below the narrow one's (it would need the spectrum far below 0.1 on both sides of the
    # centre). The spectrum is still written, said to be unconverged.
    data = yaml.safe_load(example_text("calsphere"))
    data["instrument"]["bands"] = [
        {"name": "narrow", "gaussian": {"center_nm": 700.0, "sigma_nm": 20.0}},
        {"name": "wide", "gaussian": {"center_nm": 700.0, "sigma_nm": 120.0}},
    ]
    scenario = tmp_path / "two.yaml"
    scenario.write_text(yaml.safe_dump(data, sort_keys=False))
    out = tmp_path / "s.csv"
    fit = _fit(tmp_path, {"narrow": 0.9, "wide": 0.1})
    result = runner.invoke(app, ["upsample", str(scenario), str(fit), "-o", str(out)])
    assert result.exit_code == 0, result.output
    assert "notice: the fit did not converge" in result.stdout
    comments, table = _read_csv(out)
    assert any("NOT converged" in c for c in comments)
    assert np.all((table[:, 1] >= 0) & (table[:, 1] <= 1))
