"""CCSDS OEM reader (KVN and XML) against states computed by another route.

The OEM files are written here, in the layout of the examples of CCSDS 502.0-B-2 (KVN,
section 5 / annex) and 505.0-B-1 (XML), from states that do not go through the reader:
skyfield's ``EarthSatellite`` (GCRS, and ITRS via ``frame_xyz_and_velocity(itrs)``), the
sgp4 library directly (TEME), and ERFA's IAU 2000 frame-bias matrix ``bp00`` (EME2000).
Epoch labels in TAI, TT and GPS are written with the constants of IERS Bulletin C for 2019:
TAI - UTC = 37 s, TT - TAI = 32.184 s, TAI - GPS = 19 s.

Interpolation error. Hermite of degree 5 (3 nodes, value and velocity) on 60 s samples of
an exact circular LEO orbit (1,000 km, closed-form positions and velocities) leaves < 1 mm
between nodes: the Hermite remainder ``max|r^(6)| / 6! * prod (t - t_i)^2 ~ r n^6 / 720 *
(90 * 30 * 30 s^3)^2 ~ 1e-4 m`` (n = 1.0e-3 rad/s) plus the 1 mm rounding of the written
positions (``TOL_M`` = 5 mm). SGP4's velocities are *not* the time derivative of its positions:
they differ by ~1 cm/s (measured here with sgp4 2.27: 5-13 mm/s for Calsphere 2), so a file
written from SGP4 states, as real OEMs made from TLEs are, interpolates with Hermite to
~0.2 m between 60 s nodes (measured: 0.20 m max, the velocity term ``(t - t_j) L_j^2 dv``
summed over the window); ``TOL_SGP4_M`` = 0.5 m. Lagrange on the positions alone (degree 7)
is not affected (``TOL_M``).
"""

from __future__ import annotations

from pathlib import Path

import erfa
import numpy as np
import pytest
import yaml
from sgp4.api import Satrec
from skyfield.api import EarthSatellite
from skyfield.framelib import itrs

from speclight.errors import InputError
from speclight.orbit import load_timescale, time_from_utc
from speclight.orbit.oem import oem_position_gcrs_m, read_oem
from speclight.scenario import example_text, parse_scenario
from speclight.simulation.geometry_stage import scenario_geometry

TLE = yaml.safe_load(example_text("box-wing"))["orbit"]["tle"].strip().split("\n")
#: Written-to-1-mm positions through degree-5 Hermite; the measured error is < 0.2 mm.
TOL_M = 5e-3
#: Hermite interpolation of SGP4 states, whose velocities are ~1 cm/s off the derivative of
#: the positions (module docstring); measured 0.20 m.
TOL_SGP4_M = 0.5
LABEL_OFFSET_S = {"UTC": 0.0, "TAI": 37.0, "TT": 69.184, "GPS": 18.0}
T0 = np.datetime64("2019-08-30T02:00:00", "ns")


def _epochs(start_min: float, stop_min: float, step_s: float) -> np.ndarray:
    n = round((stop_min - start_min) * 60 / step_s) + 1
    offsets = np.rint((start_min * 60 + np.arange(n) * step_s) * 1e9).astype("timedelta64[ns]")
    return T0 + offsets


def _truth_gcrs_m(utc: np.ndarray) -> np.ndarray:
    sat = EarthSatellite(TLE[1], TLE[2], TLE[0], load_timescale())
    return sat.at(time_from_utc(utc)).position.m.T


def _states_km(frame: str, utc: np.ndarray) -> np.ndarray:
    """(N, 6) position [km] and velocity [km/s] in ``frame``, not through speclight."""
    sat = EarthSatellite(TLE[1], TLE[2], TLE[0], load_timescale())
    t = time_from_utc(utc)
    if frame == "TEME":
        s = Satrec.twoline2rv(TLE[1], TLE[2])
        days = (utc - np.datetime64("2000-01-01T12:00:00", "ns")) / np.timedelta64(86400, "s")
        e, r, v = s.sgp4_array(np.full(utc.size, 2451545.0), days)
        assert not e.any()
        return np.hstack([r, v])
    p = sat.at(t)
    if frame.startswith("ITRF"):
        r, v = p.frame_xyz_and_velocity(itrs)
        return np.hstack([r.km.T, v.km_per_s.T])
    r, v = p.position.km.T, p.velocity.km_per_s.T
    if frame == "EME2000":
        bias = erfa.bp00(2451545.0, 0.0)[0]  # r_J2000 = B r_GCRS (IAU 2000 frame bias)
        r, v = r @ bias.T, v @ bias.T
    return np.hstack([r, v])


