"""Sky to detector: the gnomonic (TAN) projection and the frame's FITS WCS.

The frame's world coordinates are ICRS right ascension and declination, astrometric (the
directions a star catalogue gives and the pipeline's ``ra``, ``dec``). A direction ``u`` is
projected about the pointing ``c`` to the standard coordinates (Calabretta & Greisen 2002,
A&A 395, 1077, eq. 54, TAN; doi:10.1051/0004-6361:20021327)

.. math:: \\xi = \\frac{u \\cdot e}{u \\cdot c},\\quad \\eta = \\frac{u \\cdot n}{u \\cdot c}

with ``e``, ``n`` the east and north unit vectors at ``c``, and to pixels by the inverse of the
CD matrix of plate scale ``s`` and position angle ``theta`` of the detector's +y axis
(north through east; north up and east left at 0):

.. math:: CD = s \\begin{pmatrix} -\\cos\\theta & \\sin\\theta \\\\
          \\sin\\theta & \\cos\\theta \\end{pmatrix}

The reference pixel is the detector's centre. :func:`frame_wcs` writes the same as an
astropy WCS (the FITS header), which the tests compare with :func:`sky_to_pixel`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.attitude.quaternion import radec_from_unit_vector

F64 = NDArray[np.float64]


def east_north(u: ArrayLike) -> tuple[F64, F64]:
    """East and north unit vectors (..., 3) at directions ``u`` (..., 3), ICRS."""
    v = np.asarray(u, dtype=np.float64)
    v = v / np.linalg.norm(v, axis=-1, keepdims=True)
    z = np.zeros_like(v)
    z[..., 2] = 1.0
    east = np.cross(z, v)
    norm = np.linalg.norm(east, axis=-1, keepdims=True)
    # at a pole, east is taken along +y (RA 90 deg), as for RA = 0 there
    pole = norm[..., 0] < 1e-15
    east[pole] = [0.0, 1.0, 0.0]
    norm[pole] = 1.0
    east = east / norm
    north = np.cross(v, east)
    return east, north


@dataclass(frozen=True)
class Pointing:
    """A frame's geometry on the sky.

    Attributes
    ----------
    centre
        (3,) unit vector of the reference pixel (ICRS).
    scale_arcsec
        Plate scale [arcsec px-1].
    position_angle_deg
        Direction of the detector's +y axis, north through east [deg].
    width_px, height_px
        Detector size [px].
    """

    centre: F64
    scale_arcsec: float
    position_angle_deg: float
    width_px: int
    height_px: int

    @property
    def cd_deg(self) -> F64:
        """The CD matrix [deg px-1]: columns are the pixel axes x, y; rows RA, Dec."""
        s = self.scale_arcsec / 3600.0
        t = np.radians(self.position_angle_deg)
        return s * np.array([[-np.cos(t), np.sin(t)], [np.sin(t), np.cos(t)]])

    @property
    def reference_px(self) -> tuple[float, float]:
        """(x, y) of the reference pixel, 0-based: the detector's centre."""
        return (self.width_px - 1) / 2.0, (self.height_px - 1) / 2.0

    def moved_to(self, centre: F64) -> Pointing:
        """The same detector pointed at another direction."""
        return Pointing(
            np.asarray(centre, dtype=np.float64),
            self.scale_arcsec,
            self.position_angle_deg,
            self.width_px,
            self.height_px,
        )


def standard_coordinates_deg(u: ArrayLike, centre: ArrayLike) -> tuple[F64, F64]:
    """Gnomonic standard coordinates (xi east, eta north) [deg] of directions ``u`` (..., 3)
    about ``centre`` (3,) or (..., 3); NaN behind the tangent plane."""
    v = np.asarray(u, dtype=np.float64)
    c = np.asarray(centre, dtype=np.float64)
    east, north = east_north(c)
    cos_c = np.sum(v * c, axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        xi = np.where(cos_c > 0, np.sum(v * east, axis=-1) / cos_c, np.nan)
        eta = np.where(cos_c > 0, np.sum(v * north, axis=-1) / cos_c, np.nan)
    return np.degrees(xi), np.degrees(eta)


def sky_to_pixel(
    u: ArrayLike, pointing: Pointing, centre: ArrayLike | None = None
) -> tuple[F64, F64]:
    """Pixel coordinates (x, y), 0-based, of directions ``u`` (..., 3).

    ``centre`` (..., 3), if given, replaces the pointing's centre per direction (a
    telescope that moves during the exposure).
    """
    c = pointing.centre if centre is None else centre
    xi, eta = standard_coordinates_deg(u, c)
    dx, dy = offsets_to_pixels(xi, eta, pointing)
    x0, y0 = pointing.reference_px
    return x0 + dx, y0 + dy


def offsets_to_pixels(xi_deg: ArrayLike, eta_deg: ArrayLike, pointing: Pointing) -> tuple[F64, F64]:
    """Pixel offsets (dx, dy) of small sky offsets east and north [deg]."""
    inv = np.linalg.inv(pointing.cd_deg)
    xi, eta = np.asarray(xi_deg, dtype=np.float64), np.asarray(eta_deg, dtype=np.float64)
    return inv[0, 0] * xi + inv[0, 1] * eta, inv[1, 0] * xi + inv[1, 1] * eta


def frame_wcs(pointing: Pointing) -> object:
    """The frame's WCS as an astropy :class:`~astropy.wcs.WCS` (ICRS, TAN, CD matrix)."""
    from astropy.wcs import WCS

    ra, dec = radec_from_unit_vector(pointing.centre)
    wcs = WCS(naxis=2)
    wcs.wcs.ctype = ["RA---TAN", "DEC--TAN"]
    wcs.wcs.cunit = ["deg", "deg"]
    wcs.wcs.radesys = "ICRS"
    wcs.wcs.crval = [float(ra), float(dec)]
    x0, y0 = pointing.reference_px
    wcs.wcs.crpix = [x0 + 1.0, y0 + 1.0]  # FITS counts pixels from 1
    wcs.wcs.cd = pointing.cd_deg
    return wcs
