"""Calibration of the tumbling state's standard deviations over blind noise draws (issue 27
item 4).

Truths as in ``bench_tumbling_far.py`` (the dishless box-wing, a random torque-free state,
two 10-min passes 90 min apart, a point every 10 s, 1 % noise); for each truth
``--noise-draws`` noise draws; each draw refitted from the truth itself (this measures the
sigma, not the search): trust-region least squares on all points, as
:func:`speclight.estimate.shape.tumbling.fit_tumbling` refines. The pulls
``(estimate - truth) / sigma`` of the rate ``|H| / I_max``, both moment ratios and the
momentum direction (east and north at the estimate) should have a standard deviation near
1. Both covariance estimators of :mod:`speclight.estimate.shape.tumbling_uncertainty`
(``sandwich``, ``scalar``) are computed on the same fits.

``--model convex``: light curves from the convex model, fitted with it (noise only).
``--model map``: light curves rendered by speclight (128 px, the shadows), fitted with the
box-wing's reflectivity map (nside 8, phase angles 30-110 deg, 32 rolls, 64 px, built once):
model error. ``--model convex-on-render``: the rendered curves fitted with the convex model
(no shadows: a larger model error). A draw whose fit leaves the truth's family
(``same_family``) is counted and left out of the pulls.

    .venv/bin/python bench/bench_calibration_tumbling.py --truths 10 --noise-draws 5
    .venv/bin/python bench/bench_calibration_tumbling.py --model map --truths 40 --noise-draws 2
    .venv/bin/python bench/bench_calibration_tumbling.py --pool A.npz B.npz  # pooled pulls
"""

from __future__ import annotations

import argparse
import time

import numpy as np
from scipy.optimize import least_squares

from bench_tumbling_far import WHITE, draw_truth, geometry, map_light, render
from speclight.attitude import torque_free_attitude
from speclight.attitude.quaternion import quat_conjugate, quat_rotate
from speclight.estimate.shape.convex_model import facet_brightness
from speclight.estimate.shape.egi import mesh_facets
from speclight.estimate.shape.inversion_data import build_inversion_data
from speclight.estimate.shape.scattering import scattering_law
from speclight.estimate.shape.tumbling import (
    MAX_EVALUATIONS,
    TumblingState,
    _Problem,
    _state_vector,
    same_family,
)
from speclight.estimate.shape.tumbling_light import (
    ConvexLight,
    LightModel,
)
from speclight.estimate.shape.tumbling_uncertainty import (
    MODEL_ERROR_WEIGHT,
    SUMMARY,
    CovarianceMethod,
    momentum_basis,
    momentum_direction,
    state_std,
    state_summary,
)
from speclight.target import shapes
from speclight.target.parts import Part, Target

METHODS: tuple[CovarianceMethod, ...] = ("jackknife", "sandwich", "scalar")
#: Weights of the model-error term compared.
WEIGHTS = sorted({0.0, 1.0, 2.0, 3.0, MODEL_ERROR_WEIGHT})
VARIANTS = [(m, w) for m in METHODS for w in WEIGHTS]


def box_wing() -> tuple[Target, np.ndarray, np.ndarray]:
    """The dishless white box-wing as one part, and its facets' normals and areas."""
    parts = [(p.vertices_m, p.faces) for p in shapes.box_wing(WHITE, dish=False).parts]
    normals, areas = mesh_facets(parts)
    offsets = np.cumsum([0] + [len(v) for v, _ in parts[:-1]])
    faces = np.vstack([f + o for (_, f), o in zip(parts, offsets, strict=True)])
    mesh = Target(parts=(Part("body", np.vstack([v for v, _ in parts]), faces, WHITE),))
    return mesh, normals, areas


def pulls_of(x_fit: np.ndarray, x_truth: np.ndarray, std: np.ndarray) -> np.ndarray:
    """(5,) ``(estimate - truth) / sigma`` of the summary, the direction's components in
    the estimate's east/north basis (small angles)."""
    east, north = momentum_basis(momentum_direction(x_fit))
    diff = state_summary(x_fit, east, north) - state_summary(x_truth, east, north)
    return np.asarray(diff / std)


