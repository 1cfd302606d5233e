"""One real run of a tiny box-wing scenario through the pipeline, then `speclight plot`."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import yaml

from speclight.io.netcdf import write_dataset
from speclight.plot import plot_files
from speclight.plot.chain import band_electron_spectra
from speclight.scenario.builtin_examples import load_example
from speclight.scenario.load import parse_scenario
from speclight.simulation import simulate

pytest.importorskip("matplotlib")


@pytest.fixture(scope="module")
def tiny_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The built-in box-wing pass cut to 8 epochs at 30 s, 24 px images saved at 2 and 5.

    Lambertian parts keep it quick (the coated materials precompute tables for seconds).
    """
    scenario = yaml.safe_load(load_example("box-wing").yaml_text)
    parts = scenario["target"]["materials"]
    for k, part in enumerate(parts):
        parts[part] = {"bsdf": "lambertian", "reflectance": 0.2 + 0.2 * k}
    scenario["time"] = {
        "start": "2019-08-30T02:20:00Z",
        "stop": "2019-08-30T02:23:30Z",
        "step_s": 30.0,
    }
    scenario["render"] = {**scenario["render"], "resolution_px": 24, "save_images_at": [2, 5]}
    result = simulate(parse_scenario(yaml.safe_dump(scenario)))
    return write_dataset(result.dataset, tmp_path_factory.mktemp("run") / "tiny.nc")


def test_real_run_plots_overview_chain_and_images(tiny_run: Path, tmp_path: Path):
    written = plot_files(tiny_run, tmp_path / "pass.png")
    assert [p.name for p in written] == ["pass.png", "pass-chain.png", "pass-images.png"]
    assert all(p.stat().st_size > 20_000 for p in written)


def test_chain_band_spectra_integrate_to_the_datasets_count_rate(tiny_run: Path):
    import xarray as xr

    ds = xr.load_dataset(tiny_run, engine="h5netcdf")
    w = ds["wavelength"].values
    for i in range(ds.sizes["time"]):
        spectra = band_electron_spectra(ds, i)
        # Reference: the instrument stage's count_rate (a bin sum on the grid); here the
        # figure's curves are integrated with the trapezoid rule, which differs from the bin
        # sum only by half of the two end bins, where every band's response is < 1e-3 of its
        # peak (Gaussian bands >= 4 sigma inside 300-1240 nm) -> 1e-3 relative.
        rate = np.trapezoid(spectra, w, axis=1)
        np.testing.assert_allclose(rate, ds["count_rate"].values[i], rtol=1e-3)


def test_info_names_the_variant_a_single_mode_run_records(tiny_run: Path):
    # `speclight info` once named the path-mode variant (llvm_ad_spectral) as "the default"
    # while single-mode runs record llvm_ad_rgb: the run itself is the reference here.
    import xarray as xr

    from speclight.info import info_report

    ds = xr.load_dataset(tiny_run)
    assert ds.attrs["render_mode"] == "single"
    render = info_report()["render"]
    assert render["variant in single mode"].split()[0] == ds.attrs["render_variant"]
