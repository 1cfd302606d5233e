"""Per-epoch observation geometry: what the pipeline's later stages need from the orbit."""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass, fields
from typing import Literal

import numpy as np
from numpy.typing import NDArray

from speclight.orbit.frames import EarthOrientation, TimeLike, as_time, earth_orientation
from speclight.orbit.observer import Site, phase_angle_deg, site_position_gcrs_m, topocentric
from speclight.orbit.shadow import sunlit_fraction
from speclight.orbit.sun import sun_position_gcrs_m


@dataclass(frozen=True)
class ObservationGeometry:
    """Per-epoch geometry (N epochs); attribute or mapping access (``g.range_m``,
    ``g["range_m"]``).

    Attributes
    ----------
    r_sun_gcrs_m, r_site_gcrs_m
        (N, 3) geocentric apparent Sun and observer positions [m].
    sun_distance_m
        (N,) target-to-Sun distance [m].
    sunlit_fraction
        (N,) visible fraction of the solar disk [1].
    range_m, azimuth_deg, elevation_deg
        (N,) topocentric coordinates [m, deg, deg].
    phase_angle_deg
        (N,) Sun-target-observer angle [deg].
    sun_direction_gcrs, observer_direction_gcrs
        (N, 3) unit vectors from the target to the Sun and to the observer, GCRS axes.
    sun_elevation_deg
        (N,) elevation of the Sun's centre above the site's horizon [deg], geometric (no
        refraction, as the twilight limits -6, -12, -18 deg are defined), from the apparent
        geocentric Sun (the diurnal aberration, <= 0.32", is left out).
    """

    r_sun_gcrs_m: NDArray[np.float64]
    r_site_gcrs_m: NDArray[np.float64]
    sun_distance_m: NDArray[np.float64]
    sunlit_fraction: NDArray[np.float64]
    range_m: NDArray[np.float64]
    azimuth_deg: NDArray[np.float64]
    elevation_deg: NDArray[np.float64]
    phase_angle_deg: NDArray[np.float64]
    sun_direction_gcrs: NDArray[np.float64]
    observer_direction_gcrs: NDArray[np.float64]
    sun_elevation_deg: NDArray[np.float64]

    def __getitem__(self, key: str) -> NDArray[np.float64]:
        if key not in self.keys():
            raise KeyError(key)
        value: NDArray[np.float64] = getattr(self, key)
        return value

    def keys(self) -> list[str]:
        """Names of the arrays."""
        return [f.name for f in fields(self)]

    def __iter__(self) -> Iterator[str]:
        return iter(self.keys())

    def as_dict(self) -> dict[str, NDArray[np.float64]]:
        """The arrays as a plain dict."""
        return {k: getattr(self, k) for k in self.keys()}


def _unit(v: NDArray[np.float64]) -> NDArray[np.float64]:
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def observation_geometry(
    t: TimeLike,
    r_target_gcrs_m: NDArray[np.float64],
    site: Site,
    refraction: bool = False,
    temperature_C: float = 10.0,
    pressure_mbar: float = 1010.0,
    earth_model: Literal["wgs84", "sphere"] = "wgs84",
    orientation: EarthOrientation | None = None,
) -> ObservationGeometry:
    """Sun, site, shadow and topocentric geometry for a target trajectory.

    Parameters
    ----------
    t
        Epochs (N), skyfield ``Time`` or UTC ``datetime64``.
    r_target_gcrs_m
        (N, 3) target position [m] (NaN rows allowed; they propagate as NaN).
    site
        Observer.
    refraction, temperature_C, pressure_mbar
        See :func:`speclight.orbit.observer.topocentric`.
    earth_model
        Shadow model, see :func:`speclight.orbit.shadow.sunlit_fraction`.
    orientation
        Precomputed Earth orientation for ``t`` (computed if omitted).

    Returns
    -------
    ObservationGeometry
        ``r_sun_gcrs_m`` (N,3), ``r_site_gcrs_m`` (N,3), ``sun_distance_m`` (N,) from the
        target, ``sunlit_fraction`` (N,), ``range_m``, ``azimuth_deg``, ``elevation_deg``,
        ``phase_angle_deg`` (N,), unit vectors ``sun_direction_gcrs`` (target to Sun)
        and ``observer_direction_gcrs`` (target to observer), (N,3), and the Sun's elevation
        at the site ``sun_elevation_deg`` (N,).
    """
    t = as_time(t)
    eo = orientation if orientation is not None else earth_orientation(t)
    r = np.array(r_target_gcrs_m, dtype=np.float64, ndmin=2)
    r_sun = sun_position_gcrs_m(t)
    r_site = site_position_gcrs_m(site, t, orientation=eo)
    topo = topocentric(site, r, t, refraction, temperature_C, pressure_mbar, orientation=eo)
    sun_topo = topocentric(site, r_sun, t, orientation=eo)  # geometric: no refraction
    to_sun = r_sun - r
    return ObservationGeometry(
        r_sun_gcrs_m=r_sun,
        r_site_gcrs_m=r_site,
        sun_distance_m=np.linalg.norm(to_sun, axis=1),
        sunlit_fraction=sunlit_fraction(r, r_sun, earth_model=earth_model),
        range_m=topo.range_m,
        azimuth_deg=topo.azimuth_deg,
        elevation_deg=topo.elevation_deg,
        phase_angle_deg=phase_angle_deg(r, r_sun, r_site),
        sun_direction_gcrs=_unit(to_sun),
        observer_direction_gcrs=_unit(r_site - r),
        sun_elevation_deg=sun_topo.elevation_deg,
    )
