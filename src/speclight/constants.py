"""Physical and astronomical constants used by speclight, each with its source, in one place.

All values are in SI units (the unit is part of every name).
"""

from __future__ import annotations

import math

#: Speed of light in vacuum [m s-1] (SI 2019, exact).
C_M_S = 299_792_458.0
#: Planck constant [J s] (SI 2019, exact).
H_J_S = 6.62607015e-34
#: Planck constant times the speed of light [J m] (a photon of wavelength lambda carries hc/lambda).
HC_J_M = H_J_S * C_M_S
#: Boltzmann constant [J K-1] (SI 2019, exact).
K_B_J_K = 1.380649e-23
#: Astronomical unit [m] (IAU 2012 Resolution B2, exact).
AU_M = 149_597_870_700.0
#: Nominal solar radius [m] (IAU 2015 Resolution B3; Prsa et al. 2016, AJ 152, 41,
#: doi:10.3847/0004-6256/152/2/41).
SUN_RADIUS_M = 695_700_000.0
#: Mean radius of the Earth [m] (IUGG: R1 = (2a + b) / 3 of WGS84; Moritz 2000, J. Geodesy
#: 74, 128, doi:10.1007/s001900050278): the sphere Earthshine is reflected from.
EARTH_MEAN_RADIUS_M = 6_371_008.8
#: Rotation rate of the Earth [rad s-1]: the rate of the Earth rotation angle per second of
#: UT1, 2 pi x 1.00273781191135448 / 86400 (IERS Conventions 2010, eq. 5.15).
EARTH_ROTATION_RATE_RAD_S = 2.0 * math.pi * 1.00273781191135448 / 86400.0
#: AB magnitude zero point: flux density of a source of AB magnitude 0 [W m-2 Hz-1]
#: (3631 Jy; Oke & Gunn 1983, ApJ 266, 713, doi:10.1086/160817).
AB_ZERO_W_M2_HZ = 3631.0e-26

__all__ = [
    "AB_ZERO_W_M2_HZ",
    "AU_M",
    "C_M_S",
    "EARTH_MEAN_RADIUS_M",
    "EARTH_ROTATION_RATE_RAD_S",
    "HC_J_M",
    "H_J_S",
    "K_B_J_K",
    "SUN_RADIUS_M",
]