def report(name: str, pulls: list[np.ndarray]) -> None:
    """One line per quantity: std of the pulls, robust std (1.4826 MAD), max |pull|."""
    z = np.array(pulls)
    cells = []
    for j in range(len(SUMMARY)):
        zj = z[:, j]
        mad = 1.4826 * np.median(np.abs(zj - np.median(zj)))
        cells.append(f"{np.std(zj, ddof=1):.2f} ({mad:.2f}) {np.max(np.abs(zj)):.1f}")
    print(f"{name:34s} " + " | ".join(cells))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--truths", type=int, default=10)
    ap.add_argument("--noise-draws", type=int, default=5)
    ap.add_argument("--seed", type=int, default=2027)
    ap.add_argument("--model", choices=["convex", "map", "convex-on-render"], default="convex")
    ap.add_argument("--render-px", type=int, default=128)
    ap.add_argument("--save", help="write the pulls of every variant to this .npz")
    ap.add_argument("--pool", nargs="+", help="report the pulls of these .npz files pooled")
    a = ap.parse_args()
    if a.pool:
        files = [np.load(f) for f in a.pool]
        print(f"pooled: {', '.join(a.pool)}")
        for m, w in VARIANTS:
            key = f"{m}_{w:g}"
            report(f"{m}, model-error weight {w:g}", list(np.vstack([f[key] for f in files])))
        return
    mesh, normals, areas = box_wing()
    law = scattering_law("lambert")
    light: LightModel = ConvexLight(normals, areas, law)
    if a.model == "map":
        light = map_light(mesh, 64, 8, 32)
    t_s, sun, obs = geometry()
    chp = np.sqrt(0.5 * (1 + np.sum(sun * obs, axis=1)))
    t_jd = 2459000.5 + t_s / 86400.0
    rng = np.random.default_rng(a.seed)
    pulls: dict[tuple[CovarianceMethod, float], list[np.ndarray]] = {v: [] for v in VARIANTS}
    left = 0
    cpu0 = time.process_time()
    for k in range(a.truths):
        truth = draw_truth(rng)
        q, _ = torque_free_attitude(t_s, truth.moments, truth.q0, truth.omega0_body_rad_s)
        qc = quat_conjugate(q)
        sun_b, obs_b = quat_rotate(qc, sun), quat_rotate(qc, obs)
        if a.model != "convex":
            y = render(mesh, sun_b, obs_b, a.render_px)
        else:
            y = facet_brightness(sun_b, obs_b, normals, areas, law, chp)
        sigma = 0.01 * np.mean(y)
        x_truth = _state_vector(truth, 1.0)[:8]
        for j in range(a.noise_draws):
            data = build_inversion_data(
                t_jd, y + sigma * rng.normal(size=y.size), np.full(y.size, sigma), sun, obs,
                np.repeat([0, 1], 60), np.array([False, False]), "bench",
            )  # fmt: skip
            prob = _Problem(data, light, t_jd[0])
            res = least_squares(
                prob.residuals, x_truth, method="trf", x_scale="jac", max_nfev=MAX_EVALUATIONS
            )
            q0, w0, moments, _ = prob.state(np.append(res.x, 0.0))
            if not same_family(TumblingState(q0, w0, moments, 0.0), truth):
                left += 1
                print(f"truth {k} draw {j}: left the truth's family (chi2 {2 * res.cost:.1f})")
                continue
            line = f"truth {k} draw {j}: chi2 {2 * res.cost:.1f}"
            for m, w in VARIANTS:
                z = pulls_of(res.x, x_truth, state_std(res.x, res.jac, res.fun, m, w))
                pulls[m, w].append(z)
                if (m, w) == VARIANTS[WEIGHTS.index(MODEL_ERROR_WEIGHT)]:  # the default
                    line += f" | {m} " + " ".join(f"{v:+.2f}" for v in z)
            print(line, flush=True)
    print(
        f"{a.model}, seed {a.seed}: {a.truths} truths x {a.noise_draws} noise draws, "
        f"{left} left the family; CPU {time.process_time() - cpu0:.0f} s\n"
        f"pulls: std (robust std) max |z| of " + ", ".join(SUMMARY)
    )
    for m, w in VARIANTS:
        report(f"{m}, model-error weight {w:g}", pulls[m, w])
    if a.save:
        np.savez(a.save, **{f"{m}_{w:g}": np.array(z) for (m, w), z in pulls.items()})


if __name__ == "__main__":
    main()
