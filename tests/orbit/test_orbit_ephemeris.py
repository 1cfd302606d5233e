"""Tabulated ephemeris CSV: units and frames, against SGP4 positions of LCS 1.

Reference: the SGP4 orbit that the table samples (the table is written here with plain
string formatting, in km or m, in GCRS or ITRF).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from speclight.errors import InputError
from speclight.orbit import (
    Tle,
    earth_orientation,
    ephemeris_position_gcrs_m,
    parse_tle,
    read_ephemeris_csv,
    tle_position_gcrs_m,
)

L1 = "1 01361U 65034C   20199.53569372  .00000028  00000-0  25492-2 0  9994"
L2 = "2 01361  32.1395 267.1291 0005455 248.0922 111.8996  9.89297492995906"
#: Values written with 1 mm resolution; 10-point Lagrange at 120 s steps for LCS 1 has a
#: truncation error < 0.1 mm, so rounding dominates (< 1 cm after interpolation).
TABLE_TOLERANCE_M = 0.01


def _table(tmp_path: Path, frame: str, unit: str) -> tuple[Path, Tle]:
    tle = parse_tle(f"{L1}\n{L2}")
    t = np.datetime64("2020-07-18T00:00:00", "ns") + np.arange(0, 7201, 120) * np.timedelta64(
        1, "s"
    )
    eo = earth_orientation(t, exact=True)
    r, _ = tle_position_gcrs_m(tle, t, orientation=eo)
    if frame == "ITRF":
        r = eo.gcrs_to_itrs_vec(r)
    scale = 1e-3 if unit == "km" else 1.0
    lines = [f"# frame: {frame}", "# LCS 1 from SGP4", f"time_utc,x_{unit},y_{unit},z_{unit}"]
    for ti, ri in zip(t, r * scale, strict=True):
        iso = str(ti.astype("datetime64[ms]")) + "Z"
        lines.append(f"{iso},{ri[0]:.6f},{ri[1]:.6f},{ri[2]:.6f}")
    path = tmp_path / f"eph_{frame}_{unit}.csv"
    path.write_text("\n".join(lines) + "\n")
    return path, tle


@pytest.mark.parametrize(("frame", "unit"), [("GCRS", "km"), ("ITRF", "m")])
def test_table_reproduces_orbit(tmp_path: Path, frame: str, unit: str) -> None:
    path, tle = _table(tmp_path, frame, unit)
    eph = read_ephemeris_csv(path)
    assert eph.frame == frame and eph.r_m.shape == (61, 3)
    q = np.datetime64("2020-07-18T00:00:00", "ns") + (np.arange(-30.0, 7300.0, 37.7) * 1e9).astype(
        "timedelta64[ns]"
    )
    r, ok = ephemeris_position_gcrs_m(eph, q)
    r_true, _ = tle_position_gcrs_m(tle, q)
    inside = (q >= eph.times_utc[0]) & (q <= eph.times_utc[-1])
    assert (ok == inside).all() and np.isnan(r[~ok]).all()
    assert np.linalg.norm(r[ok] - r_true[ok], axis=1).max() < TABLE_TOLERANCE_M


def test_wrong_unit_is_rejected_with_accepted_headers(tmp_path: Path) -> None:
    path, _ = _table(tmp_path, "GCRS", "km")
    path.write_text(path.read_text().replace("x_km,y_km,z_km", "x_au,y_au,z_au"))
    with pytest.raises(InputError) as exc:
        read_ephemeris_csv(path)
    msg = str(exc.value)
    assert "x_au" in msg and "time_utc,x_m,y_m,z_m" in msg and "x_km" in msg


def test_mixed_units_missing_frame_and_bad_rows(tmp_path: Path) -> None:
    path, _ = _table(tmp_path, "GCRS", "km")
    text = path.read_text()
    path.write_text(text.replace("x_km,y_km,z_km", "x_km,y_m,z_km"))
    with pytest.raises(InputError, match="mix units"):
        read_ephemeris_csv(path)
    path.write_text(text.replace("# frame: GCRS\n", ""))
    with pytest.raises(InputError, match="no frame given"):
        read_ephemeris_csv(path)
    path.write_text(text.replace("# frame: GCRS", "# frame: GCRF"))
    with pytest.raises(InputError, match="did you mean 'GCRS'"):
        read_ephemeris_csv(path)
    rows = text.splitlines()
    rows[4], rows[5] = rows[5], rows[4]
    path.write_text("\n".join(rows))
    with pytest.raises(InputError, match="not after the previous row"):
        read_ephemeris_csv(path)
    rows = text.splitlines()
    rows[6] = rows[6].replace(",", ";", 1)
    path.write_text("\n".join(rows))
    with pytest.raises(InputError, match="line 7: cannot read"):
        read_ephemeris_csv(path)
