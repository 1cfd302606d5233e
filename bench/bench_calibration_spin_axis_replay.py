"""Add the map-error field's refits to saved calibration draws, without a new search.

Run: ``.venv/bin/python bench/bench_calibration_spin_axis_replay.py --load FILE.pkl --seed S
[--folder DIR] [--save OUT.pkl]``: ``FILE.pkl`` from ``bench_calibration_spin_axis.py --seed S
--save FILE.pkl`` (period-known draws, saved before this field existed). Each draw's truth,
geometry and measured curves are rebuilt from the seed (the draws' random numbers come in the
same order; checked against the saved truth and curves), the refits on the map displaced by
the field (:func:`speclight.estimate.spin_axis.spin_axis_map_error.map_warp_deviations`) are
added around the saved refined answer, and every covariance variant is reported as by
``--load``, with the field's own pulls against the map's error (the refit on the truth's map).
"""

from __future__ import annotations

import argparse
import pickle
import time
from pathlib import Path

import numpy as np

from bench_calibration_spin_axis import _report, pass_geometry, truth_draw
from bench_calibration_spin_axis_variants import _en_deg, oracle_report
from speclight.estimate.spin_axis.spin_axis_confidence import EAST_NORTH
from speclight.estimate.spin_axis.spin_axis_gradient import SpinMisfit
from speclight.estimate.spin_axis.spin_axis_jackknife import shrunk_second_moment
from speclight.estimate.spin_axis.spin_axis_lookup import load_band_map
from speclight.estimate.spin_axis.spin_axis_map_error import map_warp_deviations


def add_warp(rows: list[dict], seed: int, folder: Path) -> float:
    """Add ``parts["warp"]`` to ``rows`` in place; returns the CPU seconds per draw."""
    geo_all = pass_geometry(folder)
    truth = load_band_map(folder / "bw-32-3072.zarr")
    search = load_band_map(folder / "bw-32-768.zarr")
    rng = np.random.default_rng(seed)
    cpu, n = 0.0, 0
    for row in rows:
        (ra, dec), _, geo, y, _, _, _ = truth_draw(rng, geo_all, truth, "")
        assert abs(ra - row["truth"][0]) < 1e-9 and abs(dec - row["truth"][1]) < 1e-9
        p = row.get("parts") or {}
        if "xs" not in p:
            continue
        assert np.array_equal(p["y"], y), "the saved curves are not this seed's"
        model = SpinMisfit.around(search, geo, y, None, *p["refined"][:2], False)
        t0 = time.process_time()
        p["warp"] = map_warp_deviations(model, p["x0"])
        cpu += time.process_time() - t0
        n += 1
    return cpu / max(n, 1)


def warp_oracle(rows: list[dict]) -> None:
    """The map's error (the truth-map refit) over the field's own sigmas, said constrained."""
    z = []
    for r in rows:
        p = r.get("parts") or {}
        if "warp" not in p or "xt" not in p or not r["c"].constrained or not p["warp"].size:
            continue
        c = shrunk_second_moment(p["warp"])[0]
        te = _en_deg(p["x0"] - p["xt"])
        sig = np.degrees(np.sqrt(np.diag(EAST_NORTH @ c[:2, :2] @ EAST_NORTH.T)))
        z.append(te / sig)
    if z:
        za = np.array(z)
        print(
            f"\nmap error / the field's sigma over {len(z)} said constrained: std east "
            f"{np.std(za[:, 0]):.2f}, north {np.std(za[:, 1]):.2f}"
        )


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--load", type=Path, required=True)
    ap.add_argument("--seed", type=int, required=True)
    ap.add_argument("--folder", type=Path, default=Path("/tmp/bench_calibration_spin_axis"))
    ap.add_argument("--save", type=Path, default=None)
    args = ap.parse_args()
    rows = pickle.loads(args.load.read_bytes())
    parts = [r.get("parts") or {} for r in rows]
    if any("xs" in p and "warp" not in p for p in parts):
        print(f"field refits: {add_warp(rows, args.seed, args.folder):.2f} s CPU per draw")
    if args.save is not None:
        args.save.write_bytes(pickle.dumps(rows))
    _report(f"box-wing, period known (seed {args.seed}, saved draws)", rows)
    oracle_report(rows)
    warp_oracle(rows)


if __name__ == "__main__":
    main()
