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
from speclight.orbit.cpf import interpolate_table_m

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


HOLE_CSV = Path(__file__).parent / "data" / "lcs1_itrf_6h_hole.csv"


def test_epochs_in_a_hole_are_not_valid_and_the_others_unchanged() -> None:
    # ephemeris-gap reproducer: 240 s rows with none from 17:48 to 00:00 (a 6.2 h hole);
    # bridged, the 10-point polynomial was off by 2,084 km after 1 h, 36 million km later.
    eph = read_ephemeris_csv(HOLE_CSV)
    t = np.datetime64("2020-11-27T16:00:00", "ns") + np.arange(0, 8 * 3600 + 1, 60) * (
        np.timedelta64(1, "s")
    )
    r, ok = ephemeris_position_gcrs_m(eph, t)
    in_hole = (t > np.datetime64("2020-11-27T17:48:00")) & (t < np.datetime64("2020-11-28"))
    assert (ok == ~in_hole).all() and np.isnan(r[in_hole]).all()
    # outside the hole the positions are those of the plain interpolation, bit for bit
    r_itrf, ok_bridged = interpolate_table_m(eph.times_utc, eph.r_m, t)
    assert ok_bridged.all()
    assert np.array_equal(r[ok], earth_orientation(t).itrs_to_gcrs(r_itrf)[ok])


def test_gap_threshold_is_three_median_steps(tmp_path: Path) -> None:
    path, _ = _table(tmp_path, "GCRS", "km")  # 120 s rows
    rows = path.read_text().splitlines()
    del rows[10:12]  # a 360 s gap (3 steps): still bridged
    del rows[20:23]  # a 480 s gap (4 steps): not
    path.write_text("\n".join(rows))
    eph = read_ephemeris_csv(path)
    t0 = np.datetime64("2020-07-18T00:00:00", "ns")
    t = t0 + np.array([7 * 120 + 180, 19 * 120 + 240]) * np.timedelta64(1, "s")
    _, ok = ephemeris_position_gcrs_m(eph, t)
    assert ok.tolist() == [True, False]


def _edit_row(path: Path, row: int, cells: str) -> int:
    """Replace the position cells of data row ``row``; return its line number."""
    lines = path.read_text().splitlines()
    lineno = 4 + row  # two comment lines and the header come first
    lines[lineno - 1] = lines[lineno - 1].split(",")[0] + "," + cells
    path.write_text("\n".join(lines) + "\n")
    return lineno


@pytest.mark.parametrize(
    ("cells", "fragment"),
    [
        ("inf,0,0", "position [inf, 0.0, 0.0] km is not three finite numbers"),
        ("nan,1,2", "position [nan, 1.0, 2.0] km is not three finite numbers"),
        # fuzz/0124 (in m there): 1e300 overflowed the light-time step into a traceback
        ("1e300,1e300,1e300", "km is inf km from the geocentre; an Earth orbit is 6,000 to"),
        ("10,20,30", "position [10.0, 20.0, 30.0] km is 37.4166 km from the geocentre"),
    ],
)
def test_a_row_that_is_no_earth_orbit_names_its_line(
    tmp_path: Path, cells: str, fragment: str
) -> None:
    path, _ = _table(tmp_path, "GCRS", "km")
    lineno = _edit_row(path, 7, cells)
    with pytest.raises(InputError) as exc:
        read_ephemeris_csv(path)
    assert str(exc.value).startswith(f"{path}: line {lineno}: ") and fragment in str(exc.value)


@pytest.mark.parametrize(("written", "labelled"), [("m", "km"), ("km", "m")])
def test_metres_labelled_km_and_km_labelled_metres(
    tmp_path: Path, written: str, labelled: str
) -> None:
    path, _ = _table(tmp_path, "GCRS", written)
    text = path.read_text().replace(f"_{written}", f"_{labelled}")
    path.write_text(text)
    with pytest.raises(InputError) as exc:
        read_ephemeris_csv(path)
    name = {"m": "metres", "km": "kilometres"}[written]
    msg = str(exc.value)
    assert msg.startswith(f"{path}: header: the positions look like {name} labelled {labelled}")
    assert f"time_utc,x_{written},y_{written},z_{written}" in msg


@pytest.mark.parametrize(
    ("cell", "fragment"),
    [("NaT", "not a time"), ("99999-01-01T00:00:00Z", "outside 1678-2262")],
)
def test_a_time_numpy_cannot_hold_names_its_line(tmp_path: Path, cell: str, fragment: str) -> None:
    # both passed before: NaT compares false with everything, year 99999 wrapped to 1793
    path, _ = _table(tmp_path, "GCRS", "km")
    lines = path.read_text().splitlines()
    lines[-1] = cell + "," + lines[-1].split(",", 1)[1]
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match=rf"line {len(lines)}: cannot read .*{fragment}"):
        read_ephemeris_csv(path)


def test_a_row_too_long_for_the_csv_module(tmp_path: Path) -> None:
    path, _ = _table(tmp_path, "GCRS", "km")
    lines = path.read_text().splitlines()
    lines[5] += ',"' + "9" * 200_000 + '"'
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(InputError, match="line 6: not a CSV row"):
        read_ephemeris_csv(path)
