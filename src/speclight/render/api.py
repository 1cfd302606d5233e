"""Public entry point of the render stage: :func:`render_intensity`."""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError
from speclight.progress import stage
from speclight.render.epoch_inputs import EpochInputs, epoch_inputs, irradiance_rows, unit_rows
from speclight.render.polarization import rotate_linear, scattering_angle_on_sky
from speclight.render.raycast import numpy_processes
from speclight.render.result import RenderImage, RenderResult
from speclight.render.session import RenderMode, RenderSession
from speclight.target.parts import Target

MIN_RESOLUTION_PX = 8
F64 = NDArray[np.float64]


def render_intensity(
    target: Target,
    sun_dir_body: ArrayLike,
    observer_dir_body: ArrayLike,
    solar_irradiance_W_m2_nm: ArrayLike,
    wavelength_nm: ArrayLike,
    *,
    mode: RenderMode = "single",
    resolution_px: int = 256,
    samples_per_pixel: int = 16,
    seed: int = 0,
    variant: str | None = None,
    workers: int | None = None,
    progress: bool = False,
    keep_images_for: Iterable[int] | None = None,
    on_hits: Callable[..., None] | None = None,
    solar_disk: bool = False,
    session: RenderSession | None = None,
    polarization: bool = False,
    pole_body: ArrayLike | None = None,
) -> RenderResult:
    """Radiant intensity of a sunlit target toward an observer, per epoch and wavelength.

    Parameters
    ----------
    target
        The target (body frame).
    sun_dir_body, observer_dir_body
        (N, 3) unit vectors in the body frame from the target to the Sun / to the observer.
    solar_irradiance_W_m2_nm
        (N, L) solar spectral irradiance at the target [W m-2 nm-1] (bin averages); shadowing
        by the Earth is applied by the caller.
    wavelength_nm
        (L,) bin centres [nm].
    mode
        ``single`` (one bounce with self-shadowing, exact in wavelength, the default) or
        ``path`` (multi-bounce Monte Carlo path tracing with Mitsuba's spectral variant).
    resolution_px
        Image size (square) covering the target's bounding sphere.
    samples_per_pixel
        Path mode: samples per pixel. Single mode casts one ray through each pixel centre.
    seed
        Path mode: random seed (the result is reproducible for a given seed and variant).
    variant
        Mitsuba variant or ``None``/``"auto"`` (see :func:`speclight.render.choose_variant`);
        ``"numpy"`` or a ``scalar_*`` variant casts single-mode rays with numpy. Ignored when
        ``session`` is given.
    workers
        Single mode with the numpy caster: number of processes over blocks of epochs (fewer
        where :func:`~speclight.render.raycast.numpy_processes` says so: one inside a Dask
        worker). Dr.Jit variants are already parallel over all cores and ignore it.
    progress
        Show a progress bar (on a terminal).
    keep_images_for
        Epoch indices whose hyperspectral radiance image and depth map are returned.
    on_hits
        Single mode: ``on_hits(epochs, origin, direction, hits, caster)`` is called after
        each batch's primary ray cast with the batch's epoch indices (into the inputs), so
        that laser ranging (:mod:`speclight.render.laser_returns`) reuses the rays. It forces the
        in-process caster (``workers`` is ignored). Path mode ignores it.
    solar_disk
        Path mode: light with the finite solar disk (angular radius
        :data:`~speclight.illumination.SOLAR_ANGULAR_RADIUS_RAD`, same total irradiance)
        instead of a point Sun, so that smooth mirrors and smooth plastic coats show their
        glint (a point Sun never reaches the observer through a mirror). Single mode always
        models the glint with the disk and ignores it.
    session
        The run's render session (:class:`~speclight.render.session.RenderSession`: the one
        variant and the ray casters of a run); built from ``mode``, ``variant`` and the
        target's materials when not given.
    polarization
        Also compute Stokes Q, U, V (:mod:`speclight.render.polarization`), referenced to
        the sky's north-east frame given by ``pole_body``.
    pole_body
        (N, 3) the celestial pole (GCRS z axis) in the body frame; needed with
        ``polarization``.

    Returns
    -------
    RenderResult
        ``intensity_W_sr_nm`` (N, L) = sum over pixels of radiance x pixel area, NaN rows for
        epochs whose inputs are not finite; with ``polarization`` also ``stokes_W_sr_nm``
        (N, L, 3): Q, U, V.
    """
    session = _checked_session(session, mode, variant, target, polarization, pole_body)
    if int(resolution_px) < MIN_RESOLUTION_PX:
        raise InputError(
            f"render.resolution_px = {resolution_px} must be >= {MIN_RESOLUTION_PX}",
            field="render.resolution_px",
        )
    inputs = epoch_inputs(
        sun_dir_body, observer_dir_body, solar_irradiance_W_m2_nm, wavelength_nm,
        keep_images_for, pole_body if polarization else None,
    )  # fmt: skip
    if session.mode == "single":
        rendered = _render_single(
            target, inputs, session, int(resolution_px), workers, progress, on_hits
        )
    else:
        rendered = _render_path(
            target, inputs, session, int(resolution_px), int(samples_per_pixel), int(seed),
            progress, bool(solar_disk),
        )  # fmt: skip
    return _result(inputs, rendered, session.mode)


