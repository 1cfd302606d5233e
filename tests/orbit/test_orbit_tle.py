"""TLE parsing and SGP4 positions.

References: the TLE column layout and checksum rule of Vallado et al. (2006), AIAA
2006-6753, Appendix B; the ``sgp4`` library's own epoch decoding; skyfield's
``EarthSatellite.at`` (independent TEME -> GCRS chain, full IAU 2000A per epoch).
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

import numpy as np
import pytest
from sgp4.api import Satrec
from skyfield.api import EarthSatellite

from speclight.errors import InputError
from speclight.orbit import parse_tle, read_tle_file, read_tles, tle_position_gcrs_m
from speclight.orbit.frames import as_time
from speclight.orbit.timescale import load_timescale
from speclight.orbit.tle import utc_julian_date

TLE_FILE = str(files("speclight") / "data" / "tle" / "calibration_spheres.tle")
L1 = "1 01361U 65034C   20199.53569372  .00000028  00000-0  25492-2 0  9994"
L2 = "2 01361  32.1395 267.1291 0005455 248.0922 111.8996  9.89297492995906"
LCS4_L1 = "1 05398U 71067E   17237.19596243  .00000191  00000-0  60767-4 0  9996"
LCS4_L2 = "2 05398  87.6282 147.4622 0065864  59.7371 301.0323 14.33603389412679"
#: skyfield and speclight both use SGP4 + TEME->GCRS; differences are interpolation of the
#: precession-nutation matrix only (see test_orbit_frames.py), far below a millimetre.
POSITION_AGREEMENT_M = 1e-3


def _checksum(line: str) -> str:
    # Independent statement of the rule: digits add their value, '-' adds 1, mod 10.
    total = 0
    for ch in line[:68]:
        if ch.isdigit():
            total += int(ch)
        elif ch == "-":
            total += 1
    return str(total % 10)


def test_two_and_three_line_sets_parse() -> None:
    two = parse_tle(f"\n   {L1}\n{L2}   \n")
    three = parse_tle(f"LCS 1\n{L1}\n{L2}")
    zero = parse_tle(f"0 LCS 1\n{L1}\n{L2}")
    assert two.name == "" and three.name == "LCS 1" and zero.name == "LCS 1"
    assert three.norad_id == 1361
    # Epoch against sgp4's own decoding of the same line (jdsatepoch, UTC).
    sat = Satrec.twoline2rv(L1, L2)
    jd_epoch = sat.jdsatepoch + sat.jdsatepochF
    jd_ours = (three.epoch - np.datetime64("2000-01-01T12:00:00", "ns")) / np.timedelta64(
        1, "D"
    ) + 2451545.0
    assert abs(jd_ours - jd_epoch) * 86400.0 < 1e-4  # 0.1 ms


def test_checksum_failure_names_line_and_values() -> None:
    bad = L1[:68] + str((int(L1[68]) + 1) % 10)
    with pytest.raises(InputError) as exc:
        parse_tle(f"{bad}\n{L2}", source="scenario.yaml:orbit.tle")
    msg = str(exc.value)
    assert "scenario.yaml:orbit.tle" in msg
    assert "line 1" in msg and "checksum" in msg
    assert f"holds {bad[68]}" in msg and f"to {L1[68]}" in msg
    assert "1 NNNNNC NNNNNAAA" in msg  # the column template printed beside the line
    assert bad in msg


def test_minus_sign_counts_one_in_checksum() -> None:
    # Line 2 of a set with '-' signs: LCS 4's line 1 has '-' in two exponents.
    assert _checksum(LCS4_L1) == LCS4_L1[68]
    parse_tle(f"{LCS4_L1}\n{LCS4_L2}")


@pytest.mark.parametrize(
    ("line1", "line2", "fragment"),
    [
        (L1[:-1], L2, "found 68 characters, expected 69"),
        ("3" + L1[1:], L2, "expected line number '1'"),
        (L1, L2.replace(" 32.1395", "32.13950"), "column 12 is '1', expected '.'"),
        (L1[:8] + "X" + L1[9:], L2, "column 9 is 'X', expected a blank"),
        (L1, L2[:2] + "01362" + L2[7:68] + _checksum(L2[:2] + "01362" + L2[7:68]), "differ"),
    ],
)
def test_malformed_lines_are_rejected(line1: str, line2: str, fragment: str) -> None:
    with pytest.raises(InputError, match=fragment):
        parse_tle(f"{line1}\n{line2}")


def test_wrong_number_of_lines() -> None:
    with pytest.raises(InputError, match="found 1 non-blank"):
        parse_tle(L1)


def test_file_selection_by_norad_id() -> None:
    assert len(read_tles(TLE_FILE)) == 6
    latest = read_tle_file(TLE_FILE, norad_id=1361)
    assert latest.line1 == L1
    early = read_tle_file(TLE_FILE, norad_id=1361, near_epoch=np.datetime64("2019-09-01"))
    assert early.epoch < latest.epoch
    with pytest.raises(InputError, match=r"ids found: \[902, 1361, 1520, 5398\]"):
        read_tle_file(TLE_FILE, norad_id=99999)
    with pytest.raises(InputError, match="several objects"):
        read_tle_file(TLE_FILE)


def test_gcrs_positions_match_skyfield() -> None:
    tle = parse_tle(f"{L1}\n{L2}")
    sat = EarthSatellite(L1, L2, ts=load_timescale())
    times = tle.epoch + np.arange(0, 86400, 30) * np.timedelta64(1, "s")  # fast path
    r, ok = tle_position_gcrs_m(tle, times)
    sel = np.arange(0, times.size, 37)
    ref = sat.at(as_time(times[sel])).position.m.T
    assert ok.all()
    assert np.abs(r[sel] - ref).max() < POSITION_AGREEMENT_M


def test_failed_epochs_are_nan_rows_not_exceptions() -> None:
    # LCS 4 with an absurd drag term B* = 0.5 decays within weeks: sgp4 error codes 6/1.
    line1 = LCS4_L1[:53] + "+50000-0" + LCS4_L1[61:68]
    line1 += _checksum(line1)
    tle = parse_tle(f"{line1}\n{LCS4_L2}")
    times = tle.epoch + np.array([0, 1, 100, 300]) * np.timedelta64(1, "D")
    r, ok = tle_position_gcrs_m(tle, times)
    assert ok.tolist() == [True, True, False, False]
    assert np.isnan(r[~ok]).all() and np.isfinite(r[ok]).all()


def test_latin1_name_line_names_the_file_and_line(tmp_path: Path) -> None:
    # fuzz/0068: 'Kugel äöü' written in Latin-1 above a good element set (was a traceback)
    path = tmp_path / "cal.tle"
    path.write_bytes("Kugel äöü\n".encode("latin-1") + f"{L1}\n{L2}\n".encode())
    with pytest.raises(InputError) as exc:
        read_tles(path)
    msg = str(exc.value)
    assert msg.startswith(f"{path}: orbit.tle_file: cannot read TLE file: byte 0xe4 at line 1")
    assert "Latin-1" in msg and "save it as UTF-8" in msg


def test_utc_julian_date_applies_the_leap_seconds() -> None:
    # Public route to SGP4's UTC Julian date (no private skyfield call). Hand-worked: the
    # Julian date of 2020-06-01 12:00 UTC is 2459002.0 (Meeus, Astronomical Algorithms,
    # ch. 7), and TAI - UTC was 37 s then (IERS Bulletin C 52), so the TAI instant
    # 12:00:37 must map to it; the leap second 2016-12-31 23:59:60 raised TAI - UTC from 36 s
    # to 37 s, so 00:00:37.5 TAI on 2017-01-01 is 0.5 s after midnight UTC (JD 2457754.5).
    ts = load_timescale()
    jd, fr = utc_julian_date(ts.tai(2020, 6, 1, 12, 0, np.array([37.0])))
    assert jd[0] + fr[0] == pytest.approx(2459002.0, abs=1e-9)
    jd, fr = utc_julian_date(ts.tai(2017, 1, 1, 0, 0, np.array([37.5])))
    assert (jd[0] - 2457754.5) * 86400.0 + fr[0] * 86400.0 == pytest.approx(0.5, abs=1e-5)
