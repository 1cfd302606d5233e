"""The shipped material tables (data/materials) against closed forms worked by hand.

Each value below is computed from the n,k rows of data/optical_constants written out in the
test, with the textbook formulas (normal incidence; Born & Wolf, *Principles of Optics*,
7th ed., sec. 1.5.3; Macleod, *Thin-Film Optical Filters*, 4th ed., ch. 2), not with the
generating script. The tables are written with 6 decimals: ROUNDING = 5e-7.
"""

import importlib.util
from pathlib import Path

import numpy as np
import pytest
import yaml

from speclight.errors import InputError
from speclight.scenario import example_text, parse_scenario
from speclight.target import Reflectance
from speclight.target.material_tables import MATERIAL_TABLES, material_table_path

ROOT = Path(__file__).resolve().parents[2]
ROUNDING = 5e-7


def _value(name: str, wavelength_nm: float) -> float:
    r = Reflectance.table_file(material_table_path(name))
    return float(r.evaluate([wavelength_nm])[0])


def _lerp(x: float, x0: float, y0: float, x1: float, y1: float) -> float:
    return y0 + (y1 - y0) * (x - x0) / (x1 - x0)


def test_aluminium_is_the_fresnel_reflectance_of_rakic_nk():
    # Al.csv rows 619.93 nm (1.366, 7.4052) and 652.25 nm (1.5724, 7.7354), interpolated to
    # 620 nm; R = ((n-1)^2 + k^2) / ((n+1)^2 + k^2)
    n = _lerp(620.0, 619.93, 1.366, 652.25, 1.5724)
    k = _lerp(620.0, 619.93, 7.4052, 652.25, 7.7354)
    expected = ((n - 1) ** 2 + k**2) / ((n + 1) ** 2 + k**2)
    assert _value("aluminium", 620.0) == pytest.approx(expected, abs=ROUNDING)


def test_kapton_mli_is_the_incoherent_sum_over_aluminium():
    # 1000 nm: Kapton.csv n = 1.72571; k from the Urbach tail, ln k linear in the photon
    # energy E = hc/lambda through the k rows 400-430 nm (0.0592894, 0.0482295, 0.0344458,
    # 0.0182363), evaluated at 1.2398 eV; Al.csv rows 999.88 (1.4359, 9.4939), 1033.2 (1.3998,
    # 9.8914). R = R1 + (1 - R1)^2 tau^2 R2 / (1 - R1 R2 tau^2), R1 air|Kapton,
    # R2 Kapton|Al, tau = exp(-4 pi k d / lambda), d = 25 um.
    hc_ev_nm = 1239.84198
    rows_nm = np.array([400.0, 410.0, 420.0, 430.0])
    rows_k = np.array([0.0592894, 0.0482295, 0.0344458, 0.0182363])
    slope, intercept = np.polyfit(hc_ev_nm / rows_nm, np.log(rows_k), 1)
    k = np.exp(intercept + slope * hc_ev_nm / 1000.0)
    tau2 = np.exp(-8 * np.pi * k * 25_000.0 / 1000.0)
    nk = 1.72571
    n_al = complex(
        _lerp(1000.0, 999.88, 1.4359, 1033.2, 1.3998),
        _lerp(1000.0, 999.88, 9.4939, 1033.2, 9.8914),
    )
    r1 = ((nk - 1) / (nk + 1)) ** 2
    r2 = abs((nk - n_al) / (nk + n_al)) ** 2
    expected = r1 + (1 - r1) ** 2 * tau2 * r2 / (1 - r1 * r2 * tau2)
    assert _value("kapton_mli", 1000.0) == pytest.approx(expected, abs=2 * ROUNDING)
    # and the film is opaque below 450 nm (Arakawa's k: 0.06 at 400 nm over 25 um)
    assert _value("kapton_mli", 400.0) < 0.1


def test_solar_cell_at_the_quarter_wave_of_its_coating():
    # At 600 nm the 75 nm film of index 2.0 is a quarter wave: the film's reflectance is
    # |(n0 N2 - n1^2) / (n0 N2 + n1^2)|^2 (Macleod, quarter-wave layer), n0 = SiO2 1.45804,
    # N2 = Si 3.94 + 0.019934 i (the 600 nm rows); then the incoherent sum with the front
    # surface of the cover glass.
    n0, n1, n2 = 1.45804, 2.0, complex(3.94, 0.019934)
    r2 = abs((n0 * n2 - n1**2) / (n0 * n2 + n1**2)) ** 2
    r1 = ((n0 - 1) / (n0 + 1)) ** 2
    expected = r1 + (1 - r1) ** 2 * r2 / (1 - r1 * r2)
    assert _value("solar_cell", 600.0) == pytest.approx(expected, abs=ROUNDING)


def test_white_paint_is_flat():
    assert _value("white_paint", 420.0) == _value("white_paint", 1069.0) == 0.8


def test_the_script_regenerates_the_shipped_tables(tmp_path):
    spec = importlib.util.spec_from_file_location(
        "make_material_spectra", ROOT / "scripts" / "make_material_spectra.py"
    )
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.write_all(tmp_path)
    for name in MATERIAL_TABLES:
        assert (tmp_path / f"{name}.csv").read_text() == material_table_path(name).read_text()


def test_scenario_names_a_shipped_table_and_refuses_an_unknown_one():
    d = yaml.safe_load(example_text("calsphere"))
    d["target"]["materials"]["body"] = {
        "bsdf": "lambertian",
        "reflectance": {"table": "solar_cell"},
    }
    parse_scenario(yaml.safe_dump(d), source="test")
    d["target"]["materials"]["body"]["reflectance"] = {"table": "solar_cel"}
    with pytest.raises(InputError, match="solar_cell"):
        parse_scenario(yaml.safe_dump(d), source="test")
    with pytest.raises(InputError, match="unknown material table 'paint'"):
        material_table_path("paint")
