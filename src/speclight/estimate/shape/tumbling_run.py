"""Tumbling states for ``speclight shape --tumbling-starts N``: the scenario's target as the
light model, its torque-free attitude (when it has one) as a first start, the families as data.

The light model (:mod:`.tumbling_light`, chosen by :func:`tumbling_light`) is the target's
reflectivity map (rendered, so with the shadows its parts cast on each other), its band
rates turned into the mean reflectance factor of the light curves' bands: the map given
(``map_path``, made by ``speclight reflectivity-map`` from the same scenario), the
scenario's own (``render.mode: map``), or else one built from the scenario and cached
(:mod:`speclight.maps.writer.cached_map`). DAMIT light curves have no bands, and with
``no_map=True`` no map is used: the convex model of the scenario's target mesh
(:func:`.egi.mesh_facets`: faces as the render sees them, without shadows) under the
run's law.

Variables added to SHAPE.nc along ``family`` (lowest chi-square first): ``tumbling_chi2``,
``tumbling_momentum_direction(family, xyz)`` (ecliptic J2000), ``tumbling_rate``
[rad s-1], ``tumbling_moment_ratio(family, ratio)``, their standard deviations
``tumbling_rate_std``, ``tumbling_moment_ratio_std`` and
``tumbling_momentum_direction_std(family, east_north)`` [rad] (:mod:`.tumbling_uncertainty`:
block jackknife with a model-error term), ``tumbling_members``, the best state's
``tumbling_q0(family, quaternion)`` and ``tumbling_omega0(family, xyz)`` [rad s-1] at
``tumbling_t0_jd``. Attributes of the light model: ``tumbling_light_model``
(``reflectivity map`` or ``convex model``), ``tumbling_light_note`` (why, or where the
map comes from: given, the scenario's, built in this run or from the cache, with its
resolution) and, with a map, ``tumbling_map`` (its path), ``tumbling_map_nside``,
``tumbling_map_rolls``, ``tumbling_map_phase_angle_deg`` and
``tumbling_map_resolution_px`` (read from the map); ``tumbling_searched_period_h`` (the
grid's period range [h]: the given range, its upper end raised to the longest light curve's
span).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from speclight.errors import InputError
from speclight.estimate.shape.ecliptic import gcrs_to_ecliptic
from speclight.estimate.shape.egi import mesh_facets
from speclight.estimate.shape.scattering import ScatteringLaw
from speclight.estimate.shape.shape_inputs import ShapeInput
from speclight.estimate.shape.tumbling import TumblingFit, TumblingState, fit_tumbling
from speclight.estimate.shape.tumbling_light import ConvexLight, LightModel, band_map_light
from speclight.maps.writer.cached_map import MapResolution, scenario_map
from speclight.scenario import LoadedScenario


def _prior(inputs: ShapeInput, t0_jd: float) -> list[TumblingState]:
    """The scenario's torque-free state at ``t0_jd`` (diagonal inertia only), or none."""
    from speclight.attitude import torque_free_attitude
    from speclight.attitude.quaternion import quat_from_matrix, quat_multiply
    from speclight.estimate.shape.ecliptic import julian_date
    from speclight.scenario.sections_geometry import TorqueFreeAttitude
    from speclight.simulation.geometry_stage import _orientation

    assert inputs.loaded is not None
    sc = inputs.loaded.scenario
    cfg = sc.attitude
    inertia = np.asarray(getattr(cfg, "inertia_kg_m2", np.eye(3)), float)
    if not isinstance(cfg, TorqueFreeAttitude) or inertia.ndim != 1:
        return []
    start_jd = float(
        julian_date(np.array([np.datetime64(sc.time.start.replace(tzinfo=None), "ns")]))[0]
    )
    q, w = torque_free_attitude(
        np.array([(t0_jd - start_jd) * 86400.0]),
        inertia,
        _orientation(cfg.initial_attitude),
        np.asarray(cfg.angular_velocity_body_rad_s, float),
    )
    to_ecl = quat_from_matrix(gcrs_to_ecliptic(np.eye(3)).T)
    return [TumblingState(quat_multiply(to_ecl, q[0]), w[0], inertia / inertia.max(), 0.0)]


