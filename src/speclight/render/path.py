"""Path-traced render: multi-bounce Monte Carlo with Mitsuba 3's spectral ``path`` integrator.

The scene (:mod:`.path_scene`) is built once per run: the target's parts and BSDFs and a
Sun of unit spectral irradiance. Per epoch only the Sun and the rays change
(:func:`.path_scene.set_epoch`: no scene rebuild, and the kernel is reused). The rays are
those of an orthographic view along the line of sight (the single mode's pixels); each
sample's radiance is added to the wavelength bins, giving per pixel the radiance integrated
over each bin; dividing by the bin width gives the bin-averaged radiance, which is scaled
by the epoch's solar spectrum (bin averages) afterwards.

The sample budget is split in ``K`` passes with independent samples; their spread gives the
standard error of the mean per bin. All passes of an epoch are sampled in one launch of
Mitsuba's path integrator over rays and wavelengths drawn here (:mod:`.path_sampling`: the
radiance of each sample goes to its bins, without a film), whatever the materials: plastic
coats are the spectral BSDF of :mod:`.bsdfs.path_coat`. Measured lab BRDF tables are not
available in this mode; RGL ``.bsdf`` measured materials use Mitsuba's ``measured`` plugin
(:mod:`.rgl`). A smooth mirror (``specular``, smooth plastic coat) lit by the directional
(point) Sun reflects no light toward a given observer (a delta BSDF meets a delta light);
with ``solar_disk`` it shows its glint. Flat mirrors then glint with little noise (every
sample of the face reaches the disk); a curved mirror's glint covers ~theta_sun^2 / 4 of its
image (4e-6 for a sphere), so it needs ~1e7 samples per epoch for 10 % noise.

In a ``*_spectral_polarized`` variant (``render.polarization``) each sample's radiance is a
Mueller matrix; its Stokes vector is rotated to the sky's north and binned like the
intensity (:class:`.path_sampling.PassSampler`), giving Q, U, V and their standard errors.

Reference: Jakob et al., Mitsuba 3 renderer, https://mitsuba-renderer.org (2022);
Veach 1997, Robust Monte Carlo methods for light transport simulation, PhD thesis, Stanford.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.render.bsdfs.bsdf_interface import spectrum_grid
from speclight.render.bsdfs.path_plastic import group_bases, index_groups
from speclight.render.camera import image_axes, primary_rays
from speclight.render.path_sampling import FREEZE_MIN_LAUNCHES, PassSampler, launch_count
from speclight.render.path_scene import build_scene, set_epoch
from speclight.render.polarization import sky_axes
from speclight.render.raycast import Caster
from speclight.render.result import RenderImage
from speclight.target.parts import Target
from speclight.wavelength_grid import grid_bin_bounds_nm

if TYPE_CHECKING:
    from speclight.render.session import RenderSession

F64 = NDArray[np.float64]
MAX_PASSES = 8


def render_path(
    target: Target,
    sun_dir: F64,
    obs_dir: F64,
    irradiance: F64,
    wavelength_nm: F64,
    session: RenderSession,
    resolution_px: int,
    samples_per_pixel: int,
    seed: int,
    keep: Iterable[int] = (),
    on_epoch: Callable[[int], None] | None = None,
    solar_disk: bool = False,
    coat: str = "spectral",
    pole: F64 | None = None,
) -> tuple[F64, F64, dict[int, RenderImage], F64 | None, F64 | None]:
    """Intensity (N, L), its standard error (N, L) [W sr-1 nm-1], kept images, and in a
    ``*_polarized`` variant the Stokes Q, U, V (N, L, 3) and their standard errors.

    ``session``: the run's render session (its spectral variant; its ray caster gives the
    kept images' depth maps and part indices). ``on_epoch(1)`` is called after each epoch.

    ``solar_disk``: light the target with the finite solar disk instead of a point
    (directional) Sun, so that smooth mirrors and smooth plastic coats show their glint.
    ``coat``: ``'spectral'`` (plastic coats as :mod:`.bsdfs.path_coat`, one launch per epoch) or
    ``'grouped'`` (the previous model: Mitsuba's plastic with one coat index per group of
    bins, one ``mi.render`` per group, epoch and pass; kept as a reference for the tests).
    Scalar variants (no Dr.Jit kernels to trace a Python BSDF or a sample loop into) always
    render the grouped way.
    ``pole`` (N, 3): the celestial pole in the body frame; the Stokes vectors are referenced
    to the sky's north (:mod:`speclight.render.polarization`). Needed in a polarised variant.
    """
    mi = session.activate()  # a *_spectral variant (RenderSession.create checks it)
    polarized = "polarized" in session.variant
    # A single wavelength is rendered as a 1 nm wide bin around it.
    lo, hi = grid_bin_bounds_nm(wavelength_nm)
    width = hi - lo
    passes = max(1, min(MAX_PASSES, samples_per_pixel))
    spp = max(1, samples_per_pixel // passes)
    n_ep, n_wl, res = len(sun_dir), len(wavelength_nm), resolution_px
    sums = np.zeros((n_ep, passes, n_wl))
    # kept epochs' images, summed over passes (float64, filled as they are rendered)
    acc = {e: np.zeros((res, res, n_wl)) for e in set(keep)}
    stokes_sums = np.zeros((n_ep, 3, passes, n_wl)) if polarized else None
    north = _sky_north(mi, session.variant, obs_dir, pole) if polarized else None
    if coat == "grouped" or not _jit(mi):  # scalar variants: the film loop
        _render_grouped(
            mi, target, sun_dir, obs_dir, wavelength_nm, res, spp, seed, solar_disk, sums, acc,
            on_epoch,
        )  # fmt: skip
    else:
        _render_launches(
            mi, target, sun_dir, obs_dir, (lo, hi), res, (spp, passes), seed, solar_disk,
            (sums, stokes_sums, acc), on_epoch, north,
        )  # fmt: skip
    mean, err = _pass_mean_and_error(sums, irradiance)
    stokes = stokes_err = None
    if stokes_sums is not None:
        stokes, stokes_err = _stokes_mean_and_error(stokes_sums, irradiance)
    images = {
        e: _image(
            e,
            session.caster(target),
            target,
            obs_dir[e],
            resolution_px,
            a_e / passes / width * irradiance[e],
        )
        for e, a_e in acc.items()
    }
    return mean, err, images, stokes, stokes_err


def _jit(mi: Any) -> bool:
    """True in a Dr.Jit (llvm_ad, cuda_ad) variant: kernels are traced and launched."""
    import drjit as dr

    return bool(dr.is_jit_v(mi.Float))


def _sky_north(mi: Any, variant: str, obs_dir: F64, pole: F64 | None) -> F64:
    """The sky's north (N, 3) per epoch, the Stokes reference of a polarised render."""
    if not _jit(mi) or pole is None:
        raise InputError(
            f"render.polarization in render.mode 'path' needs an llvm_ad or cuda_ad "
            f"*_spectral_polarized variant (got '{variant}') and the pole",
            field="render.variant",
        )
    north, _ = sky_axes(obs_dir, pole)
    return north


