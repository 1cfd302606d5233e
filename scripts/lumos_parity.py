"""speclight against lumos-sat on lumos-sat's own Starlink v1.5 model (issue 24, item 3).

lumos-sat (Fankhauser, Askari & Tyson 2023, "Satellite optical brightness",
doi:10.3847/1538-3881/ace047; ``pip install lumos-sat``) models Starlink v1.5 as two flat
surfaces with analytic BRDFs fitted to the lab tables: the chassis underside (3.64 m², normal
to nadir) and the solar array (22.68 m², perpendicular to the chassis, normal toward the
Sun's azimuth); ``starlink_v1p5_surfaces.txt`` gives the areas and normals, the binomial
coefficients are those of the authors' model file (repository
Forrest-Fankhauser/satellite-optical-brightness, ``analysis/satellite_models/starlink_v1p5.py``,
MIT). Its Sun is 1360 W m-2 counted at 532 nm: flux ``F = 1360 sum A f cos_i cos_o / d^2``,
AB magnitude ``-2.5 log10(F lambda / (c 3631 Jy))`` with lambda = 532 nm.

This module holds the comparison both the test (tests/simulate/test_lumos_parity.py) and the
measurements of docs/real-satellites.md use:

* the geometry grid: twilight passes of synthetic Starlink-like orbits (550 km; 53, 70 and
  97.6 deg) over three sites, every epoch at which the satellite is above 15 deg, fully
  sunlit and the site's Sun below -6 deg;
* lumos-sat's magnitude at each epoch, from the satellite, site and Sun positions that
  astropy (lumos-sat's own engine) gives, put into lumos-sat's satellite-centred frame
  exactly (:func:`lumos_flux_W_m2`);
* the same two plates in speclight (:func:`plates_obj`, :func:`plates_scenario`) and
  speclight's reflectance factor put through lumos-sat's Sun and zero point
  (:func:`lumos_convention_magnitude`).

Run ``python scripts/lumos_parity.py`` to print the numbers of docs/real-satellites.md
(minutes).
"""

from __future__ import annotations

import datetime as dt
import importlib.util
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

ROOT = Path(__file__).resolve().parents[1]
F64 = NDArray[np.float64]

#: lumos-sat's constants (lumos/constants.py): Earth radius [m], Sun [W m-2], wavelength [m],
#: the speed of light it uses [m/s] and the AB zero point [W m-2 Hz-1].
LUMOS_EARTH_RADIUS_M = 6378e3
LUMOS_SUN_W_M2 = 1360.0
LUMOS_WAVELENGTH_M = 532e-9
LUMOS_SPEED_OF_LIGHT_M_S = 3.0e8
AB_ZERO_POINT_W_M2_HZ = 3631e-26

#: starlink_v1p5_surfaces.txt (Fankhauser et al. 2023): areas [m2]; normals in lumos-sat's
#: frame (z to the satellite's zenith, y toward the Sun's azimuth).
CHASSIS_AREA_M2 = 3.64
ARRAY_AREA_M2 = 22.68
CHASSIS_NORMAL_LUMOS = (0.0, 0.0, -1.0)
ARRAY_NORMAL_LUMOS = (0.0, 1.0, 0.0)
#: The lab-table binomial fits of the authors' model (satellite-optical-brightness,
#: analysis/satellite_models/starlink_v1p5.py, ``lab_chassis_brdf``, ``lab_solar_array_brdf``).
CHASSIS_BINOMIAL: dict[str, Any] = {
    "b": [[3.34, -98.085]],
    "c": [
        [-999.999, 867.538, 1000.0, 1000.0, -731.248, 618.552, -294.054, 269.248, -144.853, 75.196]
    ],
    "d": 3.0,
    "l1": -5,
    "wavelength_nm": 532.0,
}
ARRAY_BINOMIAL: dict[str, Any] = {
    "b": [[0.534, -20.409]],
    "c": [[-527.765, 1000.0, -676.579, 430.596, -175.806, 57.879]],
    "d": 3.0,
    "l1": -3,
    "wavelength_nm": 532.0,
}


@dataclass(frozen=True)
class Site:
    """An observatory (WGS84) and the start of an evening twilight window (UTC)."""

    name: str
    latitude_deg: float
    longitude_deg: float
    altitude_m: float
    window_start_utc: str


