"""Ground laser transmitters: beam footprint, line shape and spectral irradiance at the target.

Beam model. A laser beam with a Gaussian far field (TEM00) whose *full* divergence angle
``theta`` is measured between the 1/e² intensity points has, at range ``R`` (far field,
``R`` much larger than the Rayleigh range), the 1/e² radius ``w = R theta / 2`` and the
irradiance

    E(r) = 2 P / (pi w²) exp(-2 r² / w²)      [W m-2]

at a distance ``r`` from the beam axis (Saleh & Teich, *Fundamentals of Photonics*, 2nd ed.,
Wiley 2007, section 3.1, eq. 3.1-7 and 3.1-9; doi:10.1002/0471213748). On the axis this is the
peak irradiance ``2P/(pi w²)``, i.e. ``P G_t / (4 pi R²)`` with Degnan's far-field gain
``G_t = 8 / theta_t²`` for the half angle ``theta_t = theta/2`` (Degnan 1993, "Millimeter
accuracy satellite laser ranging: a review", in *Contributions of Space Geodesy to
Geodynamics: Technology*, AGU Geodynamics Series 25, eq. 2.4, doi:10.1029/GD025p0133). A
target off the axis by the angle ``delta`` (pointing error) sees ``exp(-2 (2 delta/theta)²)``
of the peak. The ``tophat`` profile spreads the power uniformly over the disk of radius
``R theta / 2``.

The target is assumed small compared with the footprint (a 10 arcsec beam is 49 m wide at
1000 km), so the irradiance is uniform over it.

Line shape: a Gaussian of full width at half maximum ``linewidth_nm``, or a tabulated emission
spectrum, normalised to unit area and averaged over the wavelength bins of the grid, so that
``sum(shape * bin_width) = 1`` when the line lies inside the grid (energy is conserved).
"""

from __future__ import annotations

from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.special import erf

from speclight.errors import InputError
from speclight.wavelength_grid import cumulative_integral, grid_bin_bounds_nm

F64 = NDArray[np.float64]
ARCSEC_RAD = float(np.pi / 180.0 / 3600.0)
#: Largest transmitting aperture considered [m]: no beam is narrower than its diffraction
#: limit ``4 lambda / (pi D)`` (Gaussian beam with waist radius D/2, Saleh & Teich eq. 3.1-20).
MAX_TRANSMITTER_APERTURE_M = 10.0
#: Widest full divergence accepted [arcsec] (10 deg, as in the scenario model).
MAX_DIVERGENCE_ARCSEC = 36000.0
BeamProfile = Literal["gaussian", "tophat"]


def check_power_w(power_w: float, field: str = "power_w") -> float:
    """Average laser power [W], checked to be finite and > 0."""
    p = float(power_w)
    if not np.isfinite(p) or p <= 0:
        raise InputError(
            f"power_w = {power_w!r} must be a finite average optical power > 0 W "
            "(e.g. 10 for a 100 mJ laser at 100 Hz); a laser that is off is simply left out "
            "of illumination.lasers",
            field=field,
        )
    return p


def check_repetition_rate_hz(rate_hz: float, field: str = "repetition_rate_hz") -> float:
    """Pulse repetition rate [Hz], checked to be finite and > 0."""
    f = float(rate_hz)
    if not np.isfinite(f) or f <= 0:
        raise InputError(
            f"repetition_rate_hz = {rate_hz!r} must be > 0 Hz (e.g. 100 or 2000)", field=field
        )
    return f


def min_divergence_arcsec(wavelength_nm: float) -> float:
    """Diffraction-limited full divergence of a :data:`MAX_TRANSMITTER_APERTURE_M` beam [arcsec]."""
    theta = 4.0 * wavelength_nm * 1e-9 / (np.pi * MAX_TRANSMITTER_APERTURE_M)
    return float(theta / ARCSEC_RAD)


