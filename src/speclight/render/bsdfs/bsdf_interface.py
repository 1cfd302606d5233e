"""What every BSDF model's render module provides: a :class:`MaterialBsdf` subclass.

The single mode splits each material's BRDF into *channels*: a geometric weight per pixel
[sr-1] (``f cos(theta_i)`` over the spectral factor) and a spectral factor [1], so that one
ray cast per epoch gives every wavelength (:mod:`speclight.render.single`). The *main*
channel's factor depends only on the epoch (through the half-phase angle); a model whose
BRDF does not factorise that way adds a *block* of channels with epoch-independent
factors (a plastic's diffuse base, an RGL file's wavelength nodes). Path mode asks the
model for its Mitsuba BSDF (:meth:`MaterialBsdf.path_bsdf`). The table of models,
their parameters and the modes each supports is :mod:`speclight.target.bsdf_models`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.render.polarization import linear_factor
from speclight.target.materials import Material
from speclight.target.reflectance import Reflectance

F64 = NDArray[np.float64]
I64 = NDArray[np.int64]


class MaterialBsdf:
    """A material's BSDF as the renders evaluate it; one subclass per model (form).

    The cosines are those of :mod:`speclight.render.shading`: ``cos_i``, ``cos_o`` of the
    light and view directions with the normal, ``cos_h`` of the half vector with the normal,
    ``cos_d`` of the light with the half vector; ``mirror_ok`` is 1 where the mirror
    direction of the view falls inside the solar disk.
    """

    def __init__(self, material: Material) -> None:
        self.material = material

    def mirror_lobe(self) -> bool:
        """True for a smooth surface that reflects like a mirror (a delta lobe, seen only as
        the glint of the solar disk)."""
        return False

    def main_weight(
        self, cos_i: F64, cos_o: F64, cos_h: F64, cos_d: F64, mirror_ok: F64
    ) -> F64:  # pragma: no cover - every model defines it
        """Per-pixel weight [sr-1] of the main channel: ``f cos_i`` over its factor."""
        raise NotImplementedError

    def main_factor(
        self, cos_half_phase: F64, wavelength_nm: F64
    ) -> F64:  # pragma: no cover - every model defines it
        """Spectral factor (N, L) [1] of the main channel at the epochs' half-phase cosines."""
        raise NotImplementedError

    def linear_factor(self, cos_half_phase: F64, wavelength_nm: F64) -> F64:
        """Stokes Q factor (N, L) of the main channel, referenced to the scattering plane's
        normal (:mod:`speclight.render.polarization`); 0 for an unpolarising model."""
        return np.zeros((len(cos_half_phase), len(wavelength_nm)))

    def block_size(self) -> int:
        """Number of block channels (0: the main channel carries all the light)."""
        return 0

    @classmethod
    def planned_block_size(
        cls, given: Mapping[str, Any], resolve: Callable[[str], Path] | None
    ) -> int:
        """:meth:`block_size` of a material not built yet, from its parameters ``given``
        (files named relative to the scenario found through ``resolve``; 0 for a file that
        cannot be read: the run reports that file itself)."""
        return 0

    def block_weights(self, cos_i: F64, cos_o: F64, cos_h: F64, cos_d: F64) -> tuple[I64, I64, F64]:
        """(row into the inputs, channel within the block, weight [sr-1]) of the block."""
        empty = np.zeros(0, np.int64)
        return empty, empty, np.zeros(0)

    def block_factor(self, wavelength_nm: F64) -> F64:
        """Spectral factors (block_size, L) [1] of the block channels."""
        return np.zeros((0, len(wavelength_nm)))

    def outside_support(self) -> NDArray[np.bool_]:
        """Which block channels carry the light of a measured table's extension, from
        outside the table's support (:mod:`speclight.target.brdf_table`); none here."""
        return np.zeros(self.block_size(), dtype=bool)

    def entries_per_pixel(self) -> int:
        """Block entries one pixel adds that the single mode's batch budget counts
        (:func:`speclight.render.material_channels.rays_per_batch`)."""
        return 0

    def fcos(
        self,
        cos_i: F64,
        cos_o: F64,
        cos_h: F64,
        cos_d: F64,
        mirror_ok: F64,
        wavelength_nm: F64,
        block_factor: F64 | None = None,
    ) -> F64:
        """``f cos(theta_i)`` (M, L) [sr-1]: the channels summed at each point, as the single
        mode sums them; ``block_factor``: :meth:`block_factor` when already computed."""
        out = self.main_weight(cos_i, cos_o, cos_h, cos_d, mirror_ok)[:, None] * self.main_factor(
            cos_d, wavelength_nm
        )
        rows, chans, w = self.block_weights(cos_i, cos_o, cos_h, cos_d)
        if rows.size:
            blk = self.block_factor(wavelength_nm) if block_factor is None else block_factor
            vals = w[:, None] * blk[chans]
            for j in range(out.shape[1]):
                out[:, j] += np.bincount(rows, vals[:, j], minlength=len(cos_i))
        return out

    def path_bsdf(self, lo_nm: float, hi_nm: float, coat: str = "spectral") -> dict[str, Any]:
        """The Mitsuba BSDF dict (one-sided; path mode makes it two-sided) over
        [lo_nm, hi_nm]; ``coat``: see :func:`speclight.render.path_scene.build_scene`."""
        m = self.material
        raise InputError(
            f"material '{m.name}': bsdf '{m.model.label}' has no path-mode model",
            field=f"target.materials.{m.name}.bsdf",
        )

    def roughness_derivative(self, cos_i: F64, cos_o: F64, cos_h: F64) -> F64 | None:
        """d(main weight)/d(roughness) [sr-1] per pixel, or None (see :meth:`gradient_problem`)."""
        return None

    def gradient_problem(self) -> str:
        """Why the roughness derivative is not available ("" when it is)."""
        m = self.material
        return f"material '{m.name}' has no microfacet roughness (bsdf '{m.bsdf}')"


