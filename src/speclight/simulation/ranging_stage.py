"""Active illumination and laser ranging stage of the pipeline (lasers from the scenario).

Use from :func:`speclight.simulation.pipeline.simulate`::

    setup = prepare_ranging(loaded, geo, wavelength_nm, target, session)  # None without lasers
    # optional, for speed in single mode: reuse the Sun render's primary rays
    #   render_intensity(..., on_hits=setup.on_hits_for(idx))     # idx: epochs rendered
    ranging = laser_ranging(loaded, geo, setup, transmission, radiometry)
    ds = ranging.add_to(ds)

Per laser and epoch: the transmitter's own range, elevation and body-frame direction
(:mod:`speclight.ranging.transmitter`); the beam irradiance at the target from the full
divergence and range (:mod:`speclight.illumination.laser`); the uplink transmission at the
transmitter's elevation from its own altitude; the line shape on the grid. The target is
rendered with each laser as light source (:mod:`speclight.render.laser_returns`), and the return is
carried to the receiver with the downlink transmission, aperture and band response
(:mod:`speclight.ranging.link`; the range bins: :mod:`speclight.ranging.bins`). A laser below
its transmitter's horizon contributes nothing at that epoch and sets the flag bit
:data:`~speclight.schema.FLAG_LASER_BELOW_HORIZON` (returned in ``RangingSetup.flags``); the
run goes on. In ``render.mode: path``
the interreflections are added at their full optical path length
(:mod:`speclight.render.laser_multibounce`, Monte Carlo with ``render.samples_per_pixel`` and
``render.seed``); single mode is single scattering, exact. In ``render.mode: map`` nothing is
rendered: the target's returns come from the reflectivity map
(:mod:`speclight.simulation.map_ranging`, ``RangingSetup.map_returns``) and the rest of this
stage is the same.

The centre of mass is the body-frame origin.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight import atmosphere, instrument, orbit, schema
from speclight.errors import InputError
from speclight.illumination import laser as lz
from speclight.instrument.photometry import photon_kernel
from speclight.orbit.timescale import time_from_utc
from speclight.ranging import link, transmitter_geometry
from speclight.ranging.bins import RANGE_BINS, range_bin_edges_m
from speclight.render.bsdfs import material_bsdf
from speclight.render.laser_returns import LaserLight, LaserReturnAccumulator, LaserReturns
from speclight.render.path_scene import MAX_DEPTH as PATH_MAX_DEPTH
from speclight.render.session import RenderSession
from speclight.scenario import LoadedScenario
from speclight.simulation.geometry_stage import Geometry
from speclight.simulation.map_ranging import scenario_map_returns
from speclight.simulation.radiometry import Radiometry, atmosphere_params
from speclight.simulation.ranging_dataset import RangingResult
from speclight.target import Target
from speclight.wavelength_grid import grid_bin_bounds_nm

F64 = NDArray[np.float64]
#: Line-shape values below this fraction of the peak are outside the laser's support.
SUPPORT_THRESHOLD = 1e-9
#: Smallest fraction of a laser line's energy that must fall inside the spectrum grid.
MIN_LINE_FRACTION = 0.99


@dataclass
class LaserSetup:
    """One laser: name, pulse rate [Hz], geometry (N,), irradiance (N,) [W m-2] at the target
    after the uplink, and the light for the render."""

    name: str
    repetition_rate_hz: float
    range_m: F64
    elevation_deg: F64
    above_horizon: NDArray[np.bool_]
    irradiance_W_m2: F64
    light: LaserLight


@dataclass
class RangingSetup:
    """Lasers, the render accumulator and the render session of one run, and the flag bits
    (N,) this stage sets (:data:`~speclight.schema.FLAG_LASER_BELOW_HORIZON`). In
    ``render.mode: map`` there is no render: ``map_returns`` gives the returns instead
    (:mod:`speclight.simulation.map_ranging`)."""

    lasers: list[LaserSetup]
    accumulator: LaserReturnAccumulator | None
    session: RenderSession | None
    flags: NDArray[np.uint16]
    wavelength_nm: F64
    map_returns: Callable[[], LaserReturns] | None = None

    def on_hits_for(self, epochs: NDArray[np.int64]) -> Callable[..., None]:
        """``on_hits`` callback for a render of ``geo`` epochs ``epochs`` (in that order)."""
        assert self.accumulator is not None
        index = np.asarray(epochs, dtype=np.int64)

        def call(local: NDArray[np.int64], *rest: Any) -> None:
            assert self.accumulator is not None
            self.accumulator(index[local], *rest)

        return call


def line_shape_per_nm(loaded: LoadedScenario, cfg: Any, wl: F64, where: str) -> F64:
    """A laser's unit-area line shape on the grid [nm-1] (its spectrum file or a Gaussian);
    the support the pipeline keeps is where it exceeds ``SUPPORT_THRESHOLD`` x its peak."""
    if cfg.spectrum_file:
        x, y = lz.read_laser_spectrum(loaded.resolve(cfg.spectrum_file))
        shape = lz.table_line_per_nm(wl, x, y)
    else:
        shape = lz.gaussian_line_per_nm(wl, cfg.wavelength_nm, cfg.linewidth_nm)
    frac = lz.line_fraction_in_grid(shape, wl)
    if frac < MIN_LINE_FRACTION:
        raise InputError(
            f"only {100 * frac:.3g} % of the line at {cfg.wavelength_nm:g} nm falls inside the "
            f"spectrum grid {wl[0]:g}..{wl[-1]:g} nm; widen spectrum.min_nm/max_nm",
            source=loaded.source,
            field=f"{where}.wavelength_nm",
        )
    return shape


def _laser(loaded: LoadedScenario, geo: Geometry, wl: F64, k: int, t: Any) -> LaserSetup:
    cfg = loaded.scenario.illumination.lasers[k]
    where = f"illumination.lasers[{k}]"
    # (simulate() prefixes the scenario file to these messages)
    # power, rate and divergence were checked when the scenario was loaded (Laser model)
    power, rate = cfg.power_w, cfg.repetition_rate_hz
    theta = cfg.divergence_arcsec * lz.ARCSEC_RAD
    site = orbit.Site(cfg.latitude_deg, cfg.longitude_deg, cfg.altitude_m)
    tx = transmitter_geometry(site, t, geo.r_target_gcrs_m, geo.quaternion_body_to_gcrs)
    min_el = cfg.min_elevation_deg
    with np.errstate(invalid="ignore"):
        up = geo.orbit_ok & (tx.elevation_deg > min_el)
    offset = cfg.pointing_offset_arcsec * lz.ARCSEC_RAD
    beam = lz.beam_irradiance_W_m2(power, theta, tx.range_m, offset, cfg.beam_profile)
    shape = line_shape_per_nm(loaded, cfg, wl, where)
    support = np.flatnonzero(shape > SUPPORT_THRESHOLD * shape.max())
    elev = np.where(up, tx.elevation_deg, np.nan)
    t_up = np.zeros((len(elev), support.size))
    if np.any(up):
        full = atmosphere.transmission(
            loaded.scenario.atmosphere.model,
            wl,
            elev[up],
            cfg.altitude_m,
            params=atmosphere_params(loaded),
        )
        t_up[up] = full[:, support]
    spectral = link.uplink_spectral_irradiance(beam, shape[support], t_up, up)
    lo, hi = grid_bin_bounds_nm(wl)
    irradiance = link.uplink_irradiance_W_m2(spectral, (hi - lo)[support], geo.orbit_ok)
    direction = np.where(up[:, None], tx.direction_body, np.nan)
    return LaserSetup(
        cfg.name,
        rate,
        tx.range_m,
        tx.elevation_deg,
        up,
        irradiance,
        LaserLight(direction, support, spectral),
    )


def prepare_ranging(
    loaded: LoadedScenario,
    geo: Geometry,
    wavelength_nm: F64,
    target: Target | None,
    session: RenderSession | None,
    range_bins: int = RANGE_BINS,
) -> RangingSetup | None:
    """Lasers' geometry and irradiance, and the accumulator; ``None`` without lasers/target.

    ``target`` and ``session``: the run's target and render session (built once per run);
    in ``render.mode: map`` both are ``None`` and the returns come from the map.
    """
    sc = loaded.scenario
    map_mode = sc.render.mode == "map"
    if not sc.illumination.lasers or (not map_mode and (target is None or session is None)):
        return None
    t = time_from_utc(geo.time_utc)
    lasers = [_laser(loaded, geo, wavelength_nm, k, t) for k in range(len(sc.illumination.lasers))]
    flags = np.zeros(geo.t_s.size, dtype=schema.FLAG_DTYPE)
    for laser in lasers:
        flags[geo.orbit_ok & ~laser.above_horizon] |= schema.FLAG_LASER_BELOW_HORIZON
    obs = np.where(geo.observable[:, None], geo.observer_direction_body, np.nan)
    if map_mode:

        def from_map() -> LaserReturns:
            lights = [la.light for la in lasers]
            return scenario_map_returns(loaded, obs, lights, wavelength_nm)

        return RangingSetup(lasers, None, None, flags, wavelength_nm, from_map)
    assert target is not None and session is not None
    acc = _accumulator(loaded, target, obs, lasers, wavelength_nm, range_bins)
    return RangingSetup(lasers, acc, session, flags, wavelength_nm)


def _accumulator(
    loaded: LoadedScenario,
    target: Target,
    obs: F64,
    lasers: list[LaserSetup],
    wavelength_nm: F64,
    range_bins: int,
) -> LaserReturnAccumulator:
    """The render of the lasers' light at the target, resolved in range (centre of mass at
    the body origin; multi-bounce paths in path mode)."""
    sc = loaded.scenario
    com = np.zeros(3)
    path = sc.render.mode == "path"
    return LaserReturnAccumulator(
        target,
        obs,
        [la.light for la in lasers],
        wavelength_nm,
        range_bin_edges_m(target, com, range_bins, multibounce=path),
        com,
        max_depth=PATH_MAX_DEPTH if path else 2,
        samples_per_pixel=sc.render.samples_per_pixel,
        seed=sc.render.seed,
    )


def laser_irradiance_W_m2_nm(setup: RangingSetup, n_wavelengths: int) -> F64:
    """Spectral irradiance of all lasers at the target on the full grid (N, L) [W m-2 nm-1]
    (after the uplink; 0 off the lines and where a laser is below its horizon)."""
    n = setup.lasers[0].light.irradiance_W_m2_nm.shape[0] if setup.lasers else 0
    out = np.zeros((n, n_wavelengths))
    for laser in setup.lasers:
        out[:, laser.light.support] += laser.light.irradiance_W_m2_nm
    return out


def laser_ranging(
    loaded: LoadedScenario,
    geo: Geometry,
    setup: RangingSetup,
    transmission: F64,
    radiometry: Radiometry | None,
) -> RangingResult:
    """Finish the laser render and carry the returns to the receiver (module docstring).

    Parameters
    ----------
    loaded, geo
        The run's scenario and geometry.
    setup
        From :func:`prepare_ranging` (its accumulator may already hold the shared-ray epochs).
    transmission
        (N, L) downlink transmission target -> observer [1].
    radiometry
        The instrument curves (band response, optics, QE); ``None``: no band outputs.
    """
    sc = loaded.scenario
    wavelength_nm = setup.wavelength_nm
    rr = _target_returns(setup, sc.render.resolution_px)
    n, n_wl = geo.t_s.size, wavelength_nm.size
    obs = geo.observable
    intensity = np.zeros((n, n_wl))
    for k, laser in enumerate(setup.lasers):
        intensity[:, laser.light.support] += rr.intensity_W_sr_nm(k)
    bands = radiometry.band_names if radiometry is not None else []
    if radiometry is not None:
        received = _received(loaded, geo, setup, rr, transmission, radiometry)
    else:
        n_bins, k_las = len(rr.bin_edges_m) - 1, len(setup.lasers)
        received = (
            np.zeros((n, k_las, 0)), np.zeros((n, 0)), np.zeros((n, 0, n_bins)),
            np.zeros((n, 0)), np.zeros((n, 0)),
        )  # fmt: skip
    for a in (intensity, *received):
        a[~obs] = np.nan
    per_pulse, total, hist, offset, factor = received
    return RangingResult(
        laser_names=[la.name for la in setup.lasers],
        band_names=list(bands),
        range_bin_edges_m=rr.bin_edges_m,
        laser_range_m=np.stack([la.range_m for la in setup.lasers], axis=1),
        laser_elevation_deg=np.stack([la.elevation_deg for la in setup.lasers], axis=1),
        laser_irradiance_W_m2=np.stack([la.irradiance_W_m2 for la in setup.lasers], axis=1),
        laser_intensity_W_sr_nm=intensity,
        return_per_pulse=per_pulse,
        return_rate_per_s=total,
        range_histogram_per_s=hist,
        range_offset_m=offset,
        reflectance_factor_m2_sr=factor,
        notes=_ranging_notes(loaded, geo, setup),
    )


def _target_returns(setup: RangingSetup, resolution_px: int) -> LaserReturns:
    """The returns at the target: from the map, or the accumulator's (finished here for
    the epochs the Sun's render did not share its rays with)."""
    if setup.map_returns is not None:  # render.mode map: the returns from the map
        return setup.map_returns()
    acc = setup.accumulator
    assert acc is not None and setup.session is not None
    if np.any(acc.active & ~acc.rendered):
        acc.finish(setup.session.caster(acc.target), resolution_px)
    return acc.result()


