"""``speclight brdf-fit``: fit a table, then simulate with the material it writes.

Reference: a table of a Lambertian surface of albedo 0.3 (f = 0.3 / pi at every sample) is
a Phong surface with kd = 0.3, ks = 0; the fitted material must then render as the
Lambertian one (Lambert's law in the renders: tests/render/test_render_single_closed_forms).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml
from typer.testing import CliRunner

from speclight.cli import app
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate

runner = CliRunner()
ALBEDO = 0.3


@pytest.fixture(scope="module")
def lambert_table(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp("brdf") / "lambert.csv"
    rows = ["# a Lambertian surface, lambda = 550 nm", "# phi_i theta_i phi_o theta_o brdf"]
    for ti in (5.0, 30.0, 60.0):
        rows += [f"{ti} -180 {to} 0 {ALBEDO / np.pi:.12e}" for to in range(-85, 86)]
    path.write_text("\n".join(rows) + "\n")
    return path


def _scenario(material: dict) -> dict:
    d = yaml.safe_load(example_text("calsphere"))
    d["time"].update(start="2020-02-29T21:15:00Z", stop="2020-02-29T21:16:00Z", step_s=20.0)
    d["render"]["resolution_px"] = 32
    d["target"]["materials"] = {"body": material}
    return d


def test_fitted_material_renders_as_the_table(lambert_table, tmp_path):
    out, fig = tmp_path / "m.yaml", tmp_path / "m.png"
    cmd = ["brdf-fit", str(lambert_table), "--model", "phong", "-o", str(out), "--plot", str(fig)]
    result = runner.invoke(app, cmd)
    assert result.exit_code == 0, result.output
    assert "incidence [deg]" in result.output and fig.stat().st_size > 10_000
    material = yaml.safe_load(out.read_text())
    assert material["bsdf"] == "phong" and material["coefficients"]["wavelength_nm"] == 550.0
    fitted = simulate(parse_scenario(yaml.safe_dump(_scenario(material)), source="fit"))
    plain = {"bsdf": "lambertian", "reflectance": ALBEDO}
    lambert = simulate(parse_scenario(yaml.safe_dump(_scenario(plain)), source="lambert"))
    got, want = (r.dataset["intensity"].values for r in (fitted, lambert))
    assert np.any(want > 0)
    # the fit gives kd = 0.3 (1 - 1e-8) and ks = 3e-9: the intensities agree to ~1e-8
    np.testing.assert_allclose(got, want, rtol=1e-6, atol=0.0)


def test_refusals_name_the_flag(lambert_table, tmp_path):
    out = tmp_path / "m.yaml"
    cases = [
        (["--model", "phnog"], "--model = 'phnog'; did you mean 'phong'?"),
        (["--model", "microfacet", "--distribution", "gxx"], "--distribution = 'gxx'"),
        (["--model", "phong", "--min-brdf", "-1"], "--min-brdf = -1.0 sr-1 must be >= 0"),
    ]
    for extra, message in cases:
        result = runner.invoke(app, ["brdf-fit", str(lambert_table), "-o", str(out), *extra])
        assert result.exit_code == 2 and message in result.output, result.output
        assert not out.exists()
    missing = runner.invoke(app, ["brdf-fit", "nope.csv", "--model", "abg", "-o", str(out)])
    assert missing.exit_code == 2 and "neither a file nor a shipped table" in missing.output
    out.write_text("x")
    kept = runner.invoke(app, ["brdf-fit", str(lambert_table), "--model", "abg", "-o", str(out)])
    assert kept.exit_code == 2 and out.read_text() == "x"
