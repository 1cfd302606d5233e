"""Laser returns from a reflectivity map (``render.mode: map``): no rendering.

The map (:mod:`speclight.maps.map_lookup`) stores, at phase angle 0, the intensity under
the Sun at 1 AU ``I(d, l)`` per body-frame direction ``d`` and wavelength bin ``l``, a coaxial
laser's mean one-way range offset ``o(d, l)`` [m] and its range histogram per band
``H(d, b, bin)`` for 1 W m-2 nm-1 on every bin (single scattering; range 1 m, aperture
1 m², no atmosphere). For each laser line (support bins ``s``, spectral irradiance at the
target ``E(n, s)`` after the uplink) and epoch ``n`` this module builds what the render of
:mod:`speclight.render.laser_returns` would return, a :class:`LaserReturns` with

* the intensity ``I1(n, s) E(n, s)``, ``I1 = I / S`` the intensity per unit irradiance
  (``S``: the solar spectrum at 1 AU the map was made with);
* the first moment ``I1 E o``: ``I1`` and ``I1 o`` are interpolated bilinearly on the HEALPix
  sphere (the lookup of the Sun's light) and the offset is their ratio, so the band offsets
  the ranging stage takes from the moments are exact up to the interpolation;
* the histogram ``I1 E h(n, bin)``: the shape ``h`` is the interpolated stored histogram of
  one band, normalised to unit sum: the band whose photon kernel holds the largest fraction
  of its total in the line's bin (a narrow band around the line). The stored histogram mixes
  the wavelengths of that band, so the shape is **exact for a target whose range
  distribution of the returns is the same at every wavelength** (grey surfaces, or one
  material whose BRDF's angular shape does not depend on wavelength, e.g. Lambertian) and
  an approximation otherwise (the band's mixture of materials instead of the line's); its
  sum is always the line's intensity.

The lookup direction is the bisector ``h = normalize(l + o)`` of the laser and observer
directions. A coaxial laser (``l`` within :data:`~speclight.render.laser_returns.COAXIAL_RAD`
of ``o``) reads the phase-0 slice at ``o``: the render's coaxial returns up to the
interpolation. A bistatic laser (phase angle ``a`` > 0 between laser and telescope) takes
its intensity from the map at its phase angle and roll (:meth:`ReflectivityMap.intensity_1au`,
the map must hold phase angles beyond 0: checked at load). A pixel ``p`` returns at
``-(p . (l + o)) / 2 = -cos(a/2) (p . h)``, so its offset and histogram are the coaxial
ones at ``h`` scaled by ``cos(a/2)`` (the histogram rebinned by linear splitting, which keeps
its mean); this is exact where the same pixels are seen and lit with the same weights as in
the coaxial view along ``h``, an approximation of order ``a`` otherwise (0.996 for the
10 deg of a station 200 km away).

The range bins are the map's (those ``simulate`` uses in single mode for the map's target:
:func:`speclight.ranging.bins.range_bin_edges_m`); a scenario whose target gives other bins
(another target than the map's) is refused, not rebinned.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.illumination import solar_irradiance_W_m2_nm
from speclight.instrument.photometry import photon_kernel
from speclight.maps.map_lookup import FIELD, ReflectivityMap, healpix_weights, load_map
from speclight.ranging.bins import range_bin_edges_m
from speclight.render.laser_returns import COAXIAL_RAD, LaserLight, LaserReturns
from speclight.scenario import LoadedScenario
from speclight.simulation.radiometry import instrument_response
from speclight.simulation.reflection import build_target

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


def scenario_map_returns(
    loaded: LoadedScenario, observer_body: F64, lights: list[LaserLight], wavelength_nm: F64
) -> LaserReturns:
    """The lasers' returns of a map-mode scenario from its map (module docstring).

    ``observer_body`` (N, 3): directions to the receiver, body frame (NaN: not observed).
    """
    sc = loaded.scenario
    assert sc.render.map_file is not None
    the_map = load_map(loaded.resolve(sc.render.map_file))
    check_range_bins(loaded, the_map)
    wl = np.asarray(wavelength_nm, dtype=float)
    k = instrument_response(loaded, wl, np.zeros((1, wl.size)), np.ones((1, wl.size)), np.ones(1))
    kernel = photon_kernel(wl, k.optics, np.ones(wl.size), k.band_response * k.qe)
    return map_laser_returns(the_map, observer_body, lights, wl, kernel)


def check_range_bins(loaded: LoadedScenario, the_map: ReflectivityMap) -> None:
    """Refuse a map without coaxial returns, or whose range bins are not the scenario
    target's (single-bounce bins about the body origin, as ``simulate`` in single mode)."""
    edges = the_map.range_bin_edges_m
    if edges is None or the_map.range_offset_m is None or the_map.range_histogram_per_s is None:
        raise InputError(
            f"the map {the_map.header.path} has no range_offset/range_histogram: make it "
            "with --phase-angles-deg 0,... from a scenario with lasers and bands",
            field="illumination.lasers",
        )
    if loaded.scenario.target is None:
        return
    own = range_bin_edges_m(build_target(loaded), np.zeros(3))
    if own.shape != edges.shape or not np.allclose(own, edges, rtol=1e-9, atol=1e-12):
        raise InputError(
            f"the map {the_map.header.path} has range bins {edges[0]:.4g}..{edges[-1]:.4g} m "
            f"({edges.size - 1} bins), the scenario's target {own[0]:.4g}..{own[-1]:.4g} m "
            f"({own.size - 1} bins): the map was made for another target; use the map's "
            "target or make a map of this one",
            field=FIELD,
        )


