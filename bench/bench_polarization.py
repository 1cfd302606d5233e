"""Cost of ``render.polarization``: run ``python bench/bench_polarization.py``.

The box-wing pass of ``bench_render.py`` (600 epochs, 189 bins 300-1240 nm, 256 px, single
mode, the vectorised Mitsuba caster), rendered without polarisation, with it, and both again
(the spread of the repeated runs is the machine's noise: other work shares the cores); then
path mode at 64 px and 16 spp on 60 epochs, spectral against spectral_polarized.
"""

from __future__ import annotations

import os
import platform
import time

import numpy as np

from bench_render import box_wing_target, pass_geometry
from speclight.illumination import solar_irradiance_W_m2_nm
from speclight.render import render_intensity


def main() -> None:
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores")
    wl = np.arange(300.0, 1241.0, 5.0)
    target = box_wing_target()
    sun, obs = pass_geometry(600)
    e = solar_irradiance_W_m2_nm(wl, 1.0)
    pole = np.tile([0.0, 0.3, 0.95], (len(sun), 1))
    render_intensity(target, sun[:5], obs[:5], e, wl, resolution_px=256)  # warm-up
    for label, pol in (("off", False), ("on", True), ("off again", False), ("on again", True)):
        t0 = time.perf_counter()
        render_intensity(
            target, sun, obs, e, wl, resolution_px=256, polarization=pol,
            pole_body=pole if pol else None,
        )  # fmt: skip
        took = time.perf_counter() - t0
        print(f"single, 600 epochs, 256 px, polarization {label}: {took:.2f} s")
    n = 60
    for pol in (False, True):
        t0 = time.perf_counter()
        render_intensity(
            target, sun[:n], obs[:n], e, wl, mode="path", resolution_px=64,
            samples_per_pixel=16, polarization=pol, pole_body=pole[:n] if pol else None,
        )  # fmt: skip
        took = time.perf_counter() - t0
        print(f"path, {n} epochs, 64 px, 16 spp, polarization {pol}: {took:.2f} s")


if __name__ == "__main__":
    main()