@dataclass
class _Rendered:
    """What a mode's render gives for the valid epochs (see :func:`render_intensity`)."""

    intensity: F64
    std: F64 | float
    images: dict[int, RenderImage]
    variant: str
    stokes: F64 | None = None
    stokes_std: F64 | float | None = None
    outside: F64 | None = None


def _checked_session(
    session: RenderSession | None,
    mode: RenderMode,
    variant: str | None,
    target: Target,
    polarization: bool,
    pole_body: ArrayLike | None,
) -> RenderSession:
    """The given session, or one for ``mode``; checked for polarisation."""
    if session is None:
        session = RenderSession.create(mode, variant, target.materials, polarization=polarization)
    if polarization and pole_body is None:
        raise InputError(
            "polarization needs pole_body (the GCRS z axis in the body frame)", field="pole_body"
        )
    if polarization and session.mode == "path" and "polarized" not in session.variant:
        raise InputError(
            f"polarization in path mode needs a session with a *_spectral_polarized variant "
            f"(RenderSession.create(..., polarization=True)), got '{session.variant}'",
            field="render.variant",
        )
    return session


def _render_single(
    target: Target,
    inputs: EpochInputs,
    session: RenderSession,
    resolution_px: int,
    workers: int | None,
    progress: bool,
    on_hits: Callable[..., None] | None,
) -> _Rendered:
    """Single mode on the valid epochs: in this process, or the numpy caster in several."""
    v = inputs.valid
    sun, obs, e, polarization = inputs.sun[v], inputs.obs[v], inputs.e[v], inputs.pole is not None
    n_workers = numpy_processes(int(workers or 1))  # one inside a Dask worker
    multi = n_workers > 1 and on_hits is None
    if multi and not session.variant.startswith(("llvm_", "cuda_")) and len(v) > 1:
        # Dr.Jit variants already use every core; the numpy caster runs one process per
        # worker on contiguous blocks of epochs (Mitsuba scenes are never pickled).
        inten, linear, imgs, outside = _single_in_processes(
            target, sun, obs, e, inputs.wl, resolution_px, inputs.keep_local, n_workers,
            polarization,
        )  # fmt: skip
        used = "numpy"
    else:
        caster = session.caster(target)
        from speclight.render.single import render_single_polarized

        with stage("rendering (single)", len(v), enabled=progress) as advance:
            inten, linear, imgs, outside = render_single_polarized(
                target, sun, obs, e, inputs.wl, caster, resolution_px, inputs.keep_local,
                on_batch=advance,
                on_hits=None if on_hits is None else _global_epochs(on_hits, v),
                polarization=polarization,
            )  # fmt: skip
        used = caster.name
    rendered = _Rendered(inten, 0.0, imgs, used, outside=outside)
    if inputs.pole is not None:
        assert linear is not None
        _stokes_on_sky(rendered, linear, scattering_angle_on_sky(sun, obs, inputs.pole[v]))
    return rendered


