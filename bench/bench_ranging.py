"""Ranging benchmark: run ``python bench/bench_ranging.py [--quick]`` and read the printout.

The built-in box-wing example (600 epochs, 189 bins, 256 px, single mode), with one SLR laser
at the observer's site (532 nm, coaxial) added, and optionally a second, bistatic one:

1. the Sun render alone (what a Sun-only run costs in the render stage);
2. the same render with the laser-ranging accumulator fed by its primary rays (``on_hits``),
   plus :func:`laser_ranging` (finishing, link, histograms): the cost ranging adds;
3. ranging on its own rays (no Sun render to share), for reference.

The issue's target: 2 is at most 30 % more than 1.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from typing import Any

import numpy as np
import yaml

from speclight.constants import AU_M
from speclight.illumination import solar_irradiance_W_m2_nm
from speclight.render import render_intensity
from speclight.render.session import RenderSession
from speclight.scenario import parse_scenario
from speclight.scenario.builtin_examples import example_text
from speclight.simulation.geometry_stage import scenario_geometry
from speclight.simulation.radiometry import (
    atmosphere_transmission,
    instrument_response,
    wavelength_grid_nm,
)
from speclight.simulation.ranging_stage import laser_ranging, prepare_ranging
from speclight.simulation.reflection import build_target

SLR = {"latitude_deg": 48.7822, "longitude_deg": 9.1967, "altitude_m": 355.0}


def scenario(n_epochs: int, bistatic: bool) -> Any:
    d = yaml.safe_load(example_text("box-wing"))
    d["time"]["stop"] = d["time"]["start"] + np.timedelta64(n_epochs - 1, "s").item()
    lasers = [
        {"name": "slr-532", **SLR, "wavelength_nm": 532.0, "linewidth_nm": 0.1, "power_w": 10.0}
        | {"repetition_rate_hz": 100.0, "divergence_arcsec": 10.0}
    ]
    if bistatic:
        lasers.append(
            {"name": "bi-1064", "latitude_deg": 47.0, "longitude_deg": 8.0, "altitude_m": 900.0}
            | {"wavelength_nm": 1064.0, "linewidth_nm": 0.1, "power_w": 20.0}
            | {"repetition_rate_hz": 1000.0, "divergence_arcsec": 20.0}
        )
    d["illumination"]["lasers"] = lasers
    return parse_scenario(yaml.safe_dump(d), source="bench")


def sun_render(loaded: Any, geo: Any, wl: np.ndarray, on_hits: Any = None) -> Any:
    """The render call of ``simulation.reflection.render_reflection`` (sunlit epochs)."""
    sc = loaded.scenario
    idx = np.flatnonzero(geo.observable & (geo.sunlit_fraction > 0))
    solar = solar_irradiance_W_m2_nm(wl, geo.sun_distance_m / AU_M)
    hook = None if on_hits is None else on_hits(idx)
    return render_intensity(
        build_target(loaded),
        geo.sun_direction_body[idx],
        geo.observer_direction_body[idx],
        solar[idx],
        wl,
        mode=sc.render.mode,
        resolution_px=sc.render.resolution_px,
        variant=sc.render.variant,
        on_hits=hook,
    )


def target_session(loaded: Any) -> tuple[Any, Any]:
    """The run's target and render session, as ``simulation.pipeline`` builds them."""
    sc = loaded.scenario
    target = build_target(loaded)
    session = RenderSession.create(
        sc.render.mode, sc.render.variant, target.materials, sc.render.polarization
    )
    return target, session


def timed(fn: Any) -> tuple[Any, float]:
    """Result and CPU time of this process (all threads) [s]: robust to other load on the
    machine, unlike wall time; Dr.Jit's worker threads are counted."""
    t0 = time.process_time()
    out = fn()
    return out, time.process_time() - t0


class Hook:
    """Times the ranging work done inside the shared render (the on_hits callbacks)."""

    def __init__(self, setup: Any) -> None:
        self.setup, self.cpu_s = setup, 0.0

    def __call__(self, idx: np.ndarray) -> Any:
        inner = self.setup.on_hits_for(idx)

        def call(*args: Any) -> None:
            t0 = time.process_time()
            inner(*args)
            self.cpu_s += time.process_time() - t0

        return call


def run(n_epochs: int, bistatic: bool, repeats: int) -> None:
    loaded = scenario(n_epochs, bistatic)
    geo = scenario_geometry(loaded)
    wl = wavelength_grid_nm(loaded.scenario.spectrum)
    elev = np.where(geo.observable, geo.elevation_deg, np.nan)
    trans = atmosphere_transmission(loaded, wl, elev)
    sun_render(loaded, geo, wl)  # JIT warm-up
    base, both, alone, inside = [], [], [], []
    for _ in range(repeats):
        res, dt = timed(lambda: sun_render(loaded, geo, wl))
        base.append(dt)
        rad = instrument_response(loaded, wl, res.intensity_W_sr_nm, trans, geo.range_m)

        def shared(rad: Any = rad) -> Any:
            t0 = time.process_time()
            setup = prepare_ranging(loaded, geo, wl, *target_session(loaded))
            assert setup is not None
            hook = Hook(setup)
            t_prep = time.process_time() - t0
            sun_render(loaded, geo, wl, on_hits=hook)
            t0 = time.process_time()
            out = laser_ranging(loaded, geo, setup, trans, rad)
            inside.append(t_prep + hook.cpu_s + time.process_time() - t0)
            return out

        _, dt = timed(shared)
        both.append(dt)

        def own(rad: Any = rad) -> Any:
            setup = prepare_ranging(loaded, geo, wl, *target_session(loaded))
            assert setup is not None
            return laser_ranging(loaded, geo, setup, trans, rad)

        _, dt = timed(own)
        alone.append(dt)
    b, s, a, d = min(base), min(both), min(alone), min(inside)
    kind = "coaxial + bistatic lasers" if bistatic else "one coaxial laser"
    print(f"\n{n_epochs} epochs, {kind} (CPU seconds of this process, best of {repeats}):")
    print(f"  1. Sun render alone               {b:7.2f} s")
    print(f"  2. Sun render + ranging (shared)  {s:7.2f} s  -> +{100 * (s / b - 1):.0f} %")
    print(f"     ranging work timed inside 2    {d:7.2f} s  -> +{100 * d / b:.0f} % of 1")
    print(f"  3. ranging on its own rays        {a:7.2f} s  ({100 * a / b:.0f} % of 1)")


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="120 epochs, one repeat")
    args = ap.parse_args()
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores")
    n, rep = (120, 1) if args.quick else (600, 3)
    run(n, bistatic=False, repeats=rep)
    run(n, bistatic=True, repeats=rep)


if __name__ == "__main__":
    main()
