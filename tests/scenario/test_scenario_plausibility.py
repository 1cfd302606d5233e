"""Values far outside anything flown or built are reported (PlausibilityWarning naming the
field, its value and the plausible range), not refused; the command line prints one
``notice:`` line. Ranges and their sources: speclight.plausible_ranges."""

from __future__ import annotations

import math
import re
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pytest
import yaml

from speclight.orbit.tle import checksum
from speclight.plausible_ranges import PlausibilityWarning
from speclight.scenario import example_names, load_example, parse_scenario
from speclight.scenario.builtin_examples import example_text
from speclight.target import Material, Reflectance, load_mesh

#: WGS72 as SGP4 uses it (Hoots & Roehrich 1980, Spacetrack Report No. 3; Vallado et al.
#: 2006, AIAA 2006-6753): GM [km3 s-2] and equatorial radius [km].
WGS72_GM_KM3_S2, WGS72_RADIUS_KM = 398600.8, 6378.135
#: SGP4's elements are Kozai mean elements; its semi-major axis differs from Kepler's law on
#: the TLE's mean motion by ~1.5 J2 (R/a)^2 ~ 1.6e-3 in n, ~7 km in a: 10 km tolerance.
KEPLER_VS_SGP4_KM = 10.0


def _notices(text: str) -> list[str]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        parse_scenario(text, source="s.yaml")
    return [str(w.message) for w in caught if issubclass(w.category, PlausibilityWarning)]


def _box_wing(**sections: dict) -> dict:
    d = yaml.safe_load(example_text("box-wing"))
    for section, values in sections.items():
        d[section].update(values)
    return d


def _laser(**changes: float) -> dict:
    laser = {
        "name": "slr",
        "latitude_deg": 48.78,
        "longitude_deg": 9.2,
        "altitude_m": 355.0,
        "wavelength_nm": 532.0,
        "power_w": 10.0,
        "repetition_rate_hz": 100.0,
        "divergence_arcsec": 10.0,
    }
    return {**laser, **changes}


@pytest.mark.parametrize(
    ("sections", "expected"),
    [
        # issue 22 item 6: a bus of 40,000 m (mm typed as m)
        (
            {"target": {"shape": {"builtin": "box_wing", "bus_size_m": [40000.0, 1.0, 1.5]}}},
            r"target\.shape\.bus_size_m\.0 = 40000 m is far outside .*plausible: 0\.001 to "
            r"150 m; the largest structure flown, the ISS, spans 109 m",
        ),
        (
            {"target": {"shape": {"builtin": "box_wing", "dish_depth_m": 0.0004}}},
            r"target\.shape\.dish_depth_m = 0\.0004 m .*plausible: 0\.001 to 150 m",
        ),
        (
            {"telescope": {"aperture_diameter_m": 43.0}},
            r"telescope\.aperture_diameter_m = 43 m .*plausible: 0\.01 to 40 m; .*ELT",
        ),
        (
            {"observer": {"altitude_m": 8000.0}},
            r"observer\.altitude_m = 8000 m .*plausible: -430 to 5700 m",
        ),
        (
            {"illumination": {"lasers": [_laser(power_w=2e4, repetition_rate_hz=1e4)]}},
            r"illumination\.lasers\.0\.power_w = 20000 W .*plausible: 0\.001 to 10000 W",
        ),
        (
            {"illumination": {"lasers": [_laser(repetition_rate_hz=0.5)]}},
            r"illumination\.lasers\.0: pulse energy power_w / repetition_rate_hz = 20 J .*"
            r"plausible: 1e-06 to 10 J",
        ),
        (
            {"illumination": {"lasers": [_laser(altitude_m=6000.0)]}},
            r"illumination\.lasers\.0\.altitude_m = 6000 m",
        ),
    ],
)
def test_an_implausible_value_is_named_with_its_range(sections: dict, expected: str) -> None:
    notices = _notices(yaml.safe_dump(_box_wing(**sections)))
    assert len(notices) == 1, notices
    assert re.search(expected, notices[0]), notices[0]
    assert notices[0].endswith("The run goes on as given")