def _render_launches(
    mi: Any,
    target: Target,
    sun_dir: F64,
    obs_dir: F64,
    bounds_nm: tuple[F64, F64],
    res: int,
    samples: tuple[int, int],
    seed: int,
    solar_disk: bool,
    out: tuple[F64, F64 | None, dict[int, F64]],
    on_epoch: Callable[[int], None] | None,
    north: F64 | None,
) -> None:
    """Path mode's own sample loop, one launch per epoch: fills ``out`` = (pass sums
    (N, P, L), Stokes pass sums (N, 3, P, L) or None, kept images) per unit irradiance.

    ``bounds_nm``: the bins' edges (lo, hi); ``samples``: (samples per pixel per pass,
    passes)."""
    (lo, hi), (spp, passes) = bounds_nm, samples
    sums, stokes_sums, acc = out
    width = hi - lo
    centre, radius = target.bounding_sphere()
    pixel_area = (2.0 * radius / res) ** 2
    scene, params = build_scene(target, lo, hi, res, spp, solar_disk, groups=[])
    freeze = launch_count(passes, res, spp, len(sun_dir)) >= FREEZE_MIN_LAUNCHES
    sampler = PassSampler(mi, scene, centre, radius, lo, hi, res, spp, passes, freeze)
    for e in range(len(sun_dir)):
        set_epoch(mi, params, target, sun_dir[e], obs_dir[e], solar_disk)
        basis = None if north is None else north[e]
        s, img = sampler.epoch(obs_dir[e], seed, e, image=e in acc, north=basis)
        if stokes_sums is not None:
            stokes_sums[e] = s[1:] / spp * pixel_area / width
            s = s[0]
        sums[e] = s / spp * pixel_area / width
        if img is not None:
            acc[e] = img / spp
        if on_epoch is not None:
            on_epoch(1)
    sampler.close()


def _pass_mean_and_error(sums: F64, irradiance: F64) -> tuple[F64, F64]:
    """Mean over the passes (N, P, L) times the irradiance, and its standard error (NaN
    with one pass)."""
    passes = sums.shape[1]
    mean = sums.mean(axis=1) * irradiance
    if passes > 1:
        err = sums.std(axis=1, ddof=1) / np.sqrt(passes) * irradiance
    else:
        err = np.full((sums.shape[0], sums.shape[2]), np.nan)
    return mean, err


