"""Ground truth for unmixing: each material's share of the band reflectance factors.

With ``render: {per_material: true}`` (single mode) the target is rendered once more with
:func:`speclight.render.material_contributions`, which splits the single-scattering intensity
by material (the pixels that see each material, with the shadows of the whole target), and
each share is carried through the same atmosphere and instrument chain as the total
(:func:`speclight.simulation.radiometry.band_reflectance_factor`). The chain is linear in the
intensity, so the shares sum to ``reflectance_factor`` over the materials (to rounding).

For the lasers the same is done with each laser as the light (its direction and spectral
irradiance at the target, after the uplink), summed over the lasers, against the lasers'
irradiance: the shares of ``laser_reflectance_factor``.

Materials are the scenario's ``target.materials`` entries (one per key, in the target's
order); ``material_reflectance`` labels each with its reflectance (a shipped table name, a
file stem, a number or the n,k name), so that parts sharing a spectrum can be summed.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight import schema
from speclight.render import material_contributions
from speclight.render.session import RenderSession
from speclight.scenario import LoadedScenario
from speclight.scenario.sections_light import (
    Conductor,
    Dielectric,
    ReflectanceFile,
    ReflectancePairs,
    ShippedTable,
)
from speclight.simulation.geometry_stage import Geometry
from speclight.simulation.radiometry import Radiometry, band_reflectance_factor
from speclight.simulation.ranging_stage import RangingSetup, laser_irradiance_W_m2_nm
from speclight.target import Target

F64 = NDArray[np.float64]


def material_labels(loaded: LoadedScenario, target: Target) -> list[str]:
    """A label of each material's reflectance, in ``target.materials`` order."""
    cfg = loaded.scenario.target
    assert cfg is not None
    out: list[str] = []
    for m in target.materials:
        spec = cfg.materials[m.name].reflectance
        if isinstance(spec, ShippedTable):
            out.append(spec.table)
        elif isinstance(spec, ReflectanceFile):
            out.append(Path(spec.file).stem)
        elif isinstance(spec, ReflectancePairs):
            out.append(f"{m.name} (table)")
        elif isinstance(spec, Conductor):
            out.append(f"conductor {spec.conductor}")
        elif isinstance(spec, Dielectric):
            out.append(f"dielectric {spec.dielectric}")
        else:
            out.append(f"{float(spec):g}")
    return out


def _shares(
    loaded: LoadedScenario,
    geo: Geometry,
    wavelength_nm: F64,
    target: Target,
    session: RenderSession,
    lit: NDArray[np.bool_],
    light_dir_body: F64,
    irradiance_W_m2_nm: F64,
) -> F64:
    """Per-material intensity (N, M, L): NaN where not observable, 0 where observable, unlit."""
    n, m = geo.t_s.size, len(target.materials)
    out = np.zeros((n, m, wavelength_nm.size))
    out[~geo.observable] = np.nan
    idx = np.flatnonzero(lit & geo.observable)
    if idx.size:
        part = material_contributions(
            target,
            light_dir_body[idx],
            geo.observer_direction_body[idx],
            irradiance_W_m2_nm[idx],
            wavelength_nm,
            resolution_px=loaded.scenario.render.resolution_px,
            session=session,
        )
        out[idx] = np.nan_to_num(part)  # a row the render could not do: no light
    return out


def _factors(
    loaded: LoadedScenario,
    radiometry: Radiometry,
    wavelength_nm: F64,
    shares: F64,
    transmission: F64,
    range_m: F64,
    illumination: F64,
) -> F64:
    return np.stack(
        [
            band_reflectance_factor(
                loaded, radiometry, wavelength_nm, shares[:, k], transmission, range_m, illumination
            )
            for k in range(shares.shape[1])
        ],
        axis=1,
    )


def solar_material_factors(
    loaded: LoadedScenario,
    geo: Geometry,
    wavelength_nm: F64,
    target: Target,
    session: RenderSession,
    solar_irradiance_W_m2_nm: F64,
    transmission: F64,
    radiometry: Radiometry,
) -> F64:
    """Each material's share of ``reflectance_factor`` (N, M, B) [m2 sr-1] under the Sun."""
    sunlit = geo.sunlit_fraction
    irradiance = solar_irradiance_W_m2_nm * sunlit[:, None]  # penumbra: as the pipeline
    shares = _shares(
        loaded, geo, wavelength_nm, target, session, sunlit > 0, geo.sun_direction_body, irradiance
    )
    illumination = irradiance * transmission
    return _factors(
        loaded, radiometry, wavelength_nm, shares, transmission, geo.range_m, illumination
    )


def laser_material_factors(
    loaded: LoadedScenario,
    geo: Geometry,
    wavelength_nm: F64,
    target: Target,
    session: RenderSession,
    setup: RangingSetup,
    transmission: F64,
    radiometry: Radiometry,
) -> F64:
    """Each material's share of ``laser_reflectance_factor`` (N, M, B) [m2 sr-1]."""
    n_wl = wavelength_nm.size
    shares = np.zeros((geo.t_s.size, len(target.materials), n_wl))
    for laser in setup.lasers:
        light = laser.light
        irradiance = np.zeros((geo.t_s.size, n_wl))
        irradiance[:, light.support] = light.irradiance_W_m2_nm
        shares += _shares(
            loaded,
            geo,
            wavelength_nm,
            target,
            session,
            laser.above_horizon,
            np.nan_to_num(light.direction_body),
            irradiance,
        )
    illumination = laser_irradiance_W_m2_nm(setup, n_wl) * np.nan_to_num(transmission)
    return _factors(
        loaded, radiometry, wavelength_nm, shares, transmission, geo.range_m, illumination
    )


def add_per_material(
    ds: xr.Dataset,
    names: list[str],
    labels: list[str],
    solar: F64 | None,
    laser: F64 | None,
) -> xr.Dataset:
    """The dataset with the ``material`` coordinate and the per-material factors."""
    ds = ds.assign_coords(material=("material", np.array(names, dtype=str)))
    ds["material"].attrs.update(schema.COORDINATES["material"])
    ds["material_reflectance"] = schema.variable(
        "material_reflectance", np.array(labels, dtype=str)
    )
    if solar is not None:
        ds["reflectance_factor_material"] = schema.variable("reflectance_factor_material", solar)
    if laser is not None:
        ds["laser_reflectance_factor_material"] = schema.variable(
            "laser_reflectance_factor_material", laser
        )
    return ds
