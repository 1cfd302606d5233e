"""One band albedo for fit, upsample and unmix (issue 25 item 6).

Reference the code did not produce: the forward simulation itself. A Lambertian sphere's
count rate is linear in its reflectance spectrum (Nussbaum et al. 2022, eq. 5), so in every
band the counts of a sphere of reflectance rho over those of a white sphere (the same
geometry, render and source) are the band albedo of rho weighted by the detected photons of
that epoch's source at the aperture. The mean source over the pass gives it to the second
order of the atmosphere's change; the flat-source average of eq. 3 is another number (a solar
cell in a blue band differs by 0.07).
"""

from __future__ import annotations

import numpy as np
import pytest
import yaml

from speclight.estimate.inputs.band_albedo import (
    band_albedo,
    dataset_mean_source_W_m2_nm,
    scenario_mean_source_W_m2_nm,
)
from speclight.estimate.inputs.band_responses import dataset_band_responses
from speclight.estimate.inputs.source_spectrum import sun_source_W_m2_nm
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate
from speclight.target import Reflectance
from speclight.target.material_tables import material_table_path

#: Float rounding of the count ratio through the pipeline's sums [1].
ROUNDING = 1e-12
#: The atmosphere's change of spectral shape over 20 s of a pass, bound on its effect [1].
PASS_CHANGE = 1e-3


def _scenario(reflectance: object) -> str:
    data = yaml.safe_load(example_text("calsphere"))
    data["time"] = {"start": "2020-02-29T21:17:00Z", "stop": "2020-02-29T21:17:20Z", "step_s": 10.0}
    data["render"]["resolution_px"] = 32
    data["instrument"].pop("noise")
    data["target"]["materials"]["body"]["reflectance"] = reflectance
    return yaml.safe_dump(data)


@pytest.fixture(scope="module")
def pair() -> tuple:
    white = simulate(parse_scenario(_scenario(1.0))).dataset
    loaded = parse_scenario(_scenario({"table": "solar_cell"}))
    return loaded, simulate(loaded).dataset, white


def test_count_ratio_is_the_source_weighted_band_albedo(pair: tuple) -> None:
    _, cell, white = pair
    ratio = cell["count_rate"].values / white["count_rate"].values  # (N, B)
    bands = dataset_band_responses(cell)
    wl = bands.wavelength_nm
    rho = Reflectance.table_file(material_table_path("solar_cell")).evaluate(wl)
    for epoch, source in enumerate(sun_source_W_m2_nm(cell)):
        got = band_albedo(rho, bands.response, wl, source)
        np.testing.assert_allclose(got, ratio[epoch], rtol=ROUNDING)
    mean = band_albedo(rho, bands.response, wl, dataset_mean_source_W_m2_nm(cell))
    np.testing.assert_allclose(mean, ratio.mean(axis=0), atol=PASS_CHANGE * 0.1)
    flat = band_albedo(rho, bands.response, wl)
    assert np.max(np.abs(flat - ratio.mean(axis=0))) > 10 * PASS_CHANGE


def test_scenario_pass_source_is_the_simulated_one(pair: tuple) -> None:
    loaded, cell, _ = pair
    np.testing.assert_allclose(
        scenario_mean_source_W_m2_nm(loaded), dataset_mean_source_W_m2_nm(cell), rtol=ROUNDING
    )


def test_no_sun_no_source() -> None:
    data = yaml.safe_load(_scenario(1.0))
    data["illumination"] = {"sun": False}
    assert scenario_mean_source_W_m2_nm(parse_scenario(yaml.safe_dump(data))) is None