def _label(utc: np.ndarray, scale: str, doy: bool = False) -> list[str]:
    lab = utc + np.timedelta64(round(LABEL_OFFSET_S[scale] * 1e9), "ns")
    out = []
    for s in np.datetime_as_string(lab, unit="ms"):
        if doy:
            day = (np.datetime64(s[:10]) - np.datetime64(s[:4] + "-01-01")).astype(int) + 1
            s = f"{s[:4]}-{day:03d}{s[10:]}"
        out.append(s)
    return out


def kvn_segment(
    frame: str, scale: str, utc: np.ndarray, name: str = "CALSPHERE 2", **keys: str
) -> str:
    """One metadata block and its data lines, KVN."""
    lab = _label(utc, scale, doy=keys.pop("doy", "") == "yes")
    meta = {
        "OBJECT_NAME": name,
        "OBJECT_ID": "1964-063E",
        "CENTER_NAME": "EARTH",
        "REF_FRAME": frame,
        "TIME_SYSTEM": scale,
        "START_TIME": lab[0],
        "STOP_TIME": lab[-1],
        **keys,
    }
    lines = ["META_START", *(f"{k} = {v}" for k, v in meta.items()), "META_STOP", ""]
    lines.append("COMMENT written by test_orbit_oem.py from skyfield / sgp4 states")
    for epoch, s in zip(lab, _states_km(frame, utc), strict=True):
        lines.append(f"{epoch} {s[0]:.6f} {s[1]:.6f} {s[2]:.6f} {s[3]:.9f} {s[4]:.9f} {s[5]:.9f}")
    lines += [
        "",
        "COVARIANCE_START",
        f"EPOCH = {lab[0]}",
        "COV_REF_FRAME = RTN",
        "3.3313494e-04",
        "4.6189273e-04 6.7824216e-04",
        "COVARIANCE_STOP",
        "",
    ]
    return "\n".join(lines)


def kvn(*segments: str) -> str:
    head = [
        "CCSDS_OEM_VERS = 2.0",
        "COMMENT test file",
        "CREATION_DATE = 2019-08-29T12:00:00",
        "ORIGINATOR = SPECLIGHT TESTS",
        "",
    ]
    return "\n".join(head) + "\n" + "\n".join(segments)


def _write(tmp_path: Path, text: str, name: str = "o.oem") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


QUERY = _epochs(10, 40, 7.0)  # off the 60 s nodes


@pytest.mark.parametrize(
    ("frame", "scale", "doy"),
    [
        ("GCRF", "UTC", "no"),
        ("ICRF", "TAI", "yes"),
        ("EME2000", "TT", "no"),
        ("ITRF2014", "GPS", "no"),
        ("ITRF-93", "UTC", "yes"),
        ("TEME", "TAI", "no"),
    ],
)
def test_kvn_reproduces_the_orbit(tmp_path: Path, frame: str, scale: str, doy: str) -> None:
    oem = read_oem(_write(tmp_path, kvn(kvn_segment(frame, scale, _epochs(0, 50, 60), doy=doy))))
    assert oem.object_name == "CALSPHERE 2" and oem.version == "2.0"
    r, ok = oem_position_gcrs_m(oem, QUERY)
    assert ok.all()
    err = np.linalg.norm(r - _truth_gcrs_m(QUERY), axis=1)
    assert err.max() < TOL_SGP4_M, err.max()