def reflectance_factor(refl: Reflectance, n_epochs: int, wavelength_nm: F64) -> F64:
    """The reflectance's spectrum (N, L) for every epoch: no angle dependence."""
    return np.broadcast_to(refl.evaluate(wavelength_nm)[None, :], (n_epochs, len(wavelength_nm)))


def finite_cosines(cos_half_phase: F64) -> F64:
    """The half-phase cosines with non-finite ones (epochs not rendered) set to 1."""
    return np.where(np.isfinite(cos_half_phase), cos_half_phase, 1.0)


def fresnel_factor(refl: Reflectance, cos_half_phase: F64, wavelength_nm: F64) -> F64:
    """Fresnel reflectance (N, L) at the half-phase angle for an n, k reflectance; the
    reflectance's spectrum (F = 1 scaled by it) for the other kinds."""
    if not refl.is_fresnel:
        return reflectance_factor(refl, len(cos_half_phase), wavelength_nm)
    return refl.at_incidence(finite_cosines(cos_half_phase), wavelength_nm)


def fresnel_linear_factor(
    refl: Reflectance, cos_half_phase: F64, wavelength_nm: F64, real_index: bool = False
) -> F64:
    """Q factor (N, L) of a Fresnel reflection at the half-phase angle: ``(R_s - R_p) / 2``
    for an n, k reflectance (its real index n only with ``real_index``: a transparent
    coat); 0 for a reflectance given as numbers (F = 1 scaled, R_s = R_p)."""
    if not refl.is_fresnel:
        return np.zeros((len(cos_half_phase), len(wavelength_nm)))
    eta = refl.eta(wavelength_nm)
    index = eta.real if real_index else eta
    return linear_factor(finite_cosines(cos_half_phase)[:, None], index[None, :])


def normalised_reflectance(
    refl: Reflectance, reference_nm: float, wavelength_nm: F64, field: str
) -> F64:
    """``R(lambda) / R(reference_nm)`` (L,) [1] of a measured or fitted BRDF's
    ``reflectance`` (1 for a constant); ``field`` names the material in errors.

    Raises
    ------
    InputError
        A spectral reflectance with no reference wavelength (a table that states none), or
        zero there.
    """
    if refl.kind == "constant":
        return np.ones(len(wavelength_nm))
    ref = refl.evaluate(np.array([reference_nm]))[0] if np.isfinite(reference_nm) else np.nan
    if not (np.isfinite(ref) and ref > 0):
        raise InputError(
            f"a spectral reflectance is normalised at the wavelength the BRDF was measured "
            f"(or fitted) at, here {reference_nm:g} nm, where it is {ref:g}: state the "
            "wavelength ('# lambda = 532 nm' in the table, coefficients.wavelength_nm), or "
            "give a constant reflectance",
            field=f"{field}.reflectance",
        )
    return np.asarray(refl.evaluate(wavelength_nm) / ref, dtype=float)


def spectrum_grid(lo_nm: float, hi_nm: float) -> F64:
    """The wavelength grid [nm] (2 nm or finer) on which path mode's BSDF spectra are given."""
    return np.linspace(lo_nm, hi_nm, max(2, int((hi_nm - lo_nm) / 2.0) + 1))


def irregular_spectrum(wavelength_nm: F64, values: F64) -> dict[str, Any]:
    """Mitsuba's ``irregular`` spectrum of ``values`` at ``wavelength_nm``."""
    return {
        "type": "irregular",
        "wavelengths": ", ".join(f"{w:.6g}" for w in wavelength_nm),
        "values": ", ".join(f"{v:.8g}" for v in values),
    }


def reflectance_spectrum(refl: Reflectance, lo_nm: float, hi_nm: float) -> dict[str, Any]:
    """Mitsuba spectrum of a reflectance over [lo_nm, hi_nm] (``uniform`` for a constant)."""
    if refl.kind == "constant":
        return {"type": "uniform", "value": refl.value}
    grid = spectrum_grid(lo_nm, hi_nm)
    return irregular_spectrum(grid, refl.evaluate(grid))
