"""User transmission tables (wavelength x airmass) against a closed-form atmosphere."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from speclight.atmosphere import airmass, transmission
from speclight.errors import InputError

GRID_NM = np.arange(400.0, 901.0, 5.0)
TABLE_NM = np.arange(380.0, 921.0, 2.0)
NODES = (1.0, 2.0, 4.0)


def tau(wavelength_nm: np.ndarray) -> np.ndarray:
    """A Rayleigh-like vertical optical depth, 0.1 (lambda / 550 nm)^-4."""
    return 0.1 * (wavelength_nm / 550.0) ** -4


def write_table(path: Path, header: str, scale: float) -> Path:
    t = np.exp(-np.outer(tau(TABLE_NM), NODES))
    rows = [
        f"{w * scale:.6g}," + ",".join(f"{v:.8f}" for v in r)
        for w, r in zip(TABLE_NM, t, strict=True)
    ]
    path.write_text("# closed-form test atmosphere\n" + header + "\n" + "\n".join(rows) + "\n")
    return path


def expected(el: np.ndarray) -> np.ndarray:
    """Closed form: T = exp(-tau m) at the bin centres, with Kasten-Young m."""
    return np.exp(-np.outer(airmass(el), tau(GRID_NM)))


def bin_tolerance(m: np.ndarray) -> np.ndarray:
    """Relative error budget of a 5 nm bin average vs the centre value, per airmass.

    At 400 nm (the steepest bin) tau' = -4 tau / lambda and tau'' = 20 tau / lambda^2.
    Curvature of T^m inside a bin: (dl^2 / 24) (m^2 tau'^2 + m tau''); the bin average of
    exp(-tau m) is not exp(m ln(average T)): <= m^2 var_bin(tau) / 2 with
    var_bin = (tau' dl)^2 / 12. Both are bounded by m^2 (curvature + var) for m >= 1.
    """
    dl, lam = 5.0, 400.0
    t0 = tau(np.array([lam]))[0]
    d1, d2 = 4 * t0 / lam, 20 * t0 / lam**2
    return np.maximum(m, 1.0) ** 2 * (dl**2 / 24 * (d1**2 + d2) + (d1 * dl) ** 2 / 12)


def test_table_reproduces_closed_form_between_and_beyond_nodes(tmp_path: Path) -> None:
    f = write_table(tmp_path / "t.csv", "wavelength_nm, 1.0, airmass=2, m4", 1.0)
    el = np.array([90.0, 40.0, 20.0, 8.0, 0.0])  # m = 1, 1.55, 2.9, 7 (beyond 4), NaN
    t = transmission("table", GRID_NM, el, 0.0, table_file=f)
    assert np.isnan(t[-1]).all()
    rel = np.abs(t[:-1] / expected(el[:-1]) - 1).max(axis=1)
    assert np.all(rel < bin_tolerance(airmass(el[:-1])))


def test_table_in_micrometres_is_detected_from_header_or_values(tmp_path: Path) -> None:
    el = np.array([60.0])
    um = write_table(tmp_path / "um.csv", "wavelength_um, 1.0, 2.0, 4.0", 1e-3)
    tol = bin_tolerance(airmass(el))[0]
    t = transmission("table", GRID_NM, el, 0.0, table_file=um)
    assert np.allclose(t, expected(el), rtol=tol)
    silent = write_table(tmp_path / "silent.csv", "wavelength, 1.0, 2.0, 4.0", 1e-3)
    with pytest.warns(UserWarning, match="read as micrometres"):
        t = transmission("table", GRID_NM, el, 0.0, table_file=silent)
    assert np.allclose(t, expected(el), rtol=tol)


def test_table_with_wrong_unit_in_header_is_explained(tmp_path: Path) -> None:
    bad = write_table(tmp_path / "bad.csv", "wavelength_nm, 1.0, 2.0, 4.0", 1e-3)
    with pytest.raises(InputError, match=r"look like micrometres.*wavelength_um") as err:
        transmission("table", GRID_NM, [60.0], 0.0, table_file=bad)
    assert err.value.field == "atmosphere.table_file"


def test_table_must_cover_grid_and_name_airmasses(tmp_path: Path) -> None:
    f = write_table(tmp_path / "t.csv", "wavelength_nm, 1.0, 2.0, 4.0", 1.0)
    with pytest.raises(InputError, match=r"covers 380\.\.920 nm"):
        transmission("table", np.arange(300.0, 1000.0, 5.0), [60.0], 0.0, table_file=f)
    g = write_table(tmp_path / "g.csv", "wavelength_nm, 1.0, 0.5, 4.0", 1.0)
    with pytest.raises(InputError, match="airmass >= 1"):
        transmission("table", GRID_NM, [60.0], 0.0, table_file=g)


def test_table_with_nan_or_garbage_is_refused_with_the_line(tmp_path: Path) -> None:
    # Reproducers fuzz/0314 (a table of 'nan' gave NaN count rates with no flag) and
    # fuzz/0309 (binary garbage raised UnicodeDecodeError, an internal error).
    nan = write_table(tmp_path / "nan.csv", "wavelength_nm, 1.0, 2.0, 4.0", 1.0)
    lines = nan.read_text().splitlines()
    lines[5] = "390, nan, nan, nan"
    nan.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=r"line 6 .*'nan'.*not a finite number") as err:
        transmission("table", GRID_NM, [60.0], 0.0, table_file=nan)
    assert err.value.source == str(nan) and err.value.field == "atmosphere.table_file"
    garbage = tmp_path / "garbage.csv"
    garbage.write_bytes(bytes.fromhex("1e746b79c84295ebda3c6c5133f46f88"))
    with pytest.raises(InputError, match=r"garbage\.csv.*byte 0xc8 at line 1, .*is not UTF-8"):
        transmission("table", GRID_NM, [60.0], 0.0, table_file=garbage)