def test_hermite_on_an_exact_orbit(tmp_path: Path) -> None:
    # circular orbit, r = 7,378 km, i = 60 deg: closed-form positions and velocities
    a_km, mu = 7378.137, 398600.4418
    n = np.sqrt(mu / a_km**3)
    utc = _epochs(0, 50, 60)
    tt = (utc - T0) / np.timedelta64(1, "s")
    th, ci, si = n * tt, np.cos(np.radians(60)), np.sin(np.radians(60))
    r = a_km * np.c_[np.cos(th), np.sin(th) * ci, np.sin(th) * si]
    v = a_km * n * np.c_[-np.sin(th), np.cos(th) * ci, np.cos(th) * si]
    lab = _label(utc, "UTC")
    seg = kvn_segment("GCRF", "UTC", utc[:2]).split("META_STOP")[0] + "META_STOP\n"
    seg = seg.replace(lab[1], lab[-1])
    seg += "\n".join(
        f"{e} " + " ".join(f"{x:.6f}" for x in ri) + " " + " ".join(f"{x:.9f}" for x in vi)
        for e, ri, vi in zip(lab, r, v, strict=True)
    )
    r_m, ok = oem_position_gcrs_m(read_oem(_write(tmp_path, kvn(seg))), QUERY)
    tq = (QUERY - T0) / np.timedelta64(1, "s")
    truth = a_km * 1e3 * np.c_[np.cos(n * tq), np.sin(n * tq) * ci, np.sin(n * tq) * si]
    assert ok.all() and np.linalg.norm(r_m - truth, axis=1).max() < TOL_M


def test_time_system_label_matters(tmp_path: Path) -> None:
    # GPS labels (UTC + 18 s) read as UTC: each state lands 18 s late, ~130 km at LEO speeds
    text = kvn(kvn_segment("GCRF", "GPS", _epochs(0, 50, 60))).replace(
        "TIME_SYSTEM = GPS", "TIME_SYSTEM = UTC"
    )
    r, _ = oem_position_gcrs_m(read_oem(_write(tmp_path, text)), QUERY)
    shifted = _truth_gcrs_m(QUERY - np.timedelta64(18, "s"))
    assert np.linalg.norm(r - shifted, axis=1).max() < TOL_SGP4_M


def test_xml_equals_kvn_and_truth(tmp_path: Path) -> None:
    utc = _epochs(0, 50, 60)
    lab = _label(utc, "UTC")
    vectors = "\n".join(
        f"<stateVector><EPOCH>{e}</EPOCH><X units='km'>{s[0]:.6f}</X><Y>{s[1]:.6f}</Y>"
        f"<Z>{s[2]:.6f}</Z><X_DOT units='km/s'>{s[3]:.9f}</X_DOT><Y_DOT>{s[4]:.9f}</Y_DOT>"
        f"<Z_DOT>{s[5]:.9f}</Z_DOT></stateVector>"
        for e, s in zip(lab, _states_km("ITRF2000", utc), strict=True)
    )
    xml = f"""<?xml version="1.0" encoding="UTF-8"?>
<oem xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" id="CCSDS_OEM_VERS" version="2.0">
 <header><CREATION_DATE>2019-08-29T12:00:00</CREATION_DATE>
  <ORIGINATOR>SPECLIGHT TESTS</ORIGINATOR></header>
 <body><segment>
  <metadata><COMMENT>metadata comment</COMMENT><OBJECT_NAME>CALSPHERE 2</OBJECT_NAME>
   <OBJECT_ID>1964-063E</OBJECT_ID><CENTER_NAME>EARTH</CENTER_NAME>
   <REF_FRAME>ITRF2000</REF_FRAME><TIME_SYSTEM>UTC</TIME_SYSTEM>
   <START_TIME>{lab[0]}</START_TIME><STOP_TIME>{lab[-1]}</STOP_TIME>
   <INTERPOLATION>HERMITE</INTERPOLATION><INTERPOLATION_DEGREE>5</INTERPOLATION_DEGREE>
  </metadata>
  <data><COMMENT>data comment</COMMENT>
{vectors}
   <covarianceMatrix><EPOCH>{lab[0]}</EPOCH><CX_X>1e-3</CX_X></covarianceMatrix>
  </data>
 </segment></body>
</oem>
"""
    r_xml, ok = oem_position_gcrs_m(read_oem(_write(tmp_path, xml, "o.xml")), QUERY)
    r_kvn, _ = oem_position_gcrs_m(
        read_oem(_write(tmp_path, kvn(kvn_segment("ITRF2000", "UTC", utc)))), QUERY
    )
    assert ok.all()
    np.testing.assert_array_equal(r_xml, r_kvn)
    assert np.linalg.norm(r_xml - _truth_gcrs_m(QUERY), axis=1).max() < TOL_SGP4_M
    bad = xml.replace("<X units='km'>", "<X units='m'>")
    with pytest.raises(InputError, match="units"):
        read_oem(_write(tmp_path, bad, "bad.xml"))


