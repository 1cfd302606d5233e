"""Least-squares fits of the analytic forms to a measured table, in log space.

The misfit is ``log10 f_model - log10 f_measured`` at every sample with both zenith angles
below 90 deg and a BRDF above ``min_brdf`` (0 by default: every positive sample), as in
lumos-sat's ``lumos.brdf.tools.fit``, which fits these forms to the same tables (with its
``clip = 1e-3``, leaving out the Starlink v1.5 tables' 1e-4 sr-1 entries at grazing
exitance): each sample counts the same, decades of the specular peak and of the diffuse
floor alike. Each fit starts from a few first guesses (the lobe's width spans
decades) with :func:`scipy.optimize.least_squares` within the coefficients' ranges, keeps the
best, and then checks the directional albedo (:mod:`.directional_albedo`): a fit that
reflects more than it receives at some incidence is refitted with the albedo held at most 1
(SLSQP from the best fit scaled down until it holds), so that every fitted material
conserves energy. The residual is reported per incidence angle (RMS and largest, in dex).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from numpy.typing import NDArray
from scipy.optimize import least_squares, minimize

from speclight.errors import InputError, did_you_mean
from speclight.target.brdf_fit.directional_albedo import ALBEDO_TOLERANCE, max_albedo
from speclight.target.brdf_fit.form_coefficients import BINOMIAL_SHAPE, FORMS, AnalyticForm
from speclight.target.brdf_samples import TableSamples

F64 = NDArray[np.float64]
#: Smallest model value taken into log space [sr-1] (a form that is 0 somewhere).
LOG_FLOOR = 1e-30


@dataclass(frozen=True)
class BrdfFit:
    """A fitted analytic model and how well it reproduces the table.

    Attributes
    ----------
    model
        The ``bsdf`` name.
    coefficients
        The fitted coefficients (``wavelength_nm`` included when the table states one).
    source
        The table fitted.
    incidence_deg
        The table's incidence angles [deg].
    rms_dex, max_dex
        Per incidence: RMS and largest |log10 f_model - log10 f_measured| [dex].
    samples
        Per incidence: the samples fitted.
    rms_dex_all
        RMS over all samples [dex].
    left_out
        Samples not fitted (zenith >= 90 deg or BRDF <= ``min_brdf``).
    min_brdf
        The BRDF [sr-1] at or below which samples were left out.
    albedo, albedo_incidence_deg
        The largest directional albedo of the fit [1] and its incidence [deg].
    constrained
        True when the fit was refitted with its albedo held at most 1.
    """

    model: str
    coefficients: dict[str, Any]
    source: str
    incidence_deg: F64
    rms_dex: F64
    max_dex: F64
    samples: NDArray[np.int64]
    rms_dex_all: float
    left_out: int
    albedo: float
    albedo_incidence_deg: float
    min_brdf: float = 0.0
    constrained: bool = field(default=False)


def _starts(form: str, f: F64) -> list[tuple[F64, tuple[F64, F64]]]:
    """First guesses and bounds of the free parameters of ``form`` for a table of values f."""
    floor = float(np.clip(np.pi * np.median(f), 1e-6, 1.0))
    peak = float(np.max(f))
    if form == "phong":
        bounds = (np.array([0.0, 0.0, 1e-3]), np.array([1.0, 1.0, 1e6]))
        return [(np.array([floor, 0.5, n]), bounds) for n in (3.0, 30.0, 300.0, 3000.0)]
    if form == "abg":
        bounds = (np.array([-15.0, -15.0, 0.05]), np.array([8.0, 4.0, 10.0]))
        out = []
        for log_b in (-6.0, -4.0, -2.0, 0.0):
            a = np.log10(peak) + log_b
            out.append((np.array([a, log_b, 2.0]), bounds))
        return out
    if form == "binomial":
        n, m, l1, l2 = (int(BINOMIAL_SHAPE[k]) for k in ("n", "m", "l1", "l2"))
        size = n * m + n * (l2 - l1)
        bounds = (np.full(size, -1e3), np.full(size, 1e3))
        return [(-np.ones(size), bounds)]  # lumos-sat's first guess
    bounds = (np.array([0.0, 0.0, 1e-3]), np.array([1.0, 1.0, 1.0]))
    return [
        (np.array([floor, f0, alpha]), bounds) for f0 in (0.05, 0.5) for alpha in (0.01, 0.1, 0.4)
    ]


def _unpacker(
    form: AnalyticForm, distribution: str, fresnel: str
) -> Callable[[F64], dict[str, Any]]:
    if form.name == "binomial":
        return lambda p: form.unpack(p, **BINOMIAL_SHAPE)
    if form.name == "microfacet":
        return lambda p: form.unpack(p, distribution, fresnel)
    return lambda p: form.unpack(p)


def fit_table_samples(
    samples: TableSamples,
    model: str,
    distribution: str = "ggx",
    fresnel: str = "schlick",
    min_brdf: float = 0.0,
) -> BrdfFit:
    """Fit analytic ``model`` (a name of :data:`~.form_coefficients.FORMS`) to a table.

    Parameters
    ----------
    samples
        The table (:func:`speclight.target.brdf_samples.read_table_samples`).
    model
        ``phong``, ``abg``, ``binomial`` or ``microfacet``.
    distribution, fresnel
        ``microfacet`` only: the normal distribution (``ggx``, ``beckmann``) and the Fresnel
        term (``schlick``, ``exact``).
    min_brdf
        Samples at or below this BRDF [sr-1] are left out (>= 0; lumos-sat used 1e-3).
    """
    if model not in FORMS:
        raise InputError(
            f"model = {model!r}{did_you_mean(model, FORMS)} is not an analytic model "
            f"(choices: {', '.join(FORMS)})",
            field="model",
        )
    for name, value in (("distribution", distribution), ("fresnel", fresnel)):
        choices = next(c.choices for c in FORMS["microfacet"].coefficients if c.name == name)
        if value not in choices:
            raise InputError(
                f"{name} = {value!r}{did_you_mean(value, choices)} must be one of "
                f"{', '.join(choices)}",
                field=name,
            )
    if not (np.isfinite(min_brdf) and min_brdf >= 0):
        raise InputError(f"min_brdf = {min_brdf!r} sr-1 must be >= 0", field="min_brdf")
    form = FORMS[model]
    keep = samples.usable() & (samples.brdf > min_brdf)
    if np.count_nonzero(keep) < 4:
        raise InputError(
            f"only {int(keep.sum())} samples have zenith angles below 90 deg and a BRDF above "
            f"{min_brdf:g} sr-1: a fit needs at least 4",
            source=samples.source,
        )
    cosines = tuple(c[keep] for c in samples.cosines())
    measured = np.log10(samples.brdf[keep])
    unpack = _unpacker(form, distribution, fresnel)

    def model_log(p: F64) -> F64:
        f = form.evaluate(*cosines, unpack(p))
        return np.log10(np.maximum(f, LOG_FLOOR))

    def residual(p: F64) -> F64:
        return model_log(p) - measured

    best = None
    starts = _starts(model, samples.brdf[keep])
    for x0, bounds in starts:
        sol = least_squares(residual, x0, bounds=bounds, x_scale="jac")
        if best is None or sol.cost < best.cost:
            best = sol
    assert best is not None
    p = best.x
    albedo, at = max_albedo(lambda *c: form.evaluate(*c, unpack(p)))
    constrained = albedo > 1.0 + ALBEDO_TOLERANCE
    if constrained:
        p = _energy_constrained(form, unpack, residual, p, albedo, starts[0][1])
        albedo, at = max_albedo(lambda *c: form.evaluate(*c, unpack(p)))
    coefficients = unpack(p)
    if np.isfinite(samples.wavelength_nm):
        coefficients["wavelength_nm"] = float(samples.wavelength_nm)
    fit = _report(samples, keep, residual(p), model, coefficients, albedo, at, constrained)
    return replace(fit, min_brdf=float(min_brdf))


def _energy_constrained(
    form: AnalyticForm,
    unpack: Callable[[F64], dict[str, Any]],
    residual: Callable[[F64], F64],
    p: F64,
    albedo: float,
    bounds: tuple[F64, F64],
) -> F64:
    """The least-squares parameters with the largest albedo held at most 1 (SLSQP, within
    the parameters' ``bounds``)."""

    def slack(q: F64) -> float:
        return 1.0 - max_albedo(lambda *c: form.evaluate(*c, unpack(q)))[0]

    start = form.scaled(p, 1.0 / (albedo * (1.0 + ALBEDO_TOLERANCE)))
    sol = minimize(
        lambda q: 0.5 * float(np.sum(residual(q) ** 2)),
        start,
        method="SLSQP",
        bounds=list(zip(*bounds, strict=True)),
        constraints=[{"type": "ineq", "fun": slack}],
        options={"maxiter": 60, "ftol": 1e-8},
    )
    return sol.x if slack(sol.x) >= -ALBEDO_TOLERANCE else start


def _report(
    samples: TableSamples,
    keep: NDArray[np.bool_],
    r: F64,
    model: str,
    coefficients: Mapping[str, Any],
    albedo: float,
    at: float,
    constrained: bool,
) -> BrdfFit:
    incidence = np.unique(samples.theta_i_deg[keep])
    ti = samples.theta_i_deg[keep]
    rms = np.array([np.sqrt(np.mean(r[ti == t] ** 2)) for t in incidence])
    worst = np.array([np.max(np.abs(r[ti == t])) for t in incidence])
    counts = np.array([np.count_nonzero(ti == t) for t in incidence])
    return BrdfFit(
        model=model,
        coefficients=dict(coefficients),
        source=samples.source,
        incidence_deg=incidence,
        rms_dex=rms,
        max_dex=worst,
        samples=counts,
        rms_dex_all=float(np.sqrt(np.mean(r**2))),
        left_out=int(np.count_nonzero(~keep)),
        albedo=albedo,
        albedo_incidence_deg=at,
        constrained=constrained,
    )
