"""Tumbling states from far starts: fraction of random true states recovered (issue 27).

Each draw: a torque-free box-wing (no dish; its mesh's EGI, Lambert) with a random state
(attitude uniform, second moments ``u`` uniform in [-1.5, 1.5]^2, body rates in a random
direction at least 20 deg from every principal axis, a turn every 0.035-0.08 h), seen over
two 10-min passes 90 min apart (a point every 10 s, 1 % noise). ``--model convex``: the light
curves from the convex model itself (no model error), fitted with it; ``--model map``: the
passes rendered by speclight (128 px, the bus and wings shadowing each other) and fitted
with the box-wing's reflectivity map (:func:`tabulated_map`: speclight's render at every
node, HEALPix ``--map-nside``, phase angles 30-110 deg, ``--map-rolls`` rolls,
``--map-px``; built once, reused for every draw). Fitted with no knowledge of the truth:
``grid`` (the coarse grid and continuation, :mod:`speclight.estimate.shape.tumbling_search`)
or ``random`` (random starts only, the earlier method). A draw is recovered when a reported
family is the truth's or its mirror's (:func:`same_family`,
:mod:`speclight.estimate.shape.tumbling_mirror`: the geometry is nearly coplanar), and
"best" when the lowest one is. Each draw gives the truth's own chi-square (not refitted):
what the light model allows at the true state; with ``--refit-truth`` also a refit from
the truth itself (no grid, the rate fixed; its stage 1 on the first pass alone can wander
off, so no reference). ``--only 2,5`` runs those draws alone (the same states and noise).

    .venv/bin/python bench/bench_tumbling_far.py --draws 20 --method grid
    .venv/bin/python bench/bench_tumbling_far.py --draws 20 --model map
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.spatial.transform import Rotation

from speclight.attitude import torque_free_attitude
from speclight.attitude.quaternion import quat_conjugate, quat_rotate
from speclight.estimate.shape.convex_model import facet_brightness, relative_residuals
from speclight.estimate.shape.ecliptic import angular_distance_deg
from speclight.estimate.shape.egi import mesh_facets
from speclight.estimate.shape.inversion_data import build_inversion_data
from speclight.estimate.shape.scattering import scattering_law
from speclight.estimate.shape.tumbling import TumblingState, fit_tumbling, same_family
from speclight.estimate.shape.tumbling_light import (
    ConvexLight,
    LightModel,
    MapLight,
    tabulated_map,
)
from speclight.estimate.shape.tumbling_mirror import mirror_plane, mirror_state
from speclight.estimate.shape.tumbling_search import moments_from_u
from speclight.render import render_intensity
from speclight.target import shapes
from speclight.target.materials import Material, Reflectance
from speclight.target.parts import Part, Target

WHITE = Material(name="w", bsdf="lambertian", reflectance=Reflectance.constant(1.0, field="r"))


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def geometry() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t_s = np.concatenate([np.arange(0, 600, 10.0), 5400 + np.arange(0, 600, 10.0)])
    sun = np.tile(_unit(np.array([1.0, 0.2, 0.1])), (t_s.size, 1))
    az = np.deg2rad(np.concatenate([np.linspace(60, 120, 60), np.linspace(50, 110, 60)]))
    obs = _unit(np.stack([np.cos(az), np.sin(az), 0.3 * np.ones_like(az)], axis=1))
    return t_s, sun, obs


def render(mesh: Target, sun_body: np.ndarray, obs_body: np.ndarray, px: int) -> np.ndarray:
    """speclight's render of the white mesh per unit solar irradiance [m2 sr-1] (N,)."""
    n = len(sun_body)
    res = render_intensity(
        mesh, sun_body, obs_body, np.ones((n, 1)), np.array([550.0]), resolution_px=px
    )
    return np.asarray(res.intensity_W_sr_nm[:, 0])


def map_light(mesh: Target, px: int, nside: int, n_rolls: int) -> MapLight:
    """The light model of ``mesh``'s map rendered at ``px`` on HEALPix ``nside`` directions,
    phase angles 30-110 deg every 10 deg and ``n_rolls`` rolls; says its build time."""
    start = time.perf_counter()
    rmap = tabulated_map(
        lambda s_b, o_b: render(mesh, s_b, o_b, px), nside=nside,
        phase_angle_deg=np.arange(30.0, 120.0, 10.0), n_rolls=n_rolls,
    )  # fmt: skip
    print(f"map built in {time.perf_counter() - start:.1f} s (wall)", flush=True)
    return MapLight(rmap)


def describe(s: TumblingState) -> str:
    """Period ``2 pi / rate`` [s], sorted moment ratios, momentum direction (ecliptic)."""
    h = s.momentum_direction
    lon, lat = np.degrees(np.arctan2(h[1], h[0])) % 360, np.degrees(np.arcsin(h[2]))
    return (
        f"period {2 * np.pi / s.rate_rad_s:.0f} s ratios {np.round(s.moment_ratios, 3)} "
        f"H ({lon:.0f}, {lat:.0f}) deg"
    )


