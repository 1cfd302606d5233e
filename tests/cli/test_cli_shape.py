"""``speclight shape`` on the command line: outputs (NetCDF, OBJ, figure), exit codes."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import trimesh
import xarray as xr
from typer.testing import CliRunner

from speclight.cli import app

sys.path.insert(0, str(Path(__file__).parents[1] / "estimate" / "shape"))
from synthetic import apparitions, lambert_mesh_brightness, to_body

FAST = ["--nside", "2", "--pole-step-deg", "90"]


def _lc(tmp_path: Path) -> Path:
    """A DAMIT file of a Lambertian ellipsoid (pole 40, 35 deg; 6.3 h), written by hand."""
    rng = np.random.default_rng(0)
    t, sun, obs, curve = apparitions(rng, n_apparitions=4, step_h=0.3)
    m = trimesh.creation.icosphere(subdivisions=2)
    m.vertices *= [2.0, 1.3, 1.0]
    sb, ob = (to_body(v, 40.0, 35.0, 6.3, t, np.floor(t[0])) for v in (sun, obs))
    y = lambert_mesh_brightness(np.asarray(m.vertices), np.asarray(m.faces), sb, ob)
    lines = [str(curve.max() + 1)]
    for k in range(curve.max() + 1):
        sel = curve == k
        lines.append(f"{sel.sum()} 0")
        lines += [
            " ".join(repr(float(x)) for x in (t[i], y[i], *sun[i], *obs[i]))
            for i in np.flatnonzero(sel)
        ]
    path = tmp_path / "ell.lc"
    path.write_text("\n".join(lines) + "\n")
    return path


def _scenario(tmp_path: Path) -> Path:
    """The box-wing example as a file (its target: the tumbling fit's light model)."""
    from speclight.scenario import example_text

    path = tmp_path / "box-wing.yaml"
    path.write_text(example_text("box-wing"))
    return path


def test_shape_writes_dataset_obj_and_figure(tmp_path):
    lc = _lc(tmp_path)
    out = tmp_path / "shape.nc"
    args = [
        "shape",
        str(lc),
        "--format",
        "damit",
        "--period-range-h",
        "6.298",
        "6.302",
        "-o",
        str(out),
        "--plot",
        str(tmp_path / "shape.png"),
        *FAST,
    ]
    result = CliRunner().invoke(app, args)
    assert result.exit_code == 0, result.output
    assert "wrote" in result.output and "shape.obj" in result.output
    with xr.open_dataset(out) as ds:
        for key in ("period_h", "pole_lambda_deg", "pole_beta_deg", "verdict", "obj_file"):
            assert key in ds.attrs
        for name in ("chi2_period", "chi2_pole", "facet_area", "brightness_fit"):
            assert "units" in ds[name].attrs and "long_name" in ds[name].attrs
        assert abs(ds.attrs["period_h"] - 6.3) < 1e-3
    mesh = trimesh.load(tmp_path / "shape.obj")
    assert mesh.is_watertight
    assert (tmp_path / "shape.png").stat().st_size > 0
    again = CliRunner().invoke(app, args)  # no overwrite without --force
    assert again.exit_code == 2


def test_shape_bad_input_exits_2(tmp_path):
    lc = _lc(tmp_path)
    base = ["shape", str(lc), "--period-range-h", "6.2", "6.4", "-o", str(tmp_path / "s.nc")]
    for extra, word in (
        (["--format", "damlt"], "damit"),
        (["--format", "damit", "--law", "lamb"], "lambert"),
        (["--format", "damit", "--nside", "3"], "nside"),
        (["--format", "damit", "--map", str(tmp_path / "m.zarr")], "--tumbling-starts"),
        (["--format", "damit", "--tumbling-starts", "1", "--map", str(lc)], "Zarr"),
        (["--format", "damit", "--map-nside", "4"], "--tumbling-starts"),
        (["--format", "damit", "--no-map"], "--tumbling-starts"),
        (["--format", "damit", "--tumbling-starts", "1", "--map-nside", "3"], "1, 2, 4"),
        (["--format", "damit", "--tumbling-starts", "1"], "--scenario"),
        (
            [
                "--format",
                "damit",
                "--tumbling-starts",
                "1",
                "--map-nside",
                "2",
                "--scenario",
                str(_scenario(tmp_path)),
            ],
            "DAMIT",
        ),
    ):
        result = CliRunner().invoke(app, [*base, *extra])
        assert result.exit_code == 2, result.output
        assert word in result.output
    csv = tmp_path / "rates.csv"
    csv.write_text("time,V\n2020-01-01T00:00:00Z,1.0\n")
    result = CliRunner().invoke(
        app, ["shape", str(csv), "--period-range-h", "1", "2", "-o", str(tmp_path / "c.nc")]
    )
    assert result.exit_code == 2 and "--scenario" in result.output