def _stokes_mean_and_error(stokes_sums: F64, irradiance: F64) -> tuple[F64, F64]:
    """Stokes Q, U, V (N, L, 3) from their pass sums (N, 3, P, L), and standard errors."""
    passes, n_wl = stokes_sums.shape[2], stokes_sums.shape[3]
    e3 = irradiance[:, None, :]
    stokes = np.moveaxis(stokes_sums.mean(axis=2) * e3, 1, 2)
    spread = stokes_sums.std(axis=2, ddof=1) / np.sqrt(passes) if passes > 1 else np.nan
    stokes_err = np.moveaxis(np.broadcast_to(spread, (*stokes_sums.shape[:2], n_wl)) * e3, 1, 2)
    return stokes, stokes_err


def _render_grouped(
    mi: Any,
    target: Target,
    sun_dir: F64,
    obs_dir: F64,
    wavelength_nm: F64,
    res: int,
    spp: int,
    seed: int,
    solar_disk: bool,
    sums: F64,
    acc: dict[int, F64],
    on_epoch: Callable[[int], None] | None,
) -> None:
    """The previous plastic model: groups of bins, one coat index each (fills ``sums``)."""
    lo, hi = grid_bin_bounds_nm(wavelength_nm)
    width = hi - lo
    _, radius = target.bounding_sphere()
    pixel_area = (2.0 * radius / res) ** 2
    groups = index_groups(target, wavelength_nm)
    spans = [(a, b) for a, b, _ in groups]
    scene, params = build_scene(target, lo, hi, res, spp, solar_disk, spans, coat="grouped")
    # Each group gets its share of the samples (>= 1 spp): the samples per bin, hence the
    # noise per bin, are those of one render over all bins.
    group_spp = [max(1, round(spp * (b - a) / len(wavelength_nm))) for a, b in spans]
    grid = spectrum_grid(float(lo[0]), float(hi[-1]))
    sensors = {sen.id(): sen for sen in scene.sensors()}
    bases = group_bases(target, groups, grid)
    # Groups outer: Mitsuba recomputes its coat tables (~0.1 s) only once per group.
    for j, (a, b, etas) in enumerate(groups):
        for k, n in etas.items():
            params[f"part{k}.bsdf.brdf_0.eta"] = n
            params[f"part{k}.bsdf.brdf_0.diffuse_reflectance.values"] = bases[j][k]
        last = on_epoch if j == len(groups) - 1 else None
        for e in range(len(sun_dir)):
            set_epoch(mi, params, target, sun_dir[e], obs_dir[e], solar_disk, f"sensor{j}")
            kept = acc[e][:, :, a:b] if e in acc else None
            _group_passes(
                mi, scene, sensors[f"sensor{j}"], (seed, e, j), group_spp[j],
                (sums[e, :, a:b], kept), (pixel_area, width[a:b]),
            )  # fmt: skip
            if last is not None:
                last(1)


def _group_passes(
    mi: Any,
    scene: Any,
    sensor: Any,
    ids: tuple[int, int, int],
    spp: int,
    out: tuple[F64, F64 | None],
    area_width: tuple[float, F64],
) -> None:
    """The passes of one epoch and group of bins: each pass's sums (P, B) into ``out[0]``
    (times the pixel area over the bins' widths ``area_width``), its image added to
    ``out[1]`` if kept; ``ids``: (seed, epoch, group)."""
    (seed, e, j), (sums, image), (pixel_area, width) = ids, out, area_width
    for k in range(len(sums)):
        s = (seed * 1_000_003 + e * MAX_PASSES + k + j * 7_919) % (2**32)
        img = np.asarray(mi.render(scene, sensor=sensor, seed=s, spp=spp), dtype=float)
        sums[k] = img.sum(axis=(0, 1)) * pixel_area / width
        if image is not None:
            image += img


def _image(
    e: int, caster: Caster, target: Target, obs: F64, res: int, radiance: F64
) -> RenderImage:
    """Kept image with a depth map and part indices from orthographic ray casting."""
    centre, radius = target.bounding_sphere()
    origin, direction, pixel_area = primary_rays(centre, radius, obs[None, :], res)
    hits = caster.intersect(origin, direction)
    depth = (hits.t_m - 2.0 * radius).reshape(res, res)
    right, up = image_axes(obs[None, :])
    return RenderImage(
        e, radiance, depth, hits.part.reshape(res, res), float(np.sqrt(pixel_area)), right[0], up[0]
    )
