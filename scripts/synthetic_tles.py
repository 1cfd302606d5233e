"""Synthetic two-line element sets for the built-in examples (starlink-*, gnss-*, geo-*).

No real element set of these satellites is shipped with speclight, so the examples fly
synthetic orbits with the elements below (SGP4 mean elements, no drag), written as TLEs with
sgp4's exporter (``Satrec.sgp4init`` then ``sgp4.exporter.export_tle``: checksums included).
They are labelled synthetic in the examples; the elements were chosen so that each example
has a sunlit pass above its site's horizon while the site is dark.

Run ``python scripts/synthetic_tles.py`` to print them.
"""

from __future__ import annotations

from dataclasses import dataclass
from datetime import UTC, datetime

import numpy as np
from sgp4.api import WGS72, Satrec
from sgp4.exporter import export_tle

EARTH_MU_KM3_S2 = 398600.8  # WGS72, as SGP4
EARTH_RADIUS_KM = 6378.135


@dataclass(frozen=True)
class Elements:
    """Mean elements of a circular-ish orbit (angles in degrees, altitude over 6378.135 km)."""

    name: str
    norad_id: int
    epoch_utc: str
    altitude_km: float
    inclination_deg: float
    raan_deg: float
    eccentricity: float
    arg_perigee_deg: float
    mean_anomaly_deg: float


def mean_motion_rev_day(altitude_km: float) -> float:
    """Keplerian mean motion [rev/day] of a circular orbit ``altitude_km`` above 6378.135 km."""
    a = EARTH_RADIUS_KM + altitude_km
    return float(np.sqrt(EARTH_MU_KM3_S2 / a**3) * 86400.0 / (2 * np.pi))


def make_tle(e: Elements) -> tuple[str, str, str]:
    """(name line, line 1, line 2) of elements ``e``."""
    t = datetime.fromisoformat(e.epoch_utc.replace("Z", "+00:00")).astimezone(UTC)
    epoch_1949 = (t - datetime(1949, 12, 31, tzinfo=UTC)).total_seconds() / 86400.0
    sat = Satrec()
    sat.sgp4init(
        WGS72,
        "i",
        e.norad_id,
        epoch_1949,
        0.0,  # bstar: no drag
        0.0,
        0.0,
        e.eccentricity,
        np.radians(e.arg_perigee_deg),
        np.radians(e.inclination_deg),
        np.radians(e.mean_anomaly_deg),
        mean_motion_rev_day(e.altitude_km) * 2 * np.pi / 1440.0,  # rad/min
        np.radians(e.raan_deg),
    )
    line1, line2 = export_tle(sat)
    return f"{e.name} (SYNTHETIC)", line1, line2


#: The examples' orbits. starlink-v1.5: a Starlink shell-1-like orbit (550 km, 53 deg) passing
#: near the zenith of Cerro Pachon in evening twilight; gnss-meo: a GPS-like orbit (20,180 km,
#: 55 deg) above Stuttgart for two hours of an October night; geo-arrays: a geostationary
#: orbit over 10.3 deg E (south of Stuttgart at 34 deg elevation) outside eclipse season;
#: starlink-v2-mini: a Starlink V2-mini-like orbit (530 km, 43 deg, a second-generation shell)
#: passing near the zenith of La Palma in evening twilight.
SYNTHETIC: tuple[Elements, ...] = (
    Elements("STARLINK-LIKE", 99901, "2024-03-20T12:00:00Z", 550.0, 53.0, 264.0, 1e-4, 90.0, 300.0),
    Elements("GPS-LIKE", 99902, "2024-10-15T00:00:00Z", 20180.0, 55.0, 255.0, 5e-3, 0.0, 180.0),
    Elements("GEO-LIKE", 99903, "2024-10-15T00:00:00Z", 35786.0, 0.05, 0.0, 2e-4, 0.0, 32.0),
    Elements(
        "STARLINK-V2-MINI-LIKE",
        99904,
        "2024-09-15T12:00:00Z",
        530.0,
        43.0,
        250.0,
        1e-4,
        90.0,
        195.0,
    ),
)

if __name__ == "__main__":
    for el in SYNTHETIC:
        print("\n".join(make_tle(el)))