#: Three sites, each in the evening twilight of another season.
SITES = (
    Site("Cerro Pachon", -30.2446, -70.7494, 2663.0, "2024-03-20T22:30:00Z"),
    Site("La Palma", 28.7606, -17.8816, 2326.0, "2024-06-20T21:00:00Z"),
    Site("Mauna Kea", 19.8207, -155.4681, 4205.0, "2024-12-21T04:00:00Z"),
)
#: Per site, (inclination, RAAN, mean anomaly) [deg] of 550 km circular orbits (epoch: noon
#: UTC of the window's day) with a sunlit pass in the window: chosen by a grid search
#: over RAAN and mean anomaly for passes that together span phase angles 27-147 deg.
PASSES: dict[str, tuple[tuple[float, float, float], ...]] = {
    "Cerro Pachon": ((53, 255, 60), (53, 135, 90), (97.6, 105, 90), (70, 270, 0), (97.6, 90, 180)),
    "La Palma": ((53, 195, 270), (97.6, 210, 30), (97.6, 30, 120), (70, 210, 150), (53, 195, 180)),
    "Mauna Kea": ((53, 345, 210), (53, 195, 330), (70, 345, 240), (97.6, 180, 300), (70, 0, 150)),
}
ALTITUDE_KM = 550.0
WINDOW_H = 1.5
STEP_S = 8.0
MIN_ELEVATION_DEG = 15.0
#: The plates' layout in the body frame of a yaw-steered nadir attitude (+z to nadir, +x
#: toward the Sun's azimuth): the array (8.1 x 2.8 m, normal +x) stands in the y-z plane
#: above the body origin; the chassis (a square of 3.64 m2, normal +z) lies behind it (x < 0)
#: and below its lower edge. Then no ray between the plates can carry light: the chassis
#: reflects only when the Sun is below its plane (its shadow rays go down, away from the
#: array) and is seen from below (its view rays go down); the array reflects only on its
#: Sun side (x > 0: its shadow and view rays go to x > 0, away from the chassis). The sum of
#: the two plates is then lumos-sat's sum, with no shadowing to model.
ARRAY_WIDTH_M = 8.1
PLATE_GAP_M = 0.05
#: The narrow band (a Gaussian, centre/sigma [nm]) and the grid of the parity runs.
BAND = "G-532/3"
BAND_CENTRE_NM, BAND_SIGMA_NM = 532.0, 3.0
SPECTRUM = {"min_nm": 510.0, "max_nm": 555.0, "step_nm": 1.0}


def _load_script(name: str) -> Any:
    spec = importlib.util.spec_from_file_location(name, ROOT / "scripts" / f"{name}.py")
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules.setdefault(name, mod)  # dataclasses look their module up
    spec.loader.exec_module(mod)
    return mod


def pass_tle(site: Site, index: int) -> str:
    """The synthetic TLE (three lines) of pass ``index`` of ``site``."""
    st = _load_script("synthetic_tles")
    inc, raan, ma = PASSES[site.name][index]
    epoch = site.window_start_utc[:10] + "T12:00:00Z"
    e = st.Elements(f"PARITY-{index}", 99500 + index, epoch, ALTITUDE_KM, inc, raan, 1e-4, 90.0, ma)
    return "\n".join(st.make_tle(e))


def window(site: Site) -> dict[str, Any]:
    """The scenario ``time`` section of the site's twilight window."""
    start = dt.datetime.fromisoformat(site.window_start_utc.replace("Z", "+00:00"))
    stop = start + dt.timedelta(hours=WINDOW_H)
    return {
        "start": site.window_start_utc,
        "stop": stop.isoformat().replace("+00:00", "Z"),
        "step_s": STEP_S,
    }


def observer(site: Site) -> dict[str, Any]:
    """The scenario ``observer`` section of ``site``."""
    return {
        "latitude_deg": site.latitude_deg,
        "longitude_deg": site.longitude_deg,
        "altitude_m": site.altitude_m,
        "min_elevation_deg": MIN_ELEVATION_DEG,
    }