def shape_bands(kernel: F64, wavelength_index: I64) -> I64:
    """For each wavelength bin, the band whose photon kernel (B, L) holds the largest
    fraction of its total there (the band whose histogram stands for a line in that bin)."""
    total = kernel.sum(axis=1, keepdims=True)
    frac = np.where(total > 0, kernel / np.where(total > 0, total, 1.0), 0.0)
    return np.asarray(np.argmax(frac[:, wavelength_index], axis=0), dtype=np.int64)


def compress_offsets(shape: F64, factor: F64, edges_m: F64) -> F64:
    """Histograms (m, U, bins) over uniform bins with each bin centre ``c`` moved to
    ``factor * c`` (factor (m,)), split linearly between the two nearest bin centres."""
    m, u, nb = shape.shape
    centres = 0.5 * (edges_m[1:] + edges_m[:-1])
    width = (edges_m[-1] - edges_m[0]) / nb
    f = (factor[:, None] * centres[None, :] - centres[0]) / width  # (m, nb)
    lo = np.clip(np.floor(f), 0, nb - 1).astype(np.int64)
    t = np.clip(f - lo, 0.0, 1.0)
    hi = np.minimum(lo + 1, nb - 1)
    base = (np.arange(m)[:, None, None] * u + np.arange(u)[None, :, None]) * nb
    size = m * u * nb
    out = np.bincount((base + lo[:, None, :]).ravel(), (shape * (1 - t)[:, None, :]).ravel(), size)
    out += np.bincount((base + hi[:, None, :]).ravel(), (shape * t[:, None, :]).ravel(), size)
    return np.asarray(out, dtype=float).reshape(m, u, nb)