def check_divergence_arcsec(
    divergence_arcsec: float, wavelength_nm: float, field: str = "divergence_arcsec"
) -> float:
    """Full 1/e² divergence [arcsec], checked against physics; returns it in radians.

    A value below the diffraction limit of a 10 m transmitter (0.014 arcsec at 532 nm) is
    not a beam: it is almost certainly an angle in radians (10 arcsec = 4.8e-5 rad) or degrees
    (10 arcsec = 0.0028 deg) written into an arcsec field, and is refused with the conversion.
    """
    d = float(divergence_arcsec)
    if not np.isfinite(d) or d <= 0:
        raise InputError(
            f"divergence_arcsec = {divergence_arcsec!r} must be a full divergence angle > 0 "
            "arcsec (typical SLR beams: 1 to 30 arcsec)",
            field=field,
        )
    lo = min_divergence_arcsec(wavelength_nm)
    if d < lo:
        raise InputError(
            f"divergence_arcsec = {d:g} is below the diffraction limit of a "
            f"{MAX_TRANSMITTER_APERTURE_M:g} m transmitter at {wavelength_nm:g} nm "
            f"({lo:.3g} arcsec): it looks like an angle in radians or degrees. Give arcsec: "
            f"{d:g} rad = {d / ARCSEC_RAD:.4g} arcsec, {d:g} deg = {d * 3600.0:.4g} arcsec",
            field=field,
        )
    if d > MAX_DIVERGENCE_ARCSEC:
        raise InputError(
            f"divergence_arcsec = {d:g} is wider than 10 deg ({MAX_DIVERGENCE_ARCSEC:g} arcsec); "
            f"if it is in microradians, {d:g} urad = {d * 1e-6 / ARCSEC_RAD:.4g} arcsec",
            field=field,
        )
    return d * ARCSEC_RAD


def beam_irradiance_W_m2(
    power_w: float,
    divergence_rad: float,
    range_m: ArrayLike,
    pointing_offset_rad: ArrayLike = 0.0,
    profile: BeamProfile = "gaussian",
) -> F64:
    """Irradiance of the beam at the target, above the atmosphere's losses [W m-2].

    Parameters
    ----------
    power_w
        Average (or pulse: give the energy for the fluence [J m-2]) power [W].
    divergence_rad
        Full divergence angle between the 1/e² points (gaussian) or of the edge (tophat) [rad].
    range_m
        Transmitter-to-target distance (N,) [m].
    pointing_offset_rad
        Angle between the beam axis and the target direction [rad].
    profile
        ``gaussian``: ``2P/(pi w²) exp(-2 r²/w²)``, ``w = R theta/2`` (module docstring);
        ``tophat``: ``P / (pi w²)`` inside ``r <= w``, 0 outside.

    Returns
    -------
    numpy.ndarray
        Irradiance (N,) [W m-2]; NaN where the range is not finite.
    """
    r = np.asarray(range_m, dtype=float)
    w = r * divergence_rad / 2.0
    off = np.asarray(pointing_offset_rad, dtype=float) * r  # lateral offset [m]
    with np.errstate(invalid="ignore", divide="ignore"):
        if profile == "gaussian":
            return np.asarray(2.0 * power_w / (np.pi * w**2) * np.exp(-2.0 * (off / w) ** 2))
        if profile == "tophat":
            return np.asarray(np.where(off <= w, power_w / (np.pi * w**2), 0.0))
    raise InputError(
        f"beam profile '{profile}' is not known (choices: gaussian, tophat)", field="beam_profile"
    )