def plates_obj(path: Path) -> Path:
    """Write lumos-sat's two surfaces as an OBJ (parts ``chassis`` and ``array``)."""
    c = float(np.sqrt(CHASSIS_AREA_M2))
    w = ARRAY_WIDTH_M
    h = ARRAY_AREA_M2 / w
    g = PLATE_GAP_M
    chassis = [(-g - c, -c / 2, g), (-g, -c / 2, g), (-g, c / 2, g), (-g - c, c / 2, g)]
    array = [(0.0, -w / 2, -h), (0.0, w / 2, -h), (0.0, w / 2, 0.0), (0.0, -w / 2, 0.0)]
    lines = [f"v {x:.9f} {y:.9f} {z:.9f}" for x, y, z in chassis + array]
    lines += ["usemtl chassis", "f 1 2 3 4", "usemtl array", "f 5 6 7 8"]
    path.write_text("\n".join(lines) + "\n")
    return path


def plates_scenario(site: Site, index: int, mesh_path: Path, resolution_px: int) -> dict[str, Any]:
    """speclight's scenario of lumos-sat's model on pass ``index`` of ``site``.

    The frame is lumos-sat's: ``nadir`` with ``geocentric`` nadir (lumos-sat's Earth is a
    sphere: its z axis is the satellite's radius vector) and yaw steering (the Sun in the
    body x-z plane on +x: lumos-sat's y axis, the Sun's azimuth, is body +x; its x axis is
    body y, its z axis body -z). The materials are lumos-sat's binomial fits; no atmosphere;
    a narrow band at lumos-sat's 532 nm, :data:`BAND` on a 1 nm grid (the reflectance
    factor is the same in every band for these grey materials; the band's AB magnitude
    differs from lumos-sat's by the two Suns, :func:`sun_bridge_mag`).
    """
    return {
        "name": "lumos-parity",
        "time": window(site),
        "observer": observer(site),
        "orbit": {"tle": pass_tle(site, index)},
        "attitude": {"model": "nadir", "nadir_type": "geocentric", "yaw_steering": True},
        "target": {
            "shape": {"mesh_file": str(mesh_path)},
            "materials": {
                "chassis": {"bsdf": "binomial", "coefficients": CHASSIS_BINOMIAL},
                "array": {"bsdf": "binomial", "coefficients": ARRAY_BINOMIAL},
            },
        },
        "illumination": {"sun": True},
        "atmosphere": {"model": "none"},
        "spectrum": dict(SPECTRUM),
        "render": {"mode": "single", "resolution_px": resolution_px},
        "instrument": {"bands": [{"name": BAND}]},
    }


def passes() -> Iterator[tuple[Site, int]]:
    """Every (site, pass index) of the grid."""
    for site in SITES:
        for index in range(len(PASSES[site.name])):
            yield site, index


def lumos_surfaces(chassis: Any = None, array: Any = None) -> list[Any]:
    """lumos-sat's Starlink v1.5 surfaces (its binomial lab fits unless BRDFs are given)."""
    from lumos.brdf.library import BINOMIAL
    from lumos.geometry import Surface

    def binomial(c: dict[str, Any]) -> Any:
        return BINOMIAL(np.array(c["b"]), np.array(c["c"]), c["d"], c["l1"])

    return [
        Surface(
            CHASSIS_AREA_M2, np.array(CHASSIS_NORMAL_LUMOS), chassis or binomial(CHASSIS_BINOMIAL)
        ),
        Surface(ARRAY_AREA_M2, np.array(ARRAY_NORMAL_LUMOS), array or binomial(ARRAY_BINOMIAL)),
    ]


