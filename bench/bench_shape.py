"""Shape inversion (issue 27): calibration of the uncertainties and the cost of the search.

Run: ``.venv/bin/python bench/bench_shape.py [--draws 20] [--part calibration|timing|all]``,
or on a real DAMIT file kept outside the repository (the blind check of issue 27):
``.venv/bin/python bench/bench_shape.py --part damit --lc FILE --period-range-h LO HI
[--reference LAMBDA BETA PERIOD] [--workers N]``

1. **Calibration** (blind draws): each draw a Lambertian ellipsoid with random axes
   (b/a, c/b uniform in [0.6, 0.95]), a random pole (uniform on the sphere), a random period
   in [4, 10] h, observed at 6 random apparitions x 2 nights (tests/estimate/shape/
   synthetic.py) with 1 % noise, brightness from the exact convex sum (the model class is
   right, so the spread is the noise's). The inversion (``run_shape``, Lambert law, the
   period range +-3 resolution steps around the truth, 30 deg pole map) knows nothing else.
   For each draw whose best pole is the true one (not its mirror): ``z = (estimate - truth)
   / sigma`` for the period, the pole latitude and the longitude (times cos beta), sigma
   from the covariance; printed: the std and mean of each z (near 1 and 0 when calibrated),
   how many draws found the mirror instead and how many reported it.
2. **Timing**: the seconds of one trial period (one fit from ``n_start_poles`` poles), of
   one pole-map fit, and their scaling with the number of points (120 .. 960) and facets
   (HEALPix nside 1, 2, 4: 12, 48, 192).

3. **DAMIT** (``--part damit``): ``run_shape`` on a ``.lc`` file as ``speclight shape --format
   damit`` runs it; printed: the period, the pole and its mirror, the distance of the pole
   found (or its mirror) from a published one (``--reference``), the wall-clock and CPU
   seconds (the scan's worker processes included) and the load average before and after.

Other jobs share the machine: the seconds are indicative.
"""

from __future__ import annotations

import argparse
import os
import resource
import sys
import time
from pathlib import Path

import numpy as np
import trimesh
from threadpoolctl import threadpool_limits

sys.path.insert(0, str(Path(__file__).parents[1] / "tests" / "estimate" / "shape"))
from synthetic import apparitions, lambert_mesh_brightness, to_body

from speclight.estimate.shape import ShapeOptions, run_shape
from speclight.estimate.shape.convex_fit import fit_convex
from speclight.estimate.shape.convex_model import ConvexModel
from speclight.estimate.shape.ecliptic import angular_distance_deg, pole_vector
from speclight.estimate.shape.egi import facet_normals
from speclight.estimate.shape.inversion_data import build_inversion_data
from speclight.estimate.shape.period_scan import period_step_h
from speclight.estimate.shape.scattering import scattering_law
from speclight.estimate.shape.shape_inputs import ShapeInput

NOISE = 0.01


def _draw(rng: np.random.Generator, n_apparitions: int = 6, step_h: float = 0.3):
    m = trimesh.creation.icosphere(subdivisions=3)
    ba, cb = rng.uniform(0.6, 0.95, 2)
    m.vertices *= [1.0, ba, ba * cb]
    v = rng.normal(size=3)
    v /= np.linalg.norm(v)
    lam, bet = np.rad2deg(np.arctan2(v[1], v[0])) % 360, np.rad2deg(np.arcsin(v[2]))
    period = rng.uniform(4.0, 10.0)
    t, sun, obs, curve = apparitions(rng, n_apparitions=n_apparitions, step_h=step_h)
    t0 = np.floor(t[0])
    sb, ob = (to_body(x, lam, bet, period, t, t0) for x in (sun, obs))
    y = lambert_mesh_brightness(np.asarray(m.vertices), np.asarray(m.faces), sb, ob)
    y = y * (1 + NOISE * rng.normal(size=y.size))
    d = build_inversion_data(
        t, y, NOISE * y, sun, obs, curve, np.zeros(curve.max() + 1, bool), "draw"
    )
    return d, lam, bet, period


def calibration(draws: int) -> None:
    rng = np.random.default_rng(2027)
    z, mirrors, reported, seconds = [], 0, 0, []
    for k in range(draws):
        d, lam, bet, period = _draw(rng)
        step = float(period_step_h(period, d.baseline_d, 1.0))
        lo = period - 3 * step * rng.uniform(0.2, 1.0)
        hi = period + 3 * step * rng.uniform(0.2, 1.0)
        t = time.perf_counter()
        run = run_shape(
            ShapeInput(d, [], None, None, "1", "draw"),
            ShapeOptions(lo, hi, law="lambert"),
        )
        seconds.append(time.perf_counter() - t)
        b, c = run.best, run.cov
        if angular_distance_deg(pole_vector(b.lambda_deg, b.beta_deg), pole_vector(lam, bet)) > 20:
            mirrors += 1
            reported += int(run.mirror_reported)
            at_truth = fit_convex(run.model, lam, bet, period, log_areas=b.theta[3:])
            print(
                f"draw {k}: chi2 {b.chi2:.1f} at the pole found, {at_truth.chi2:.1f} refitted "
                f"from the truth; pole constrained: {run.pole_constrained}; other poles "
                f"reported as fitting as well: {len(run.equivalent_minima)}"
            )
            print(
                f"draw {k}: pole ({b.lambda_deg:.1f}, {b.beta_deg:.1f}) not the truth "
                f"({lam:.1f}, {bet:.1f}); mirror reported: {run.mirror_reported}"
            )
            continue
        dlam = (b.lambda_deg - lam + 180) % 360 - 180
        z.append(
            (
                (b.period_h - period) / c.period_h,
                (b.beta_deg - bet) / c.beta_deg,
                dlam / c.lambda_deg,
            )
        )
        print(
            f"draw {k}: z = {np.round(z[-1], 2)}, sigma_P = {c.period_h:.2g} h, sigma_pole "
            f"{c.pole_deg:.2g} deg, {seconds[-1]:.1f} s"
        )
    zz = np.array(z)
    print(
        f"\n{len(z)} draws at the true pole, {mirrors} at another ({reported} with the mirror "
        f"reported); median {np.median(seconds):.1f} s a draw"
    )
    for name, col in zip(("period", "beta", "lambda cos beta"), zz.T, strict=True):
        print(f"  z({name}): std {np.std(col, ddof=1):.2f}, mean {np.mean(col):.2f}")


