"""The analytic forms' coefficients: names, meanings, checks, and their vector for a fit.

A material of an analytic model (``bsdf: phong|abg|binomial|microfacet``) gives its
coefficients as one mapping, ``coefficients: {kd: 0.1, ks: 0.4, n: 30}``, checked here
(:func:`coefficient_problem`, one message per problem naming the key, the value and what is
accepted). Every form also takes ``wavelength_nm``: the wavelength its coefficients hold at
(the table's, for a fit), to which a spectral ``reflectance`` is normalised.

:data:`FORMS` maps each model name to an :class:`AnalyticForm`: the numpy function
(:mod:`.analytic_forms`), the coefficients, and how a least-squares fit sees them (a vector
of free parameters with bounds and a first guess, and a scale factor that keeps a
candidate's albedo at most 1).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass
from types import MappingProxyType
from typing import Any

import numpy as np
from numpy.typing import NDArray

from speclight.errors import did_you_mean
from speclight.target.brdf_fit import analytic_forms

F64 = NDArray[np.float64]
Form = Callable[..., Any]
#: lumos-sat's binomial shape for the Starlink v1.5 chassis (Fankhauser et al. 2023, notebook
#: "BRDF Fitting" of Forrest-Fankhauser/satellite-optical-brightness): n = 1 power of V,
#: m = 2 powers of D, Gaussian indices l1 = -5 .. l2 - 1 = 4, base d = 3.
BINOMIAL_SHAPE = {"n": 1, "m": 2, "l1": -5, "l2": 5, "d": 3.0}


@dataclass(frozen=True)
class Coefficient:
    """One coefficient of a form.

    Attributes
    ----------
    name
        Its key in ``coefficients``.
    meaning
        What it is, with its unit and range, for messages and docs.
    kind
        ``number``, ``integer``, ``matrix`` (a list of rows of numbers) or ``choice``.
    low, high
        Numbers: the value must lie in [low, high] (``open_low``: in (low, high]).
    choices
        ``choice``: the accepted values (the first is the default).
    """

    name: str
    meaning: str
    kind: str = "number"
    low: float = -np.inf
    high: float = np.inf
    open_low: bool = False
    choices: tuple[str, ...] = ()

    def problem(self, value: Any) -> str | None:
        """Why ``value`` is not accepted (None when it is)."""
        where = f"coefficients.{self.name} = {value!r}"
        if self.kind == "choice":
            if value not in self.choices:
                hint = did_you_mean(str(value), self.choices)
                return f"{where} must be one of {', '.join(self.choices)}{hint} ({self.meaning})"
            return None
        if self.kind == "matrix":
            return _matrix_problem(where, value, self.meaning)
        if isinstance(value, bool) or not isinstance(value, int | float | np.number):
            return f"{where} must be a number ({self.meaning})"
        if self.kind == "integer" and float(value) != int(value):
            return f"{where} must be an integer ({self.meaning})"
        v = float(value)
        inside = (self.low < v if self.open_low else self.low <= v) and v <= self.high
        if not (np.isfinite(v) and inside):
            bracket = "(" if self.open_low else "["
            return f"{where} must lie in {bracket}{self.low:g}, {self.high:g}] ({self.meaning})"
        return None


def _matrix_problem(where: str, value: Any, meaning: str) -> str | None:
    rows = value if isinstance(value, list | tuple) else None
    if not rows or not all(isinstance(r, list | tuple) and r for r in rows):
        return f"{where} must be a list of rows of numbers ({meaning})"
    if len({len(r) for r in rows}) != 1:
        return f"{where}: its rows must have the same length ({meaning})"
    try:
        arr = np.asarray(rows, dtype=float)
    except (TypeError, ValueError):
        return f"{where} must hold numbers only ({meaning})"
    if not np.all(np.isfinite(arr)):
        return f"{where} must hold finite numbers ({meaning})"
    return None


WAVELENGTH = Coefficient(
    "wavelength_nm",
    "the wavelength [nm] the coefficients hold at; a spectral reflectance is normalised "
    "there (optional)",
    low=0.0,
    open_low=True,
)


@dataclass(frozen=True)
class AnalyticForm:
    """An analytic BRDF form and how a fit sees it.

    Attributes
    ----------
    name
        The ``bsdf`` name.
    evaluate
        ``f(cos_i, cos_o, cos_h, cos_d, coefficients, ops)`` [sr-1].
    coefficients
        Its coefficients (``wavelength_nm`` is added to every form).
    pack, unpack
        Coefficients <-> the fit's free-parameter vector (``unpack`` takes the fixed ones,
        e.g. the binomial's shape, as keyword arguments).
    scaled
        The free parameters of the same form times a factor s in (0, 1].
    """

    name: str
    evaluate: Form
    coefficients: tuple[Coefficient, ...]
    pack: Callable[[Mapping[str, Any]], F64]
    unpack: Callable[..., dict[str, Any]]
    scaled: Callable[[F64, float], F64]

    def problem(self, given: Mapping[str, Any]) -> str | None:
        """What is wrong with a ``coefficients`` mapping (None when it is fine)."""
        if not isinstance(given, Mapping):
            return f"coefficients {given!r} must be a mapping of {self.names()}"
        accepted = (*self.coefficients, WAVELENGTH)
        names = [c.name for c in accepted]
        for key in given:
            if key not in names:
                hint = did_you_mean(str(key), names)
                return (
                    f"unknown coefficient '{key}' of bsdf '{self.name}'{hint} "
                    f"(accepted: {self.names()})"
                )
        for c in accepted:
            if c.name not in given:
                if c is WAVELENGTH or c.kind == "choice":
                    continue
                return f"bsdf '{self.name}' needs coefficients.{c.name} ({c.meaning})"
            why = c.problem(given[c.name])
            if why is not None:
                return why
        return _shape_problem(self.name, given)

    def names(self) -> str:
        """The coefficient names, for messages."""
        return ", ".join(c.name for c in self.coefficients) + ", wavelength_nm (optional)"

    def complete(self, given: Mapping[str, Any]) -> dict[str, Any]:
        """The coefficients with every left-out choice at its default."""
        out = dict(given)
        for c in self.coefficients:
            if c.kind == "choice" and c.name not in out:
                out[c.name] = c.choices[0]
        return out


def _shape_problem(name: str, given: Mapping[str, Any]) -> str | None:
    if name != "binomial":
        return None
    b, c = np.asarray(given["b"], dtype=float), np.asarray(given["c"], dtype=float)
    if b.shape[0] != c.shape[0]:
        return (
            f"coefficients.b has {b.shape[0]} rows and coefficients.c {c.shape[0]}: both have "
            "one row per power of V"
        )
    return None


def _phong_unpack(p: F64) -> dict[str, Any]:
    return {"kd": float(p[0]), "ks": float(p[1]), "n": float(p[2])}


def _abg_unpack(p: F64) -> dict[str, Any]:
    return {"a": float(10 ** p[0]), "b": float(10 ** p[1]), "g": float(p[2])}


def _binomial_unpack(p: F64, n: int, m: int, l1: int, l2: int, d: float) -> dict[str, Any]:
    b = np.reshape(p[: n * m], (n, m))
    c = np.reshape(p[n * m :], (n, l2 - l1))
    return {"b": b.tolist(), "c": c.tolist(), "d": float(d), "l1": int(l1)}


def _binomial_pack(c: Mapping[str, Any]) -> F64:
    b, cc = np.asarray(c["b"], dtype=float), np.asarray(c["c"], dtype=float)
    return np.concatenate([b.ravel(), cc.ravel()])


def _binomial_scaled(p: F64, s: float) -> F64:
    out = p.copy()
    out[0] += np.log10(s)  # b[0][0] is log10 of an overall factor
    return out


def _microfacet_unpack(p: F64, distribution: str, fresnel: str) -> dict[str, Any]:
    return {
        "diffuse": float(p[0]),
        "f0": float(p[1]),
        "roughness": float(p[2]),
        "distribution": distribution,
        "fresnel": fresnel,
    }


def _microfacet_scaled(p: F64, s: float) -> F64:
    return np.array([p[0] * s, p[1] * s, p[2]])


_PHONG = AnalyticForm(
    "phong",
    analytic_forms.phong,
    (
        Coefficient("kd", "diffuse coefficient, 0 <= kd <= 1", low=0.0, high=1.0),
        Coefficient("ks", "specular coefficient, 0 <= ks <= 1; kd + ks <= 1", low=0.0, high=1.0),
        Coefficient("n", "specular exponent (lobe width), n > 0", low=0.0, high=1e7, open_low=True),
    ),
    pack=lambda c: np.array([c["kd"], c["ks"], c["n"]], dtype=float),
    unpack=_phong_unpack,
    scaled=lambda p, s: np.array([p[0] * s, p[1] * s, p[2]]),
)
_ABG = AnalyticForm(
    "abg",
    analytic_forms.abg,
    (
        Coefficient("a", "amplitude A [sr-1], A > 0 (A / B is the peak)", low=0.0, open_low=True),
        Coefficient("b", "knee B, B > 0", low=0.0, open_low=True),
        Coefficient("g", "log-log slope g, 0 < g <= 10", low=0.0, high=10.0, open_low=True),
    ),
    pack=lambda c: np.array([np.log10(c["a"]), np.log10(c["b"]), c["g"]], dtype=float),
    unpack=_abg_unpack,
    scaled=lambda p, s: np.array([p[0] + np.log10(s), p[1], p[2]]),
)
_BINOMIAL = AnalyticForm(
    "binomial",
    analytic_forms.binomial,
    (
        Coefficient("b", "b[k][j]: the powers D^j of the k-th power of V", kind="matrix"),
        Coefficient("c", "c[k][j]: the Gaussian terms d^(j + l1) of V^k", kind="matrix"),
        Coefficient("d", "specularity base d > 0", low=0.0, high=1e6, open_low=True),
        Coefficient("l1", "index of the first Gaussian term", kind="integer", low=-50, high=50),
    ),
    pack=_binomial_pack,
    unpack=_binomial_unpack,
    scaled=_binomial_scaled,
)
_MICROFACET = AnalyticForm(
    "microfacet",
    analytic_forms.microfacet,
    (
        Coefficient("diffuse", "Lambertian albedo rho_d, 0 <= rho_d <= 1", low=0.0, high=1.0),
        Coefficient(
            "f0", "Fresnel reflectance at normal incidence, 0 <= F0 <= 1", low=0.0, high=1.0
        ),
        Coefficient(
            "roughness", "microfacet alpha, 0 < alpha <= 1", low=0.0, high=1.0, open_low=True
        ),
        Coefficient(
            "distribution", "the normal distribution", kind="choice", choices=("ggx", "beckmann")
        ),
        Coefficient(
            "fresnel",
            "Schlick's approximation or the exact dielectric Fresnel term",
            kind="choice",
            choices=("schlick", "exact"),
        ),
    ),
    pack=lambda c: np.array([c["diffuse"], c["f0"], c["roughness"]], dtype=float),
    unpack=_microfacet_unpack,
    scaled=_microfacet_scaled,
)
#: The analytic forms by ``bsdf`` name.
FORMS: Mapping[str, AnalyticForm] = MappingProxyType(
    {f.name: f for f in (_PHONG, _ABG, _BINOMIAL, _MICROFACET)}
)


class FrozenCoefficients(Mapping[str, Any]):
    """A read-only, hashable copy of a ``coefficients`` mapping (rows of a matrix as tuples),
    so that a :class:`~speclight.target.Material` holding it stays immutable."""

    def __init__(self, given: Mapping[str, Any]) -> None:
        self._items = {str(k): _frozen(v) for k, v in given.items()}

    def __getitem__(self, key: str) -> Any:
        return self._items[key]

    def __iter__(self) -> Iterator[str]:
        return iter(self._items)

    def __len__(self) -> int:
        return len(self._items)

    def __hash__(self) -> int:
        return hash(tuple(sorted(self._items.items())))

    def __repr__(self) -> str:
        return f"FrozenCoefficients({self._items!r})"

    def plain(self) -> dict[str, Any]:
        """The coefficients as plain YAML values (matrices as lists of lists)."""
        return {k: [list(r) for r in v] if isinstance(v, tuple) else v for k, v in self.items()}


def _frozen(value: Any) -> Any:
    if isinstance(value, list | tuple | np.ndarray):
        return tuple(_frozen(v) for v in value)
    if isinstance(value, np.generic):
        return value.item()
    return value


def coefficient_problem(name: str, given: Any) -> str | None:
    """What is wrong with the ``coefficients`` of a material of model ``name`` (None: fine)."""
    return FORMS[name].problem(given)


def evaluate(
    name: str,
    given: Mapping[str, Any],
    cos_i: Any,
    cos_o: Any,
    cos_h: Any,
    cos_d: Any,
    ops: analytic_forms.ArrayOps = analytic_forms.NUMPY,
) -> Any:
    """f [sr-1] of form ``name`` with coefficients ``given`` at the shading cosines
    (:mod:`.analytic_forms`; ``ops``: numpy's array functions, or Dr.Jit's in path mode)."""
    form = FORMS[name]
    return form.evaluate(cos_i, cos_o, cos_h, cos_d, form.complete(given), ops)
