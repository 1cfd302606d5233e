"""Rendering one chunk of a reflectivity map: Sun intensity, unit count rates, laser offsets.

Used by :func:`speclight.maps.writer.reflectivity_map_run.reflectivity_map`; conventions in
:mod:`speclight.maps.map_geometry`.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight import instrument
from speclight.maps.map_geometry import sun_observer
from speclight.scenario import LoadedScenario

F64 = NDArray[np.float64]


def render_chunk(
    loaded: LoadedScenario,
    target: Any,
    session: Any,
    dirs: F64,
    geoms: list[tuple[int, int, float, float]],
    shapes: dict[str, int],
    wl: F64,
    solar: F64,
    kernel: Any,
    k: int,
    workers: int = 1,
) -> tuple[F64, F64]:
    """Intensity (n, P, R, L) and unit count rates (n, P, R, B) of one chunk of directions.

    Parameters
    ----------
    loaded
        The scenario.
    target, session
        The built target and the render session (kept per worker).
    dirs
        The chunk's phase-vector directions (n, 3), body frame.
    geoms
        (phase index, roll index, phase [rad], roll [rad]) rendered per direction.
    shapes
        The store's sizes (:mod:`speclight.maps.map_format`).
    wl
        The wavelength grid [nm] (L,).
    solar
        The Sun's spectral irradiance at 1 AU [W m-2 nm-1] (L,).
    kernel
        The instrument response (optics, QE, bands) of ``simulate``.
    k
        The chunk's index (for messages).
    workers
        Processes of the numpy ray caster (Dr.Jit variants ignore it).
    """
    from speclight.render import render_intensity

    sc = loaded.scenario
    n = len(dirs)
    p = np.repeat(dirs, len(geoms), axis=0)
    a = np.tile([g[2] for g in geoms], n)
    r = np.tile([g[3] for g in geoms], n)
    sun, obs = sun_observer(p, a, r)
    result = render_intensity(
        target,
        sun,
        obs,
        solar,
        wl,
        mode=session.mode,
        resolution_px=sc.render.resolution_px,
        samples_per_pixel=sc.render.samples_per_pixel,
        seed=(sc.render.seed + k) % 2**32,  # each chunk its own Monte Carlo samples
        variant=sc.render.variant,
        workers=workers,
        solar_disk=sc.illumination.solar_disk,
        session=session,
    )
    rows = result.intensity_W_sr_nm.reshape(n, len(geoms), wl.size)
    inten = np.empty((n, shapes["phase"], shapes["roll"], wl.size))
    for g, (j, kk, angle, _) in enumerate(geoms):
        if angle == 0:
            inten[:, j, :, :] = rows[:, g, None, :]
        else:
            inten[:, j, kk, :] = rows[:, g, :]
    rows_all = inten.reshape(-1, wl.size)
    unit = np.ones(len(rows_all))  # range 1 m, area 1 m2, transmission 1
    flux = instrument.spectral_flux_W_nm(rows_all, np.ones_like(rows_all), 1.0, unit)
    ones = np.ones(wl.size)
    rate = instrument.count_rate_per_s(
        flux, wl, kernel.optics, ones, kernel.band_response * kernel.qe
    )
    return inten, rate.reshape(n, shapes["phase"], shapes["roll"], -1)


def coaxial_returns(
    target: Any,
    session: Any,
    dirs: F64,
    wl: F64,
    loaded: LoadedScenario,
    kernel: Any,
    edges_m: F64,
) -> tuple[F64, F64]:
    """A coaxial laser's returns: mean offsets (n, L) [m] and band histograms (n, B, bins).

    ``speclight.render.laser_returns`` (single scattering, the centre of mass at the body
    origin as in ``simulate``) for a laser of spectral irradiance 1 W m-2 nm-1 on every
    wavelength bin along each direction:

    * the mean one-way range offset per wavelength bin, the intensity-weighted mean of each
      pixel's offset ``-(p - c) . o`` (negative: in front of the centre of mass; exact, from
      the first moment, not from the bins), so that a laser line at any wavelength of the grid
      reads its bin; NaN where nothing returns;
    * the histogram over the range bins ``edges_m`` of the detected photo-electrons per
      second per band, carried to the bands as ``simulate`` does
      (:func:`speclight.ranging.link.downlink_conversion` and ``band_histograms``) for a
      range of 1 m, an aperture of 1 m^2 and no atmosphere (transmission 1), with the
      scenario's optics, QE and bands; (n, 0, bins) without bands.

    Parameters
    ----------
    target, session
        The built target and the render session.
    dirs
        The phase-vector directions (n, 3), body frame (the laser and the observer along it).
    wl
        The wavelength grid [nm] (L,).
    loaded
        The scenario.
    kernel
        The instrument response (optics, QE, bands).
    edges_m
        The range bin edges [m] (bins + 1,).
    """
    from speclight.instrument.photometry import photon_kernel
    from speclight.ranging import link
    from speclight.render import LaserLight, render_laser_returns

    n = len(dirs)
    light = LaserLight(dirs, np.arange(wl.size), np.ones((n, wl.size)))
    returns = render_laser_returns(
        target,
        dirs,
        [light],
        wl,
        resolution_px=loaded.scenario.render.resolution_px,
        bin_edges_m=edges_m,
        session=session,
    )
    total = returns.intensity_W_sr_nm(0)
    with np.errstate(invalid="ignore", divide="ignore"):
        offset = np.where(total > 0, returns.moment_m[0] / total, np.nan)
    if not kernel.band_names:
        return offset, np.zeros((n, 0, len(edges_m) - 1))
    photons = photon_kernel(wl, kernel.optics, np.ones(wl.size), kernel.band_response * kernel.qe)
    conversion = link.downlink_conversion(
        np.ones((n, wl.size)), np.ones(n, dtype=bool), np.ones(n), 1.0, photons
    )
    return offset, link.band_histograms(returns.histogram[0], conversion)
