"""``speclight frames`` on a simulated Calsphere pass: files, WCS, truth, and the checks
against the dataset's own topocentric rates and count rates; exit codes of bad input."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml
from typer.testing import CliRunner

from speclight.cli import app

pytest.importorskip("galsim")
pytest.importorskip("photutils")

SCENARIO = """\
name: calsphere-frames
time: {start: 2020-02-29T21:16:00Z, stop: 2020-02-29T21:16:12Z, step_s: 1.0}
observer: {latitude_deg: 48.7822, longitude_deg: 9.1967, altitude_m: 355}
telescope: {aperture_diameter_m: 0.43, obstruction_diameter_m: 0.1}
orbit:
  tle: |
    CALSPHERE 4A
    1 01520U 65065H   20058.86916325  .00000035  00000-0  49354-4 0  9992
    2 01520  90.0403 128.7439 0072289 113.7399 336.8322 13.35807489655439
attitude: {model: fixed, quaternion: [1.0, 0.0, 0.0, 0.0]}
target:
  shape: {builtin: sphere, radius_m: 0.18}
  materials: {body: {bsdf: lambertian, reflectance: 0.9}}
atmosphere: {model: none}
render: {mode: single, resolution_px: 16, save_images_at: [5]}
instrument:
  bands: [{name: V, filter: bessell-V}]
  imaging:
    detector: {width_px: 160, height_px: 128, plate_scale_arcsec: 2.0, bias_adu: 100,
               gain_e_per_adu: 1.0, full_well_e: 1.0e9, saturation_adu: 2000000000}
    exposure_s: 0.2
    cadence_s: 5
    psf: {seeing: {profile: gaussian, fwhm_arcsec: 4.0}, diffraction: false}
    sky: {model: none}
    stars: {catalogue: none}
    noise: false
"""


@pytest.fixture(scope="module")
def simulated(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("frames")
    (folder / "s.yaml").write_text(SCENARIO)
    out = folder / "s.nc"
    result = CliRunner().invoke(app, ["simulate", str(folder / "s.yaml"), "-o", str(out)])
    assert result.exit_code == 0, result.output
    return out


def test_frames_files_wcs_and_the_checks_against_the_dataset(simulated, tmp_path) -> None:
    from astropy.io import fits
    from astropy.wcs import WCS
    from photutils.aperture import RectangularAperture

    out, fig = tmp_path / "frames", tmp_path / "frames.png"
    result = CliRunner().invoke(app, ["frames", str(simulated), "-o", str(out), "--plot", str(fig)])
    assert result.exit_code == 0, result.output
    truth = json.loads((out / "truth.json").read_text())
    assert len(truth["frames"]) == 3 and fig.stat().st_size > 10_000
    assert (out / "frames.csv").read_text().count("\n") == 4
    # the render kept at 21:16:05 shapes the frame of 21:16:05.1 (a 0.07" sphere: a point)
    used = [r["image_time_utc"] for r in truth["frames"]]
    assert used[0] is None and used[1].startswith("2020-02-29T21:16:05") and used[2] is None
    assert not any(r["resolved"] for r in truth["frames"])
    ds = xr.open_dataset(simulated)
    seconds = (ds.time.values - ds.time.values[0]) / np.timedelta64(1, "s")
    for record in truth["frames"]:
        with fits.open(out / record["file"]) as hdul:
            header, data = hdul[0].header, hdul[0].data.astype(np.float64)
        wcs = WCS(header)
        t = record["target"]
        # the reference pixel is the target at mid-exposure (the pipeline's ra, dec)
        x, y = wcs.world_to_pixel_values(record["ra_deg"], record["dec_deg"])
        assert np.hypot(x - 79.5, y - 63.5) < 1e-6
        start = (np.datetime64(record["start_utc"]) - ds.time.values[0]) / np.timedelta64(1, "s")
        mid = start + 0.1
        # geometry: the streak is the output's angular rate x exposure (within 1 px)
        rate_arcsec = np.interp(mid, seconds, ds["angular_rate"].values) * 3600.0
        length = np.hypot(t["end_x"] - t["start_x"], t["end_y"] - t["start_y"])
        assert abs(length - rate_arcsec * 0.2 / 2.0) < 1.0
        east = np.interp(mid, seconds, ds["ra_cos_dec_rate"].values)
        north = np.interp(mid, seconds, ds["dec_rate"].values)
        move = np.linalg.inv(wcs.pixel_scale_matrix) @ np.array([east, north]) * 0.2
        got = np.array([t["end_x"] - t["start_x"], t["end_y"] - t["start_y"]])
        assert np.hypot(*(got - move)) < 1.0
        # flux: photometry of the streak = the dataset's count rate x exposure (within 1 %)
        theta = np.arctan2(got[1], got[0])
        box = RectangularAperture((t["x"], t["y"]), w=length + 24, h=24, theta=theta)
        counts = box.do_photometry(data - header["BIASLVL"])[0][0] * header["GAIN"]
        fine = np.linspace(start, start + 0.2, 201)
        expected = np.trapezoid(np.interp(fine, seconds, ds["count_rate"].values[:, 0]), fine)
        assert counts == pytest.approx(expected, rel=0.01)


def test_frames_refuses_a_dataset_without_imaging_and_a_full_folder(simulated, tmp_path) -> None:
    folder = tmp_path / "f"
    folder.mkdir()
    (folder / "keep.txt").write_text("mine")
    result = CliRunner().invoke(app, ["frames", str(simulated), "-o", str(folder)])
    assert result.exit_code == 2 and "not empty" in result.output
    imaging = tmp_path / "imaging.yaml"
    imaging.write_text(yaml.safe_dump({"detector": {"width_px": 64, "height_px": 64}}))
    result = CliRunner().invoke(
        app, ["frames", str(simulated), "-o", str(tmp_path / "g"), "--imaging", str(imaging)]
    )
    assert result.exit_code == 2 and "plate scale" in result.output
    assert "Traceback" not in result.output


def test_a_failed_run_leaves_no_folder(simulated, tmp_path) -> None:
    imaging = tmp_path / "imaging.yaml"
    section = {"detector": {"plate_scale_arcsec": 2.0}, "bands": ["Vee"], "frames": 1}
    imaging.write_text(yaml.safe_dump(section))
    out = tmp_path / "never"
    result = CliRunner().invoke(
        app, ["frames", str(simulated), "-o", str(out), "--imaging", str(imaging)]
    )
    assert result.exit_code == 2 and "not among the dataset's bands (V)" in result.output
    assert not out.exists()
