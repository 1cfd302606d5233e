"""IGS SP3-c/d reader against ITRS positions computed by another route.

The SP3 files are written here in the column layout of Hilla, *The Extended Standard Product
3 Orbit Format (SP3-d)* (IGS 2016) from skyfield's ITRS positions (``frame_xyz(itrs)``) of a
GPS-like orbit built with the sgp4 library's ``Satrec.sgp4init`` (a = 26,560 km, i = 55 deg,
2.005 rev/day) and exported as a TLE. Epochs are labelled in GPS time: GPS - UTC = 18 s in
2020 (IERS Bulletin C: TAI - UTC = 37 s; TAI - GPS = 19 s).

Interpolation error, measured: 10-point Lagrange on 5-min samples leaves < 2 mm on this orbit
(positions written to 1 mm, Lebesgue constant of 10 centred equidistant points ~3); the
truncation term ``r (n h)^10 / 10!`` with n h = 0.044 rad is ~1e-11 m. ``TOL_M`` = 1 cm.
"""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path

import numpy as np
import pytest
import yaml
from sgp4.api import WGS72, Satrec
from sgp4.exporter import export_tle
from skyfield.api import EarthSatellite
from skyfield.framelib import itrs

from speclight.errors import InputError
from speclight.orbit import load_timescale, time_from_utc
from speclight.orbit.sp3 import read_sp3, sp3_position_gcrs_m
from speclight.scenario import example_text, parse_scenario
from speclight.simulation.geometry_stage import scenario_geometry

TOL_M = 1e-2
GPS_MINUS_UTC = np.timedelta64(18, "s")
T0_GPS = np.datetime64("2020-06-01T00:00:00", "ns")
STEP = np.timedelta64(300, "s")
N_EPOCHS = 73  # 6 h


def _tle(mean_anomaly_deg: float) -> tuple[str, str]:
    sat = Satrec()
    epoch = (datetime(2020, 6, 1, tzinfo=UTC) - datetime(1949, 12, 31, tzinfo=UTC)).days
    sat.sgp4init(
        WGS72, "i", 99001, float(epoch), 0.0, 0.0, 0.0, 0.005,  # bstar, ndot, nddot, ecc
        np.radians(30.0), np.radians(55.0), np.radians(mean_anomaly_deg),  # argp, inc, M
        2.005 * 2 * np.pi / 1440.0, np.radians(120.0),  # mean motion [rad/min], RAAN
    )  # fmt: skip
    return export_tle(sat)


SATS = {"G01": _tle(10.0), "G02": _tle(100.0)}


def _sat(name: str) -> EarthSatellite:
    return EarthSatellite(*SATS[name], name, load_timescale())


def _gps_epochs() -> np.ndarray:
    return T0_GPS + np.arange(N_EPOCHS) * STEP


def sp3_text(version: str = "d", system: str = "GPS", label_shift=GPS_MINUS_UTC) -> str:
    """An SP3 file of G01 and G02; ``label_shift``: label minus the UTC instant."""
    labels = _gps_epochs()
    utc = labels - label_shift
    ts = time_from_utc(utc)
    pos = {k: _sat(k).at(ts).frame_xyz(itrs).km.T for k in SATS}
    sec = (T0_GPS - np.datetime64("1980-01-06", "ns")) / np.timedelta64(1, "s")
    week, sow = divmod(sec, 604800)
    lines = [
        f"#{version}P2020  6  1  0  0  0.00000000 {N_EPOCHS:7d} ORBIT IGS14 HLM TST",
        f"## {int(week):4d} {sow:15.8f} {300.0:14.8f} 59001 0.0000000000000",
        "+    2   G01G02" + "  0" * 15,
        "++         2  2" + "  0" * 15,
        f"%c G  cc {system} ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc",
        "%c cc cc ccc ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc",
        "%f  1.2500000  1.025000000  0.00000000000  0.000000000000000",
        "%i    0    0    0    0      0      0      0      0         0",
        "/* written by test_orbit_sp3.py from skyfield ITRS positions",
    ]
    for i, lab in enumerate(labels):
        s = str(lab)
        lines.append(
            f"*  {s[:4]} {int(s[5:7]):2d} {int(s[8:10]):2d} {int(s[11:13]):2d} "
            f"{int(s[14:16]):2d} {0.0:11.8f}"
        )
        for k in SATS:
            x, y, z = pos[k][i]
            lines.append(f"P{k}{x:14.6f}{y:14.6f}{z:14.6f}{123.456789:14.6f}")
    lines.append("EOF")
    return "\n".join(lines) + "\n"


def _write(tmp_path: Path, text: str, name: str = "o.sp3") -> Path:
    p = tmp_path / name
    p.write_text(text)
    return p


#: Query instants (UTC) between nodes, inside the file: 1 h to 5 h every 137 s.
QUERY = T0_GPS + np.timedelta64(3600, "s") + np.arange(106) * np.timedelta64(137, "s")


