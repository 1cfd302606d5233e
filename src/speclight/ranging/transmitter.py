"""Where a ground laser transmitter is seen from the target: range, elevation, body direction.

A transmitter may stand elsewhere than the receiver (bistatic ranging); its own topocentric
range and elevation (for the beam footprint and the uplink atmosphere) and its direction in the
target's body frame (the light direction of the render) come from the target's GCRS position
and the body-to-GCRS attitude quaternion, exactly as the receiver's do.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight import orbit
from speclight.attitude.body_frame import to_body
from speclight.orbit.frames import TimeLike

F64 = NDArray[np.float64]


@dataclass
class TransmitterGeometry:
    """Per-epoch geometry of one transmitter.

    Attributes
    ----------
    range_m
        (N,) transmitter-to-target distance [m].
    elevation_deg
        (N,) geometric elevation of the target above the transmitter's horizon [deg].
    direction_body
        (N, 3) unit vector from the target to the transmitter, body frame [1].
    """

    range_m: F64
    elevation_deg: F64
    direction_body: F64


def transmitter_geometry(
    site: orbit.Site, t: TimeLike, r_target_gcrs_m: F64, quaternion_body_to_gcrs: F64
) -> TransmitterGeometry:
    """Range, elevation and body-frame direction of a transmitter at ``site``.

    Parameters
    ----------
    site
        Transmitter site on the WGS84 ellipsoid.
    t
        Epochs (N), skyfield ``Time`` or UTC ``datetime64``.
    r_target_gcrs_m
        (N, 3) geocentric target position [m] (NaN rows stay NaN).
    quaternion_body_to_gcrs
        (N, 4) attitude, scalar first.

    Returns
    -------
    TransmitterGeometry
    """
    from speclight.orbit.frames import earth_orientation

    eo = earth_orientation(t)
    topo = orbit.topocentric(site, r_target_gcrs_m, t, orientation=eo)
    to_site = orbit.site_position_gcrs_m(site, t, orientation=eo) - r_target_gcrs_m
    norm = np.linalg.norm(to_site, axis=1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = np.where(norm > 0, to_site / norm, np.nan)
    return TransmitterGeometry(
        range_m=np.asarray(topo.range_m, dtype=float),
        elevation_deg=np.asarray(topo.elevation_deg, dtype=float),
        direction_body=to_body(quaternion_body_to_gcrs, unit),
    )