def _tle_with(eccentricity_7: str, mean_motion_rev_day: float) -> str:
    lines = _box_wing()["orbit"]["tle"].strip().split("\n")
    l2 = lines[2][:26] + eccentricity_7 + lines[2][33:52] + f"{mean_motion_rev_day:11.8f}"
    l2 = l2 + lines[2][63:68]
    return "\n".join([*lines[:2], l2 + str(checksum(l2))])


def _kepler_heights_km(eccentricity: float, mean_motion_rev_day: float) -> tuple[float, float]:
    n_rad_s = mean_motion_rev_day * 2 * math.pi / 86400.0
    a_km = (WGS72_GM_KM3_S2 / n_rad_s**2) ** (1 / 3)
    return a_km * (1 - eccentricity) - WGS72_RADIUS_KM, a_km * (1 + eccentricity) - WGS72_RADIUS_KM


@pytest.mark.parametrize(
    ("ecc_7", "eccentricity", "n", "which"),
    [("0016940", 0.001694, 16.9, "perigee"), ("8000000", 0.8, 0.08, "apogee")],
)
def test_an_orbit_below_the_karman_line_or_beyond_the_moon(ecc_7, eccentricity, n, which):
    d = _box_wing()
    d["orbit"] = {"tle": _tle_with(ecc_7, n)}
    notices = _notices(yaml.safe_dump(d))
    assert len(notices) == 1, notices
    found = re.search(rf"orbit\.tle \({which} height\) = ([0-9.e+]+) m", notices[0])
    assert found, notices[0]
    perigee_km, apogee_km = _kepler_heights_km(eccentricity, n)
    expected_km = perigee_km if which == "perigee" else apogee_km
    assert float(found[1]) / 1e3 == pytest.approx(expected_km, abs=KEPLER_VS_SGP4_KM)


@pytest.mark.parametrize("name", example_names())
def test_the_built_in_examples_are_plausible(name: str) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlausibilityWarning)
        load_example(name)


def test_a_mesh_is_checked_when_read(tmp_path: Path) -> None:
    # a 0.4-unit cube in a file written in kilometres: 400 m across its faces
    corners = np.array([[x, y, z] for x in (0, 0.4) for y in (0, 0.4) for z in (0, 0.4)])
    faces = [(1, 2, 4, 3), (5, 7, 8, 6), (1, 5, 6, 2), (3, 4, 8, 7), (1, 3, 7, 5), (2, 6, 8, 4)]
    text = "".join(f"v {x} {y} {z}\n" for x, y, z in corners)
    text += "".join("f " + " ".join(map(str, f)) + "\n" for f in faces)
    (tmp_path / "km.obj").write_text(text)
    white = Material("w", "lambertian", Reflectance.constant(1.0))
    with pytest.warns(PlausibilityWarning) as caught:
        load_mesh(tmp_path / "km.obj", white, scale_m_per_unit=1000.0)
    diameter_m = 400.0 * math.sqrt(3)  # the cube's space diagonal
    message = str(caught[0].message)
    assert message.startswith(
        "target.shape.mesh_file (its bounding diameter with scale_m_per_unit = 1000) = "
        f"{diameter_m:g} m is far outside"
    ), message


def test_the_command_line_prints_one_notice_and_runs(tmp_path: Path) -> None:
    d = _box_wing(telescope={"aperture_diameter_m": 43.0}, time={"step_s": 600.0})
    d.pop("target")  # geometry only: fast
    scenario = tmp_path / "s.yaml"
    scenario.write_text(yaml.safe_dump(d))
    code = (
        "import sys\nfrom speclight.cli import main\n"
        f"sys.argv = ['speclight', 'simulate', {str(scenario)!r}, '-o', "
        f"{str(tmp_path / 'o.nc')!r}, '-q']\nmain()\n"
    )
    run = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    notices = [line for line in run.stderr.splitlines() if "aperture_diameter_m" in line]
    assert len(notices) == 1 and notices[0].startswith(
        "notice: telescope.aperture_diameter_m = 43 m is far outside"
    ), run.stderr
    assert (tmp_path / "o.nc").is_file()