def gaussian_line_per_nm(wavelength_nm: ArrayLike, center_nm: float, fwhm_nm: float) -> F64:
    """Unit-area Gaussian line averaged over each wavelength bin [nm-1].

    ``sigma = FWHM / (2 sqrt(2 ln 2))``; the bin average is the exact integral of the
    Gaussian over the bin (error functions) over the bin width.
    """
    wl = np.asarray(wavelength_nm, dtype=float).ravel()
    if not (np.isfinite(fwhm_nm) and fwhm_nm > 0):
        raise InputError(f"linewidth_nm = {fwhm_nm!r} must be > 0", field="linewidth_nm")
    lo, hi = grid_bin_bounds_nm(wl)
    sigma = fwhm_nm / (2.0 * np.sqrt(2.0 * np.log(2.0)))
    z = np.sqrt(2.0) * sigma
    cdf_hi = 0.5 * (1.0 + erf((hi - center_nm) / z))
    cdf_lo = 0.5 * (1.0 + erf((lo - center_nm) / z))
    return np.asarray((cdf_hi - cdf_lo) / (hi - lo))


def table_line_per_nm(wavelength_nm: ArrayLike, table_nm: ArrayLike, value: ArrayLike) -> F64:
    """A tabulated emission spectrum (linear between nodes, 0 outside) normalised to unit area
    and averaged over each bin [nm-1]."""
    wl = np.asarray(wavelength_nm, dtype=float).ravel()
    x = np.asarray(table_nm, dtype=float)
    y = np.asarray(value, dtype=float)
    if x.ndim != 1 or x.shape != y.shape or x.size < 2 or np.any(np.diff(x) <= 0):
        raise InputError(
            "a laser spectrum table needs >= 2 rows with strictly increasing wavelength_nm",
            field="spectrum_file",
        )
    if np.any(~np.isfinite(y)) or np.any(y < 0) or not np.any(y > 0):
        raise InputError(
            "laser spectrum values must be finite, >= 0 and not all 0", field="spectrum_file"
        )
    lo, hi = grid_bin_bounds_nm(wl)
    total = np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(x))[-1]  # the table's integral
    cum_hi, cum_lo = cumulative_integral(x, y, hi), cumulative_integral(x, y, lo)
    return np.asarray((cum_hi - cum_lo) / (hi - lo) / total)


def read_laser_spectrum(path: str | Path) -> tuple[F64, F64]:
    """Read a laser emission spectrum CSV: columns ``wavelength_nm, value`` (any scale).

    Lines starting with ``#`` and a non-numeric header line are skipped.
    """
    p = Path(path)
    if not p.is_file():
        raise InputError(f"laser spectrum file '{p}' does not exist", field="spectrum_file")
    try:
        data = np.genfromtxt(p, delimiter=",", comments="#", dtype=float)
    except ValueError as exc:
        raise InputError(f"cannot read '{p}' as CSV: {exc}", field="spectrum_file") from exc
    data = np.atleast_2d(data)
    data = data[np.all(np.isfinite(data), axis=1)] if data.shape[-1] >= 2 else data
    if data.ndim != 2 or data.shape[1] != 2:
        raise InputError(
            f"'{p}' must have two columns: wavelength_nm, value", field="spectrum_file"
        )
    return data[:, 0].copy(), data[:, 1].copy()


def line_fraction_in_grid(shape_per_nm: F64, wavelength_nm: ArrayLike) -> float:
    """Fraction of the line's energy that falls inside the grid's bins."""
    wl = np.asarray(wavelength_nm, dtype=float).ravel()
    lo, hi = grid_bin_bounds_nm(wl)
    return float(np.sum(shape_per_nm * (hi - lo)))


def pulse_energy_J(power_w: float, repetition_rate_hz: float) -> float:
    """Energy per pulse = average power / repetition rate [J]."""
    return check_power_w(power_w) / check_repetition_rate_hz(repetition_rate_hz)


__all__ = [
    "ARCSEC_RAD",
    "BeamProfile",
    "beam_irradiance_W_m2",
    "check_divergence_arcsec",
    "check_power_w",
    "check_repetition_rate_hz",
    "gaussian_line_per_nm",
    "line_fraction_in_grid",
    "min_divergence_arcsec",
    "pulse_energy_J",
    "read_laser_spectrum",
    "table_line_per_nm",
]