def _require_target(inputs: ShapeInput) -> LoadedScenario:
    if inputs.loaded is None or inputs.loaded.scenario.target is None:
        raise InputError(
            "tumbling states need a scenario with a target (its mesh or its reflectivity map "
            "is the light model): give `loaded`",
            field="n_starts",
        )
    return inputs.loaded


def tumbling_fit(
    inputs: ShapeInput,
    light: LightModel,
    *,
    min_period_h: float,
    max_period_h: float,
    n_starts: int,
    seed: int,
) -> TumblingFit:
    """Fit the torque-free state of the scenario's target to ``inputs`` with the light
    model ``light`` (:func:`tumbling_light`; module doc)."""
    _require_target(inputs)
    d = inputs.data
    seed_curve = int(np.argmax(np.bincount(d.curve)))
    t0 = float(np.mean(d.time_jd[d.curve == seed_curve][[0, -1]]))
    return fit_tumbling(
        d,
        light,
        min_period_h=min_period_h,
        max_period_h=max_period_h,
        n_starts=n_starts,
        seed=seed,
        initial_states=_prior(inputs, t0),
        t0_jd=t0,
    )


@dataclass(frozen=True)
class TumblingLight:
    """The tumbling fit's light ``model`` and what it is: ``kind`` (``reflectivity map`` or
    ``convex model``), ``note`` (why, or where the map comes from) and the map's ``map_path``."""

    model: LightModel
    kind: str
    note: str
    map_path: Path | None = None

    def describe(self) -> str:
        """One line for the messages."""
        where = f" {self.map_path}" if self.map_path is not None else ""
        return f"tumbling light model: {self.kind}{where} ({self.note})"

    def attrs(self) -> dict[str, Any]:
        """SHAPE.nc's attributes of the light model (module doc)."""
        out: dict[str, Any] = {"tumbling_light_model": self.kind, "tumbling_light_note": self.note}
        if self.map_path is not None:
            from speclight.maps.map_lookup import read_header

            h = read_header(self.map_path)
            out.update(
                tumbling_map=str(self.map_path),
                tumbling_map_nside=h.nside,
                tumbling_map_rolls=int(h.roll_deg.size),
                tumbling_map_phase_angle_deg=h.phase_angle_deg,
                tumbling_map_resolution_px=int(h.attrs.get("resolution_px", 0)),
            )
        return out


def tumbling_light(
    inputs: ShapeInput,
    law: ScatteringLaw,
    *,
    map_path: str | Path | None = None,
    no_map: bool = False,
    map_resolution: MapResolution | None = None,
    cache_dir: Path | None = None,
    progress: bool = False,
    say: Callable[[str], None] | None = None,
) -> TumblingLight:
    """The light model of the tumbling fit (module doc).

    Parameters
    ----------
    inputs
        The light curves, with their scenario (``loaded``) and bands.
    law
        The scattering law of the convex model.
    map_path
        A reflectivity map of the scenario's target to use (``speclight reflectivity-map``).
    no_map
        True: the convex model of the mesh; else, without ``map_path``, the scenario's map
        (``render.mode: map``) or one built from it (:func:`.cached_map.scenario_map`).
    map_resolution
        Resolution of the map built (default :meth:`.cached_map.MapResolution.of_nside`).
    cache_dir
        Cache folder of the built maps (default :func:`speclight.cache.cache_root`).
    progress, say
        The build's progress bar and its messages (:func:`.cached_map.scenario_map`).
    """
    loaded = _require_target(inputs)
    if map_path is not None and (no_map or map_resolution is not None):
        raise InputError(
            f"map_path = {map_path} is the map to use: give it without no_map=True (the "
            "convex model) and without map_resolution (of a map built from the scenario)",
            field="map_path",
        )
    if map_resolution is not None and no_map:
        raise InputError(
            f"map_resolution = {map_resolution.nside} is the resolution of a map built from "
            "the scenario: give it without no_map=True (the convex model)",
            field="map_resolution",
        )
    if inputs.bands is None:  # DAMIT light curves: no band rates to read a map with
        for name, value in (("map_path", map_path), ("map_resolution", map_resolution)):
            if value is not None:
                raise InputError(
                    f"{name} = {getattr(value, 'nside', value)}: a reflectivity map needs "
                    "speclight light curves (band rates), not DAMIT's; DAMIT light curves are "
                    "fitted with the convex model of the scenario's mesh",
                    field=name,
                )
        return _convex(loaded, law, "DAMIT light curves have no band rates to read a map with")
    if map_path is None and no_map:
        return _convex(loaded, law, "asked for instead of a map")
    note = "given"
    render = loaded.scenario.render
    if map_path is None and render.mode == "map" and render.map_file is not None:
        if map_resolution is not None:
            raise InputError(
                f"map_resolution = {map_resolution.nside}: the scenario renders from its own "
                f"map (render.map_file = {render.map_file}), which is used; drop map_resolution",
                field="map_resolution",
            )
        map_path, note = loaded.resolve(render.map_file), "the scenario's render.map_file"
    if map_path is None:
        built = scenario_map(
            loaded, inputs.data.phase_angle_deg, map_resolution, cache_dir=cache_dir,
            progress=progress, say=say,
        )  # fmt: skip
        map_path = built.path
        note = (
            f"{'built from the scenario in this run' if built.built else 'from the cache'}: "
            f"{built.resolution.describe()}"
        )
    b = inputs.bands  # the bands averaged into the brightness
    model = band_map_light(map_path, b.band_names, b.response, b.wavelength_nm)
    return TumblingLight(model, "reflectivity map", note, Path(map_path))


