"""Where the spin axis's error goes with a free period: the period's share, the map's share.

Run: ``.venv/bin/python bench/bench_calibration_spin_axis_free_period.py FILE.free.pkl
[--method jackknife-warp]``, ``FILE.free.pkl`` from ``bench_calibration_spin_axis.py
--period-draws N --save FILE.pkl``. For each draw said constrained, with the covariance
``C`` of ``--method`` in (east, north, phase, extra turn ``f``):

* the error east / north and its part the map makes (the refined answer against the refit
  on the truth's own map), both over the reported (marginal) sigmas;
* the period's pull: ``f``'s error (``-(P_refined - P_true) / |dP/df|``) over ``sqrt(C_ff)``;
* the axis-period correlations ``C_af / sqrt(C_aa C_ff)``, the conditional sigmas (the
  period known: ``C_aa - C_af C_fa / C_ff``) and the axis error the period's own error
  predicts by the regression ``C_af / C_ff df`` (a Gaussian's conditional mean).

If the east bias were the period-axis trade, the predicted part would carry it and the
rest over the conditional sigmas would have a standard deviation near 1.
"""

from __future__ import annotations

import argparse
import pickle
from pathlib import Path

import numpy as np

from bench_calibration_spin_axis_variants import _covariance, _en_deg
from speclight.estimate.spin_axis.spin_axis_confidence import EAST_NORTH


def _row(r: dict, key: str) -> dict | None:
    p, c = r["parts"], r["c"]
    if not c.constrained or "xs" not in p or p["x0"].size < 4:
        return None
    cov = _covariance(p, key)
    t = np.eye(4)
    t[:2, :2] = EAST_NORTH
    ce = t @ cov @ t.T  # east, north, phase, f [rad^2]
    deg = np.degrees(1.0)
    df = -r["period_err"] / p["period_scale"]
    cond = ce[:2, :2] - np.outer(ce[:2, 3], ce[3, :2]) / ce[3, 3]
    return dict(
        err=np.array([r["east"], r["north"]]),
        map=_en_deg(p["x0"] - p["xt"]),
        sigma=np.sqrt(np.diag(ce[:2, :2])) * deg,
        cond=np.sqrt(np.diag(cond)) * deg,
        rho=ce[:2, 3] / np.sqrt(np.diag(ce[:2, :2]) * ce[3, 3]),
        pull_f=df / np.sqrt(ce[3, 3]),
        pred=ce[:2, 3] / ce[3, 3] * df * deg,
    )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("load", type=Path)
    ap.add_argument("--method", default="jackknife-warp")
    args = ap.parse_args()
    rows = [_row(r, args.method) for r in pickle.loads(args.load.read_bytes())]
    got = [r for r in rows if r is not None]
    for r in got:
        e, m, s = r["err"], r["map"], r["sigma"]
        print(
            f"error {e[0]:+6.2f} {e[1]:+6.2f} deg (map's {m[0]:+6.2f} {m[1]:+6.2f}); sigma "
            f"{s[0]:.2f} {s[1]:.2f} (period known {r['cond'][0]:.2f} {r['cond'][1]:.2f}); "
            f"rho(axis, f) {r['rho'][0]:+.2f} {r['rho'][1]:+.2f}; period pull "
            f"{r['pull_f']:+.2f}; predicted by it {r['pred'][0]:+.2f} {r['pred'][1]:+.2f}"
        )
    if not got:
        return
    err, mp, sig = (np.array([r[k] for r in got]) for k in ("err", "map", "sigma"))
    cond, pred = np.array([r["cond"] for r in got]), np.array([r["pred"] for r in got])
    pull_f, rho = np.array([r["pull_f"] for r in got]), np.array([r["rho"] for r in got])
    z, rest = err / sig, (err - pred) / cond
    print(f"\n{len(got)} draws said constrained ({args.method})")
    print(
        f"error / sigma: east mean {z[:, 0].mean():+.2f} std {z[:, 0].std():.2f}, north mean "
        f"{z[:, 1].mean():+.2f} std {z[:, 1].std():.2f}"
    )
    print(
        f"period pull: mean {pull_f.mean():+.2f} std {pull_f.std():.2f}, beyond 2.5 in "
        f"{int(np.sum(abs(pull_f) > 2.5))}"
    )
    print(
        f"|rho(axis, period)| median east {np.median(abs(rho[:, 0])):.2f}, north "
        f"{np.median(abs(rho[:, 1])):.2f}; above 0.5 in {int(np.sum(abs(rho) > 0.5))} of "
        f"{rho.size}"
    )
    zm, zn = mp / sig, (err - mp) / sig
    print(
        f"the map's part / sigma: std east {zm[:, 0].std():.2f}, north {zm[:, 1].std():.2f}; "
        f"the rest (noise) / sigma: std east {zn[:, 0].std():.2f}, north {zn[:, 1].std():.2f}"
    )
    print(
        f"(error - period-predicted) / period-known sigma: std east {rest[:, 0].std():.2f} "
        f"(mean {rest[:, 0].mean():+.2f}), north {rest[:, 1].std():.2f} "
        f"(mean {rest[:, 1].mean():+.2f})"
    )


if __name__ == "__main__":
    main()
