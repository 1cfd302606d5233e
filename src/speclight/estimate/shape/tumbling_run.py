"""Tumbling states for ``speclight shape --tumbling-starts N``: the scenario's target as the
EGI, its torque-free attitude (when it has one) as a first start, the families as data.

The light model (:mod:`.tumbling_light`) is the convex model of the scenario's target mesh
(:func:`.egi.mesh_facets`: faces as the render sees them, without the shadows parts cast on
each other) under the run's law, or, with ``map_path``, the target's reflectivity map (made
by ``speclight reflectivity-map`` from the same scenario: rendered, so with the shadows),
its band rates turned into the mean reflectance factor of the light curves' bands. Variables added
to SHAPE.nc along ``family`` (lowest chi-square first): ``tumbling_chi2``,
``tumbling_momentum_direction(family, xyz)`` (ecliptic J2000), ``tumbling_rate`` [rad s-1],
``tumbling_moment_ratio(family, ratio)``, their standard deviations ``tumbling_rate_std``,
``tumbling_moment_ratio_std`` and ``tumbling_momentum_direction_std(family, east_north)``
[rad] (:mod:`.tumbling_uncertainty`: block jackknife with a model-error term),
``tumbling_members``, the best state's
``tumbling_q0(family, quaternion)`` and ``tumbling_omega0(family, xyz)`` [rad s-1] at
``tumbling_t0_jd``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr

from speclight.errors import InputError
from speclight.estimate.shape.ecliptic import gcrs_to_ecliptic
from speclight.estimate.shape.egi import mesh_facets
from speclight.estimate.shape.scattering import ScatteringLaw
from speclight.estimate.shape.shape_inputs import ShapeInput
from speclight.estimate.shape.tumbling import TumblingFit, TumblingState, fit_tumbling
from speclight.estimate.shape.tumbling_light import ConvexLight, LightModel, band_map_light


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


def tumbling_fit(
    inputs: ShapeInput,
    law: ScatteringLaw,
    *,
    min_period_h: float,
    max_period_h: float,
    n_starts: int,
    seed: int,
    map_path: str | Path | None = None,
) -> TumblingFit:
    """Fit the torque-free state of the scenario's target to ``inputs`` (module doc)."""
    if inputs.loaded is None or inputs.loaded.scenario.target is None:
        raise InputError(
            "tumbling states need a scenario with a target (its mesh is the EGI): give `loaded`",
            field="n_starts",
        )
    d = inputs.data
    light = _light(inputs, law, map_path)
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


def _light(inputs: ShapeInput, law: ScatteringLaw, map_path: str | Path | None) -> LightModel:
    """The map's light model with ``map_path``, else the convex model of the target's mesh."""
    assert inputs.loaded is not None
    if map_path is not None:
        if inputs.bands is None:
            raise InputError(
                "a reflectivity map needs speclight light curves (band rates), not DAMIT's",
                field="map_path",
            )
        b = inputs.bands  # the bands averaged into the brightness
        return band_map_light(map_path, b.band_names, b.response, b.wavelength_nm)
    from speclight.simulation.reflection import build_target

    target = build_target(inputs.loaded)
    normals, areas = mesh_facets(
        [(p.vertices_m, p.faces) for p in target.parts if p.sphere_radius_m is None]
    )
    return ConvexLight(normals, areas, law)


def add_tumbling(ds: xr.Dataset, fit: TumblingFit) -> xr.Dataset:
    """``ds`` with the families of ``fit`` (module doc)."""
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
    return out