def astropy_positions_m(
    tle: str, site: Site, time_utc: NDArray[np.datetime64]
) -> tuple[F64, F64, F64]:
    """ITRS positions [m] of the satellite, the site and the Sun at ``time_utc``, as
    lumos-sat computes them (``lumos.constellation``: SGP4, astropy TEME -> ITRS; astropy's
    ``get_sun``); no light time."""
    import astropy.units as u
    from astropy.coordinates import ITRS, TEME, CartesianRepresentation, EarthLocation, get_sun
    from astropy.time import Time
    from astropy.utils import iers
    from sgp4.api import Satrec

    iers.conf.auto_download = False  # astropy's bundled Earth orientation: no network
    _, line1, line2 = tle.splitlines()
    t = Time([str(x) for x in time_utc.astype("datetime64[ns]")], scale="utc")
    err, r_km, _ = Satrec.twoline2rv(line1, line2).sgp4_array(t.jd1, t.jd2)
    assert not np.any(err), "SGP4 failed"
    teme = TEME(CartesianRepresentation(r_km.T * u.km), obstime=t)
    sat = teme.transform_to(ITRS(obstime=t)).cartesian.xyz.to(u.m).value.T
    loc = EarthLocation.from_geodetic(
        site.longitude_deg * u.deg, site.latitude_deg * u.deg, site.altitude_m * u.m
    )
    obs = loc.get_itrs(t).cartesian.xyz.to(u.m).value.T
    sun = get_sun(t).transform_to(ITRS(obstime=t)).cartesian.xyz.to(u.m).value.T
    return sat, obs, sun


def lumos_frame(sat_m: F64, obs_m: F64, sun_m: F64) -> tuple[F64, F64, F64]:
    """The geometry in lumos-sat's satellite-centred frame, exactly.

    lumos-sat's frame (``lumos.calculator``): origin the Earth's centre, z through the
    satellite (at ``(0, 0, R + h)``), y the Sun's direction made perpendicular to z
    (``vector_2_sun = (0, cos a, -sin a)``, ``a`` the angle past the terminator), x = y x z.
    Returns the satellite's height above lumos-sat's Earth radius [m] (so that ``R + h`` is
    the satellite's true geocentric distance), ``a`` [rad] and the observer's position in
    that frame [m] (so that the satellite-observer vector and range are the true ones).
    """
    r = np.linalg.norm(sat_m, axis=1)
    z = sat_m / r[:, None]
    s = sun_m - sat_m
    s /= np.linalg.norm(s, axis=1)[:, None]
    sz = np.einsum("nk,nk->n", s, z)
    y = s - sz[:, None] * z
    y /= np.linalg.norm(y, axis=1)[:, None]
    x = np.cross(y, z)
    observer_lumos = np.stack([np.einsum("nk,nk->n", obs_m, e) for e in (x, y, z)], axis=1)
    return r - LUMOS_EARTH_RADIUS_M, -np.arcsin(sz), observer_lumos


def lumos_flux_W_m2(
    surfaces: list[Any],
    tle: str,
    site: Site,
    time_utc: NDArray[np.datetime64],
    earthshine: Any = None,
) -> F64:
    """lumos-sat's flux at the site [W m-2] (its ``get_intensity_satellite_frame``) at the
    true geometry of each epoch; ``earthshine``: an Earth BRDF of ``lumos.brdf.library``
    (none: the Sun alone)."""
    from lumos.calculator import get_intensity_satellite_frame

    height, past_terminator, obs = lumos_frame(*astropy_positions_m(tle, site, time_utc))
    return np.array(
        [
            get_intensity_satellite_frame(
                surfaces,
                h,
                a,
                o,
                include_sun=True,
                include_earthshine=earthshine is not None,
                earth_brdf=earthshine,
            )
            for h, a, o in zip(height, past_terminator, obs, strict=True)
        ]
    )


def lumos_magnitude(flux_W_m2: ArrayLike) -> F64:
    """lumos-sat's AB magnitude of a flux [W m-2] (``intensity_to_ab_mag``, not clipped)."""
    nu_hz = LUMOS_SPEED_OF_LIGHT_M_S / LUMOS_WAVELENGTH_M
    with np.errstate(divide="ignore"):
        return -2.5 * np.log10(np.asarray(flux_W_m2) / nu_hz / AB_ZERO_POINT_W_M2_HZ)


def lumos_convention_magnitude(reflectance_factor_m2_sr: ArrayLike, range_m: ArrayLike) -> F64:
    """speclight's reflectance factor [m2 sr-1] as a lumos-sat magnitude: its flux under
    lumos-sat's Sun, ``1360 F / d^2`` [W m-2], through lumos-sat's zero point."""
    rf = np.asarray(reflectance_factor_m2_sr, dtype=np.float64)
    return lumos_magnitude(LUMOS_SUN_W_M2 * rf / np.asarray(range_m, dtype=np.float64) ** 2)


