"""The checked inputs of a render call: unit directions, irradiance, the epochs that render.

Shared by :func:`speclight.render.render_intensity` and
:func:`speclight.render.material_contributions`.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError

F64 = NDArray[np.float64]


def unit_rows(
    a: ArrayLike, name: str, n: int | None = None
) -> tuple[NDArray[np.float64], NDArray[np.bool_]]:
    x = np.asarray(a, dtype=float)
    if x.ndim == 1 and x.shape == (3,):
        x = x[None, :]
    if x.ndim != 2 or x.shape[1] != 3 or (n is not None and len(x) != n):
        want = f"({n}, 3)" if n is not None else "(N, 3)"
        raise InputError(f"{name} must have shape {want}, got {x.shape}", field=name)
    norm = np.linalg.norm(x, axis=1)
    ok = np.isfinite(norm) & (norm > 0)
    out = np.where(ok[:, None], x / np.where(ok, norm, 1.0)[:, None], np.nan)
    return out, ok


@dataclass
class EpochInputs:
    """The checked inputs of a render: unit directions (NaN rows where not finite),
    irradiance (N, L), wavelengths (L,), the epochs that render (``valid``, indices into the
    inputs) and the kept images' indices among them; ``pole`` with polarisation."""

    sun: F64
    obs: F64
    e: F64
    wl: F64
    ok: NDArray[np.bool_]
    valid: NDArray[np.int64]
    keep_local: list[int]
    pole: F64 | None


def irradiance_rows(solar_irradiance_W_m2_nm: ArrayLike, n: int, n_wl: int) -> F64:
    """The irradiance as (N, L) (a (L,) spectrum is the same for every epoch), checked."""
    e = np.asarray(solar_irradiance_W_m2_nm, dtype=float)
    if e.ndim == 1:
        e = np.broadcast_to(e, (n, n_wl))
    if e.shape != (n, n_wl):
        raise InputError(
            f"solar_irradiance_W_m2_nm must have shape (N, L) = ({n}, {n_wl}), got {e.shape}",
            field="solar_irradiance_W_m2_nm",
        )
    return e


def epoch_inputs(
    sun_dir_body: ArrayLike,
    observer_dir_body: ArrayLike,
    solar_irradiance_W_m2_nm: ArrayLike,
    wavelength_nm: ArrayLike,
    keep_images_for: Iterable[int] | None,
    pole_body: ArrayLike | None,
) -> EpochInputs:
    """The checked inputs (:class:`EpochInputs`); ``pole_body`` only with polarisation."""
    wl = np.asarray(wavelength_nm, dtype=float).ravel()
    sun, ok_s = unit_rows(sun_dir_body, "sun_dir_body")
    obs, ok_o = unit_rows(observer_dir_body, "observer_dir_body", len(sun))
    e = irradiance_rows(solar_irradiance_W_m2_nm, len(sun), len(wl))
    ok = ok_s & ok_o & np.all(np.isfinite(e), axis=1)
    keep = sorted(int(k) for k in (keep_images_for or ()))
    for k in keep:
        if not 0 <= k < len(sun):
            raise InputError(
                f"keep_images_for index {k} is outside 0..{len(sun) - 1}", field="keep_images_for"
            )
    pole = None
    if pole_body is not None:
        pole, ok_p = unit_rows(pole_body, "pole_body", len(sun))
        ok = ok & ok_p
    valid = np.flatnonzero(ok)
    remap = {int(g): j for j, g in enumerate(valid)}
    keep_local = [remap[k] for k in keep if k in remap]
    return EpochInputs(sun, obs, e, wl, ok, valid, keep_local, pole)