def _truth(name: str, utc: np.ndarray) -> np.ndarray:
    return _sat(name).at(time_from_utc(utc)).position.m.T


@pytest.mark.parametrize("version", ["c", "d"])
def test_reproduces_the_orbit(tmp_path: Path, version: str) -> None:
    path = _write(tmp_path, sp3_text(version))
    for name in SATS:
        sp3 = read_sp3(path, name)
        assert (sp3.version, sp3.coordinate_system, sp3.time_system) == (version, "IGS14", "GPS")
        assert sp3.interval_s == 300.0 and sp3.skipped_lines == []
        r, ok = sp3_position_gcrs_m(sp3, QUERY)
        assert ok.all()
        assert np.linalg.norm(r - _truth(name, QUERY), axis=1).max() < TOL_M


def test_time_systems(tmp_path: Path) -> None:
    # the same instants labelled in UTC give the same positions
    utc_file = read_sp3(
        _write(tmp_path, sp3_text(system="UTC", label_shift=np.timedelta64(0))), "G01"
    )
    gps_file = read_sp3(_write(tmp_path, sp3_text(), "g.sp3"), "G01")
    q = QUERY[:20]
    r_utc, _ = sp3_position_gcrs_m(utc_file, q)
    r_gps, _ = sp3_position_gcrs_m(gps_file, q)
    assert np.linalg.norm(r_utc - _truth("G01", q), axis=1).max() < TOL_M
    assert np.linalg.norm(r_gps - _truth("G01", q), axis=1).max() < TOL_M
    # GPS labels declared UTC: every Earth-fixed state 18 s late (~20 km off the orbit)
    wrong = read_sp3(_write(tmp_path, sp3_text().replace("cc GPS", "cc UTC"), "w.sp3"), "G01")
    r_wrong, _ = sp3_position_gcrs_m(wrong, q)
    r_late_itrs = _sat("G01").at(time_from_utc(q - GPS_MINUS_UTC)).frame_xyz(itrs).m
    r_late = np.einsum("jin,jn->ni", itrs.rotation_at(time_from_utc(q)), r_late_itrs)
    assert np.linalg.norm(r_wrong - r_late, axis=1).max() < TOL_M
    assert np.linalg.norm(r_wrong - r_gps, axis=1).min() > 15e3
    with pytest.raises(InputError, match="time system 'XYZ' is not known"):
        read_sp3(_write(tmp_path, sp3_text().replace("cc GPS", "cc XYZ"), "x.sp3"), "G01")


@pytest.mark.parametrize("bad", ["999999.999999", "0.000000"])
def test_bad_record_is_skipped_and_its_hole_flagged(tmp_path: Path, bad: str) -> None:
    lines = sp3_text().split("\n")
    i = [k for k, ln in enumerate(lines) if ln.startswith("PG01")][36]  # epoch 03:00 GPS
    x = f"{float(bad):14.6f}"
    lines[i] = lines[i][:4] + (x if bad.startswith("9") else x * 3) + lines[i][4 + len(x) :]
    sp3 = read_sp3(_write(tmp_path, "\n".join(lines)), "G01")
    assert sp3.skipped_lines == [i + 1] and len(sp3.segments) == 2
    hole_gps = T0_GPS + 36 * STEP
    q = QUERY
    r, ok = sp3_position_gcrs_m(sp3, q)
    in_hole = np.abs((q + GPS_MINUS_UTC - hole_gps) / np.timedelta64(1, "s")) < 300
    np.testing.assert_array_equal(ok, ~in_hole)
    assert np.linalg.norm(r[ok] - _truth("G01", q[ok]), axis=1).max() < TOL_M


def test_outside_the_file_is_flagged(tmp_path: Path) -> None:
    sp3 = read_sp3(_write(tmp_path, sp3_text()), "G02")
    q = T0_GPS - GPS_MINUS_UTC + np.array([-1, 0, 6 * 3600, 6 * 3600 + 1]) * np.timedelta64(1, "s")
    _, ok = sp3_position_gcrs_m(sp3, q)
    np.testing.assert_array_equal(ok, [False, True, True, False])


def test_malformed_lines_and_unknown_satellite(tmp_path: Path) -> None:
    lines = sp3_text().split("\n")
    i = next(k for k, ln in enumerate(lines) if ln.startswith("PG02"))
    lines[i] = lines[i][:10] + "x" + lines[i][11:]
    with pytest.raises(InputError, match=rf"line {i + 1}: x y z \[km\] not in columns"):
        read_sp3(_write(tmp_path, "\n".join(lines)), "G01")
    j = next(k for k, ln in enumerate(lines) if ln.startswith("* "))
    lines = sp3_text().split("\n")
    lines[j] = "*  2020  6  x"
    with pytest.raises(InputError, match=rf"line {j + 1}: not an epoch line"):
        read_sp3(_write(tmp_path, "\n".join(lines)), "G01")
    path = _write(tmp_path, sp3_text(), "ok.sp3")
    assert read_sp3(path, "g1").satellite == "G01"
    with pytest.raises(InputError, match=r"'R01' is not in the file; did you mean 'G01'\?"):
        read_sp3(path, "R01")
    with pytest.raises(InputError, match=r"2 satellites \(G01, G02\); choose one"):
        read_sp3(path)
    with pytest.raises(InputError, match="not an SP3-c or SP3-d file"):
        read_sp3(_write(tmp_path, "#aP2020 ...\n", "a.sp3"))