def _convex(loaded: LoadedScenario, law: ScatteringLaw, note: str) -> TumblingLight:
    """The convex model of the scenario's target mesh under ``law``."""
    from speclight.simulation.reflection import build_target

    target = build_target(loaded)
    normals, areas = mesh_facets(
        [(p.vertices_m, p.faces) for p in target.parts if p.sphere_radius_m is None]
    )
    return TumblingLight(ConvexLight(normals, areas, law), "convex model", note)


def add_tumbling(
    ds: xr.Dataset, fit: TumblingFit, light: TumblingLight | None = None
) -> xr.Dataset:
    """``ds`` with the families of ``fit`` and the attributes of its ``light`` model
    (module doc)."""
    best = [fam[0] for fam in fit.families]
    v = {
        "tumbling_chi2": (
            ("family",),
            [s.chi2 for s in best],
            {"units": "1", "long_name": "chi-square of the family's best state"},
        ),
        "tumbling_members": (
            ("family",),
            [len(f) for f in fit.families],
            {"units": "1", "long_name": "starts that ended in the family"},
        ),
        "tumbling_momentum_direction": (
            ("family", "xyz"),
            [s.momentum_direction for s in best],
            {"units": "1", "long_name": "angular momentum direction, ecliptic J2000"},
        ),
        "tumbling_rate": (
            ("family",),
            [s.rate_rad_s for s in best],
            {"units": "rad s-1", "long_name": "|H| / I_max"},
        ),
        "tumbling_moment_ratio": (
            ("family", "ratio"),
            [s.moment_ratios for s in best],
            {"units": "1", "long_name": "smaller principal moments over the largest, sorted"},
        ),
        "tumbling_rate_std": (
            ("family",),
            [s.std[0] for s in best],
            {"units": "rad s-1", "long_name": "standard deviation of tumbling_rate"},
        ),
        "tumbling_moment_ratio_std": (
            ("family", "ratio"),
            [s.std[1:3] for s in best],
            {"units": "1", "long_name": "standard deviation of tumbling_moment_ratio"},
        ),
        "tumbling_momentum_direction_std": (
            ("family", "east_north"),
            [s.std[3:5] for s in best],
            {"units": "rad", "long_name": "std of the momentum direction, east and north"},
        ),
        "tumbling_q0": (
            ("family", "quaternion"),
            [s.q0 for s in best],
            {
                "units": "1",
                "long_name": "body-to-ecliptic quaternion at tumbling_t0_jd (w, x, y, z)",
            },
        ),
        "tumbling_omega0": (
            ("family", "xyz"),
            [s.omega0_body_rad_s for s in best],
            {"units": "rad s-1", "long_name": "body rates at tumbling_t0_jd"},
        ),
    }
    out = ds.assign(v)
    out.attrs["tumbling_t0_jd"] = fit.t0_jd
    out.attrs["tumbling_families"] = len(fit.families)
    out.attrs["tumbling_detected"] = int(fit.detected)
    out.attrs["tumbling_p_value"] = fit.p_value
    out.attrs["tumbling_searched_period_h"] = np.asarray(fit.searched_period_h, dtype=float)
    if light is not None:
        out.attrs.update(light.attrs())
    return out
