"""Optics / QE curves: numbers, presets, tables with unit detection."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.instrument import DETECTOR_PRESETS, load_preset, spectral_curve

GRID_NM = np.arange(300.0, 1241.0, 5.0)


def test_number_is_constant_and_percent_number_is_refused() -> None:
    assert np.all(spectral_curve(0.85, GRID_NM) == 0.85)
    with pytest.raises(InputError, match=r"write 0\.85, not 85") as err:
        spectral_curve(85, GRID_NM, field="instrument.optics_transmission")
    assert err.value.field == "instrument.optics_transmission"


def test_spad_preset_matches_datasheet_peak() -> None:
    # Hamamatsu S13360-6025CS datasheet (kapd1052e): photon detection efficiency 25 % at
    # the peak sensitivity wavelength 450 nm. Digitisation reads +-0.5 % and +-10 nm.
    wl, pde = load_preset("hamamatsu-s13360-spad")
    assert pde.max() == pytest.approx(0.25, abs=0.005)
    assert wl[np.argmax(pde)] == pytest.approx(450.0, abs=10.0)
    on_grid = spectral_curve("Hamamatsu-S13360-SPAD", GRID_NM)
    assert on_grid.max() == pytest.approx(0.25, abs=0.01)
    # Outside the tabulated range (279-897 nm) the efficiency is 0, by definition.
    assert np.all(on_grid[GRID_NM >= 905.0] == 0.0)


@pytest.mark.parametrize("name", list(DETECTOR_PRESETS))
def test_every_preset_is_a_fraction_with_units_resolved(name: str) -> None:
    q = spectral_curve(name, GRID_NM)
    # QE of silicon detectors peaks between 0.2 and 1 (fraction, not percent) in 400-700 nm.
    assert 0.2 < q.max() <= 1.0 and 400 <= GRID_NM[np.argmax(q)] <= 700
    assert np.all(q >= 0)


def test_unknown_preset_suggests_the_right_name() -> None:
    with pytest.raises(InputError, match="did you mean 'sony-imx428-cmos'"):
        spectral_curve("sony-imx482-cmos", GRID_NM)


def test_table_in_micrometres_and_percent_without_header_is_detected(tmp_path: Path) -> None:
    # A triangle 0 -> 80 % -> 0 over 0.5-0.7 um; its bin average is exact for a
    # piecewise-linear curve, so compare with the closed form at the bin centres (the
    # peak bin averages the apex: 80 % - slope * 2.5 nm / 2).
    f = tmp_path / "qe.csv"
    f.write_text("0.5,0\n0.6,80\n0.7,0\n")
    with pytest.warns(UserWarning) as record:
        q = spectral_curve(str(f), GRID_NM)
    messages = " ".join(str(w.message) for w in record)
    assert "micrometres" in messages and "percent" in messages
    centre = GRID_NM == 550.0
    assert q[centre][0] == pytest.approx(0.4, rel=1e-12)
    assert q[GRID_NM == 600.0][0] == pytest.approx(0.8 - 0.8 / 100 * 2.5 / 2, rel=1e-12)
    assert np.all(q[(GRID_NM < 495) | (GRID_NM > 705)] == 0.0)


def test_table_header_contradicting_values_is_explained(tmp_path: Path) -> None:
    f = tmp_path / "qe.csv"
    f.write_text("wavelength_nm,qe_fraction\n0.5,0.1\n0.6,0.8\n0.7,0.1\n")
    with pytest.raises(InputError, match="look like micrometres"):
        spectral_curve(f, GRID_NM)
    g = tmp_path / "qe2.csv"
    g.write_text("wavelength_nm,qe_fraction\n500,10\n600,80\n700,10\n")
    with pytest.raises(InputError, match="says fraction but reaches 80"):
        spectral_curve(g, GRID_NM)
    with pytest.raises(InputError, match="does not exist"):
        spectral_curve(tmp_path / "missing.csv", GRID_NM)