def _stokes_on_sky(rendered: _Rendered, linear: F64, chi: F64) -> None:
    """Set the single mode's Stokes (Q_s, 0, 0) in the scattering plane's frame, turned by
    ``chi`` (N,) to the sky's north-east frame; the kept images' pixels too."""
    q, u = rotate_linear(linear, np.zeros_like(linear), chi)
    rendered.stokes = np.stack([q, u, np.zeros_like(q)], axis=-1)
    rendered.stokes_std = 0.0
    for j, img in rendered.images.items():  # the kept pixels: the same rotation
        if img.stokes_qu_W_m2_sr_nm is not None:
            qs = img.stokes_qu_W_m2_sr_nm
            qi, ui = rotate_linear(qs[..., 0], qs[..., 1], chi[j])
            img.stokes_qu_W_m2_sr_nm = np.stack([qi, ui], axis=-1)


def _render_path(
    target: Target,
    inputs: EpochInputs,
    session: RenderSession,
    resolution_px: int,
    samples_per_pixel: int,
    seed: int,
    progress: bool,
    solar_disk: bool,
) -> _Rendered:
    """Path mode on the valid epochs."""
    from speclight.render.path import render_path

    v = inputs.valid
    with stage("rendering (path)", len(v), enabled=progress) as advance:
        inten, err, imgs, st, st_err = render_path(
            target, inputs.sun[v], inputs.obs[v], inputs.e[v], inputs.wl, session,
            resolution_px, samples_per_pixel, seed, inputs.keep_local, on_epoch=advance,
            solar_disk=solar_disk, pole=None if inputs.pole is None else inputs.pole[v],
        )  # fmt: skip
    return _Rendered(inten, err, imgs, session.variant, st, st_err)


def _result(inputs: EpochInputs, rendered: _Rendered, mode: RenderMode) -> RenderResult:
    """The rendered epochs placed among all inputs' (NaN rows for those not rendered)."""
    n, n_wl = len(inputs.sun), len(inputs.wl)
    v = inputs.valid
    intensity = np.full((n, n_wl), np.nan)
    std = np.full((n, n_wl), np.nan)
    intensity[v] = rendered.intensity
    std[v] = rendered.std
    stokes = stokes_std = None
    if inputs.pole is not None:
        stokes = np.full((n, n_wl, 3), np.nan)
        stokes_std = np.full((n, n_wl, 3), np.nan)
        if rendered.stokes is not None:
            stokes[v] = rendered.stokes
            stokes_std[v] = rendered.stokes_std
    outside = None
    if rendered.outside is not None:
        outside = np.full((n, n_wl), np.nan)
        outside[v] = rendered.outside
    images = {}
    for j, img in rendered.images.items():
        g = int(v[j])
        img.epoch = g
        images[g] = img
    return RenderResult(
        intensity, std, inputs.ok, rendered.variant, mode, images, stokes, stokes_std, outside
    )


def _global_epochs(on_hits: Callable[..., None], valid: NDArray[np.int64]) -> Callable[..., None]:
    """Wrap ``on_hits`` so that it receives epoch indices into the caller's inputs."""

    def call(epochs: NDArray[np.int64], *rest: object) -> None:
        on_hits(valid[epochs], *rest)

    return call


def _single_chunk(args: tuple) -> tuple:
    from speclight.render.raycast import NumpyCaster
    from speclight.render.single import render_single_polarized

    target, sun, obs, e, wl, res, keep, polarization = args
    return render_single_polarized(
        target, sun, obs, e, wl, NumpyCaster(target), res, keep, polarization=polarization
    )


