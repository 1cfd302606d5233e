"""ILRS CPF reader (format versions 1 and 2) and its interpolation accuracy.

References: the CPF column layouts of Ricklefs et al., Consolidated Laser Ranging
Prediction Format v1.01 (ILRS 2006) and v2.00 (ILRS 2018), typed here by hand in the
style of real ILRS files (e.g. 'H1 CPF  2  DGF ... lageos1'); SGP4 positions of LCS 1 as
the "true" orbit that a CPF file samples.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import speclight
from speclight.errors import InputError
from speclight.orbit import (
    cpf_position_gcrs_m,
    earth_orientation,
    format_cpf,
    parse_tle,
    read_cpf,
    tle_position_gcrs_m,
)

L1 = "1 01361U 65034C   20199.53569372  .00000028  00000-0  25492-2 0  9994"
L2 = "2 01361  32.1395 267.1291 0005455 248.0922 111.8996  9.89297492995906"
LCS4_L1 = "1 05398U 71067E   17237.19596243  .00000191  00000-0  60767-4 0  9996"
LCS4_L2 = "2 05398  87.6282 147.4622 0065864  59.7371 301.0323 14.33603389412679"

# Columns per the v1.01 / v2.00 record descriptions (1-based): H1 version 8-9, source
# 12-14, production date 16-28, sequence 31-34 (v1) or 31-33 + sub-daily 35-36 (v2),
# target 36-45 (v1) or 38-47 (v2); H2 COSPAR 4-11, SIC 13-16, NORAD 18-25, start 27-45,
# end 47-65, step 67-71, TIV 73, class 75, frame 77-78, rotation 80, CoM 82, v2 location
# 84-85; record 10: direction 4, MJD 6-10, seconds 12-24, leap 26-27, x/y/z 29-45/47-63/
# 65-81; record 20: direction 4, vx/vy/vz 6-24/26-44/46-64.
CPF_V1 = """\
H1 CPF  1  SGF 2017 08 29 02  7241 lageos1
H2  7603901 1155     8820 2017 08 29 00 00 00 2017 08 29 00 06 00   120 1 1  0 0 0
H5  0.2510
H9
10 0 57994      0.000000  0    -5589316.482   -1974289.211    3681478.390
10 0 57994    120.000000  0    -5121237.102   -1208834.590    4440154.417
10 0 57994    240.000000  0    -4571048.871    -425718.013    5088542.215
10 0 57994    360.000000  0    -3950063.337     360212.904    5612779.551
99
"""
CPF_V2 = """\
H1 CPF  2  DGF 2020 12 07 03 342 01 lageos1    NONE
H2  7603901 1155     8820 2020 12 07 00 00 00 2020 12 07 00 04 00   120 1 1  0 0 0  1
H9
00 a comment record
10 0 59190      0.000000  0      1234567.890     -7654321.098      3456789.012
20 0    -1000.000000     2000.000000     3000.500000
10 0 59190    120.000000  0      1114567.890     -7414321.098      3816849.072
20 0    -1000.000000     2000.000000     3000.500000
10 0 59190    240.000000  0       994567.890     -7174321.098      4176909.132
20 0    -1000.000000     2000.000000     3000.500000
99
"""
#: CPF positions are written to 1 mm, so interpolation of a perfect orbit is limited by
#: that rounding (amplified by the Lagrange weights, Lebesgue constant ~3-5 for 10
#: equidistant centred points): < 1 cm. The degree-9 truncation error for LCS 1 at
#: 240 s is < 0.1 mm (see test_orbit_frames.py).
CPF_INTERPOLATION_TOLERANCE_M = 0.01


def _write(tmp_path: Path, text: str, name: str = "x.cpf") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


def test_reads_version_1(tmp_path: Path) -> None:
    cpf = read_cpf(_write(tmp_path, CPF_V1))
    assert (cpf.version, cpf.source, cpf.target_name) == (1, "SGF", "lageos1")
    assert (cpf.cospar_id, cpf.sic, cpf.norad_id) == ("7603901", "1155", "8820")
    assert cpf.step_s == 120 and cpf.reference_frame == 0 and cpf.com_offset_m == 0.2510
    assert cpf.start_utc == np.datetime64("2017-08-29T00:00:00")
    # MJD 57994 = 2017-08-29.
    assert cpf.times_utc[3] == np.datetime64("2017-08-29T00:06:00")
    assert cpf.r_itrf_m[0].tolist() == [-5589316.482, -1974289.211, 3681478.390]
    assert cpf.v_itrf_m_s is None


def test_reads_version_2_with_velocities(tmp_path: Path) -> None:
    cpf = read_cpf(_write(tmp_path, CPF_V2))
    assert (cpf.version, cpf.source, cpf.target_name) == (2, "DGF", "lageos1")
    assert cpf.times_utc.tolist()[-1] == np.datetime64("2020-12-07T00:04:00", "ns").item()
    assert cpf.r_itrf_m[2].tolist() == [994567.890, -7174321.098, 4176909.132]
    assert cpf.v_itrf_m_s is not None
    assert cpf.v_itrf_m_s[1].tolist() == [-1000.0, 2000.0, 3000.5]


@pytest.mark.parametrize(
    ("bad_line", "lineno", "fragment"),
    [
        ("10 0 57994    120.000000  0    -5121237.102   -1208834.590", 6, "need 8"),
        (
            "10 0 57994    120.00x000  0    -5121237.102   -1208834.590    4440154.417",
            6,
            "record 10 has an unreadable field",
        ),
        ("15 0 57994", 6, "unknown record type '15'"),
    ],
)
def test_malformed_records_name_file_line_and_record(
    tmp_path: Path, bad_line: str, lineno: int, fragment: str
) -> None:
    lines = CPF_V1.splitlines()
    lines[lineno - 1] = bad_line
    path = _write(tmp_path, "\n".join(lines) + "\n", "bad.cpf")
    with pytest.raises(InputError) as exc:
        read_cpf(path)
    msg = str(exc.value)
    assert str(path) in msg and f"line {lineno}" in msg and fragment in msg
    assert bad_line in msg


def test_unsupported_frame_version_and_non_cpf(tmp_path: Path) -> None:
    frame1 = CPF_V1.replace("1 1  0 0 0", "1 1  1 0 0")
    with pytest.raises(InputError, match=r"reference frame 1 .*true of date.* not supported"):
        read_cpf(_write(tmp_path, frame1))
    with pytest.raises(InputError, match="format version 3 is not supported"):
        read_cpf(_write(tmp_path, CPF_V1.replace("H1 CPF  1", "H1 CPF  3")))
    with pytest.raises(InputError, match="not an ILRS CPF file"):
        read_cpf(_write(tmp_path, CPF_V1.replace("H1 CPF", "H1 XYZ")))


@pytest.mark.parametrize("version", [1, 2])
@pytest.mark.parametrize(("norad", "step_s"), [(1361, 60), (1361, 240), (5398, 60)])
def test_interpolation_reproduces_sgp4(
    tmp_path: Path, version: int, norad: int, step_s: int
) -> None:
    # LCS 1 (2,700 km altitude, 145 min period) and LCS 4 (LEO, 100 min period).
    tle = parse_tle(f"{L1}\n{L2}") if norad == 1361 else parse_tle(f"{LCS4_L1}\n{LCS4_L2}")
    start = np.datetime64("2020-07-18T00:00:00", "ns")
    nodes = start + np.arange(0, 6 * 3600 + 1, step_s) * np.timedelta64(1, "s")
    eo = earth_orientation(nodes, exact=True)
    r_nodes, _ = tle_position_gcrs_m(tle, nodes, orientation=eo)
    text = format_cpf(
        nodes,
        eo.gcrs_to_itrs_vec(r_nodes),
        version=version,
        target_name="test",
        cospar_id="6503403",
        sic="9999",
        norad_id=str(norad),
    )
    cpf = read_cpf(_write(tmp_path, text))
    assert cpf.version == version and len(cpf.times_utc) == nodes.size
    # Off-node epochs, including the ends of the table (one-sided windows).
    query = start + (np.arange(7.3, 6 * 3600, 53.0) * 1e9).astype("timedelta64[ns]")
    r_cpf, ok = cpf_position_gcrs_m(cpf, query)
    r_true, _ = tle_position_gcrs_m(tle, query)
    assert ok.all()
    assert np.linalg.norm(r_cpf - r_true, axis=1).max() < CPF_INTERPOLATION_TOLERANCE_M


def test_epochs_outside_the_file_are_nan(tmp_path: Path) -> None:
    cpf = read_cpf(_write(tmp_path, CPF_V1))
    t = np.array(
        ["2017-08-28T23:59:59", "2017-08-29T00:01:00", "2017-08-29T00:06:01"],
        dtype="datetime64[ns]",
    )
    r, ok = cpf_position_gcrs_m(cpf, t)
    assert ok.tolist() == [False, True, False]
    assert np.isnan(r[~ok]).all() and np.isfinite(r[ok]).all()


def test_gap_in_the_table_is_not_bridged(tmp_path: Path) -> None:
    lines = CPF_V1.splitlines()
    del lines[6]  # the record at 240 s: a 240 s hole in a 120 s table
    cpf = read_cpf(_write(tmp_path, "\n".join(lines) + "\n"))
    t = np.array(["2017-08-29T00:01:00", "2017-08-29T00:03:00"], dtype="datetime64[ns]")
    _, ok = cpf_position_gcrs_m(cpf, t)
    assert ok.tolist() == [True, False]


def test_shipped_sample_file() -> None:
    path = Path(speclight.__file__).parent / "data/cpf/lcs1_20201127_speclight_sgp4.cpf"
    cpf = read_cpf(path)
    assert (cpf.version, cpf.target_name, cpf.norad_id, cpf.step_s) == (2, "lcs1", "1361", 240)
    assert cpf.times_utc[0] == cpf.start_utc and cpf.times_utc[-1] == cpf.end_utc
    t = np.datetime64("2020-11-27T17:30:00", "ns") + np.arange(0, 600, 7) * np.timedelta64(1, "s")
    r, ok = cpf_position_gcrs_m(cpf, t)
    r_true, _ = tle_position_gcrs_m(parse_tle(f"{L1}\n{L2}"), t)
    assert ok.all()
    assert np.linalg.norm(r - r_true, axis=1).max() < CPF_INTERPOLATION_TOLERANCE_M


SAMPLE_CPF = Path(speclight.__file__).parent / "data/cpf/lcs1_20201127_speclight_sgp4.cpf"


def _sample_with(tmp_path: Path, seconds_of_day: str, record: str) -> tuple[Path, int]:
    """The shipped sample with the record 10 at ``seconds_of_day`` replaced; its line."""
    lines = SAMPLE_CPF.read_text().splitlines()
    lineno = next(
        i
        for i, ln in enumerate(lines, 1)
        if ln.startswith("10 ") and ln.split()[3] == seconds_of_day
    )
    lines[lineno - 1] = record
    return _write(tmp_path, "\n".join(lines) + "\n", "edited.cpf"), lineno


@pytest.mark.parametrize(
    "position",
    [
        "inf 0 0",  # fuzz/0089: overflowed the light-time step into a skyfield IndexError
        "nan nan nan",  # issue 9 item 8: flagged below_min_elevation, not orbit_failed
        "1e300 1e300 1e300",
        "0.000 0.000 0.000",
    ],
)
def test_a_corrupt_record_fails_the_epochs_around_it_only(tmp_path: Path, position: str) -> None:
    path, lineno = _sample_with(tmp_path, "63360.000000", f"10 0 59180 63360.000000 0 {position}")
    cpf = read_cpf(path)
    assert cpf.unusable_lines == (lineno,)
    t = np.datetime64("2020-11-27T17:20:00", "ns") + np.arange(0, 1801, 30) * np.timedelta64(1, "s")
    r, ok = cpf_position_gcrs_m(cpf, t)
    # the neighbours of the 17:36 record are at 17:32 and 17:40
    around = (t > np.datetime64("2020-11-27T17:32")) & (t < np.datetime64("2020-11-27T17:40"))
    assert (ok == ~around).all() and np.isnan(r[around]).all()
    r_true, _ = tle_position_gcrs_m(parse_tle(f"{L1}\n{L2}"), t)
    assert np.linalg.norm(r[ok] - r_true[ok], axis=1).max() < CPF_INTERPOLATION_TOLERANCE_M


def test_a_file_of_corrupt_records_is_an_input_error(tmp_path: Path) -> None:
    lines = CPF_V1.splitlines()
    for i in (4, 5, 6):
        lines[i] = lines[i].rsplit(None, 3)[0] + " nan nan nan"
    with pytest.raises(InputError) as exc:
        read_cpf(_write(tmp_path, "\n".join(lines) + "\n"))
    assert "4 position records (type 10, direction 0), 1 of them usable; need >= 2" in str(
        exc.value
    )
    assert "Line 5: position [nan, nan, nan] m is not a finite point 6,000 to 2,000,000 km" in str(
        exc.value
    )


@pytest.mark.parametrize(
    ("bad_line", "lineno", "fragment"),
    [
        # fuzz/0102: round(1e20 * 1e9) did not fit a timedelta64 (OverflowError)
        ("10 0 57994 1e20 0 -5121237.102 -1208834.590 4440154.417", 6, "seconds of day 1e20"),
        ("10 0 57994 nan 0 -5121237.102 -1208834.590 4440154.417", 6, "seconds of day nan"),
        ("10 0 999999 0.0 0 -5121237.102 -1208834.590 4440154.417", 6, "MJD 999999 is not a day"),
        ("H5  x.2510", 3, "record H5 has an unreadable field"),
    ],
)
def test_record_fields_out_of_range_name_the_line(
    tmp_path: Path, bad_line: str, lineno: int, fragment: str
) -> None:
    lines = CPF_V1.splitlines()
    lines[lineno - 1] = bad_line
    path = _write(tmp_path, "\n".join(lines) + "\n", "bad.cpf")
    with pytest.raises(InputError) as exc:
        read_cpf(path)
    msg = str(exc.value)
    assert msg.startswith(f"{path}: line {lineno}: ") and fragment in msg and bad_line in msg


def test_header_year_beyond_numpy_times_is_an_input_error(tmp_path: Path) -> None:
    # year 99999 wrapped around silently to 1793 before
    text = CPF_V1.replace("2017 08 29 00 06 00", "99999 08 29 00 06 00")
    with pytest.raises(InputError, match=r"line 2: H2 has an unreadable field \(year 99999"):
        read_cpf(_write(tmp_path, text))
