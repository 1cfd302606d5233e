"""RGL measured materials (``.bsdf`` files) through Mitsuba 3's ``measured`` BSDF plugin.

Both render modes use Mitsuba's own implementation of the Dupuy & Jakob 2018 parameterisation
("An Adaptive Parameterization for Efficient Material Acquisition and Rendering", ACM TOG
37(6) 274, doi:10.1145/3272127.3275059), so they share one BRDF:

* path mode puts the plugin in the scene (:func:`path_bsdf`);
* single mode calls the plugin's ``eval`` for every lit pixel (:func:`pixel_weights`), in the
  run's spectral Dr.Jit variant (the render session chooses ``*_spectral`` for a target with
  RGL materials, :mod:`speclight.render.session`, and nothing switches it), at the file's
  wavelength nodes. The plugin interpolates the
  tabulated spectra linearly in wavelength (and holds them constant outside the file's range),
  so the BRDF at any wavelength is ``sum_j f(lambda_j) h_j(lambda)`` with ``h_j`` the hat
  functions on the nodes (:func:`hat_factor`): the single mode's channel sum reproduces the
  plugin exactly in wavelength, without a coarse-grid approximation.

Directions: Mitsuba's ``eval(si.wi, wo)`` returns ``f cos(theta_wo)`` with ``si.wi`` toward the
camera and ``wo`` toward the light, as its path tracer calls it; the single mode does the same
(``wi`` = observer, ``wo`` = Sun), so the weight is ``f cos(theta_sun)`` [sr-1] like the other
models' main channel. Only isotropic files are accepted (see
:class:`~speclight.target.materials.Material`): the BRDF then depends on the two elevations
and the azimuth difference only, and the single mode places the observer at azimuth 0.

A constant ``reflectance`` c in (0, 1] scales the measured BRDF (1: as measured); in path mode
this is Mitsuba's ``blendbsdf`` of the measured BSDF (weight c) with a black one.
"""

from __future__ import annotations

from functools import cache
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.render.variant import activate
from speclight.target.bsdf_models import MEASURED_RGL
from speclight.target.materials import Material
from speclight.target.rgl_file import load_rgl_info

F64 = NDArray[np.float64]
#: Lanes per ``eval`` call (bounds the Dr.Jit memory use).
EVAL_BATCH = 1 << 20


def is_rgl(m: Material) -> bool:
    """True for a ``measured`` material whose ``brdf_table`` is an RGL ``.bsdf`` file."""
    return m.model is MEASURED_RGL


def scale(m: Material) -> float:
    """The constant scale factor of an RGL material (its ``reflectance``)."""
    return float(m.reflectance.value)


def node_count(m: Material) -> int:
    """Number of single-mode channels of an RGL material: its file's wavelength nodes."""
    return len(load_rgl_info(str(m.brdf_table)).wavelength_nm)


def hat_factor(m: Material, wavelength_nm: F64) -> F64:
    """(W, L) weights of the file's W wavelength nodes at the grid wavelengths [1].

    Row j is the piecewise-linear hat function of node j (the first and last extended as
    constants beyond the file's range), times the material's scale; ``f(lambda) = sum_j
    f_j h_j(lambda)`` is then the plugin's own linear interpolation in wavelength.
    """
    nodes = load_rgl_info(str(m.brdf_table)).wavelength_nm
    eye = np.eye(len(nodes))
    return np.stack([np.interp(wavelength_nm, nodes, row) for row in eye]) * scale(m)


def _eval_variant(variant: str | None) -> str:
    """The variant ``eval`` runs in: ``variant``, or the active one; a vectorised spectral one."""
    if variant is None:
        import mitsuba as mi

        variant = mi.variant() or ""
    if not (variant.startswith(("cuda_ad_", "llvm_ad_")) and variant.endswith("_spectral")):
        raise InputError(
            "RGL .bsdf materials in render.mode 'single' need Mitsuba with a cuda_ad or llvm_ad "
            f"spectral variant (the run uses '{variant or 'none'}'); install Mitsuba and "
            "libLLVM >= 16, or use render.mode 'path'",
            field="render.variant",
        )
    return variant


@cache
def _plugin(variant: str, path: str) -> Any:
    import mitsuba as mi

    return mi.load_dict({"type": "measured", "filename": path})


