"""Tumbling states from far starts: fraction of random true states recovered (issue 27).

Each draw: a torque-free box-wing (no dish; its mesh's EGI, Lambert) with a random state
(attitude uniform, second moments ``u`` uniform in [-1.5, 1.5]^2, body rates in a random
direction at least 20 deg from every principal axis, a turn every 0.035-0.08 h), seen over
two 10-min passes 90 min apart (a point every 10 s, 1 % noise; the light curves from the
convex model itself, so no model error). Fitted with no knowledge of the truth:
``grid`` (the coarse grid and continuation, :mod:`speclight.estimate.shape.tumbling_search`)
or ``random`` (random starts only, the earlier method). A draw is recovered when a reported
family is the truth's or its mirror's (:func:`same_family`,
:mod:`speclight.estimate.shape.tumbling_mirror`: the geometry is nearly coplanar), and
"best" when the lowest one is.

    .venv/bin/python bench/bench_tumbling_far.py --draws 20 --method grid
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.spatial.transform import Rotation

from speclight.attitude import torque_free_attitude
from speclight.attitude.quaternion import quat_conjugate, quat_rotate
from speclight.estimate.shape.convex_model import facet_brightness
from speclight.estimate.shape.egi import mesh_facets
from speclight.estimate.shape.inversion_data import build_inversion_data
from speclight.estimate.shape.scattering import scattering_law
from speclight.estimate.shape.tumbling import TumblingState, fit_tumbling, same_family
from speclight.estimate.shape.tumbling_light import ConvexLight
from speclight.estimate.shape.tumbling_mirror import mirror_plane, mirror_state
from speclight.estimate.shape.tumbling_search import moments_from_u
from speclight.target import shapes
from speclight.target.materials import Material, Reflectance


def _unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def geometry() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    t_s = np.concatenate([np.arange(0, 600, 10.0), 5400 + np.arange(0, 600, 10.0)])
    sun = np.tile(_unit(np.array([1.0, 0.2, 0.1])), (t_s.size, 1))
    az = np.deg2rad(np.concatenate([np.linspace(60, 120, 60), np.linspace(50, 110, 60)]))
    obs = _unit(np.stack([np.cos(az), np.sin(az), 0.3 * np.ones_like(az)], axis=1))
    return t_s, sun, obs


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
    a = ap.parse_args()
    white = Material(name="w", bsdf="lambertian", reflectance=Reflectance.constant(1.0, field="r"))
    parts = [(p.vertices_m, p.faces) for p in shapes.box_wing(white, dish=False).parts]
    normals, areas = mesh_facets(parts)
    law = scattering_law("lambert")
    t_s, sun, obs = geometry()
    chp = np.sqrt(0.5 * (1 + np.sum(sun * obs, axis=1)))
    t_jd = 2459000.5 + t_s / 86400.0
    rng = np.random.default_rng(a.seed)
    hits = best = 0
    for k in range(a.draws):
        truth = draw_truth(rng)
        q, _ = torque_free_attitude(t_s, truth.moments, truth.q0, truth.omega0_body_rad_s)
        qc = quat_conjugate(q)
        y = facet_brightness(quat_rotate(qc, sun), quat_rotate(qc, obs), normals, areas, law, chp)
        sigma = 0.01 * np.mean(y)
        data = build_inversion_data(
            t_jd, y + sigma * rng.normal(size=y.size), np.full(y.size, sigma), sun, obs,
            np.repeat([0, 1], 60), np.array([False, False]), "bench",
        )  # fmt: skip
        start = time.process_time()
        fit = fit_tumbling(
            data, ConvexLight(normals, areas, law), min_period_h=0.03, max_period_h=0.1,
            n_starts=0 if a.method == "grid" else a.random_starts,
            seed=k, t0_jd=t_jd[0], rate_span=0.015, grid=a.method == "grid",
        )  # fmt: skip
        cpu = time.process_time() - start
        mirror = mirror_state(truth, mirror_plane(sun, obs)[0])
        found = [same_family(f[0], truth) or same_family(f[0], mirror) for f in fit.families]
        hits += any(found)
        best += found[0]
        print(
            f"draw {k}: recovered {any(found)} best {found[0]} families {len(found)} "
            f"chi2 {fit.families[0][0].chi2:.1f} (n=120) cpu {cpu:.1f} s "
            f"period {2 * np.pi / truth.rate_rad_s:.0f} s "
            f"ratios {np.round(truth.moment_ratios, 2)}",
            flush=True,
        )
    print(f"{a.method}: recovered {hits}/{a.draws}, best {best}/{a.draws}")


if __name__ == "__main__":
    main()
