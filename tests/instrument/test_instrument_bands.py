"""Bands: Gaussian names, speclite filters, tables, grid coverage."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from speclite.filters import load_filter

from speclight.errors import InputError
from speclight.instrument import band_response, bin_widths_nm, parse_band

GRID_NM = np.arange(300.0, 1241.0, 5.0)


def test_gaussian_name_is_parsed_and_normalised() -> None:
    band = parse_band("G-531/26")
    assert (band.kind, band.center_nm, band.sigma_nm) == ("gaussian", 531.0, 26.0)
    r = band_response(["G-531/26"], GRID_NM)[0]
    # Closed form: integral of exp(-x^2/2s^2) = s sqrt(2 pi); bin averages keep it exactly.
    assert np.sum(r * bin_widths_nm(GRID_NM)) == pytest.approx(26 * np.sqrt(2 * np.pi), rel=1e-12)
    # Peak 1 at 531 nm. The nearest bin is centred at 530 nm (offset 1 nm: factor
    # exp(-0.5 (1/26)^2)) and averages 5 nm (curvature factor 1 - (5^2/24)/26^2 to second
    # order; the next term is O((5/26)^4) ~ 1e-5).
    expected_peak = np.exp(-0.5 * (1 / 26) ** 2) * (1 - 25 / 24 / 26**2)
    assert r.max() == pytest.approx(expected_peak, abs=5e-5)
    with pytest.raises(InputError, match=r"G-<centre_nm>/<sigma_nm>"):
        parse_band("G-531")


def test_speclite_filter_keeps_its_integral() -> None:
    # Reference: trapezoid integral of speclite's own table (independent of the bins).
    f = load_filter("sdss2010-r")
    ref = np.trapezoid(f.response, f.wavelength / 10.0)
    r = band_response(["sdss2010-r"], GRID_NM)[0]
    assert np.sum(r * bin_widths_nm(GRID_NM)) == pytest.approx(ref, rel=1e-12)


def test_unknown_filter_lists_near_matches() -> None:
    with pytest.raises(InputError) as err:
        band_response(["bessel-V"], GRID_NM)
    msg = str(err.value)
    assert "did you mean 'bessell-V'" in msg and "near matches" in msg and "bessell-B" in msg
    assert err.value.field == "instrument.bands"


def test_band_outside_the_grid_is_refused() -> None:
    with pytest.raises(InputError, match="outside the wavelength grid"):
        band_response(["G-1500/20"], GRID_NM)
    with pytest.raises(InputError, match="outside the wavelength grid"):
        band_response(["twomass-Ks"], GRID_NM)  # 2.0-2.4 um


def test_table_band_in_micrometres(tmp_path: Path) -> None:
    f = tmp_path / "narrow.csv"
    f.write_text("wavelength_um,response\n0.60,0\n0.61,1\n0.62,1\n0.63,0\n")
    band = parse_band(str(f))
    assert band.kind == "table" and band.name == "narrow"
    r = band_response([band], GRID_NM)[0]
    # Trapezoid area of the table: 10/2 + 10 + 10/2 = 20 nm.
    assert np.sum(r * bin_widths_nm(GRID_NM)) == pytest.approx(20.0, rel=1e-12)
