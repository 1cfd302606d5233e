"""Intensity from a reflectivity map instead of a render (``render.mode: map``).

The map (a Zarr store written by ``speclight reflectivity-map``, layout in
:mod:`speclight.maps.map_format`) holds the intensity at 1 AU on HEALPix
phase-vector directions x phase angles x rolls (conventions: :mod:`.map_geometry`). An
epoch's intensity is interpolated:

* over the direction bilinearly on the HEALPix sphere (astropy-healpix
  ``bilinear_interpolation_weights``: the 4 nearest pixel centres);
* linearly in phase angle between the two stored angles around it (clamped to the first
  and last stored angle outside their range);
* linearly and periodically in roll (all rolls are equal at phase angle 0), the roll
  measured in each of the 4 pixel centres' own reference frame (``u`` projected on it), so
  that the interpolation is smooth across the poles of the roll reference.

No Mitsuba here: reading the map and interpolating is numpy and astropy-healpix only.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError
from speclight.maps.map_format import FORMAT_NAME
from speclight.maps.map_geometry import lonlat_deg, map_coordinates, roll_reference

F64 = NDArray[np.float64]
FIELD = "render.map_file"


@dataclass(frozen=True)
class MapHeader:
    """What a map covers, read without its data arrays."""

    path: Path
    nside: int
    wavelength_nm: F64
    band_names: list[str]
    phase_angle_deg: F64
    roll_deg: F64
    attrs: dict[str, Any]
    #: names of the store's arrays (``range_offset``, ``range_histogram`` where it has them)
    arrays: frozenset[str] = frozenset()


def _open_group(path: Path) -> Any:
    import zarr

    if not path.is_dir():
        raise InputError(
            f"{path} does not exist or is not a Zarr store (a folder written by "
            "speclight reflectivity-map)",
            field=FIELD,
        )
    try:
        group = zarr.open_group(str(path), mode="r")
        attrs = dict(group.attrs)
    except Exception as exc:
        raise InputError(f"cannot open {path} as a Zarr store ({exc})", field=FIELD) from None
    if attrs.get("format") != FORMAT_NAME:
        raise InputError(f"{path} is not a speclight reflectivity map", field=FIELD)
    if not attrs.get("complete", False):
        failed: Any = attrs.get("failed_chunks", {})
        why = f"{len(failed)} chunk(s) failed" if failed else "it was interrupted"
        raise InputError(
            f"{path} is an unfinished reflectivity map ({why}); rerun speclight "
            "reflectivity-map with the same parameters to complete it",
            field=FIELD,
        )
    return group


def read_header(path: str | Path) -> MapHeader:
    """The header of a complete map; :class:`InputError` if it is missing or unfinished."""
    path = Path(path)
    group = _open_group(path)
    attrs = dict(group.attrs)
    return MapHeader(
        path=path,
        nside=int(attrs["healpix_nside"]),
        wavelength_nm=np.asarray(group["wavelength"][...], dtype=float),
        band_names=[str(b) for b in attrs.get("band_names", [])],
        phase_angle_deg=np.asarray(group["phase_angle_deg"][...], dtype=float),
        roll_deg=np.asarray(group["roll_deg"][...], dtype=float),
        attrs=attrs,
        arrays=frozenset(str(k) for k in group.array_keys()),
    )


def check_map_matches(header: MapHeader, wavelength_nm: ArrayLike, band_names: list[str]) -> None:
    """Refuse a map whose wavelength grid or bands differ from the scenario's."""
    wl = np.asarray(wavelength_nm, dtype=float)
    ok = wl.shape == header.wavelength_nm.shape and np.allclose(wl, header.wavelength_nm, atol=1e-9)
    if not ok:
        have = header.wavelength_nm
        span = f"{have[0]:g}..{have[-1]:g} nm, {have.size} bins" if have.size else "empty"
        raise InputError(
            f"the map {header.path} has the wavelength grid {span}, the scenario "
            f"{wl[0]:g}..{wl[-1]:g} nm, {wl.size} bins; set spectrum as in the map's scenario",
            field="spectrum",
        )
    if list(band_names) != header.band_names:
        raise InputError(
            f"the map {header.path} has the bands {header.band_names}, the scenario "
            f"{list(band_names)}; use the map's bands",
            field="instrument.bands",
        )


