"""``speclight period --source laser`` and the synodic correction ``--synodic auto``.

Reference: the scenario's own spin period (120 s). Under coaxial lasers the phase angle is 0
and the phase-angle bisector is the observer direction, so the light curve is a function of
the observer's body-frame direction alone and the correction in the bisector's frame
(Harris et al. 1984) holds by construction: the plain periodogram sees the synodic period,
about 1 % (over 3 of its statistical sigmas) off on this pass, and ``auto`` must give the
rotation period within 1 % and within 4 of its standard deviations (what the issue asks of a
box-wing from one pass).
"""

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.estimate.period.period_run import estimate_period
from speclight.scenario import parse_scenario
from speclight.scenario.builtin_examples import example_text
from speclight.simulation.pipeline import simulate

TRUE_PERIOD_S = 120.0


@pytest.fixture(scope="module")
def laser_pass(tmp_path_factory):
    text = example_text("box-wing-laser").replace("sun: true", "sun: false")
    start = text.index("    - {name: wettzell-532")
    text = text[:start] + text[text.index("atmosphere:") :]  # coaxial lines only
    text = text.replace("resolution_px: 256", "resolution_px: 48")
    loaded = parse_scenario(text, source="box-wing-laser (coaxial, 48 px)")
    path = tmp_path_factory.mktemp("laser") / "pass.nc"
    simulate(loaded).dataset.to_netcdf(path, engine="h5netcdf")
    return path


def test_laser_pass_rotation_period_with_the_synodic_correction(laser_pass):
    plain = estimate_period(laser_pass, source="laser", synodic="report", draws=2)
    auto = estimate_period(laser_pass, source="laser", draws=2)
    assert plain.synodic is not None and not plain.synodic.applied
    # the synodic effect is there: 118.90 s, 4.4 of its statistical sigmas (0.25 s) off
    assert abs(plain.period_s - TRUE_PERIOD_S) > 3 * plain.statistical_std_s
    assert auto.synodic is not None and auto.synodic.applied
    assert abs(auto.period_s / TRUE_PERIOD_S - 1) < 0.01
    assert abs(auto.period_s - TRUE_PERIOD_S) < 4 * auto.period_std_s
    # the rates read are the laser reflectance factors (no Sun: the count rates are 0)
    assert auto.to_json()["n_epochs"] > 500


def test_laser_source_needs_laser_returns(tmp_path):
    csv = tmp_path / "lc.csv"
    t = np.datetime64("2020-01-01T00:00:00") + np.arange(30) * np.timedelta64(1, "s")
    csv.write_text("time,B\n" + "".join(f"{x}Z,{10 + k % 3}\n" for k, x in enumerate(t)))
    with pytest.raises(InputError, match="source='laser' reads the laser return rates"):
        estimate_period(csv, source="laser")
    with pytest.raises(InputError, match="source = 'moon'"):
        estimate_period(csv, source="moon")
    with pytest.raises(InputError, match="synodic = 'always'"):
        estimate_period(csv, synodic="always")  # type: ignore[arg-type]
