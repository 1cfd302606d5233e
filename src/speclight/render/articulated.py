"""Rendering a target with articulated parts: epochs grouped by the parts' angles.

Every epoch has its own joint angles (:mod:`speclight.target.articulation`). The epochs are
grouped by their angles rounded to ``angle_step_deg`` (exact angles when it is 0); each group
is rendered with the target posed at the group's angles, in one :func:`render_intensity` call
with the run's session. A scene is thus built once per distinct pose, not per epoch: a
sun-tracking array over a pass turns through a few tens of degrees, so a 0.5 deg step gives a
few tens of scenes, whatever the number of epochs. Bus and array are one scene in each pose,
so the shadows between them are those of the render (the shadow rays see every part).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator

import numpy as np
from numpy.typing import NDArray

from speclight.render.api import render_intensity
from speclight.render.result import RenderResult
from speclight.render.session import RenderSession
from speclight.target.articulation import Joint, posed_target
from speclight.target.parts import Target

F64 = NDArray[np.float64]


def pose_groups(angles_rad: F64, angle_step_deg: float) -> tuple[F64, NDArray[np.int64]]:
    """The distinct poses (G, J) [rad] and each epoch's pose index (N,).

    Angles are rounded to multiples of ``angle_step_deg`` (wrapped to (-180, 180] deg first);
    0 keeps the exact angles (one pose per distinct angle row).
    """
    a = np.asarray(angles_rad, float)
    wrapped = np.angle(np.exp(1j * a))
    if angle_step_deg > 0:
        step = np.radians(angle_step_deg)
        wrapped = np.round(wrapped / step) * step
    poses, inverse = np.unique(wrapped, axis=0, return_inverse=True)
    return poses, inverse.reshape(-1).astype(np.int64)


def posed_groups(
    target: Target, joints: tuple[Joint, ...], angles_rad: F64, angle_step_deg: float
) -> Iterator[tuple[NDArray[np.int64], Target]]:
    """``(epochs, posed target)`` per pose of :func:`pose_groups`, in its order.

    Every renderer of an articulated target (the pipeline's, the roughness-gradient pass's)
    groups its epochs through this, so that they pose the parts alike.
    """
    poses, group = pose_groups(angles_rad, angle_step_deg)
    for g, pose in enumerate(poses):
        yield np.flatnonzero(group == g), posed_target(target, joints, pose)


def render_articulated(
    target: Target,
    joints: tuple[Joint, ...],
    angles_rad: F64,
    sun_dir_body: F64,
    observer_dir_body: F64,
    solar_irradiance_W_m2_nm: F64,
    wavelength_nm: F64,
    *,
    session: RenderSession,
    angle_step_deg: float = 0.5,
    keep_images_for: Iterable[int] | None = None,
    **kwargs: object,
) -> RenderResult:
    """Like :func:`render_intensity`, with the joints at ``angles_rad`` (N, J) per epoch.

    ``kwargs`` are passed to :func:`render_intensity` (``resolution_px``, ``seed``, ...).
    """
    n, n_wl = len(sun_dir_body), len(wavelength_nm)
    keep = set(int(k) for k in (keep_images_for or ()))
    on_hits = kwargs.pop("on_hits", None)
    pole = kwargs.pop("pole_body", None)
    out = _unrendered(n, n_wl, bool(kwargs.get("polarization")), session)
    for idx, posed in posed_groups(target, joints, angles_rad, angle_step_deg):
        if on_hits is not None:
            kwargs["on_hits"] = _in_group(on_hits, idx)  # type: ignore[arg-type]
        local_keep = [j for j, e in enumerate(idx) if int(e) in keep]
        res = render_intensity(
            posed,
            sun_dir_body[idx],
            observer_dir_body[idx],
            solar_irradiance_W_m2_nm[idx],
            wavelength_nm,
            session=session,
            keep_images_for=local_keep or None,
            pole_body=None if pole is None else np.asarray(pole)[idx],
            **kwargs,  # type: ignore[arg-type]
        )
        session.forget(posed)  # one scene alive at a time
        _place(out, res, idx)
    return out


def _unrendered(n: int, n_wl: int, polarized: bool, session: RenderSession) -> RenderResult:
    """A result of ``n`` epochs none of which is rendered yet (NaN, not ok)."""
    stokes = stokes_std = None
    if polarized:
        stokes, stokes_std = np.full((n, n_wl, 3), np.nan), np.full((n, n_wl, 3), np.nan)
    return RenderResult(
        np.full((n, n_wl), np.nan), np.full((n, n_wl), np.nan), np.zeros(n, bool),
        session.variant, str(session.mode), {}, stokes, stokes_std,
    )  # fmt: skip


def _place(out: RenderResult, res: RenderResult, idx: NDArray[np.int64]) -> None:
    """Put the render ``res`` of the epochs ``idx`` (a group of one pose) into ``out``."""
    out.intensity_W_sr_nm[idx] = res.intensity_W_sr_nm
    out.intensity_std_W_sr_nm[idx] = res.intensity_std_W_sr_nm
    out.ok[idx] = res.ok
    if out.stokes_W_sr_nm is not None and out.stokes_std_W_sr_nm is not None:
        out.stokes_W_sr_nm[idx] = res.stokes_W_sr_nm
        out.stokes_std_W_sr_nm[idx] = res.stokes_std_W_sr_nm
    if res.outside_support_W_sr_nm is not None:
        if out.outside_support_W_sr_nm is None:
            out.outside_support_W_sr_nm = np.zeros_like(out.intensity_W_sr_nm)
        out.outside_support_W_sr_nm[idx] = res.outside_support_W_sr_nm
    out.variant, out.mode = res.variant, res.mode
    for j, img in res.images.items():
        img.epoch = int(idx[j])
        out.images[int(idx[j])] = img


def _in_group(on_hits: Callable[..., None], idx: NDArray[np.int64]) -> Callable[..., None]:
    """Wrap ``on_hits`` so that it receives epoch indices into the caller's inputs."""

    def call(epochs: NDArray[np.int64], *rest: object) -> None:
        on_hits(idx[epochs], *rest)

    return call
