"""Path-mode pass benchmark (issue 16): whole passes of distinct epochs, side by side.

Run: ``.venv/bin/python bench/bench_path_pass.py [--epochs 60] [--px 128] [--spp 16]``

The built-in box-wing example's own pass (its orbit, attitude and geometry), every k-th of
its 600 epochs (distinct epochs: the Sun and the line of sight change each time), in path
mode at 128 px and 16 spp over its 189 bins, timed three ways in one process:

1. speclight, the example's coated (``plastic``) materials;
2. speclight, uncoated materials of similar roughness (the coats replaced by ``beckmann``
   conductors and the same roughness; the antenna stays ``lambertian``);
3. the bare Mitsuba loop of the same renders: the same scene (Mitsuba's own ``roughplastic``
   with one coat index for the coated parts), ``mi.render`` once per epoch at the full spp
   into one plain sensor, only the two transforms updated between epochs, no speclight
   around it: the physical limit of one launch per epoch on this machine.

Each is run once on one epoch first (tables computed or read from the cache, kernels
compiled), then timed on one epoch (the fixed cost of a run: the scene, the tables) and on
the N epochs; the cost per epoch is the difference over N - 1. Printed: the one-epoch run,
seconds per epoch, a 600-epoch pass (one-epoch run + 599 epochs), Dr.Jit kernel launches per
epoch, and the ratios coated / uncoated and speclight / bare. Absolute times depend on the
machine's load; compare ratios within one run.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from typing import Any

import numpy as np

from speclight.render import render_intensity
from speclight.render.path_scene import build_scene, set_epoch
from speclight.render.session import RenderSession
from speclight.scenario import example_text, parse_scenario
from speclight.simulation.geometry_stage import scenario_geometry
from speclight.simulation.reflection import build_target
from speclight.target import Material, Reflectance, Target
from speclight.wavelength_grid import grid_bin_bounds_nm


def _uncoated(target: Target) -> Target:
    mats = {}
    for part in target.parts:
        m = part.material
        if m.bsdf == "plastic":
            m = Material(m.name, "beckmann", Reflectance.conductor("Al"), roughness=m.roughness)
        mats[part.name] = m
    from speclight.target import box_wing

    return box_wing(mats)


def _launches(fn: Any) -> tuple[float, int]:
    import drjit as dr

    dr.set_flag(dr.JitFlag.KernelHistory, True)
    dr.kernel_history()  # clears it
    t0 = time.perf_counter()
    fn()
    dt = time.perf_counter() - t0
    n = sum(1 for k in dr.kernel_history() if k.get("type") == dr.KernelType.JIT)
    dr.set_flag(dr.JitFlag.KernelHistory, False)
    return dt, n


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--epochs", type=int, default=60, help="epochs timed (of the 600)")
    ap.add_argument("--px", type=int, default=128)
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument(
        "--model", action="store_true", help="also time 16/64/256 spp (the time estimate's model)"
    )
    args = ap.parse_args()
    loaded = parse_scenario(example_text("box-wing"))
    geo = scenario_geometry(loaded)
    lit = np.flatnonzero(geo.observable & (geo.sunlit_fraction > 0))
    pick = lit[np.linspace(0, len(lit) - 1, args.epochs).astype(int)]
    sun, obs = geo.sun_direction_body[pick], geo.observer_direction_body[pick]
    wl = np.arange(300.0, 1241.0, 5.0)
    e = np.ones((len(pick), len(wl)))
    coated = build_target(loaded)
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores; box-wing pass, {len(pick)} "
        f"distinct epochs of {len(lit)}, {args.px} px, {args.spp} spp, {len(wl)} bins"
    )
    rows = []
    n_ep = len(pick)
    for name, target in (("coated", coated), ("uncoated", _uncoated(coated))):
        kw = dict(mode="path", resolution_px=args.px, samples_per_pixel=args.spp, seed=1)
        render_intensity(target, sun[:1], obs[:1], e[:1], wl, **kw)  # tables, compilation
        t1, n1 = _launches(
            lambda t=target, kw=kw: render_intensity(t, sun[:1], obs[:1], e[:1], wl, **kw)
        )
        tn, nn = _launches(lambda t=target, kw=kw: render_intensity(t, sun, obs, e, wl, **kw))
        rows.append((f"speclight, {name}", t1, tn, nn - n1))
    session = RenderSession.create("path", None, coated.materials)
    mi = session.activate()
    lo, hi = grid_bin_bounds_nm(wl)

    def bare(epochs: range) -> None:
        scene, params = build_scene(coated, lo, hi, args.px, args.spp, coat="grouped")
        sensor = scene.sensors()[0]
        for k in epochs:
            set_epoch(mi, params, coated, sun[k], obs[k], False, "sensor0")
            np.asarray(mi.render(scene, sensor=sensor, seed=k, spp=args.spp))

    bare(range(1))
    t1, n1 = _launches(lambda: bare(range(1)))
    tn, nn = _launches(lambda: bare(range(n_ep)))
    rows.append(("bare Mitsuba loop (coated, one index)", t1, tn, nn - n1))
    # per epoch: (pass of N epochs - pass of 1 epoch) / (N - 1): the fixed cost of a run
    # (scene, tables read from the cache) is the one-epoch run's, shown apart
    per = {name: (tn - t1) / (n_ep - 1) for name, t1, tn, _ in rows}
    print(f"{'':40} {'1-epoch run':>11} {'s/epoch':>8} {'600 epochs':>11} {'launches/epoch':>15}")
    for name, t1, _, dn in rows:
        print(
            f"{name:40} {t1:10.2f}s {per[name]:8.3f} {t1 + 599 * per[name]:10.1f}s "
            f"{dn / (n_ep - 1):15.1f}"
        )
    bare_s = per["bare Mitsuba loop (coated, one index)"]
    print(
        f"coated / uncoated: {per['speclight, coated'] / per['speclight, uncoated']:.2f}; "
        f"speclight coated / bare: {per['speclight, coated'] / bare_s:.2f}; "
        f"speclight uncoated / bare: {per['speclight, uncoated'] / bare_s:.2f}"
    )

    if args.model:
        _model(coated, sun, obs, wl, args.px)


def _model(target: Target, sun: Any, obs: Any, wl: Any, px: int) -> None:
    """Seconds per epoch against spp: the fixed and per-sample costs of the time estimate."""
    n = min(36, len(sun))  # >= FREEZE_MIN_LAUNCHES: frozen, as in a long run
    e = np.ones((n, len(wl)))
    print(f"time per epoch against spp ({n} epochs, coated, {px} px):")
    for spp in (16, 64, 256):
        kw = dict(mode="path", resolution_px=px, samples_per_pixel=spp, seed=2)
        render_intensity(target, sun[:1], obs[:1], e[:1], wl, **kw)
        t0 = time.perf_counter()
        r = render_intensity(target, sun[:n], obs[:n], e, wl, **kw)
        dt = (time.perf_counter() - t0) / n
        i, err = r.intensity_W_sr_nm, r.intensity_std_W_sr_nm
        noise = float(np.median(err[i > 0] / i[i > 0]))
        print(
            f"  {spp:4d} spp: {dt:.3f} s/epoch, {px * px * spp / dt:.3g} samples/s, "
            f"median noise per 5 nm bin and epoch {100 * noise:.1f} %"
        )


if __name__ == "__main__":
    main()
