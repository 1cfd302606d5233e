"""Laser light curves and ranging returns of spin-axis candidates, from a map's phase-0 slice.

A coaxial laser lights the target from the observer's direction (phase angle 0), so the
body-frame Sun direction of the map is the observer direction. The map holds, at phase 0,
the intensity under the Sun at 1 AU ``I(d, l)`` and the mean one-way range offset of a
coaxial return ``o(d, l)`` per wavelength bin (single scattering). With the solar spectrum
at 1 AU ``S(l)``, ``I1 = I / S`` is the intensity per unit irradiance, and

* the band ``b`` rate under the lasers is ``R_b(d) = sum_l K_bl I1(d, l)``,
* its first moment in range ``M_b(d) = sum_l K_bl I1(d, l) o(d, l)``, so the band's mean
  range offset is ``M_b / R_b``,

with ``K_bl = response_bl x lambda_l x E(l)``: the band response (optics and QE folded in),
the photons per joule (proportional to the wavelength) and the lasers' spectrum at the
aperture ``E`` (each epoch's divided by its sum, then averaged over the epochs). This is how
``simulate`` weights the returns of each laser line per band (``speclight.ranging.link``:
the band rate and the band moment are the same conversion kernel applied to the rendered
intensity and moment), except that ``E``'s shape is taken as constant over the pass (the
downlink transmission changes it slightly with elevation).

**Ranging term** of the misfit: ``sum (o_pred - o_meas)^2 / (n * mean(o_meas^2))`` over the
epochs and bands with a measured offset: the squared differences divided by the mean square
of the measured offsets (the reference normalises its ranging returns before the least
squares without saying how; this makes the term a relative squared error like the
intensity term, whose curves are divided by their means). **Weight**: given, or by default
the ratio of the two terms' medians over all grid candidates (axes x phases), so that over
the grid both terms are of the same typical size and count alike. A predicted offset where the map
returns nothing (``R_b = 0``) counts as 0 (the centre of mass).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.spin_axis.spin_axis_lookup import EpochGeometry, SpinFrameMap
from speclight.maps.map_lookup import ReflectivityMap, read_header

F64 = NDArray[np.float64]
FIELD = "map_path"
#: Largest ranging weight accepted: the intensity term, about 1e-3..1, would then count for
#: less than 1e-6 of the misfit.
MAX_WEIGHT = 1e6


def laser_kernel(response: F64, wavelength_nm: F64, source_W_m2_nm: F64 | None) -> F64:
    """``K`` (B, L): band response x wavelength x the mean normalised laser spectrum."""
    if source_W_m2_nm is None:
        e = np.ones(wavelength_nm.size)
    else:
        src = np.nan_to_num(np.asarray(source_W_m2_nm, dtype=float))
        total = src.sum(axis=1)
        keep = total > 0
        e = np.mean(src[keep] / total[keep, None], axis=0) if keep.any() else np.zeros(src.shape[1])
    return np.asarray(response, dtype=float) * wavelength_nm[None, :] * e[None, :]


def laser_band_map(path: str | Path, kernel: F64, need_offsets: bool) -> ReflectivityMap:
    """A one-geometry map (phase angle 0, one roll) of ``[R_b..., M_b...]`` (2B channels;
    ``M`` NaN-free zeros where the map has no range offsets and they are not needed)."""
    import zarr

    from speclight.illumination import solar_irradiance_W_m2_nm

    header = read_header(path)
    zero = np.flatnonzero(np.isclose(header.phase_angle_deg, 0.0))
    if zero.size == 0:
        angles = ", ".join(f"{a:g}" for a in header.phase_angle_deg)
        raise InputError(
            f"the map {path} has no phase angle 0 (it has {angles} deg): laser light and "
            "ranging returns need the coaxial slice; make it with phase_angles_deg=0,...",
            field=FIELD,
        )
    group: Any = zarr.open_group(str(path), mode="r")
    has_offsets = "range_offset" in group
    if need_offsets and not has_offsets:
        raise InputError(
            f"the map {path} has no range_offset (it was made from a scenario without lasers); "
            "make it with the lasers on, or give ranging_weight=0",
            field=FIELD,
        )
    wl = header.wavelength_nm
    inten = np.asarray(group["intensity"][:, int(zero[0]), 0, :], dtype=float)
    i1 = inten / solar_irradiance_W_m2_nm(wl, 1.0)[None, :]
    off = np.asarray(group["range_offset"][...], dtype=float) if has_offsets else np.zeros_like(i1)
    rate = i1 @ kernel.T
    moment = (i1 * np.nan_to_num(off)) @ kernel.T
    one = dataclasses.replace(header, phase_angle_deg=np.zeros(1), roll_deg=np.zeros(1))
    values = np.concatenate([rate, moment], axis=1)[:, None, None, :].astype(np.float32)
    return ReflectivityMap(one, np.asarray(group["direction_body"][...], float), values)


def coaxial(geo: EpochGeometry) -> EpochGeometry:
    """The epochs lit from the observer's direction (phase angle 0)."""
    return EpochGeometry(geo.observer_gcrs, geo.observer_gcrs, geo.t_s, geo.period_s)


