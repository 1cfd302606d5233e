"""The tumbling fit's light model at the truth: the reflectivity map built from the scenario
(``speclight shape --tumbling-starts N`` without ``--map``; maps/writer/cached_map.py) at
several resolutions, and the convex model, against speclight's own light curves (issue 27).

The box-wing example (bus, two wings, dish; its materials and bands) made torque-free
(principal moments 450, 800, 1000 kg m2; body rates (0.01, 0.03, 0.02) rad/s, a turn in
about 3 min), its 10-min pass simulated by speclight at 10 s (60 points, 128 px, the
example's noise) and read as ``speclight shape`` reads it (the mean reflectance factor of
all bands). The scenario's own torque-free state (the truth) gives the body-frame Sun and
observer directions at every point; each light model's brightness there (not refitted)
against the data is the chi-square at the truth, with the brightness scale fitted as the
fit fits it for calibrated data (the convex model has albedo 1): what the light model
allows at the true state (a perfect model: about the number of points). Each map is
built into an empty cache folder (the build's wall time) and then asked for again (found
in the cache).

    .venv/bin/python bench/bench_tumbling_map_resolution.py --nsides 2,4,8 --extra --fine
    .venv/bin/python bench/bench_tumbling_map_resolution.py --nsides 8 --fine --fit --refit
"""

from __future__ import annotations

import argparse
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

from speclight.attitude.quaternion import quat_conjugate, quat_rotate
from speclight.estimate.shape import read_shape_input
from speclight.estimate.shape.convex_model import relative_residuals
from speclight.estimate.shape.scattering import scattering_law
from speclight.estimate.shape.tumbling import fit_tumbling, same_family
from speclight.estimate.shape.tumbling_light import LightModel
from speclight.estimate.shape.tumbling_mirror import mirror_plane, mirror_state
from speclight.estimate.shape.tumbling_run import _prior, tumbling_light
from speclight.io.netcdf import write_dataset
from speclight.maps.writer.cached_map import MapResolution
from speclight.scenario import example_text, parse_scenario
from speclight.simulation import simulate


