"""The render session of a run: the one Mitsuba variant and the ray casters every render uses.

Mitsuba's variant is process-wide state. A run chooses it once, from the render mode and the
target's materials, and hands the session to the Sun render, the laser render and everything
else, so that no stage can switch it during the run:

* ``path`` mode and RGL measured materials need a spectral variant (``*_spectral``);
* ``path`` mode with ``render.polarization`` needs ``*_spectral_polarized``;
* single mode without them casts rays only, and the ``*_rgb`` variant is enough;
* without Mitsuba (or with ``render.variant: numpy``) single mode casts rays with numpy.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Literal

from speclight.errors import InputError
from speclight.render.polarization import check_polarizable
from speclight.render.raycast import Caster, make_caster
from speclight.render.rgl import is_rgl
from speclight.render.variant import activate, choose_variant
from speclight.target.materials import Material
from speclight.target.parts import Target

RenderMode = Literal["single", "path"]


@dataclass
class RenderSession:
    """The variant chosen for a run, and its ray casters (one per target, built once).

    Build it with :meth:`create`; ``variant`` is e.g. ``llvm_ad_rgb``, ``llvm_ad_spectral``,
    ``scalar_spectral`` or ``numpy``.
    """

    mode: RenderMode
    variant: str
    _casters: dict[int, tuple[Target, Caster]] = field(default_factory=dict, repr=False)

    @classmethod
    def create(
        cls,
        mode: str,
        requested: str | None,
        materials: Iterable[Material],
        polarization: bool = False,
    ) -> RenderSession:
        """Choose the variant for ``mode`` and the target's ``materials``.

        ``requested``: the scenario's ``render.variant`` (``None``/``"auto"`` for the best one).
        ``polarization``: the scenario's ``render.polarization`` (path mode then needs a
        ``*_spectral_polarized`` variant; the single mode computes polarisation itself).
        """
        if mode not in ("single", "path"):
            raise InputError(
                f"render.mode = '{mode}' must be 'single' or 'path'", field="render.mode"
            )
        materials = list(materials)
        rgl = any(is_rgl(m) for m in materials)
        polarized = polarization and mode == "path"
        if polarization:
            check_polarizable(materials, mode)
        variant = choose_variant(requested, spectral=mode == "path" or rgl, polarized=polarized)
        spectral = variant.endswith("_spectral")
        if polarized and not variant.endswith("_spectral_polarized"):
            raise InputError(
                f"render.polarization in render.mode 'path' needs a *_spectral_polarized "
                f"variant, got '{variant}' (use 'auto', llvm_ad_spectral_polarized, "
                "cuda_ad_spectral_polarized or scalar_spectral_polarized)",
                field="render.variant",
            )
        if mode == "path" and not (spectral or polarized):
            raise InputError(
                f"render.mode 'path' needs a *_spectral variant, got '{variant}' "
                "(use 'auto', llvm_ad_spectral, cuda_ad_spectral or scalar_spectral)",
                field="render.variant",
            )
        if mode == "single" and rgl and not (spectral and variant.startswith(("llvm_", "cuda_"))):
            raise InputError(
                "RGL .bsdf materials in render.mode 'single' need Mitsuba with a cuda_ad or "
                f"llvm_ad spectral variant (render.variant is '{variant}'); install Mitsuba and "
                "libLLVM >= 16, or use render.mode 'path'",
                field="render.variant",
            )
        return cls(mode, variant)  # type: ignore[arg-type]

    @property
    def uses_mitsuba(self) -> bool:
        """True when the variant is a Mitsuba one (not the numpy fallback)."""
        return self.variant != "numpy"

    def activate(self):  # type: ignore[no-untyped-def]
        """Activate the session's variant and return the ``mitsuba`` module."""
        return activate(self.variant)

    def caster(self, target: Target) -> Caster:
        """The ray caster of ``target`` in the session's variant (built once per target)."""
        key = id(target)  # the target is kept with its caster, so the id stays its own
        if key not in self._casters:
            self._casters[key] = (target, make_caster(target, self.variant))
        return self._casters[key][1]

    def forget(self, target: Target) -> None:
        """Drop the caster of ``target`` (a posed copy of an articulated target, used once)."""
        self._casters.pop(id(target), None)
