"""The path mode's sample loop: its own rays and wavelengths, Mitsuba's path integrator, bins.

``mi.render`` accumulates every sample into a film holding all wavelength bins: with a
``specfilm`` of 189 bins each sample adds 190 values to its pixel, and developing the film
touches every pixel and bin again; on the box-wing at 128 px and 16 spp that was 80-90 % of
an epoch's time. Path mode needs only the sum over pixels per bin (and, for a kept image,
per pixel), so here each sample adds its four wavelengths' radiance to one bin each:

* lane ``i`` of a launch is sample ``s`` of pixel ``p`` of pass ``k`` (pass-major); its ray
  is the orthographic primary ray of :func:`speclight.render.camera.primary_rays` jittered
  uniformly over the pixel (the box pixel filter of the film it replaces);
* its wavelengths are Mitsuba's hero-wavelength sampling, stratified over the grid:
  ``lambda_j = lo + W frac(u + j / n)``, j = 0..n-1 (n = 4 wavelengths per sample, W the
  grid's width), each uniform over [lo, lo + W] with pdf 1 / W (Wilkie et al. 2014, "Hero
  wavelength spectral sampling", doi:10.1111/cgf.12419);
* ``integrator.sample`` (Mitsuba's ``path``) gives the radiance L(lambda_j) of the path;
  ``L W / n`` is added to the bin holding lambda_j, which estimates the radiance integrated
  over that bin; over the ``spp`` samples of a pixel the mean is the pixel's value, the
  film's estimator. The sums are taken in float64 in numpy, in a fixed order, so that a run
  is reproducible bit for bit.

All values that change between epochs (the Sun's transform in the scene, the ray origin and
axes, the seed) are opaque inputs, so each launch reuses the compiled kernel: one launch per
epoch (more only when an epoch has more than :data:`MAX_LANES` samples). The launch is a
frozen function (``dr.freeze``, Dr.Jit >= 1.1): traced and recorded on the first epoch, then
replayed with the new inputs, which halves an epoch's time (tracing Mitsuba's integrator and
the Python BSDF took ~2/3 of it); where freezing is not available or fails, every launch is
traced. Setting the environment variable ``SPECLIGHT_PATH_FREEZE=0`` traces every launch
(same results, about 2x slower per epoch): a way around a Dr.Jit whose frozen functions fail.
"""

from __future__ import annotations

import gc
import hashlib
import os
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.render.camera import image_axes

F64 = NDArray[np.float64]
#: Most samples (lanes) per launch: its state and outputs (the four wavelengths' radiance and
#: bins, summed in numpy) stay below a few hundred MB; larger epochs take several launches.
MAX_LANES = 1 << 21
#: Fewest launches in a run for which the launch is frozen (break-even ~20, measured on the
#: box-wing: recording ~0.5 s, each replay ~0.03 s faster than tracing).
FREEZE_MIN_LAUNCHES = 32
#: Environment variable: ``0`` turns frozen launches off (every launch traced).
FREEZE_ENV = "SPECLIGHT_PATH_FREEZE"