def test_pipeline_geometry_from_sp3_equals_tle(tmp_path: Path) -> None:
    _write(tmp_path, sp3_text(), "gps.sp3")
    d = yaml.safe_load(example_text("box-wing"))
    d.pop("target")
    d["time"] = {"start": "2020-06-01T01:00:00Z", "stop": "2020-06-01T05:00:00Z", "step_s": 600}
    d["orbit"] = {"tle": "G01\n" + "\n".join(SATS["G01"])}
    geo_tle = scenario_geometry(parse_scenario(yaml.safe_dump(d), source="t", base_dir=tmp_path))
    d["orbit"] = {"sp3_file": "gps.sp3", "satellite": "G01"}
    geo = scenario_geometry(parse_scenario(yaml.safe_dump(d), source="s", base_dir=tmp_path))
    assert geo.orbit_ok.all()
    assert np.abs(geo.range_m - geo_tle.range_m).max() < TOL_M
    assert np.abs(geo.elevation_deg - geo_tle.elevation_deg).max() < 1e-7  # 1 cm at 20,000 km
    np.testing.assert_array_equal(geo.flags, geo_tle.flags)


#: The first example file of the SP3-d specification (Hilla 2016; simulated positions from
#: broadcast ephemerides, 140 satellites of 6 systems), first two epochs and a few vehicles.
SP3D_SPEC_EXAMPLE = """\
#dP2013  4  3  0  0  0.00000000       3 ORBIT WGS84 BCT MGEX
## 1734 259200.00000000   900.00000000 56385 0.0000000000000
+  140   G01G02G03G04G05G06G07G08G09G10G11G12G13G14G15G16G17
+        G18G19G20G21G22G23G24G25G26G27G28G29G30G31G32R01R02
+        R03R04R05R06R07R08R09R10R11R12R13R14R15R16R17R18R19
+        R20R21R22R23R24E01E02E03E04E05E06E07E08E09E10E11E12
+        E13E14E15E16E17E18E19E20E21E22E23E24E25E26E27E28E29
+        E30C01C02C03C04C05C06C07C08C09C10C11C12C13C14C15C16
+        C17C18C19C20C21C22C23C24C25C26C27C28C29C30C31C32C33
+        C34C35J01J02J03I01I02I03I04I05I06I07S20S24S27S28S29
+        S33S35S37S38  0  0  0  0  0  0  0  0  0  0  0  0  0
++         0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0  0
%c M  cc GPS ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc
%c cc cc ccc ccc cccc cccc cccc cccc ccccc ccccc ccccc ccccc
%f  1.2500000  1.025000000  0.00000000000  0.000000000000000
%i    0    0    0    0      0      0      0      0         0
/* Note: This is a simulated file, meant to illustrate what an SP3-d header
*  2013  4  3  0  0  0.00000000
PG01   5783.206741 -18133.044484 -18510.756016     12.734450
PG02 -22412.401440  13712.162332    528.367722    425.364822
PS28   5169.591020  41849.037979     17.421140      0.170452
*  2013  4  3  0 15  0.00000000
PG01      0.00000       0.000000      0.000000      0.000000
PG02 -22399.401440  13799.162332   1599.367722    425.400822
EOF
"""


def test_specification_example(tmp_path: Path) -> None:
    path = _write(tmp_path, SP3D_SPEC_EXAMPLE, "spec.sp3")
    with pytest.raises(InputError, match=r"140 satellites \(G01, G02, .*, ...\)"):
        read_sp3(path)
    with pytest.raises(InputError, match="G01: 1 good position records of 2"):
        read_sp3(path, "G01")  # the 00:15 record is the format's "bad or absent" zero
    sp3 = read_sp3(path, "G02")
    assert (sp3.coordinate_system, sp3.time_system, sp3.interval_s) == ("WGS84", "GPS", 900.0)
    # 2013-04-03 00:00 GPS is 2013-04-02 23:59:44 UTC (TAI - UTC = 35 s in 2013)
    t = time_from_utc(np.array(["2013-04-02T23:59:44"], dtype="datetime64[ns]"))
    r_gcrs, ok = sp3_position_gcrs_m(sp3, t)
    r_itrs_km = itrs.rotation_at(t)[:, :, 0] @ r_gcrs[0] / 1e3
    assert ok.all()
    np.testing.assert_allclose(r_itrs_km, [-22412.401440, 13712.162332, 528.367722], atol=1e-9)