@dataclass(frozen=True)
class RangingTerm:
    """Measured offsets and the map that predicts them (module docstring)."""

    bmap: ReflectivityMap  # laser_band_map: 2B channels
    sfm: SpinFrameMap  # its spin-frame resampling
    offset_m: F64  # (T, B) measured, NaN where none
    weight: float | None  # None: balanced over the grid (resolve_weight)
    #: the intensity is the laser light of the same map (one lookup serves both terms)
    shares_rates: bool = False

    def select(self, ok: NDArray[np.bool_]) -> RangingTerm:
        """Only the epochs ``ok``."""
        return dataclasses.replace(self, offset_m=self.offset_m[ok])

    @property
    def n_bands(self) -> int:
        return int(self.offset_m.shape[1])


def offsets_from_channels(rm: NDArray, scale: F64 | None, n_b: int) -> NDArray:
    """Band offsets ``M / R`` (..., B) from channels ``[R..., M...]`` (each divided by
    ``scale``); 0 where ``R <= 0``."""
    s = np.ones(2 * n_b) if scale is None else np.asarray(scale, dtype=float)
    r = rm[..., :n_b] * s[:n_b].astype(rm.dtype)
    m = rm[..., n_b:] * s[n_b:].astype(rm.dtype)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(r > 0, m / r, 0.0)


def term_from_offsets(pred: NDArray, meas: F64) -> NDArray:
    """Ranging term (module docstring) of predicted offsets (..., T, B) against ``meas``."""
    ok = np.isfinite(meas)
    norm = float(np.mean(meas[ok] ** 2)) if ok.any() else 0.0
    if norm <= 0:
        return np.zeros(pred.shape[:-2])
    d = np.where(ok, np.nan_to_num(pred) - np.nan_to_num(meas), 0.0)
    return np.asarray(np.sum(d**2, axis=(-2, -1)) / (ok.sum() * norm))


def exact_term(term: RangingTerm, observer_body: F64) -> float:
    """The ranging term of one candidate with the map's own interpolation."""
    rm = term.bmap.intensity_1au(observer_body, observer_body)
    off = offsets_from_channels(np.nan_to_num(rm), None, term.n_bands)
    return float(term_from_offsets(off, term.offset_m))


def resolve_weight(term: RangingTerm, e_i: F64, e_r: F64) -> RangingTerm:
    """``term`` with its weight: as given, or ``median(e_i) / median(e_r)`` over the finite
    candidates of the grid (module docstring; 0 where the ranging term is 0 everywhere)."""
    if term.weight is not None:
        return term
    ok = np.isfinite(e_i) & np.isfinite(e_r)
    med_r = float(np.median(e_r[ok])) if ok.any() else 0.0
    weight = float(np.median(e_i[ok])) / med_r if med_r > 0 else 0.0
    return dataclasses.replace(term, weight=weight)


def measured_offsets(measured: str | Path, n_t: int) -> F64 | None:
    """``range_offset(time, band)`` [m] of a simulate NetCDF, or None where it has none."""
    from speclight.io.user_dataset import read_user_dataset, values

    ds = read_user_dataset(measured, "MEASURED", what="measurements", variables=["range_offset"])
    if "range_offset" not in ds:
        return None
    off = values(ds, "range_offset", ("time", "band"), str(measured), "MEASURED")
    if off.shape[0] != n_t or not np.any(np.isfinite(off)):
        return None
    return np.asarray(off)


def map_has_offsets(map_path: str | Path) -> bool:
    """Whether the map stores ``range_offset``."""
    import zarr

    return "range_offset" in zarr.open_group(str(map_path), mode="r")


def check_ranging_weight(weight: float | None, offsets: F64 | None) -> float | None:
    """The ranging term's weight: None (balanced over the grid) where there are offsets and
    none was given, 0 where there are none."""
    if weight is None:
        return None if offsets is not None else 0.0
    if not (np.isfinite(weight) and 0 <= weight <= MAX_WEIGHT):
        raise InputError(
            f"ranging_weight = {weight} must be a number from 0 to {MAX_WEIGHT:g} (a weight "
            "of the ranging term against the intensity term; beyond it the intensity no "
            "longer counts, and the sum overflows)",
            field="ranging_weight",
        )
    if weight > 0 and offsets is None:
        raise InputError(
            f"ranging_weight = {weight} but MEASURED has no range_offset(time, band) (a "
            "simulate NetCDF of a pass with lasers has it; a CSV never)",
            field="ranging_weight",
        )
    return float(weight)
