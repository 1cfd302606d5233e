"""Load-time checks of lasers in ``render: {mode: map}`` (``speclight.simulation.map_ranging``).

A map-mode scenario with lasers needs a map that holds the coaxial returns: phase angle 0,
``range_offset`` and ``range_histogram`` (made by ``speclight reflectivity-map`` with
``--phase-angles-deg 0,...`` from a scenario with lasers and bands). A laser farther than
:data:`COAXIAL_BASELINE_M` from the observer lights the target at a phase angle > 0
(bistatic): its intensity is then read from the map at that phase angle, so the map must hold
phase angles beyond 0.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from speclight.errors import InputError

if TYPE_CHECKING:
    from speclight.maps.map_lookup import MapHeader
    from speclight.scenario.scenario_model import Scenario

#: A laser within this distance of the observer is coaxial for a map: its phase angle is
#: below 1 mrad (0.06 deg) for any target beyond 100 km, far below a map's direction spacing.
COAXIAL_BASELINE_M = 100.0
_REMAKE = (
    "make the map with speclight reflectivity-map --phase-angles-deg 0,... from a scenario "
    "with lasers and bands, so that it holds range_offset and range_histogram"
)


def laser_baselines_m(sc: Scenario) -> list[float]:
    """Distance [m] of each laser's site from the observer's (WGS84)."""
    from speclight.orbit import Site

    obs = Site(sc.observer.latitude_deg, sc.observer.longitude_deg, sc.observer.altitude_m)
    here = obs.position_itrs_m
    return [
        float(
            np.linalg.norm(
                Site(la.latitude_deg, la.longitude_deg, la.altitude_m).position_itrs_m - here
            )
        )
        for la in sc.illumination.lasers
    ]


def check_map_lasers(sc: Scenario, source: str, header: MapHeader) -> None:
    """Refuse lasers the map cannot serve (module docstring); nothing without lasers.
    ``source``: the scenario file, named in the messages."""
    lasers = sc.illumination.lasers
    if not lasers:
        return
    angles = header.phase_angle_deg
    listed = ", ".join(f"{a:g}" for a in angles)
    if not np.any(np.isclose(angles, 0.0)):
        raise InputError(
            f"render.mode 'map' takes the lasers' returns from the map's phase angle 0; "
            f"{header.path} has phase angles {listed} deg only: {_REMAKE}",
            source=source,
            field="illumination.lasers",
        )
    missing = [a for a in ("range_offset", "range_histogram") if a not in header.arrays]
    if missing:
        raise InputError(
            f"render.mode 'map' takes the lasers' returns from the map; {header.path} has no "
            f"{' or '.join(missing)} (made from a scenario without lasers or bands): {_REMAKE}",
            source=source,
            field="illumination.lasers",
        )
    if np.max(angles) > 0:
        return  # bistatic lasers read the map at their phase angle
    for k, base in enumerate(laser_baselines_m(sc)):
        if base > COAXIAL_BASELINE_M:
            raise InputError(
                f"laser '{lasers[k].name}' stands {base / 1e3:.3g} km from the observer "
                f"(bistatic: phase angle about {base / 1e3:.3g} km / range > 0 between laser "
                f"and telescope), and the map {header.path} has phase angle 0 only (accepted "
                f"in map mode: lasers within {COAXIAL_BASELINE_M:g} m of the observer); make "
                "the map with --phase-angles-deg 0,A,... covering the laser's phase angles, "
                "from a scenario with lasers",
                source=source,
                field=f"illumination.lasers[{k}]",
            )