def _single_in_processes(
    target: Target,
    sun: NDArray[np.float64],
    obs: NDArray[np.float64],
    e: NDArray[np.float64],
    wl: NDArray[np.float64],
    res: int,
    keep: list[int],
    workers: int,
    polarization: bool = False,
) -> tuple[NDArray[np.float64], NDArray[np.float64] | None, dict, NDArray[np.float64] | None]:
    import itertools
    import multiprocessing as mp
    from concurrent.futures import ProcessPoolExecutor

    bounds = np.linspace(0, len(sun), min(workers, len(sun)) + 1).astype(int)
    jobs = []
    for a, b in itertools.pairwise(bounds):
        local = [k - a for k in keep if a <= k < b]
        jobs.append((target, sun[a:b], obs[a:b], e[a:b], wl, res, local, polarization))
    with ProcessPoolExecutor(len(jobs), mp_context=mp.get_context("spawn")) as pool:
        parts = list(pool.map(_single_chunk, jobs))
    images = {}
    for a, (_, _, imgs, _) in zip(bounds[:-1], parts, strict=True):
        for k, img in imgs.items():
            images[int(a) + k] = img
    linear = np.concatenate([p[1] for p in parts]) if polarization else None
    outside = None if parts[0][3] is None else np.concatenate([p[3] for p in parts])
    return np.concatenate([p[0] for p in parts]), linear, images, outside


def material_contributions(
    target: Target,
    sun_dir_body: ArrayLike,
    observer_dir_body: ArrayLike,
    solar_irradiance_W_m2_nm: ArrayLike,
    wavelength_nm: ArrayLike,
    *,
    resolution_px: int = 256,
    variant: str | None = None,
    session: RenderSession | None = None,
) -> NDArray[np.float64]:
    """Each material's contribution to the single-scattering intensity (N, M, L) [W sr-1 nm-1].

    Same inputs as :func:`render_intensity` (single mode). ``[:, k, :]`` is the light reflected
    by the pixels of ``target.materials[k]``; the sum over materials is the intensity
    ``render_intensity`` gives (to rounding). NaN rows for epochs whose inputs are not finite.

    Intensity is linear in each material's reflectance where the BRDF is proportional to it
    (``lambertian``, and ``beckmann``/``ggx``/``specular`` with a reflectance given as numbers
    rather than n,k): scaling material k's reflectance by ``a_k`` scales its contribution by
    ``a_k``, so ``contributions[:, :, band]`` is the design matrix of a fit of per-material
    albedos, and the contributions are the endmember spectra of an unmixing. For ``plastic``
    only the diffuse base scales with ``diffuse_reflectance``; the coat does not.

    Examples
    --------
    >>> from speclight.target import Material, Reflectance, cube
    >>> grey = Material("grey", "lambertian", Reflectance.constant(0.5))
    >>> c = material_contributions(cube(1.0, grey), [0, 0, 1], [0, 0, 1], [1.0, 1.0],
    ...                            [500.0, 600.0], resolution_px=16, variant="numpy")
    >>> c.shape
    (1, 1, 2)
    """
    wl = np.asarray(wavelength_nm, dtype=float).ravel()
    sun, ok_s = unit_rows(sun_dir_body, "sun_dir_body")
    obs, ok_o = unit_rows(observer_dir_body, "observer_dir_body", len(sun))
    e = irradiance_rows(solar_irradiance_W_m2_nm, len(sun), len(wl))
    if session is None:
        session = RenderSession.create("single", variant, target.materials)
    ok = ok_s & ok_o & np.all(np.isfinite(e), axis=1)
    out = np.full((len(sun), len(target.materials), len(wl)), np.nan)
    valid = np.flatnonzero(ok)
    if valid.size:
        from speclight.render.single import material_contributions as contributions

        out[valid] = contributions(
            target, sun[valid], obs[valid], e[valid], wl, session.caster(target), int(resolution_px)
        )
    return out
