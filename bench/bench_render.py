"""Render-stage benchmark: run ``python bench/bench_render.py [--quick]`` and read the printout.

1. A box-wing pass (600 epochs, 189 wavelength bins 300-1240 nm, 256 x 256 px) in single
   mode with the vectorised Mitsuba caster (llvm/cuda) and with the numpy caster (what the
   scalar variants and a Mitsuba-less install use; timed on a subset and extrapolated).
2. Single mode epochs/s against image size (60 epochs, after a warm-up render at each size).
3. Path mode: samples per pixel needed for 1 % noise per 5 nm bin, and the time that takes.
"""

from __future__ import annotations

import argparse
import os
import platform
import time

import numpy as np

from speclight.illumination import solar_irradiance_W_m2_nm
from speclight.render import available_variants, render_intensity
from speclight.target import Material, Reflectance, box_wing


def box_wing_target():
    return box_wing(
        {
            "bus": Material("mli", "beckmann", Reflectance.dielectric("Kapton"), roughness=0.3),
            "wing_+y": Material("cells", "ggx", Reflectance.dielectric("Si"), roughness=0.1),
            "wing_-y": Material("cells", "ggx", Reflectance.dielectric("Si"), roughness=0.1),
            "antenna": Material("paint", "lambertian", Reflectance.constant(0.8)),
        }
    )


def pass_geometry(n: int) -> tuple[np.ndarray, np.ndarray]:
    """Sun fixed, observer sweeping 160 deg across the body frame during the pass."""
    t = np.linspace(-1.0, 1.0, n)
    az = np.radians(80.0) * t
    el = np.radians(50.0) - np.radians(35.0) * t**2
    obs = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)], axis=1)
    sun = np.tile(np.array([0.5, 0.3, 0.81]) / np.linalg.norm([0.5, 0.3, 0.81]), (n, 1))
    return sun, obs


def timed(fn):
    t0 = time.perf_counter()
    out = fn()
    return out, time.perf_counter() - t0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="fewer epochs")
    args = ap.parse_args()
    print(
        f"machine: {platform.machine()}, {os.cpu_count()} cores; variants: {available_variants()}"
    )
    wl = np.arange(300.0, 1241.0, 5.0)
    target = box_wing_target()
    fast = [
        v for v in available_variants() if v.startswith(("cuda_", "llvm_")) and v.endswith("_rgb")
    ]
    n_pass = 60 if args.quick else 600
    sun, obs = pass_geometry(n_pass)
    e = np.tile(solar_irradiance_W_m2_nm(wl), (n_pass, 1))

    print("\n1. box-wing pass, single mode, 189 bins, 256 px")
    if fast:
        render_intensity(target, sun[:2], obs[:2], e[:2], wl, variant=fast[0])  # JIT warm-up
        res, dt = timed(lambda: render_intensity(target, sun, obs, e, wl, variant=fast[0]))
        print(f"  {fast[0]:>14}: {n_pass} epochs in {dt:.2f} s ({n_pass / dt:.1f} epochs/s)")
    n_np = 10 if args.quick else 30
    res_np, dt = timed(
        lambda: render_intensity(target, sun[:n_np], obs[:n_np], e[:n_np], wl, variant="numpy")
    )
    print(
        f"  {'numpy':>14}: {n_np} epochs in {dt:.2f} s ({n_np / dt:.2f} epochs/s; "
        f"{n_pass} epochs ~ {dt * n_pass / n_np:.0f} s)"
    )
    if fast:
        diff = np.nanmax(np.abs(res_np.intensity_W_sr_nm - res.intensity_W_sr_nm[:n_np]))
        rel = diff / np.nanmax(res.intensity_W_sr_nm)
        print(f"  numpy vs {fast[0]}: max |dI| / max I = {rel:.1e}")

    print("\n2. single mode epochs/s vs image size (box-wing, 189 bins)")
    variant = fast[0] if fast else "numpy"
    n = 60 if fast else 5
    for px in (64, 128, 256, 512):  # each size warmed up first (its kernel compiled or loaded)
        render_intensity(target, sun[:2], obs[:2], e[:2], wl, resolution_px=px, variant=variant)
        _, dt = timed(
            lambda px=px: render_intensity(
                target, sun[:n], obs[:n], e[:n], wl, resolution_px=px, variant=variant
            )
        )
        print(f"  {variant} {px:4d} px: {n / dt:7.2f} epochs/s")

    spectral = [
        v for v in available_variants() if v.endswith("_spectral") and not v.startswith("scalar")
    ]
    if spectral:
        print("\n3. path mode noise (box-wing, one mid-pass epoch, 5 nm bins, 128 px)")
        k = n_pass // 2
        render_intensity(
            target,
            sun[k : k + 1],
            obs[k : k + 1],
            e[k : k + 1],
            wl,
            mode="path",
            resolution_px=16,
            samples_per_pixel=8,
            variant=spectral[0],
        )  # JIT warm-up
        for spp in (16, 64, 256):
            r, dt = timed(
                lambda spp=spp: render_intensity(
                    target,
                    sun[k : k + 1],
                    obs[k : k + 1],
                    e[k : k + 1],
                    wl,
                    mode="path",
                    resolution_px=128,
                    samples_per_pixel=spp,
                    variant=spectral[0],
                )
            )
            rel = np.median(r.intensity_std_W_sr_nm / r.intensity_W_sr_nm)
            need = spp * (rel / 0.01) ** 2
            print(
                f"  spp {spp:4d}: median noise per bin {100 * rel:.2f} % in {dt:.2f} s/epoch; "
                f"1 % needs ~{need:.0f} spp (~{dt * need / spp:.0f} s/epoch)"
            )


if __name__ == "__main__":
    main()