def timing(blas_threads: int | None) -> None:
    """One trial period and one pole-map fit; ``blas_threads``: BLAS threads (None: as
    the library starts, all cores)."""
    rng = np.random.default_rng(1)
    print(f"BLAS threads: {blas_threads or 'all'}")
    print("points facets  trial-period [s]  pole-map fit [s]")
    for n_app, nside in ((2, 2), (4, 2), (8, 2), (16, 2), (8, 1), (8, 4)):
        d, lam, bet, period = _draw(rng, n_apparitions=n_app)
        model = ConvexModel(
            d, facet_normals(nside), scattering_law("lambert"), np.floor(d.time_jd[0])
        )
        reps = 3
        limit = threadpool_limits(limits=blas_threads, user_api="blas") if blas_threads else None
        t = time.perf_counter()
        for _ in range(reps):
            for pl, pb in ((0, 45), (120, -30), (240, 10), (60, -60)):
                fit_convex(model, pl, pb, period, max_iterations=30)
        trial = (time.perf_counter() - t) / reps
        t = time.perf_counter()
        for _ in range(reps):
            fit_convex(model, lam, bet, period, free_pole=False, max_iterations=30)
        pole = (time.perf_counter() - t) / reps
        if limit is not None:
            limit.restore_original_limits()
        print(f"{d.n_points:6d} {len(model.normals):6d}  {trial:16.3f}  {pole:16.3f}")


def _cpu_seconds() -> float:
    """User + system CPU seconds of this process and its finished children (the scan's
    workers)."""
    return sum(
        r.ru_utime + r.ru_stime
        for r in (
            resource.getrusage(who) for who in (resource.RUSAGE_SELF, resource.RUSAGE_CHILDREN)
        )
    )


def damit(
    lc: str, lo: float, hi: float, reference: list[float] | None, workers: int | None
) -> None:
    """The inversion of a DAMIT file, timed, against a published pole and period."""
    from speclight.estimate.shape import read_shape_input

    inputs = read_shape_input(lc, "damit")
    d = inputs.data
    print(f"{d.n_points} points in {d.n_curves} curves over {d.baseline_d:.0f} d")
    print(f"load average before: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    t, cpu = time.perf_counter(), _cpu_seconds()
    run = run_shape(inputs, ShapeOptions(lo, hi, workers=workers))
    wall, cpu = time.perf_counter() - t, _cpu_seconds() - cpu
    print(f"load average after: {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    b, m = run.best, run.mirror
    print(
        f"{run.scan.trial_period_h.size} trial periods; wall {wall:.0f} s, CPU {cpu:.0f} s "
        f"(workers {workers or 'all cores'})"
    )
    print(f"period {b.period_h:.7f} +- {run.cov.period_h:.1g} h")
    print(f"pole ({b.lambda_deg:.1f}, {b.beta_deg:.1f}) chi2 {b.chi2:.1f}")
    print(
        f"mirror ({m.lambda_deg:.1f}, {m.beta_deg:.1f}) chi2 {m.chi2:.1f}: minimum "
        f"{run.mirror_is_minimum}, fits as well {run.mirror_reported}"
    )
    if reference:
        lam, bet, per = reference
        found = pole_vector(b.lambda_deg, b.beta_deg)
        dist = [
            float(angular_distance_deg(found, pole_vector(la, bet))) for la in (lam, lam + 180.0)
        ]
        print(
            f"reference ({lam}, {bet}), P {per} h: period off by {b.period_h - per:+.2g} h, "
            f"pole {dist[0]:.1f} deg from it, {dist[1]:.1f} deg from its mirror"
        )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--draws", type=int, default=20)
    ap.add_argument("--part", choices=("calibration", "timing", "damit", "all"), default="all")
    ap.add_argument("--lc", help="a DAMIT .lc file (--part damit)")
    ap.add_argument("--period-range-h", nargs=2, type=float, default=(5.0, 7.0))
    ap.add_argument("--reference", nargs=3, type=float, metavar=("LAMBDA", "BETA", "PERIOD"))
    ap.add_argument("--workers", type=int, default=None)
    args = ap.parse_args()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    if args.part == "damit":
        if not args.lc:
            ap.error("--part damit needs --lc FILE")
        damit(args.lc, *args.period_range_h, args.reference, args.workers)
        return
    if args.part in ("timing", "all"):
        timing(None)
        timing(1)
    if args.part in ("calibration", "all"):
        calibration(args.draws)


if __name__ == "__main__":
    main()
