"""Light models of the tumbling fit: body-frame Sun and observer directions to brightness.

The torque-free fit (:mod:`.tumbling`, :mod:`.tumbling_search`) asks one thing of the body:
its brightness for (N, 3) unit directions from the target to the Sun and to the observer in
the body frame (and the cosine of half the phase angle, which some scattering laws use).
Two implementations:

* :class:`ConvexLight`: the convex model of an EGI (:func:`.convex_model.facet_brightness`):
  every facet facing both the Sun and the observer is lit and seen, no shadows;
* :class:`MapLight`: a reflectivity map (:mod:`speclight.maps`: the target rendered by
  speclight for many body-frame geometries, so with the shadows its parts cast on each
  other), interpolated by :meth:`speclight.maps.map_lookup.ReflectivityMap.intensity_1au`
  (bilinear on the HEALPix sphere, linear in phase angle and roll), one channel: the mean
  band reflectance factor [m2 sr-1] the shape input fits (:func:`band_map_light`).

:func:`tabulated_map` tabulates any light model (or a render) at a map's nodes, so that a
map can be built in memory without a Zarr store (the tests build the rendered box-wing's).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from speclight.estimate.shape.convex_model import facet_brightness
from speclight.estimate.shape.scattering import ScatteringLaw
from speclight.maps.map_geometry import healpix_directions, sun_observer
from speclight.maps.map_lookup import MapHeader, ReflectivityMap

F64 = NDArray[np.float64]


class LightModel(Protocol):
    """Brightness (N,) of the body for body-frame unit directions ``sun_body`` and
    ``observer_body`` (N, 3) from the target, and ``cos_half_phase`` (N,) [1]."""

    def __call__(self, sun_body: F64, observer_body: F64, cos_half_phase: F64) -> F64: ...


@dataclass(frozen=True)
class ConvexLight:
    """The convex model of an EGI: facet ``normals`` (F, 3), ``areas`` (F,) [m2 or 1] and
    the scattering ``law`` (:func:`.convex_model.facet_brightness`; no shadows)."""

    normals: F64
    areas: F64
    law: ScatteringLaw

    def __call__(self, sun_body: F64, observer_body: F64, cos_half_phase: F64) -> F64:
        return facet_brightness(
            sun_body, observer_body, self.normals, self.areas, self.law, cos_half_phase
        )


@dataclass(frozen=True)
class MapLight:
    """A one-channel reflectivity map ``rmap`` (intensity (D, P, R, 1)) as the light model;
    the brightness is the interpolated value, 0 where the geometry has no phase vector (phase
    angle 180 deg: nothing is seen lit)."""

    rmap: ReflectivityMap

    def __call__(self, sun_body: F64, observer_body: F64, cos_half_phase: F64) -> F64:
        values = self.rmap.intensity_1au(sun_body, observer_body)[:, 0]
        return np.asarray(np.nan_to_num(values, nan=0.0))


def one_channel(rmap: ReflectivityMap, weights: F64) -> MapLight:
    """The light model of ``rmap``'s channels (L) combined with ``weights`` (L,) [1] (e.g. a
    band mean): the interpolation is linear, so combining before equals combining after."""
    values = np.tensordot(rmap.intensity_W_sr_nm, np.asarray(weights, float), axes=([3], [0]))
    return MapLight(
        ReflectivityMap(rmap.header, rmap.direction_body, values[..., None].astype(np.float32))
    )


def band_map_light(
    path: str | Path, band_names: list[str], response: F64, wavelength_nm: F64
) -> MapLight:
    """The mean band reflectance factor [m2 sr-1] of a map's ``count_rate`` over the
    ``band_names`` (the shape input's, :class:`.shape_inputs.ShapeInput`), as the shape
    input turns rates into factors (eq. 5 of Nussbaum et al. 2022,
    :func:`speclight.instrument.reflectance_factor_m2_sr`): the map's rates are for a range
    of 1 m, an aperture of 1 m2, the Sun at 1 AU and no atmosphere; ``response`` (B, L) the
    bands' responses (optics and QE included) on the map's ``wavelength_nm`` (L,)."""
    from speclight.errors import InputError
    from speclight.estimate.spin_axis.spin_axis_lookup import load_band_map
    from speclight.illumination import solar_irradiance_W_m2_nm
    from speclight.instrument import reflectance_factor_m2_sr

    bmap = load_band_map(path)
    missing = [b for b in band_names if b not in bmap.header.band_names]
    wl = np.asarray(wavelength_nm, float)
    same_grid = wl.shape == bmap.header.wavelength_nm.shape and np.allclose(
        wl, bmap.header.wavelength_nm, atol=1e-9
    )
    if missing or not same_grid:
        raise InputError(
            f"the map {path} has the bands {bmap.header.band_names} on "
            f"{bmap.header.wavelength_nm.size} wavelength bins; the light curves need the "
            f"bands {band_names} on the scenario's {wl.size} bins: make the map from the "
            "same scenario",
            field="map_path",
        )
    ones = np.ones(wl.size)
    per_rate = reflectance_factor_m2_sr(
        np.ones((1, len(band_names))),
        np.ones(1),
        1.0,
        solar_irradiance_W_m2_nm(wl)[None, :],
        wl,
        ones,
        ones,
        response,
    )[0]  # the factor [m2 sr-1] of a rate of 1 s-1 in each band
    weights = np.zeros(len(bmap.header.band_names))
    for b, name in enumerate(band_names):
        weights[bmap.header.band_names.index(name)] = per_rate[b] / len(band_names)
    return one_channel(bmap, weights)


def tabulated_map(
    light: Callable[[F64, F64], F64],
    *,
    nside: int,
    phase_angle_deg: F64,
    n_rolls: int,
) -> ReflectivityMap:
    """A one-channel map in memory: ``light(sun_body, observer_body)`` (N,) evaluated at
    every node (HEALPix ``nside`` phase vectors x ``phase_angle_deg`` x ``n_rolls`` rolls,
    the conventions of :mod:`speclight.maps.map_geometry`), in one call."""
    p = healpix_directions(nside)
    a = np.deg2rad(np.asarray(phase_angle_deg, float))
    r = 2 * np.pi * np.arange(n_rolls) / n_rolls
    pp, aa, rr = np.meshgrid(np.arange(len(p)), a, r, indexing="ij")
    sun, obs = sun_observer(p[pp.ravel()], aa.ravel(), rr.ravel())
    values = np.asarray(light(sun, obs), float).reshape(len(p), a.size, n_rolls, 1)
    header = MapHeader(
        path=Path("<memory>"),
        nside=nside,
        wavelength_nm=np.zeros(1),
        band_names=[],
        phase_angle_deg=np.asarray(phase_angle_deg, float),
        roll_deg=np.degrees(r),
        attrs={},
    )
    return ReflectivityMap(header, p, values.astype(np.float32))