def launch_count(passes: int, resolution_px: int, spp: int, epochs: int) -> int:
    """Launches a run of ``epochs`` epochs takes (:data:`MAX_LANES` samples at most each)."""
    per_epoch = passes * resolution_px * resolution_px * spp
    return epochs * -(-per_epoch // MAX_LANES)


def launch_seed(seed: int, epoch: int, chunk: int) -> int:
    """32-bit sampler seed of one launch (hash of run seed, epoch and chunk)."""
    digest = hashlib.blake2b(f"{seed},{epoch},{chunk}".encode(), digest_size=4).digest()
    return int.from_bytes(digest, "little")


class PassSampler:
    """Renders epochs of a scene into per-pass bin sums (and optional images).

    Parameters
    ----------
    mi
        The ``mitsuba`` module, spectral variant active.
    scene
        The scene of :func:`speclight.render.path_scene.build_scene` (its Sun updated per
        epoch by the caller).
    centre, radius_m
        Bounding sphere of the target: the view is 2 ``radius_m`` wide, centred on it.
    edges_lo, edges_hi
        Contiguous wavelength bins [nm].
    resolution_px, spp, passes
        Pixels per side, samples per pixel in each pass, independent passes.
    freeze
        Freeze the launch (recording it costs about ten traced launches; the replays save
        about half an epoch each): worth it from :data:`FREEZE_MIN_LAUNCHES` launches.

    In a ``*_polarized`` variant the integrator's radiance is a Mueller matrix whose first
    column is the Stokes vector, referenced to Mitsuba's implicit basis
    ``mueller.stokes_basis(-ray.d)``; each sample's Stokes vector is rotated to the basis
    ``north`` given per epoch (Mitsuba's second axis is then ``(-ray.d) x north``: east on the
    sky, :mod:`speclight.render.polarization`), V's sign turned to the IAU's (Mitsuba's
    positive V is clockwise as seen facing the source, the IAU's counter-clockwise) and its
    four components binned. No film and
    no ``stokes`` integrator are used (the latter's AOV channels crash with AOV output and
    ``specfilm`` breaks with its Stokes output).
    """

    def __init__(
        self,
        mi: Any,
        scene: Any,
        centre: F64,
        radius_m: float,
        edges_lo: F64,
        edges_hi: F64,
        resolution_px: int,
        spp: int,
        passes: int,
        freeze: bool = True,
    ) -> None:
        self.mi, self.scene = mi, scene
        self.integrator = scene.integrator()
        self.sampler = mi.load_dict({"type": "independent"})
        self.centre, self.radius = np.asarray(centre, float), float(radius_m)
        self.res, self.spp, self.passes = int(resolution_px), int(spp), int(passes)
        self.n_bins = len(edges_lo)
        self.n_stokes = 4 if "polarized" in mi.variant() else 1
        self.lo_nm = float(edges_lo[0])
        self.width_nm = float(edges_hi[-1] - edges_lo[0])
        self.hi_edges = mi.Float(np.asarray(edges_hi, np.float32))
        import drjit as dr

        # Frozen (Dr.Jit >= 1.1): the launch is traced once and replayed per epoch. Earlier
        # runs' garbage is collected now, before any recording (see _launch).
        freeze = freeze and hasattr(dr, "freeze") and os.environ.get(FREEZE_ENV, "1") != "0"
        self._frozen = dr.freeze(self._trace) if freeze else None
        if self._frozen is not None:
            gc.collect()

    def close(self) -> None:
        """Drop the frozen launch (its recordings, and the cycle through ``self``)."""
        self._frozen = None

    def epoch(
        self, obs: F64, seed: int, epoch: int, image: bool = False, north: F64 | None = None
    ) -> tuple[F64, F64 | None]:
        """Sums (passes, L) over samples of ``L W / n`` per bin, and per pixel (res, res, L)
        over all passes when ``image``; divide by ``spp`` for the film's pixel values.

        Polarised variant: the sums are (4, passes, L), Stokes I, Q, U, V referenced to
        ``north`` (3,) (the image stays intensity only)."""
        obs = np.asarray(obs, float)
        total = self.passes * self.res * self.res * self.spp
        sums = np.zeros(self.n_stokes * self.passes * self.n_bins)
        pixels: F64 | None = None  # the first launch's array, then added to
        right, up = image_axes(obs[None, :])
        basis = up[0] if north is None else np.asarray(north, float)
        frame = (self.centre + 2.0 * self.radius * obs, right[0], up[0], -obs, basis)
        for c, start in enumerate(range(0, total, MAX_LANES)):
            n = min(MAX_LANES, total - start)
            s, px = self._launch(frame, launch_seed(seed, epoch, c), start, n, image)
            sums += s
            if px is not None:
                pixels = px if pixels is None else pixels + px
        shape = (self.passes, self.n_bins)
        out = sums.reshape((self.n_stokes, *shape) if self.n_stokes > 1 else shape)
        img = None if pixels is None else pixels.reshape(self.res, self.res, self.n_bins)
        return out, img

    def _launch(
        self, frame: tuple[F64, ...], seed: int, start: int, n: int, image: bool
    ) -> tuple[F64, F64 | None]:
        import drjit as dr

        mi = self.mi
        origin, right, up, direction, basis = (dr.opaque(mi.Vector3f, v.tolist()) for v in frame)
        # 64-bit lane numbers: an epoch may have more than 2^32 samples (4096 px x 256 spp)
        uint64: Any = dr.uint64_array_t(mi.UInt32)
        first = dr.opaque(uint64, start)
        # n, image: Python values (a change re-traces a frozen launch)
        args: tuple[Any, ...] = (
            self.scene,
            dr.opaque(mi.UInt32, seed),
            first,
            origin,
            right,
            up,
            direction,
            basis,
            self.hi_edges,
            n,
            image,
        )
        if self._frozen is not None:
            # No garbage collection while a launch is recorded or replayed: freeing Dr.Jit
            # arrays of an earlier run's cycles then aborts the process (Dr.Jit 1.5:
            # "enqueue_host_func(): this function cannot be recorded").
            collecting = gc.isenabled()
            gc.disable()
            try:
                keys, pixel_keys, values = self._frozen(*args)
            except RuntimeError:  # a Dr.Jit that cannot freeze this: trace every launch
                self._frozen = None
            finally:
                if collecting:
                    gc.enable()
        if self._frozen is None:
            keys, pixel_keys, values = self._trace(*args)
        dr.eval(keys, pixel_keys, values)
        # Summed here in float64, in a fixed order: a run is reproducible bit for bit
        # (atomic float32 adds on several threads are not).
        nb = self.n_bins
        v = np.concatenate([x.numpy() for x in values]).astype(float)
        k = np.concatenate([x.numpy() for x in keys])
        sums = np.bincount(k, v, self.n_stokes * self.passes * nb).astype(float)
        if not image:
            return sums, None
        pk = np.concatenate([x.numpy() for x in pixel_keys])
        v0 = v[: len(pk)]  # the first values are the intensity's (Stokes I)
        return sums, np.bincount(pk, v0, self.res * self.res * nb).astype(float)

    def _trace(
        self,
        scene: Any,
        seed: Any,
        first: Any,
        origin: Any,
        right: Any,
        up: Any,
        direction: Any,
        basis: Any,
        hi_edges: Any,
        n: int,
        image: bool,
    ) -> tuple[list[Any], list[Any], list[Any]]:
        """One launch's samples: bin keys (pass, bin), pixel keys (pixel, bin) and values.

        Every Dr.Jit value it reads is an argument, so that it can be frozen
        (``dr.freeze``: recorded once, then replayed without tracing)."""
        import drjit as dr

        mi, res, spp, nb = self.mi, self.res, self.spp, self.n_bins
        self.sampler.seed(seed, n)
        # lanes first .. first + n - 1 of the epoch (pass-major, then pixel, then sample)
        uint64: Any = dr.uint64_array_t(mi.UInt32)
        idx = uint64(dr.arange(mi.UInt32, n)) + first
        pix = mi.UInt32((idx // spp) % (res * res))
        row, col = pix // res, pix % res
        u = self.sampler.next_2d()
        x = ((mi.Float(col) + u.x) * (2.0 / res) - 1.0) * self.radius
        y = (1.0 - (mi.Float(row) + u.y) * (2.0 / res)) * self.radius
        u_wl = self.sampler.next_1d()
        n_wl = dr.size_v(mi.UnpolarizedSpectrum)
        lam = mi.UnpolarizedSpectrum(
            *[self.lo_nm + self.width_nm * _frac(dr, u_wl + j / n_wl) for j in range(n_wl)]
        )
        ray = mi.Ray3f(mi.Point3f(origin + x * right + y * up), mi.Vector3f(direction), 0.0, lam)
        radiance, _, _ = self.integrator.sample(
            scene, self.sampler, mi.RayDifferential3f(ray), None, True
        )
        pas = mi.UInt32(idx // (res * res * spp))
        if self.n_stokes > 1:  # Stokes vector (first column), rotated to the basis
            forward = -mi.Vector3f(direction)
            current = mi.mueller.stokes_basis(forward)
            rotated = mi.mueller.rotate_stokes_basis(forward, current, basis) @ radiance
            # Mitsuba's V > 0 is right-handed as optics counts it, clockwise for the observer
            # facing the source (its polarisation guide); the IAU's V > 0 turns
            # counter-clockwise (north toward east): V changes sign here, the one place
            # (tests/render/test_render_polarization_vsign.py).
            components = [rotated[0][0], rotated[1][0], rotated[2][0], -rotated[3][0]]
        else:
            components = [radiance]
        keys, pixel_keys, values = [], [], []
        bins = []
        for j in range(n_wl):
            wl_j = lam[j]
            b = dr.binary_search(0, nb - 1, lambda i, w=wl_j: dr.gather(mi.Float, hi_edges, i) <= w)
            bins.append(b)
            if image:
                pixel_keys.append(pix * nb + b)
        for c, comp in enumerate(components):
            for j in range(n_wl):
                keys.append((c * self.passes + pas) * nb + bins[j])
                values.append(comp[j] * (self.width_nm / n_wl))
        return keys, pixel_keys, values


def _frac(dr: Any, v: Any) -> Any:
    return v - dr.floor(v)