def draw_truth(rng: np.random.Generator) -> TumblingState:
    moments = moments_from_u(rng.uniform(-1.5, 1.5, 2))
    while True:
        d = _unit(rng.normal(size=3))
        if np.max(np.abs(d)) < np.cos(np.deg2rad(20.0)):
            break
    period_s = 3600.0 * rng.uniform(0.035, 0.08)
    q0 = Rotation.random(rng=rng).as_quat(scalar_first=True)
    return TumblingState(q0, 2 * np.pi / period_s * d, moments, 0.0)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--draws", type=int, default=20)
    ap.add_argument("--seed", type=int, default=2027)
    ap.add_argument("--method", choices=["grid", "random"], default="grid")
    ap.add_argument("--random-starts", type=int, default=48)
    ap.add_argument("--model", choices=["convex", "map"], default="convex")
    ap.add_argument("--map-nside", type=int, default=8)
    ap.add_argument("--map-rolls", type=int, default=32)
    ap.add_argument("--map-px", type=int, default=64)
    ap.add_argument("--render-px", type=int, default=128)
    ap.add_argument("--refit-truth", action="store_true", help="also refit from the truth")
    ap.add_argument("--only", type=str, default="", help="comma-separated draws to run")
    a = ap.parse_args()
    only = {int(k) for k in a.only.split(",") if k}
    parts = [(p.vertices_m, p.faces) for p in shapes.box_wing(WHITE, dish=False).parts]
    normals, areas = mesh_facets(parts)
    law = scattering_law("lambert")
    offsets = np.cumsum([0] + [len(v) for v, _ in parts[:-1]])
    faces = np.vstack([f + o for (_, f), o in zip(parts, offsets, strict=True)])
    mesh = Target(parts=(Part("body", np.vstack([v for v, _ in parts]), faces, WHITE),))
    light: LightModel = ConvexLight(normals, areas, law)
    if a.model == "map":
        light = map_light(mesh, a.map_px, a.map_nside, a.map_rolls)
    t_s, sun, obs = geometry()
    chp = np.sqrt(0.5 * (1 + np.sum(sun * obs, axis=1)))
    t_jd = 2459000.5 + t_s / 86400.0
    plane = mirror_plane(sun, obs)[0]
    common = dict(min_period_h=0.03, max_period_h=0.1, t0_jd=t_jd[0])
    rng = np.random.default_rng(a.seed)
    hits = best = 0
    for k in range(a.draws):
        truth = draw_truth(rng)
        noise = rng.normal(size=t_s.size)  # drawn for every draw: --only keeps the stream
        if only and k not in only:
            continue
        q, _ = torque_free_attitude(t_s, truth.moments, truth.q0, truth.omega0_body_rad_s)
        qc = quat_conjugate(q)
        sun_b, obs_b = quat_rotate(qc, sun), quat_rotate(qc, obs)
        if a.model == "map":
            y = render(mesh, sun_b, obs_b, a.render_px)
        else:
            y = facet_brightness(sun_b, obs_b, normals, areas, law, chp)
        sigma = 0.01 * np.mean(y)
        data = build_inversion_data(
            t_jd, y + sigma * noise, np.full(y.size, sigma), sun, obs,
            np.repeat([0, 1], 60), np.array([False, False]), "bench",
        )  # fmt: skip
        # the truth itself, not refitted: the light model's own error at the true state
        at_truth_chi2 = float(np.sum(relative_residuals(data, light(sun_b, obs_b, chp)) ** 2))
        start = time.process_time()
        fit = fit_tumbling(
            data, light, n_starts=0 if a.method == "grid" else a.random_starts, seed=k,
            rate_span=0.015, grid=a.method == "grid", **common,
        )  # fmt: skip
        cpu = time.process_time() - start
        refit = float("nan")
        if a.refit_truth:
            refit = fit_tumbling(
                data, light, initial_states=[truth], n_starts=0, rate_span=0.0, grid=False,
                **common,
            ).families[0][0].chi2  # fmt: skip
        mirror = mirror_state(truth, plane)
        found = [same_family(f[0], truth) or same_family(f[0], mirror) for f in fit.families]
        hits += any(found)
        best += found[0]
        top = fit.families[0][0]
        off = [angular_distance_deg(top.momentum_direction, r.momentum_direction)
               for r in (truth, mirror)]  # fmt: skip
        print(
            f"draw {k}: truth {describe(truth)}\n"
            f"  start: {a.method} (no prior), periods searched "
            f"{np.round(3600 * np.array(fit.searched_period_h))} s\n"
            f"  found: {describe(top)}; H {off[0]:.1f} deg from the truth's, {off[1]:.1f} "
            f"from the mirror's; detected {fit.detected}\n"
            f"  recovered {any(found)} best {found[0]} families {len(found)} "
            f"chi2 {top.chi2:.1f} (the truth {at_truth_chi2:.1f}, refitted from it "
            f"{refit:.1f}; n=120) "
            f"cpu {cpu:.1f} s",
            flush=True,
        )
    n = len(only) if only else a.draws
    print(f"{a.model} {a.method}: recovered {hits}/{n}, best {best}/{n}")


if __name__ == "__main__":
    main()