def _received(
    loaded: LoadedScenario,
    geo: Geometry,
    setup: RangingSetup,
    rr: LaserReturns,
    transmission: F64,
    radiometry: Radiometry,
) -> tuple[F64, F64, F64, F64, F64]:
    """Per band: returns per pulse (N, K, B), rate (N, B), range histogram (N, B, bins),
    centre-of-mass offset (N, B) and reflectance factor (N, B) at the receiver."""
    sc = loaded.scenario
    wavelength_nm = setup.wavelength_nm
    n_wl = wavelength_nm.size
    area = instrument.aperture_area_m2(
        sc.telescope.aperture_diameter_m, sc.telescope.obstruction_diameter_m
    )
    # electrons per joule per bin x width (B, L); each band's own detector QE is folded
    # into its response, as for the Sun's count rates (simulation/radiometry.py)
    kernel = photon_kernel(
        wavelength_nm,
        radiometry.optics,
        np.ones(n_wl),
        radiometry.band_response * radiometry.qe,
    )
    conversions = [
        link.downlink_conversion(
            transmission[:, la.light.support],
            geo.observable,
            geo.range_m,
            area,
            kernel[:, la.light.support],
        )
        for la in setup.lasers
    ]
    returns = link.receiver_returns(
        rr.histogram, rr.moment_m, conversions, [la.repetition_rate_hz for la in setup.lasers]
    )
    # eq. 5 with the lasers' line instead of the Sun (docs/upsample-unmix.md): the same
    # reflectance factor as the Sun's, from the return rates and the lasers' irradiance
    illumination = laser_irradiance_W_m2_nm(setup, n_wl) * np.nan_to_num(transmission)
    factor = instrument.reflectance_factor_m2_sr(
        returns.rate_per_s,
        geo.range_m,
        area,
        illumination,
        wavelength_nm,
        radiometry.optics,
        np.ones(n_wl),
        radiometry.band_response * radiometry.qe,
    )
    return (
        returns.per_pulse,
        returns.rate_per_s,
        returns.histogram_per_s,
        returns.offset_m,
        factor,
    )


def _ranging_notes(loaded: LoadedScenario, geo: Geometry, setup: RangingSetup) -> list[str]:
    """What the run should say about its laser returns (lasers below the horizon, mirrors)."""
    notes = []
    obs = geo.observable
    below = [la.name for la in setup.lasers if np.any(obs & geo.orbit_ok & ~la.above_horizon)]
    if below:
        notes.append(
            f"laser(s) {', '.join(below)} below the transmitter's horizon at some observable "
            "epochs (flag laser_below_horizon): no return from them there"
        )
    acc = setup.accumulator
    if (
        acc is not None
        and loaded.scenario.render.mode == "path"
        and any(material_bsdf(m).mirror_lobe() for m in acc.target.materials)
    ):
        notes.append(
            "laser ranging in render.mode 'path' does not follow the mirror reflection of "
            "smooth (specular, smooth plastic) surfaces between bounces"
        )
    return notes
