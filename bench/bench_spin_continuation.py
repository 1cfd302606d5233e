"""Does continuation enlarge the gradient refinement's basin? (issue 15 item 2)

Run: ``.venv/bin/python bench/bench_spin_continuation.py [--case rendered|map]
[--variants NAME,...]``

The problem, the optimum, the starts (same seed, same draws) and the success criterion of
``bench/bench_spin_refine.py``. Variants
(:mod:`speclight.estimate.spin_axis.spin_axis_continuation`,
:func:`speclight.estimate.spin_axis.spin_axis_refine.refine_staged`): the ``--refine`` methods by
their names (``gradient``, ``slsqp``, ``gradient-continuation``: here, an nside-8 map,
the same as ``map:2x8/4x8``); ``map:S1/S2/...``: L-BFGS-B on the map degraded to each
stage in turn, each stage ``NSIDExROLLS``, then on the real map; ``time:S1/S2``: the light
curves smoothed with a Gaussian of S seconds; ``both:...``: stages ``NSIDExROLLS~SIGMA``;
``multi:R:K``: plain gradient runs from the start, its phase + 180 deg twin and K axes on a
ring R deg around the start (phase kept), the lowest misfit kept (``multi+`` the same with
the continuation ``map:2x8/4x8`` for each run). Printed per start set: converged / tried,
the median misfit + gradient evaluations per start (all stages and runs together), and for
the converged starts the largest final misfit over the optimum's (``e/e* max``) and axis
distance from it. ``--search``: step 5 of ``bench_spin_refine.py`` (the grid search, then
every ``--refine`` method from its best and mirror cells).
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from speclight.estimate.spin_axis.spin_axis_continuation import Stage
from speclight.estimate.spin_axis.spin_axis_core import angular_distance_deg
from speclight.estimate.spin_axis.spin_axis_refine import (
    REFINE_METHODS,
    Refined,
    refine_candidate,
    refine_staged,
)

sys.path.insert(0, str(Path(__file__).parent))
from bench_spin_refine import (
    BOUND,
    TRUTH,
    _dphase,
    _offset_axis,
    _problem,
    _whole_search,
    start_sets,
)

DEFAULT = (
    "gradient,slsqp,map:4x8,map:2x8/4x8,map:2x2/4x4,map:1x2/2x4/4x8,time:20/5,time:40/15/5,"
    "both:2x2~20/4x4~5,multi:30:6,multi:45:6,multi+:30:6,gradient-continuation"
)


def _stages(spec: str) -> list[Stage]:
    out = []
    for part in spec.split("/"):
        geom, _, sigma = part.partition("~")
        if "x" in geom:
            ns, nr = geom.split("x")
            out.append(Stage(int(ns), int(nr), float(sigma or 0)))
        else:
            out.append(Stage(None, None, float(geom)))
    return out


def _variant(name: str, bmap, geo, y):
    kind, _, spec = name.partition(":")
    if kind in REFINE_METHODS:
        return lambda st, b, p: refine_candidate(bmap, geo, y, None, st, 2.5, kind, b, None, p)
    if kind in ("map", "time", "both"):
        stages = _stages(spec)
        return lambda st, b, p: refine_staged(bmap, geo, y, None, st, stages, b, None, p)
    radius, k = (float(v) for v in spec.split(":"))
    inner = _stages("2x8/4x8") if kind == "multi+" else []

    def multi(st, b, p) -> Refined:
        starts = [st, (st[0], st[1], st[2] + 180.0)]
        for i in range(int(k)):
            ra, dec = _offset_axis(st[0], st[1], radius, 2 * np.pi * i / k)
            starts.append((ra, dec, st[2]))
        tries = [refine_staged(bmap, geo, y, None, s, inner, b, None, p) for s in starts]
        best = min(tries, key=lambda r: r.error)
        return Refined(
            *best.answer,
            best.period_s,
            sum(r.n_misfit for r in tries),
            sum(r.n_gradient for r in tries),
        )

    return multi


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--px", type=int, default=32)
    ap.add_argument("--bearings", type=int, default=10)
    ap.add_argument("--case", choices=("rendered", "map"), default="rendered")
    ap.add_argument("--variants", default=DEFAULT)
    ap.add_argument("--no-period", action="store_true", help="skip the free-period starts")
    ap.add_argument(
        "--search", action="store_true", help="also: every method from the grid's cells"
    )
    args = ap.parse_args()
    print(f"{platform.node()} {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs")
    rng = np.random.default_rng(15)
    with tempfile.TemporaryDirectory() as tmp:
        bmap, geo, y = _problem(Path(tmp), args.px, args.case)
    print(f"case {args.case}: {y.shape[0]} epochs x {y.shape[1]} bands")
    optimum = {}
    for bound in (None, BOUND):
        res = [refine_candidate(bmap, geo, y, None, TRUTH, 2.5, m, bound) for m in REFINE_METHODS]
        optimum[bound] = min(res, key=lambda r: r.error)
        o = optimum[bound]
        print(
            f"optimum (period {'free' if bound else 'fixed'}): RA {o.ra_deg:.3f} Dec "
            f"{o.dec_deg:.3f} phase {o.phase_deg:.3f} period {o.period_s:.4f} s, misfit "
            f"{o.error:.6g}"
        )
    # the starts of bench_spin_refine.py: the same draws in the same order
    sets = start_sets(optimum, rng, args.bearings, period=not args.no_period)
    names = args.variants.split(",")
    runners = {n: _variant(n, bmap, geo, y) for n in names}
    for name in names:
        print(f"\n## {name}", flush=True)
        t_all = time.perf_counter()
        for label, starts, bound in sets:
            ref = optimum[bound]
            ok, twin, nf, ng, ratio, dist_ok = 0, 0, [], [], [], []
            for start, p0 in starts:
                r = runners[name](start, bound, p0)
                d = angular_distance_deg(r.ra_deg, r.dec_deg, ref.ra_deg, ref.dec_deg)
                good = d < 1.0 and abs(r.period_s / ref.period_s - 1) < 5e-4
                is_twin = good and _dphase(r.phase_deg, ref.phase_deg + 180.0) < 1.0
                good &= _dphase(r.phase_deg, ref.phase_deg) < 1.0 or is_twin
                ok += int(good)
                twin += int(is_twin)
                nf.append(r.n_misfit)
                ng.append(r.n_gradient)
                if good:
                    ratio.append(r.error / ref.error)
                    dist_ok.append(d)
            tw = f" ({twin} twin)" if twin else ""
            acc = f"; e/e* max {max(ratio):.6f}, {max(dist_ok):.3f} deg" if ratio else ""
            print(
                f"| {label} | {ok}/{len(starts)}{tw}: {np.median(nf):.0f} + "
                f"{np.median(ng):.0f}g{acc} |",
                flush=True,
            )
        print(f"({time.perf_counter() - t_all:.1f} s)")
    if args.search:
        _whole_search(bmap, geo, y, optimum[None])


if __name__ == "__main__":
    main()