@dataclass(frozen=True)
class ReflectivityMap:
    """A map loaded in memory: its header, ``intensity`` (D, P, R, L) [W sr-1 nm-1] and,
    where the map has them, the coaxial ``range_histogram`` (D, B, bins) [s-1 per bin] and
    its bin edges (bins + 1,) [m], and the coaxial ``range_offset`` (D, L) [m]."""

    header: MapHeader
    direction_body: F64
    intensity_W_sr_nm: NDArray[np.float32]
    range_histogram_per_s: NDArray[np.float32] | None = None
    range_bin_edges_m: F64 | None = None
    range_offset_m: NDArray[np.float32] | None = None

    @functools.cached_property
    def roll_frames(self) -> tuple[F64, F64]:
        """``(e_lon, e_lat)`` (D, 3): the roll reference axes of the map's directions
        (:func:`.map_geometry.roll_reference`), made once per loaded map."""
        return roll_reference(self.direction_body)

    def intensity_1au(self, sun_body: ArrayLike, observer_body: ArrayLike) -> F64:
        """Interpolated intensity (N, L) [W sr-1 nm-1] under the Sun at 1 AU.

        ``sun_body``, ``observer_body``: (N, 3) directions from the target in the body frame.
        NaN rows where the geometry has no phase vector (phase angle 180 deg, NaN inputs).
        """
        from astropy import units as u
        from astropy_healpix import bilinear_interpolation_weights

        p, a, _ = map_coordinates(sun_body, observer_body)
        n = len(p)
        out = np.full((n, self.intensity_W_sr_nm.shape[-1]), np.nan)
        ok = np.isfinite(a)
        if not np.any(ok):
            return out
        lon, lat = lonlat_deg(p[ok])
        pix, w_pix = bilinear_interpolation_weights(
            lon * u.deg, lat * u.deg, self.header.nside, order="ring"
        )
        j, w_phase = phase_angle_weights(self.header.phase_angle_deg, np.degrees(a[ok]))
        u = plane_axis(sun_body, observer_body)[ok]
        acc = np.zeros((int(ok.sum()), out.shape[1]))
        for i in range(4):
            # the roll in the reference frame of this pixel centre (the frames of neighbouring
            # pixels differ by their longitude difference, much near the poles)
            e_lon, e_lat = self.roll_frames[0][pix[i]], self.roll_frames[1][pix[i]]
            roll = np.arctan2(np.sum(u * e_lat, axis=1), np.sum(u * e_lon, axis=1))
            k, w_roll = roll_weights(self.header.roll_deg.size, roll)
            for jj in range(2):
                for kk in range(2):
                    w = w_pix[i] * w_phase[jj] * w_roll[kk]
                    acc += w[:, None] * self.intensity_W_sr_nm[pix[i], j[jj], k[kk]]
        out[ok] = acc
        return out

    def coaxial_range_histogram(self, observer_body: ArrayLike) -> F64:
        """Interpolated coaxial range histogram (N, B, bins) [s-1 per bin] at phase angle 0.

        ``observer_body``: (N, 3) directions from the target to the receiver (and the
        coaxial laser), body frame; bilinear on the HEALPix sphere as :meth:`intensity_1au`.
        The map's conditions: a laser of 1 W m-2 nm-1 on every wavelength bin, range 1 m,
        aperture 1 m^2, no atmosphere. NaN rows for NaN or zero directions.
        """

        hist = self.range_histogram_per_s
        if hist is None:
            raise InputError(
                f"the map {self.header.path} has no range_histogram (made from a scenario "
                "without lasers or bands, or without phase angle 0)",
                field=FIELD,
            )
        ok, pix, w_pix = healpix_weights(self.header.nside, observer_body)
        out = np.full((len(ok), *hist.shape[1:]), np.nan)
        if not np.any(ok):
            return out
        acc = np.zeros((int(ok.sum()), *hist.shape[1:]))
        for i in range(4):
            acc += w_pix[i][:, None, None] * hist[pix[i]]
        out[ok] = acc
        return out