def local_directions(cos_i: F64, cos_o: F64, cos_phase: F64) -> tuple[F64, F64]:
    """Unit (P, 3) Sun and observer directions in a local frame (normal +z, observer at phi 0).

    ``cos_phase`` is the cosine of the Sun-target-observer angle, ``s . o``.
    """
    sin_i = np.sqrt(np.clip(1.0 - cos_i**2, 0.0, 1.0))
    sin_o = np.sqrt(np.clip(1.0 - cos_o**2, 0.0, 1.0))
    den = sin_i * sin_o
    cos_phi = np.where(den > 1e-12, (cos_phase - cos_i * cos_o) / np.maximum(den, 1e-300), 1.0)
    cos_phi = np.clip(cos_phi, -1.0, 1.0)
    sin_phi = np.sqrt(1.0 - cos_phi**2)
    sun = np.stack([sin_i * cos_phi, sin_i * sin_phi, cos_i], axis=1)
    obs = np.stack([sin_o, np.zeros_like(sin_o), cos_o], axis=1)
    return sun, obs


def eval_plugin(path: str, sun_local: F64, obs_local: F64, variant: str | None = None) -> F64:
    """``f cos(theta_sun)`` [sr-1] (P, W) of an RGL file at its W wavelength nodes.

    Calls Mitsuba's ``measured`` plugin with ``si.wi`` = observer and ``wo`` = Sun (local
    frames), as its path tracer does, in ``variant`` (default: the active variant, which must
    be a ``cuda_ad_*`` or ``llvm_ad_*`` spectral one; it is never switched).
    """
    nodes = load_rgl_info(path).wavelength_nm
    n_pix, n_wl = len(sun_local), len(nodes)
    n_grp = (n_wl + 3) // 4  # Mitsuba's spectral variants carry 4 wavelengths per lane
    lam = np.resize(nodes, 4 * n_grp).reshape(n_grp, 4).astype(np.float32)  # (G, 4)
    out = np.zeros((n_pix, n_wl))
    if n_pix == 0:
        return out
    step = max(1, EVAL_BATCH // n_grp)
    mi = activate(_eval_variant(variant))
    import drjit as dr

    bsdf = _plugin(mi.variant(), path)
    ctx = mi.BSDFContext()
    for a in range(0, n_pix, step):
        n = min(step, n_pix - a)
        # lanes ordered (pixel, group): each pixel's directions repeated for every group
        wi = np.repeat(obs_local[a : a + n], n_grp, axis=0).T.astype(np.float32)
        wo = np.repeat(sun_local[a : a + n], n_grp, axis=0).T.astype(np.float32)
        wl = np.tile(lam, (n, 1)).T  # (4, n * G)
        si = dr.zeros(mi.SurfaceInteraction3f, n * n_grp)
        si.wi = mi.Vector3f(np.ascontiguousarray(wi))
        si.sh_frame = mi.Frame3f(mi.Vector3f(0.0, 0.0, 1.0))
        si.wavelengths = mi.Spectrum(np.ascontiguousarray(wl))
        val = bsdf.eval(ctx, si, mi.Vector3f(np.ascontiguousarray(wo)))
        v = np.asarray(val, dtype=float).T.reshape(n, 4 * n_grp)  # (pixel, group * 4)
        out[a : a + n] = v[:, :n_wl]
    return out


def pixel_weights(m: Material, cos_i: F64, cos_o: F64, cos_d: F64) -> F64:
    """(P, W) single-mode weights ``f cos(theta_i)`` [sr-1] at the file's wavelength nodes.

    ``cos_d`` is the cosine between the Sun direction and the half vector (the phase angle is
    twice that angle).
    """
    sun, obs = local_directions(cos_i, cos_o, 2.0 * cos_d**2 - 1.0)
    return eval_plugin(str(m.brdf_table), sun, obs)


def path_bsdf(m: Material) -> dict[str, Any]:
    """Mitsuba BSDF dict (not yet two-sided) of an RGL material for the path mode."""
    inner: dict[str, Any] = {"type": "measured", "filename": str(m.brdf_table)}
    c = scale(m)
    if c == 1.0:
        return inner
    return {
        "type": "blendbsdf",
        "weight": c,
        "bsdf_0": {"type": "diffuse", "reflectance": 0.0},
        "bsdf_1": inner,
    }