def test_segments_gap_and_useable_span(tmp_path: Path) -> None:
    first = kvn_segment("GCRF", "UTC", _epochs(0, 20, 60), USEABLE_START_TIME="2019-08-30T02:05:00")
    second = kvn_segment("ITRF2014", "GPS", _epochs(30, 50, 60))
    oem = read_oem(_write(tmp_path, kvn(first, second)))
    assert len(oem.segments) == 2
    q = _epochs(0, 50, 30.0)
    r, ok = oem_position_gcrs_m(oem, q)
    minutes = (q - T0) / np.timedelta64(60, "s")
    expect = ((minutes >= 5) & (minutes <= 20)) | (minutes >= 30)
    np.testing.assert_array_equal(ok, expect)
    assert np.isnan(r[~ok]).all()
    assert np.linalg.norm(r[ok] - _truth_gcrs_m(q[ok]), axis=1).max() < TOL_SGP4_M
    _, ok_after = oem_position_gcrs_m(oem, _epochs(50.5, 51, 30.0))
    assert not ok_after.any()  # not extrapolated


def test_lagrange_and_accelerations(tmp_path: Path) -> None:
    seg = kvn_segment(
        "GCRF", "UTC", _epochs(0, 50, 60), INTERPOLATION="LAGRANGE", INTERPOLATION_DEGREE="7"
    )
    lines = [ln + " 0.001 0.002 0.003" if ln.startswith("2019-") else ln for ln in seg.split("\n")]
    oem = read_oem(_write(tmp_path, kvn("\n".join(lines))))
    assert oem.segments[0].method == "lagrange" and oem.segments[0].n_points == 8
    r, ok = oem_position_gcrs_m(oem, QUERY)
    assert ok.all() and np.linalg.norm(r - _truth_gcrs_m(QUERY), axis=1).max() < TOL_M


def test_pipeline_geometry_from_oem_equals_tle(tmp_path: Path) -> None:
    _write(tmp_path, kvn(kvn_segment("TEME", "UTC", _epochs(0, 50, 60))), "cal2.oem")
    d = yaml.safe_load(example_text("box-wing"))
    d.pop("target")
    d["time"] = {"start": "2019-08-30T02:20:00Z", "stop": "2019-08-30T02:29:00Z", "step_s": 10}
    geo_tle = scenario_geometry(parse_scenario(yaml.safe_dump(d), source="t", base_dir=tmp_path))
    d["orbit"] = {"oem_file": "cal2.oem", "object": "1964-063e"}
    geo = scenario_geometry(parse_scenario(yaml.safe_dump(d), source="o", base_dir=tmp_path))
    assert geo.orbit_ok.all()
    assert np.abs(geo.range_m - geo_tle.range_m).max() < TOL_SGP4_M
    # 0.5 m across >= 1,000 km is < 3e-5 degrees
    assert np.abs(geo.elevation_deg - geo_tle.elevation_deg).max() < 3e-5
    np.testing.assert_array_equal(geo.flags, geo_tle.flags)


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (("CENTER_NAME = EARTH", "CENTER_NAME = MOON"), "CENTER_NAME = MOON is not supported"),
        (("REF_FRAME = GCRF", "REF_FRAME = TOD"), "REF_FRAME = TOD is not supported"),
        (("TIME_SYSTEM = UTC", "TIME_SYSTEM = TDB"), "TIME_SYSTEM = TDB is not supported"),
        (("INTERPOLATION = HERMITE", "INTERPOLATION = SPLINE"), "SPLINE is not supported"),
        (("STOP_TIME = 2019-08-30T02:50:00.000", "STOP_TIME = soon"), "STOP_TIME = 'soon'"),
    ],
)
def test_unsupported_metadata(tmp_path: Path, edit: tuple[str, str], message: str) -> None:
    text = kvn(kvn_segment("GCRF", "UTC", _epochs(0, 50, 60), INTERPOLATION="HERMITE"))
    with pytest.raises(InputError, match=message):
        read_oem(_write(tmp_path, text.replace(*edit)))