def scenario_text(px: int) -> str:
    d = yaml.safe_load(example_text("box-wing"))
    d["time"]["step_s"] = 10.0
    q = np.array([0.9, 0.1, -0.3, 0.2])
    d["attitude"] = {
        "model": "torque_free",
        "inertia_kg_m2": [450.0, 800.0, 1000.0],
        "initial_attitude": {"quaternion": (q / np.linalg.norm(q)).tolist()},
        "angular_velocity_body_rad_s": [0.01, 0.03, 0.02],
    }
    d["render"]["resolution_px"] = px
    return yaml.safe_dump(d)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--nsides", default="2,4,8", help="MapResolution.of_nside values")
    ap.add_argument("--extra", action="store_true", help="also nside 8 with 16 rolls / 32 px")
    ap.add_argument("--fine", action="store_true", help="also nside 16, 32 rolls, 64 px")
    ap.add_argument(
        "--fit", action="store_true", help="also fit each light model with no prior (grid)"
    )
    ap.add_argument("--refit", action="store_true", help="also refit each from the truth")
    ap.add_argument("--data-px", type=int, default=128)
    ap.add_argument("--folder", help="reuse this folder's data and maps (default: a new one)")
    a = ap.parse_args()
    folder = Path(a.folder) if a.folder else Path(tempfile.mkdtemp(prefix="bench_tumbling_map_"))
    scenario = folder / "box-wing-tumbling.yaml"
    scenario.write_text(scenario_text(a.data_px))
    loaded = parse_scenario(scenario.read_text(), source=str(scenario))
    start = time.perf_counter()
    if not (folder / "lc.nc").exists():
        write_dataset(simulate(loaded).dataset, folder / "lc.nc")
    inputs = read_shape_input(folder / "lc.nc", "speclight", loaded)
    d = inputs.data
    print(
        f"data: {d.time_jd.size} points, phase angles {d.phase_angle_deg.min():.1f}-"
        f"{d.phase_angle_deg.max():.1f} deg, simulated in {time.perf_counter() - start:.1f} s",
        flush=True,
    )
    t0 = float(d.time_jd[0])
    truth = _prior(inputs, t0)[0]
    from speclight.attitude import torque_free_attitude

    q, _ = torque_free_attitude(
        (d.time_jd - t0) * 86400.0, truth.moments, truth.q0, truth.omega0_body_rad_s
    )
    qc = quat_conjugate(q)
    sun_b, obs_b = quat_rotate(qc, d.sun_ecliptic), quat_rotate(qc, d.observer_ecliptic)
    law = scattering_law("lambert")

    def chi2(light_model: LightModel) -> str:
        """Chi-square at the truth with the brightness scale fitted (the fit's own free
        scale of calibrated data), and that scale."""
        lum = light_model(sun_b, obs_b, d.cos_half_phase)
        w = 1.0 / d.sigma**2
        scale = float(np.sum(w * d.brightness * lum) / np.sum(w * lum * lum))
        r2 = np.sort(relative_residuals(d, scale * lum) ** 2)
        rel = np.abs(scale * lum / d.brightness - 1.0)
        return (
            f"{np.sum(r2):.0f} ({np.sum(r2[:-1]):.0f} without the worst point; scale "
            f"{scale:.3f}), relative error median {np.median(rel):.3f}, 90 % "
            f"{np.percentile(rel, 90):.3f}"
        )

    period_h = 2 * np.pi / truth.rate_rad_s / 3600.0
    common = dict(min_period_h=0.7 * period_h, max_period_h=1.5 * period_h, n_starts=0, t0_jd=t0)

    def fit(light_model: LightModel) -> str:
        """The grid search with no prior (the truth not among the starts): whether a family
        is the truth's or its mirror's, the best chi-square, CPU seconds."""
        start = time.process_time()
        f = fit_tumbling(d, light_model, rate_span=0.015, **common)  # type: ignore[arg-type]
        cpu = time.process_time() - start
        mirror = mirror_state(truth, mirror_plane(d.sun_ecliptic, d.observer_ecliptic)[0])
        found = [same_family(g[0], truth) or same_family(g[0], mirror) for g in f.families]
        return (
            f"; fit with no prior: truth's family found {any(found)} (best {found[0]}), best "
            f"chi2 {f.families[0][0].chi2:.0f}, {len(found)} families, {cpu:.0f} CPU s"
        )

    def refit(light_model: LightModel) -> str:
        """The fit from the truth alone (no grid, the rate scale fixed): where the light
        model's own minimum near the truth lies."""
        own = fit_tumbling(
            d,
            light_model,
            initial_states=[truth],
            rate_span=0.0,
            grid=False,
            **common,  # type: ignore[arg-type]
        ).families[0][0]
        return (
            f"; refitted from the truth: chi2 {own.chi2:.0f}, in the truth's family "
            f"{same_family(own, truth)}, moment ratios {np.round(own.moment_ratios, 3)} "
            f"(truth {np.round(truth.moment_ratios, 3)}), rate "
            f"{100 * (own.rate_rad_s / truth.rate_rad_s - 1):+.2f} %"
        )

    def fits(light_model: LightModel) -> str:
        return (fit(light_model) if a.fit else "") + (refit(light_model) if a.refit else "")

    convex = tumbling_light(inputs, law, no_map=True)
    print(
        f"convex model: chi2 at the truth {chi2(convex.model)}{fits(convex.model)}",
        flush=True,
    )
    resolutions = [MapResolution.of_nside(int(n)) for n in a.nsides.split(",")]
    if a.extra:
        resolutions += [MapResolution(8, 16, 10.0, 64), MapResolution(8, 32, 10.0, 32)]
    if a.fine:
        resolutions += [MapResolution(16, 32, 10.0, 64)]
    for res in resolutions:
        cache = folder / f"cache-{res.nside}-{res.rolls}-{res.resolution_px}"
        start = time.perf_counter()
        light = tumbling_light(inputs, law, map_resolution=res, cache_dir=cache)
        assert a.folder or "in this run" in light.note
        built_s = time.perf_counter() - start
        start = time.perf_counter()
        again = tumbling_light(inputs, law, map_resolution=res, cache_dir=cache)
        cached_s = time.perf_counter() - start
        assert "from the cache" in again.note
        attrs = light.attrs()
        n_phase = len(attrs["tumbling_map_phase_angle_deg"])
        renders = 12 * res.nside**2 * n_phase * res.rolls
        print(
            f"{res.describe()}: {n_phase} phase angles, {renders} renders, built in "
            f"{built_s:.1f} s (wall), found again in {cached_s:.2f} s; chi2 at the truth "
            f"{chi2(light.model)}{fits(light.model)}",
            flush=True,
        )


if __name__ == "__main__":
    main()