def sun_bridge_mag(time_utc: NDArray[np.datetime64]) -> F64:
    """speclight's AB magnitude in :data:`BAND` minus the lumos-convention magnitude of the
    same grey target [mag]: the two Suns.

    speclight's band flux of a target of reflectance factor ``F`` is ``F / d^2`` times the
    E490 spectrum at the Sun's distance ``r`` through the band; its AB magnitude (photon
    weighted) is ``-2.5 log10(F / d^2 int E R lambda dlambda / (c 3631 Jy int R / lambda
    dlambda))``; lumos-sat's is ``-2.5 log10(F / d^2 1360 W m-2 lambda_0 / (c 3631 Jy))``.
    The difference is ``-2.5 log10(<E>_band (1 AU / r)^2 / (1360 W m-2 / 532 nm))`` with
    ``<E>_band = int E R lambda / int R / lambda``. Computed here from the shipped table
    (ASTM E490-00a, ``src/speclight/data/solar``) read with numpy, the band's Gaussian on a
    0.01 nm grid and astropy's Sun distance: not from speclight's code.
    """
    import astropy.units as u
    from astropy.coordinates import get_sun
    from astropy.time import Time

    path = ROOT / "src/speclight/data/solar/astm_e490_00a_am0.csv"
    wavelength_nm, irradiance = np.loadtxt(path, delimiter=",", comments="#", skiprows=3).T
    lo = SPECTRUM["min_nm"] - SPECTRUM["step_nm"] / 2
    hi = SPECTRUM["max_nm"] + SPECTRUM["step_nm"] / 2
    lam = np.arange(lo, hi, 0.01)
    e = np.interp(lam, wavelength_nm, irradiance)  # [W m-2 nm-1] at 1 AU
    r = np.exp(-0.5 * ((lam - BAND_CENTRE_NM) / BAND_SIGMA_NM) ** 2)
    band_mean = np.trapezoid(e * r * lam, lam) / np.trapezoid(r / lam, lam)  # [W m-2 nm]
    t = Time([str(x) for x in time_utc.astype("datetime64[ns]")], scale="utc")
    r_au = get_sun(t).distance.to(u.au).value
    lumos = LUMOS_SUN_W_M2 * LUMOS_WAVELENGTH_M * 1e9  # [W m-2 nm]
    return -2.5 * np.log10(band_mean / r_au**2 / lumos)


def array_width_px(observer_body: F64, radius_m: float, resolution_px: int) -> F64:
    """Width [px] of the array's image across the image's vertical axis (the render's
    orthographic camera: up is body z made perpendicular to the view, right = up x view):
    a plate seen nearly edge-on covers few pixel columns, and its area is then known to the
    pixel-centre rasterisation's +-1 column."""
    o = observer_body
    up = np.array([0.0, 0.0, 1.0]) - o[:, 2:3] * o
    up /= np.linalg.norm(up, axis=1)[:, None]
    right = np.cross(up, o)
    return ARRAY_WIDTH_M * np.abs(right[:, 1]) / (2.0 * radius_m / resolution_px)


def grid_epochs(loaded: Any) -> NDArray[np.datetime64]:
    """The epochs of a pass that the grid keeps: observable (above the minimum elevation, in
    a dark sky: the Sun below -6 deg at the site), the satellite fully sunlit, and in
    sunlight by lumos-sat's own test too (its spherical Earth's shadow, with 0.5 deg to
    spare: it returns no light past ``arccos(R / (R + h))``)."""
    from speclight.simulation.geometry_stage import scenario_geometry

    geo = scenario_geometry(loaded)
    keep = geo.observable & (geo.sunlit_fraction >= 1.0)
    # geocentric nadir: body +z is minus lumos-sat's z, so its angle past the terminator is
    # arcsin of the Sun's body z component
    past_terminator = np.arcsin(np.clip(geo.sun_direction_body[:, 2], -1.0, 1.0))
    horizon = np.arccos(LUMOS_EARTH_RADIUS_M / np.linalg.norm(geo.r_target_gcrs_m, axis=1))
    with np.errstate(invalid="ignore"):
        keep &= past_terminator < horizon - np.radians(0.5)
    return geo.time_utc[keep]
