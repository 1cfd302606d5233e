"""The light curves an inversion fits: epochs, brightness, weights and geometry.

Whatever the input (a DAMIT ``.lc`` file, a speclight measured light curve with its
scenario), the inversion sees points with a light-time corrected epoch, a brightness, its
standard deviation and the unit vectors from the target to the Sun and to the observer in
ecliptic J2000, grouped into light curves each relative (only its shape counts: the model
is divided by its mean over the curve, as the data are) or calibrated.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.shape.damit_lc import DamitLightCurve

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]
#: Fewest points per light curve: a relative curve of fewer carries almost no shape.
MIN_POINTS_PER_CURVE = 3
#: Relative sigma given to points that come without one (about 0.01 mag).
NOMINAL_SIGMA = 0.01


@dataclass(frozen=True)
class InversionData:
    """Points of all light curves (module doc).

    Attributes
    ----------
    time_jd
        (N,) light-time corrected epochs [d] (Julian date).
    brightness
        (N,) brightness [any unit; for calibrated curves the unit of the fitted areas].
    sigma
        (N,) standard deviations of ``brightness`` (same unit); relative curves use
        ``sigma / mean(brightness)`` of their curve.
    sun_ecliptic
        (N, 3) unit vectors target -> Sun, ecliptic J2000.
    observer_ecliptic
        (N, 3) unit vectors target -> observer, ecliptic J2000.
    curve
        (N,) index of each point's light curve, 0..C-1, non-decreasing (each curve's
        points are one contiguous run, in time order).
    calibrated
        (C,) True where a light curve is calibrated.
    """

    time_jd: F64
    brightness: F64
    sigma: F64
    sun_ecliptic: F64
    observer_ecliptic: F64
    curve: I64
    calibrated: NDArray[np.bool_]

    @property
    def n_points(self) -> int:
        """Number of points N."""
        return int(self.time_jd.size)

    @property
    def n_curves(self) -> int:
        """Number of light curves C."""
        return int(self.calibrated.size)

    @property
    def baseline_d(self) -> float:
        """Time from the first to the last point [d]."""
        return float(np.ptp(self.time_jd))

    @property
    def cos_half_phase(self) -> F64:
        """(N,) cosine of half the phase angle."""
        return np.sqrt(
            np.clip(
                0.5 * (1.0 + np.sum(self.sun_ecliptic * self.observer_ecliptic, axis=1)), 0.0, 1.0
            )
        )

    @property
    def phase_angle_deg(self) -> F64:
        """(N,) phase angle [deg]."""
        return np.asarray(np.rad2deg(2.0 * np.arccos(self.cos_half_phase)))

    def subset(self, index: I64) -> InversionData:
        """The points ``index`` (curves renumbered, empty ones dropped)."""
        kept, curve = np.unique(self.curve[index], return_inverse=True)
        return InversionData(
            self.time_jd[index],
            self.brightness[index],
            self.sigma[index],
            self.sun_ecliptic[index],
            self.observer_ecliptic[index],
            curve.astype(np.int64),
            self.calibrated[kept],
        )

    def with_brightness(self, brightness: F64) -> InversionData:
        """The same points and geometry with other brightness values."""
        return InversionData(
            self.time_jd,
            np.asarray(brightness, float),
            self.sigma,
            self.sun_ecliptic,
            self.observer_ecliptic,
            self.curve,
            self.calibrated,
        )


def _unit(v: F64) -> F64:
    return np.asarray(v / np.linalg.norm(v, axis=1, keepdims=True))


def build_inversion_data(
    time_jd: F64,
    brightness: F64,
    sigma: F64 | None,
    sun: F64,
    observer: F64,
    curve: I64,
    calibrated: NDArray[np.bool_],
    source: str,
) -> InversionData:
    """Check and assemble :class:`InversionData` (vectors normalised; sigma 1 where None).

    Points with a non-finite brightness or geometry are dropped; light curves left with
    fewer than :data:`MIN_POINTS_PER_CURVE` points are dropped too.

    Raises
    ------
    InputError
        When nothing is left to fit, or a sigma is not > 0.
    """
    sig = np.ones_like(brightness) if sigma is None else np.asarray(sigma, float)
    ok = (
        np.isfinite(brightness)
        & np.isfinite(sig)
        & np.all(np.isfinite(sun), axis=1)
        & np.all(np.isfinite(observer), axis=1)
        & np.isfinite(time_jd)
    )
    if np.any(ok & ~(sig > 0)):
        raise InputError("every brightness sigma must be > 0", source=source, field="sigma")
    counts = np.bincount(curve[ok], minlength=calibrated.size)
    ok &= counts[curve] >= MIN_POINTS_PER_CURVE
    if not np.any(ok):
        raise InputError(
            f"no light curve has {MIN_POINTS_PER_CURVE} or more points with a finite "
            "brightness and geometry",
            source=source,
            field="LC",
        )
    # points grouped by light curve (each curve one contiguous run), in time within a curve
    order = np.flatnonzero(ok)[np.lexsort((time_jd[ok], curve[ok]))]
    kept, new_curve = np.unique(curve[order], return_inverse=True)
    return InversionData(
        np.asarray(time_jd[order], float),
        np.asarray(brightness[order], float),
        sig[order],
        _unit(sun[order]),
        _unit(observer[order]),
        new_curve.astype(np.int64),
        np.asarray(calibrated, bool)[kept],
    )


def from_damit(curves: list[DamitLightCurve], source: str) -> InversionData:
    """Inversion data from the light curves of a DAMIT ``.lc`` file. The file has no sigmas:
    each point's sigma is :data:`NOMINAL_SIGMA` times its curve's mean brightness (0.01 mag),
    so that all points weigh the same in relative terms; the uncertainties are then scaled
    by the residuals (:mod:`.uncertainty`)."""
    return build_inversion_data(
        np.concatenate([c.time_jd for c in curves]),
        np.concatenate([c.brightness for c in curves]),
        np.concatenate(
            [np.full(c.time_jd.size, NOMINAL_SIGMA * np.mean(c.brightness)) for c in curves]
        ),
        np.concatenate([c.sun_ecliptic_au for c in curves]),
        np.concatenate([c.observer_ecliptic_au for c in curves]),
        np.concatenate([np.full(c.time_jd.size, k) for k, c in enumerate(curves)]),
        np.array([c.calibrated for c in curves]),
        source,
    )
