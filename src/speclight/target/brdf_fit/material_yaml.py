"""A fitted model as a scenario material (``speclight brdf-fit -o MATERIAL.yaml``), and its
report.

The file is one material mapping, ``{bsdf: MODEL, coefficients: {...}}``, with comment lines
that say where it came from and how well it fits: its content goes as it is under a name in
a scenario's ``target.materials`` (or ``"*"``). Its ``reflectance`` is left at its default, 1
(grey, as fitted); give a spectral one to colour it, normalised at
``coefficients.wavelength_nm``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import yaml

from speclight.target.brdf_fit.log_fit import BrdfFit


def material_mapping(fit: BrdfFit) -> dict[str, Any]:
    """The material ``{bsdf, coefficients}`` of a fit (plain YAML values)."""

    def plain(v: Any) -> Any:
        if isinstance(v, list | tuple | np.ndarray):
            return [plain(x) for x in v]
        if isinstance(v, np.generic):
            return v.item()
        return v

    return {"bsdf": fit.model, "coefficients": {k: plain(v) for k, v in fit.coefficients.items()}}


def report_lines(fit: BrdfFit) -> list[str]:
    """The fit's residual per incidence angle and its largest directional albedo."""
    lines = [
        f"{fit.model} fitted to {fit.source}: {int(fit.samples.sum())} samples in log10 "
        f"({fit.left_out} left out: zenith >= 90 deg or BRDF <= {fit.min_brdf:g} sr-1)",
        "incidence [deg]  samples  RMS [dex]  largest [dex]",
    ]
    for t, n, rms, worst in zip(
        fit.incidence_deg, fit.samples, fit.rms_dex, fit.max_dex, strict=True
    ):
        lines.append(f"{t:15.1f}  {n:7d}  {rms:9.3f}  {worst:13.3f}")
    lines.append(f"all              {int(fit.samples.sum()):7d}  {fit.rms_dex_all:9.3f}")
    held = " (refitted with it held at most 1)" if fit.constrained else ""
    lines.append(
        f"largest directional albedo {fit.albedo:.3f} at {fit.albedo_incidence_deg:g} deg "
        f"incidence{held}"
    )
    return lines


def material_yaml(fit: BrdfFit) -> str:
    """The text of MATERIAL.yaml (module doc)."""
    header = [
        "# A material for a scenario's target.materials (speclight brdf-fit; docs/brdf-models.md):",
        "#   target: {materials: {NAME: <this mapping>}}",
        *(f"# {line}" for line in report_lines(fit)),
        "# reflectance (default 1): a scale R(lambda) / R(coefficients.wavelength_nm)",
    ]
    body = yaml.safe_dump(material_mapping(fit), sort_keys=False, default_flow_style=None)
    return "\n".join(header) + "\n" + body
