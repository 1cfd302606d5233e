"""What has been flown or built: the ranges outside which a value is most likely in a wrong
unit, and the notice that says so.

A bus of 40,000 m (millimetres typed as metres) is a valid number and a valid scenario; it
runs to magnitude -16 without a word. Values far outside anything flown or built are
therefore reported, not refused: one :class:`PlausibilityWarning` per field, naming the
field, its value and the plausible range with the object that sets it. The command line
prints it as a one-line ``notice:`` on stderr (``speclight.cli``); the run goes on as given
(a study of an unbuilt 200 m structure is allowed). Hard limits, outside which a run cannot
work at all, stay errors where they are defined (e.g.
:data:`speclight.target.mesh_io.MAX_BOUNDING_RADIUS_M`).

The ranges and their sources:

* **Sizes of a target's parts** (:data:`TARGET_SIZE_M`): up to 150 m. The largest structure
  flown, the International Space Station, is 109 m along its truss (NASA, "International
  Space Station Facts and Figures", nasa.gov). Down to 1 mm: catalogues of objects seen from
  the ground reach centimetres at best (about 10 cm in low orbit), so a part below 1 mm is
  a size in a wrong unit (metres typed as kilometres).
* **Telescope aperture** (:data:`TELESCOPE_APERTURE_M`): up to 40 m, ESO's Extremely Large
  Telescope (39.3 m, the largest under construction; the largest in use, the GTC, is
  10.4 m); down to 1 cm, below the lenses of the smallest wide-field survey cameras.
* **Laser average power** (:data:`LASER_POWER_W`): up to 10 kW: lasers ranging to debris run
  at tens of watts (1064 nm, 1 kHz, 30 W; Long et al. 2024, J. Space Technol. Appl. 4, 245),
  and 5 kW is the class proposed to push debris by photon pressure (Mason et al. 2011,
  "Orbital debris-debris collision avoidance", arXiv:1103.1690); down to 1 mW (a laser
  pointer).
* **Laser pulse energy** (``power_w / repetition_rate_hz``, :data:`LASER_PULSE_ENERGY_J`):
  1 microjoule to 10 J: satellite laser ranging fires from tens of microjoules (kHz
  systems) to about 0.1 J per pulse (lunar ranging at 20 Hz, APOLLO: Murphy et al. 2008,
  PASP 120, 20, doi:10.1086/526428).
* **Site altitude** (:data:`SITE_ALTITUDE_M`): the highest observatory, the University of
  Tokyo Atacama Observatory on Cerro Chajnantor, stands at 5,640 m; the lowest land, the
  Dead Sea shore, at -430 m.
* **Orbit** (from a TLE, at load): a perigee below 100 km (the Karman line: such an orbit
  re-enters within hours) or an apogee beyond the Moon's mean distance, 384,400 km (no
  longer an Earth orbit that SGP4 describes): :data:`PERIGEE_ALTITUDE_M`,
  :data:`APOGEE_ALTITUDE_M`.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass


class PlausibilityWarning(UserWarning):
    """A value far outside anything flown or built (most likely a wrong unit); the run goes
    on as given."""


@dataclass(frozen=True)
class PlausibleRange:
    """The range of a quantity that has been flown or built, and what sets each end.

    Attributes
    ----------
    low, high
        The ends [``unit``]; a value outside is reported.
    unit
        The unit of the quantity, for messages.
    low_reason, high_reason
        What sets each end (shown in the notice).
    hint
        The likely mistake, for the notice ("a size in mm?").
    """

    low: float
    high: float
    unit: str
    low_reason: str
    high_reason: str
    hint: str = "check its unit"


TARGET_SIZE_M = PlausibleRange(
    1e-3,
    150.0,
    "m",
    "ground sensors detect objects of centimetres at best",
    "the largest structure flown, the ISS, spans 109 m",
    "check its unit (metres; a size in mm or km?)",
)
TELESCOPE_APERTURE_M = PlausibleRange(
    0.01,
    40.0,
    "m",
    "smaller than the lens of any survey camera",
    "the largest telescope under construction, the ELT, is 39.3 m",
    "check its unit (metres; cm?)",
)
LASER_POWER_W = PlausibleRange(
    1e-3,
    1e4,
    "W",
    "below a laser pointer",
    "debris-ranging lasers run at tens of W; 5 kW is the class proposed to push debris",
    "check its unit (average power in W, not mW or the pulse energy)",
)
LASER_PULSE_ENERGY_J = PlausibleRange(
    1e-6,
    10.0,
    "J",
    "laser ranging pulses are tens of microjoules or more",
    "lunar laser ranging fires about 0.1 J",
    "check power_w (average W) and repetition_rate_hz (Hz)",
)
SITE_ALTITUDE_M = PlausibleRange(
    -430.0,
    5700.0,
    "m",
    "the lowest land, the Dead Sea shore, is at -430 m",
    "the highest observatory, on Cerro Chajnantor, is at 5,640 m",
    "check its unit (metres above the WGS84 ellipsoid)",
)
PERIGEE_ALTITUDE_M = PlausibleRange(
    100e3,
    math.inf,
    "m",
    "below the Karman line an orbit re-enters within hours",
    "",
    "check the mean motion and eccentricity",
)
APOGEE_ALTITUDE_M = PlausibleRange(
    -math.inf,
    384_400e3,
    "m",
    "",
    "beyond the Moon's mean distance, 384,400 km, it is no Earth orbit",
    "check the mean motion and eccentricity",
)


def implausibility(field: str, value: float, plausible: PlausibleRange) -> str | None:
    """The notice for ``value`` of ``field`` outside ``plausible``, or None.

    Parameters
    ----------
    field
        Dotted name of the field (``target.shape.bus_size_m.0``), for the notice.
    value
        Its value [``plausible.unit``].
    plausible
        The range.
    """
    v = float(value)
    if plausible.low <= v <= plausible.high:
        return None
    low = v < plausible.low
    bound = f">= {plausible.low:g}" if low else f"<= {plausible.high:g}"
    if math.isfinite(plausible.low) and math.isfinite(plausible.high):
        bound = f"{plausible.low:g} to {plausible.high:g}"
    reason = plausible.low_reason if low else plausible.high_reason
    return (
        f"{field} = {v:g} {plausible.unit} is far outside anything flown or built "
        f"(plausible: {bound} {plausible.unit}; {reason}): {plausible.hint}. The run goes on "
        "as given"
    )


def warn_implausible(field: str, value: float, plausible: PlausibleRange) -> bool:
    """Issue :func:`implausibility` as a :class:`PlausibilityWarning`; True if there was one.

    Python shows a warning once per message, so a scenario read again (a sweep's cases, a
    fit's trials) does not repeat it.
    """
    notice = implausibility(field, value, plausible)
    if notice is not None:
        warnings.warn(notice, PlausibilityWarning, stacklevel=2)
    return notice is not None
