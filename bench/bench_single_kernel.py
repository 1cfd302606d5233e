"""Single mode against a bare Dr.Jit kernel of the same algorithm, in one run, interleaved.

Run ``python bench/bench_single_kernel.py [--epochs 600] [--repeats 3] [--variant llvm_ad_rgb]``
and read the printout (issue 26 item 1: speclight within 3x of the bare kernel at 64 px and
2x at 256 px).

Both render the box-wing example's first ``--epochs`` sunlit epochs (its own geometry, 189
bins 300-1240 nm) at 64 and 256 px, alternating (speclight, bare, speclight, bare ...) so
that both see the same machine load:

* **speclight**: :func:`speclight.render.render_intensity` in single mode (every material's
  channels: the box-wing's three plastics have 3 x 33 x 33 base channels, 3,271 in all);
* **bare**: the algorithm written directly in Dr.Jit, float32: orthographic pixel-centre
  rays, ``scene.ray_intersect``, a shadow ``ray_test`` toward the Sun, per pixel a Beckmann
  weight (the part's roughness) and a diffuse weight ``cos_i / pi``, summed per epoch and
  part with ``scatter_reduce`` in the same launch; then the spectra as one matrix product.
  It has no coat channels (4 x 2 channels, not 3,271) and no deterministic sums, so 1x is
  not the goal.

Prints ms per epoch (best and median of the repeats), primary rays per second and the ratio.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from speclight.render import RenderSession, render_intensity
from speclight.scenario.builtin_examples import example_text
from speclight.scenario.load import parse_scenario
from speclight.simulation.geometry_stage import scenario_geometry
from speclight.simulation.reflection import build_target
from speclight.target.parts import Target

WAVELENGTH_NM = np.arange(300.0, 1241.0, 5.0)  # 189 bins


def box_wing(n_epochs: int) -> tuple[Target, np.ndarray, np.ndarray]:
    """The box-wing example's target and the body-frame Sun and observer directions of its
    first ``n_epochs`` sunlit, observable epochs."""
    loaded = parse_scenario(example_text("box-wing"), source="box-wing", base_dir=Path.cwd())
    geo = scenario_geometry(loaded, None)
    lit = np.flatnonzero(geo.observable & (geo.sunlit_fraction > 0))[:n_epochs]
    return build_target(loaded), geo.sun_direction_body[lit], geo.observer_direction_body[lit]


class BareKernel:
    """The algorithm in plain Dr.Jit (module doc), on the caster's scene."""

    def __init__(self, target: Target, session: RenderSession, resolution_px: int) -> None:
        import drjit as dr
        import mitsuba as mi

        self.mi, self.dr = mi, dr
        caster: Any = session.caster(target)
        self.scene = caster.scene
        self.part_of_face = mi.UInt32(caster.face_part)
        self.alpha = mi.Float([float(m.roughness or 0.3) for m in target.materials])
        self.part_mat = mi.UInt32(target.part_material_index)
        self.n_mat = len(target.materials)
        self.centre, self.radius = target.bounding_sphere()
        self.res = resolution_px
        rng = np.random.default_rng(0)
        self.factors = rng.uniform(0.1, 1.0, (2 * self.n_mat, len(WAVELENGTH_NM)))

    def render(self, sun: np.ndarray, obs: np.ndarray, batch_rays: int = 1_000_000) -> np.ndarray:
        out = []
        per = max(1, batch_rays // self.res**2)
        for a in range(0, len(sun), per):
            out.append(self._batch(sun[a : a + per], obs[a : a + per]))
        return np.concatenate(out) @ self.factors

    def _batch(self, sun: np.ndarray, obs: np.ndarray) -> np.ndarray:
        mi, dr = self.mi, self.dr
        b, px = len(sun), self.res * self.res
        idx = dr.arange(mi.UInt32, b * px)
        e, p = idx // px, idx % px
        o = mi.Vector3f(dr.gather(mi.Vector3f, mi.Vector3f(obs.T.astype(np.float32)), e))
        s = mi.Vector3f(dr.gather(mi.Vector3f, mi.Vector3f(sun.T.astype(np.float32)), e))
        ref = dr.select(dr.abs(o.z) > 0.999, mi.Vector3f(0, 1, 0), mi.Vector3f(0, 0, 1))
        up = dr.normalize(ref - dr.dot(ref, o) * o)
        right = dr.cross(up, o)
        col, row = mi.Float(p % self.res), mi.Float(p // self.res)
        x = ((col + 0.5) / self.res * 2 - 1) * self.radius
        y = -((row + 0.5) / self.res * 2 - 1) * self.radius
        origin = (
            mi.Point3f(*[float(c) for c in self.centre]) + x * right + y * up + 2 * self.radius * o
        )
        si = self.scene.ray_intersect(mi.Ray3f(origin, -o), mi.RayFlags.Minimal, False)
        n = dr.normalize(si.n)
        n = dr.select(dr.dot(n, o) < 0, -n, n)
        cos_o, cos_i = dr.dot(n, o), dr.dot(n, s)
        lit = si.is_valid() & (cos_i > 0) & (cos_o > 0)
        pos = si.p + 1e-4 * self.radius * n
        lit &= ~self.scene.ray_test(mi.Ray3f(pos, s), lit)
        h = dr.normalize(s + o)
        cos_h = dr.dot(n, h)
        mat = dr.gather(
            mi.UInt32,
            self.part_mat,
            dr.gather(mi.UInt32, self.part_of_face, si.prim_index, lit),
            lit,
        )
        a2 = dr.square(dr.gather(mi.Float, self.alpha, mat, lit))
        c2 = dr.square(dr.maximum(cos_h, 1e-6))
        d = dr.exp(-(1 - c2) / (c2 * a2)) / (dr.pi * a2 * c2 * c2)
        sums = dr.zeros(mi.Float, b * 2 * self.n_mat)
        slot = e * (2 * self.n_mat) + 2 * mat
        dr.scatter_reduce(dr.ReduceOp.Add, sums, d / (4 * cos_o), slot, lit)
        dr.scatter_reduce(dr.ReduceOp.Add, sums, cos_i / dr.pi, slot + 1, lit)
        return np.asarray(sums, dtype=float).reshape(b, 2 * self.n_mat)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--epochs", type=int, default=600)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--sizes", default="64,256")
    args = ap.parse_args()
    print(f"machine: {platform.machine()}, {os.cpu_count()} cores, load {os.getloadavg()}")
    target, sun, obs = box_wing(args.epochs)
    n = len(sun)
    session = RenderSession.create("single", args.variant, target.materials)
    irradiance = np.full((n, len(WAVELENGTH_NM)), 1.5)
    for res in [int(r) for r in args.sizes.split(",")]:
        bare = BareKernel(target, session, res)

        def ours(res: int = res) -> None:
            render_intensity(
                target, sun, obs, irradiance, WAVELENGTH_NM, resolution_px=res, session=session
            )

        runs: dict[str, list[float]] = {"speclight": [], "bare": []}
        ours()
        bare.render(sun, obs)  # compile both kernels first
        for _ in range(args.repeats):
            for name, fn in (("speclight", ours), ("bare", partial(bare.render, sun, obs))):
                t0 = time.perf_counter()
                fn()
                runs[name].append((time.perf_counter() - t0) / n * 1e3)
        best = {k: min(v) for k, v in runs.items()}
        for k, v in runs.items():
            rays = res * res / (best[k] * 1e-3)
            print(
                f"{res:4d} px {k:9s}: {best[k]:7.3f} ms/epoch best, {np.median(v):7.3f} median "
                f"({rays:.2e} primary rays/s)"
            )
        print(f"{res:4d} px ratio speclight / bare (best): {best['speclight'] / best['bare']:.2f}")
    print(f"{n} epochs, {len(WAVELENGTH_NM)} bins, {session.variant}, load {os.getloadavg()}")


if __name__ == "__main__":
    main()