def healpix_weights(
    nside: int, directions: ArrayLike
) -> tuple[NDArray[np.bool_], NDArray[np.int64], F64]:
    """Bilinear HEALPix interpolation (RING) at directions (N, 3), any length: ``ok`` (N,)
    (finite, non-zero rows), pixel indices (4, n_ok) and weights (4, n_ok) of those rows."""
    from astropy import units as u
    from astropy_healpix import bilinear_interpolation_weights

    d = np.atleast_2d(np.asarray(directions, dtype=float))
    with np.errstate(invalid="ignore", divide="ignore"):
        norm = np.linalg.norm(d, axis=1)
        ok = np.isfinite(norm) & (norm > 0)
    if not np.any(ok):
        return ok, np.zeros((4, 0), dtype=np.int64), np.zeros((4, 0))
    lon, lat = lonlat_deg(d[ok] / norm[ok, None])
    pix, w = bilinear_interpolation_weights(lon * u.deg, lat * u.deg, int(nside), order="ring")
    return ok, np.asarray(pix, dtype=np.int64), np.asarray(w, dtype=float)


def plane_axis(sun: ArrayLike, observer: ArrayLike) -> F64:
    """``u = normalize(sun - observer)`` (N, 3): the Sun's side of the Sun-observer plane
    (any unit vector at phase angle 0, where the roll does not matter)."""
    s = np.atleast_2d(np.asarray(sun, dtype=float))
    o = np.atleast_2d(np.asarray(observer, dtype=float))
    with np.errstate(invalid="ignore", divide="ignore"):
        d = s / np.linalg.norm(s, axis=1)[:, None] - o / np.linalg.norm(o, axis=1)[:, None]
        n = np.linalg.norm(d, axis=1)
    return np.where((n > 1e-12)[:, None], d / np.where(n > 1e-12, n, 1.0)[:, None], [1.0, 0, 0])


def phase_angle_weights(stored_deg: F64, a_deg: F64) -> tuple[NDArray[np.int64], F64]:
    """Indices (2, N) and weights (2, N) of linear interpolation in phase angle, clamped
    (also used by the spin-axis search)."""
    if stored_deg.size == 1:
        zero = np.zeros(a_deg.size, dtype=np.int64)
        return np.stack([zero, zero]), np.stack([np.ones(a_deg.size), np.zeros(a_deg.size)])
    x = np.clip(a_deg, stored_deg[0], stored_deg[-1])
    hi = np.clip(np.searchsorted(stored_deg, x, side="right"), 1, stored_deg.size - 1)
    lo = hi - 1
    t = (x - stored_deg[lo]) / (stored_deg[hi] - stored_deg[lo])
    return np.stack([lo, hi]), np.stack([1.0 - t, t])


def roll_weights(n_rolls: int, roll_rad: F64) -> tuple[NDArray[np.int64], F64]:
    """Indices (2, N) and weights (2, N) of periodic linear interpolation in roll."""
    f = np.mod(roll_rad, 2 * np.pi) / (2 * np.pi / n_rolls)
    lo = np.floor(f).astype(np.int64) % n_rolls
    t = f - np.floor(f)
    return np.stack([lo, (lo + 1) % n_rolls]), np.stack([1.0 - t, t])


def load_map(path: str | Path) -> ReflectivityMap:
    """Read a complete map into memory (cached per path and modification time)."""
    path = Path(path).resolve()
    stamp = (path / "zarr.json").stat().st_mtime_ns if (path / "zarr.json").exists() else 0
    return _load(path, stamp)


@functools.lru_cache(maxsize=2)
def _load(path: Path, stamp: int) -> ReflectivityMap:
    header = read_header(path)
    group = _open_group(path)
    hist, edges, offset = None, None, None
    if "range_offset" in group:
        offset = np.asarray(group["range_offset"][...], dtype=np.float32)
    if "range_histogram" in group:
        hist = np.asarray(group["range_histogram"][...], dtype=np.float32)
        bounds = np.asarray(group["range_bin_bounds"][...], dtype=float)
        edges = np.append(bounds[:, 0], bounds[-1, 1])
    return ReflectivityMap(
        header=header,
        direction_body=np.asarray(group["direction_body"][...], dtype=float),
        intensity_W_sr_nm=np.asarray(group["intensity"][...], dtype=np.float32),
        range_histogram_per_s=hist,
        range_bin_edges_m=edges,
        range_offset_m=offset,
    )