def test_malformed_data_line_names_its_line(tmp_path: Path) -> None:
    lines = kvn(kvn_segment("GCRF", "UTC", _epochs(0, 50, 60))).split("\n")
    i = next(i for i, ln in enumerate(lines) if ln.startswith("2019-08-30T02:03"))
    lines[i] = lines[i].rsplit(" ", 1)[0]  # 6 fields
    with pytest.raises(InputError, match=rf"line {i + 1}: cannot read .*6 fields instead of 7"):
        read_oem(_write(tmp_path, "\n".join(lines)))
    lines[i] = "2019-08-30T02:02:00.000 1 2 3 4 5 6"  # not after the previous epoch
    with pytest.raises(InputError, match=rf"line {i + 1}: epoch .* is not after"):
        read_oem(_write(tmp_path, "\n".join(lines)))


def test_object_choice(tmp_path: Path) -> None:
    a = kvn_segment("GCRF", "UTC", _epochs(0, 20, 60))
    b = kvn_segment("GCRF", "UTC", _epochs(0, 20, 60), name="LCS 1").replace(
        "1964-063E", "1965-034C"
    )
    path = _write(tmp_path, kvn(a, b))
    with pytest.raises(InputError, match=r"several objects .*CALSPHERE 2, LCS 1.*orbit.object"):
        read_oem(path)
    with pytest.raises(InputError, match="did you mean 'CALSPHERE 2'"):
        read_oem(path, "CALSPHERE2")
    assert read_oem(path, "lcs 1").object_id == "1965-034C"


def test_epoch_numpy_cannot_hold_names_its_line(tmp_path: Path) -> None:
    lines = kvn(kvn_segment("GCRF", "UTC", _epochs(0, 50, 60))).split("\n")
    i = next(i for i, ln in enumerate(lines) if ln.startswith("2019-08-30T02:03"))
    lines[i] = "3019" + lines[i][4:]  # numpy's nanosecond times would wrap around
    with pytest.raises(InputError, match=rf"line {i + 1}: .*outside 1678-2262"):
        read_oem(_write(tmp_path, "\n".join(lines)))


@pytest.mark.parametrize(
    ("orbit", "message"),
    [
        ({"oem_file": "a.oem", "sp3_file": "b.sp3"}, "exactly one of .*found oem_file, sp3_file"),
        ({"tle_file": "a.tle", "object": "X"}, "object selects an object of oem_file"),
        ({"oem_file": "a.oem", "satellite": "G01"}, "satellite selects a satellite of sp3_file"),
    ],
)
def test_scenario_orbit_keys(orbit: dict, message: str) -> None:
    d = yaml.safe_load(example_text("box-wing"))
    d["orbit"] = orbit
    with pytest.raises(InputError, match=message):
        parse_scenario(yaml.safe_dump(d), source="s")


def test_missing_or_foreign_file(tmp_path: Path) -> None:
    with pytest.raises(InputError, match=r"orbit\.oem_file: cannot read OEM file: no such file"):
        read_oem(tmp_path / "none.oem")
    with pytest.raises(InputError, match="no CCSDS_OEM_VERS line"):
        read_oem(_write(tmp_path, "META_START\nOBJECT_NAME = X\nMETA_STOP\n"))
    with pytest.raises(InputError, match="root element is <ndm>, not <oem>"):
        read_oem(_write(tmp_path, "<ndm><oem/></ndm>", "n.xml"))
    with pytest.raises(InputError, match="DOCTYPE"):
        read_oem(_write(tmp_path, '<!DOCTYPE oem [<!ENTITY a "b">]><oem/>', "d.xml"))