def map_laser_returns(
    the_map: ReflectivityMap,
    observer_body: F64,
    lights: list[LaserLight],
    wavelength_nm: F64,
    kernel: F64,
) -> LaserReturns:
    """Per-laser intensity histograms and first moments from a map (module docstring).

    Parameters
    ----------
    the_map
        A map with phase angle 0, ``range_offset`` and ``range_histogram``.
    observer_body
        (N, 3) unit vectors from the target to the receiver, body frame (NaN: not observed).
    lights
        The lasers as for the render (:class:`LaserLight`).
    wavelength_nm
        (L,) the map's grid [nm].
    kernel
        (B, L) photon kernel of the bands (chooses each line's histogram band).
    """
    hist_map, offset_map = the_map.range_histogram_per_s, the_map.range_offset_m
    edges = the_map.range_bin_edges_m
    assert hist_map is not None and offset_map is not None and edges is not None
    j0 = int(np.flatnonzero(np.isclose(the_map.header.phase_angle_deg, 0.0))[0])
    inten0 = the_map.intensity_W_sr_nm[:, j0, 0, :]  # (D, L): phase 0, every roll alike
    solar = solar_irradiance_W_m2_nm(np.asarray(wavelength_nm, dtype=float), 1.0)
    obs = np.asarray(observer_body, dtype=float)
    n, nb = len(obs), len(edges) - 1
    rendered = np.zeros(n, dtype=bool)
    histograms, moments = [], []
    for light in lights:
        sup = np.asarray(light.support, dtype=np.int64)
        h_k, m_k = np.zeros((n, sup.size, nb)), np.zeros((n, sup.size))
        lit = (
            np.all(np.isfinite(light.direction_body), axis=1)
            & np.any(light.irradiance_W_m2_nm > 0, axis=1)
            & np.all(np.isfinite(obs), axis=1)
        )
        idx = np.flatnonzero(lit)
        if idx.size:
            m_k[idx], h_k[idx] = _one_light(
                the_map, inten0, offset_map, hist_map, edges, solar, kernel, obs[idx], light, idx
            )
            rendered[idx] = True
        histograms.append(h_k)
        moments.append(m_k)
    return LaserReturns(histograms, moments, np.asarray(edges, dtype=float).copy(), rendered)


def _one_light(
    the_map: ReflectivityMap,
    inten0: NDArray[np.float32],
    offset_map: NDArray[np.float32],
    hist_map: NDArray[np.float32],
    edges: F64,
    solar: F64,
    kernel: F64,
    obs: F64,
    light: LaserLight,
    idx: I64,
) -> tuple[F64, F64]:
    """First moments (m, S) and histograms (m, S, bins) of one laser's lit epochs."""
    sup = np.asarray(light.support, dtype=np.int64)
    las = light.direction_body[idx]
    o = obs / np.linalg.norm(obs, axis=1)[:, None]
    la = las / np.linalg.norm(las, axis=1)[:, None]
    cos_a = np.clip(np.sum(la * o, axis=1), -1.0, 1.0)
    half = np.sqrt(0.5 * (1.0 + cos_a))  # cos(a / 2)
    ok, pix, w = healpix_weights(the_map.header.nside, la + o)  # the bisector
    m = len(idx)
    s1 = solar[sup]
    i1 = np.zeros((m, sup.size))
    m1 = np.zeros((m, sup.size))
    bands = shape_bands(kernel, sup)
    used, which = np.unique(bands, return_inverse=True)
    shape = np.zeros((m, used.size, len(edges) - 1))
    for i in range(4):
        rows = pix[i]
        unit = inten0[rows[:, None], sup[None, :]] / s1  # per unit irradiance
        i1[ok] += w[i][:, None] * unit
        m1[ok] += w[i][:, None] * unit * np.nan_to_num(offset_map[rows[:, None], sup[None, :]])
        shape[ok] += w[i][:, None, None] * hist_map[rows[:, None], used[None, :]]
    with np.errstate(invalid="ignore", divide="ignore"):
        offset = np.where(i1 > 0, m1 / np.where(i1 > 0, i1, 1.0), 0.0) * half[:, None]
    bistatic = cos_a < np.cos(COAXIAL_RAD)
    if np.any(bistatic):
        b = np.flatnonzero(bistatic)
        i1[b] = the_map.intensity_1au(la[b], o[b])[:, sup] / s1
        shape[b] = compress_offsets(shape[b], half[b], edges)
    inten = np.nan_to_num(i1) * light.irradiance_W_m2_nm[idx]
    total = shape.sum(axis=2, keepdims=True)
    shape = np.where(total > 0, shape / np.where(total > 0, total, 1.0), 0.0)
    per_line = shape[:, which, :]  # (m, S, bins)
    # a band that receives nothing here: the whole line in the bin of its mean offset
    empty = per_line.sum(axis=2) <= 0
    if np.any(empty):
        nb = len(edges) - 1
        width = (edges[-1] - edges[0]) / nb
        k = np.clip(((offset - edges[0]) / width).astype(np.int64), 0, nb - 1)
        r, s = np.nonzero(empty)
        per_line[r, s, k[r, s]] = 1.0
    return inten * offset, inten[:, :, None] * per_line
