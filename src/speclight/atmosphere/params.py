"""Parameters of the atmosphere models: names, defaults, accepted ranges, validation.

Every parameter is a keyword of :func:`speclight.atmosphere.transmission` and a key of the
scenario's ``atmosphere:`` block; errors name it as ``atmosphere.<key>``.
"""

from __future__ import annotations

import math
import re
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal, get_args

from speclight.errors import InputError, did_you_mean

AtmosphereModel = Literal["none", "spectrl2", "6s", "table"]
MODELS: tuple[str, ...] = get_args(AtmosphereModel)

#: 6S standard atmospheres (Py6S ``AtmosProfile`` predefined types). ``user`` scales the
#: U.S. 1962 profile to ``water_vapour_cm`` and ``ozone_atm_cm``.
SIXS_ATMOSPHERE_PROFILES: tuple[str, ...] = (
    "user",
    "tropical",
    "midlatitude-summer",
    "midlatitude-winter",
    "subarctic-summer",
    "subarctic-winter",
    "us-standard-1962",
)
#: 6S aerosol models (Py6S ``AeroProfile`` predefined types).
SIXS_AEROSOL_PROFILES: tuple[str, ...] = (
    "continental",
    "maritime",
    "urban",
    "desert",
    "biomass-burning",
    "stratospheric",
    "none",
)


@dataclass(frozen=True)
class AtmosphereParams:
    """Validated parameters of an atmosphere model (defaults documented per field).

    Attributes
    ----------
    water_vapour_cm
        Precipitable water column [cm]; default 1.42 (U.S. Standard Atmosphere 1962).
    ozone_atm_cm
        Ozone column [atm-cm]; default 0.344 (U.S. Standard Atmosphere 1962).
    aod_500nm
        Aerosol optical depth (SPECTRL2's turbidity) at 500 nm [1]; default 0.1 (clear).
    angstrom_exponent
        Angstrom exponent alpha of the aerosol optical depth [1]; default 1.14 (SPECTRL2's
        rural aerosol, Bird & Riordan 1986). For 6S it only converts ``aod_500nm`` to the
        550 nm reference of 6S; the spectral shape then comes from ``aerosol_profile``.
    atmosphere_profile
        6S only: standard atmosphere (:data:`SIXS_ATMOSPHERE_PROFILES`); default ``user``.
        A named profile brings its own water and ozone columns.
    aerosol_profile
        6S only: aerosol model (:data:`SIXS_AEROSOL_PROFILES`); default ``continental``.
    airmass_nodes
        6S only: airmasses at which 6S is run [1]; default (1, 2, 3, 5, 8, 12), i.e.
        elevations down to ~5 deg are interpolated, lower ones extrapolated (Beer-Lambert
        slope of the last segment).
    table_file
        ``table`` only: CSV file of transmission vs wavelength and airmass (required).
    fallback_to_spectrl2
        6S only: when the 6S executable cannot run, use SPECTRL2 instead of failing.
    cache_dir
        6S only: cache folder; default ``$SPECLIGHT_CACHE_DIR`` or ``~/.cache/speclight``.
    """

    water_vapour_cm: float = 1.42
    ozone_atm_cm: float = 0.344
    aod_500nm: float = 0.1
    angstrom_exponent: float = 1.14
    atmosphere_profile: str = "user"
    aerosol_profile: str = "continental"
    airmass_nodes: tuple[float, ...] = (1.0, 2.0, 3.0, 5.0, 8.0, 12.0)
    table_file: Path | None = None
    fallback_to_spectrl2: bool = False
    cache_dir: Path | None = None
    given: frozenset[str] = field(default_factory=frozenset)

    @property
    def aod_550nm(self) -> float:
        """Aerosol optical depth at 550 nm from the Angstrom law [1]."""
        return self.aod_500nm * (550.0 / 500.0) ** (-self.angstrom_exponent)


_COMMON = ("water_vapour_cm", "ozone_atm_cm", "aod_500nm", "angstrom_exponent")
_ALLOWED: dict[str, tuple[str, ...]] = {
    "none": (),
    "spectrl2": _COMMON,
    "6s": (
        *_COMMON,
        "atmosphere_profile",
        "aerosol_profile",
        "airmass_nodes",
        "fallback_to_spectrl2",
        "cache_dir",
    ),
    "table": ("table_file",),
}
_RANGES: dict[str, tuple[float, float]] = {
    "water_vapour_cm": (0.0, 10.0),
    "ozone_atm_cm": (0.0, 1.0),
    "aod_500nm": (0.0, 5.0),
    "angstrom_exponent": (-1.0, 4.0),
}


def _number(key: str, value: Any) -> float:
    lo, hi = _RANGES[key]
    try:
        x = float(value)
    except (TypeError, ValueError):
        x = math.nan
    if isinstance(value, bool) or not (lo <= x <= hi):
        raise InputError(
            f"{key} = {value!r} must be a number in {lo:g}..{hi:g}", field=f"atmosphere.{key}"
        )
    return x


_ALIASES = {"noaerosols": "none", "usstandard": "us-standard-1962", "us62": "us-standard-1962"}


def _squash(text: str) -> str:
    return re.sub(r"[^a-z0-9]", "", text.lower())


def _choice(key: str, value: Any, choices: Sequence[str]) -> str:
    """Match a name case- and separator-insensitively (Py6S's ``MidlatitudeSummer`` works)."""
    text = str(value).strip()
    squashed = {_squash(c): c for c in choices}
    found = squashed.get(_squash(text)) or _ALIASES.get(_squash(text))
    if found is None or found not in choices:
        raise InputError(
            f"unknown {key} {value!r}{did_you_mean(text, choices)} (choices: {', '.join(choices)})",
            field=f"atmosphere.{key}",
        )
    return found


def model_keys(model: str, fields: Any) -> tuple[str, ...]:
    """The parameters of ``model`` that ``fields`` (e.g. a scenario model class) has."""
    names = getattr(fields, "model_fields", fields)
    return tuple(k for k in _ALLOWED[model] if k in names)


def check_model(model: str) -> AtmosphereModel:
    """Return ``model`` if it is a known atmosphere model name, else raise InputError."""
    if model not in MODELS:
        raise InputError(
            f"unknown atmosphere model {model!r}{did_you_mean(str(model), MODELS)} "
            f"(choices: {', '.join(MODELS)})",
            field="atmosphere.model",
        )
    return model  # type: ignore[return-value]


def parse_params(model: AtmosphereModel, params: Mapping[str, Any]) -> AtmosphereParams:
    """Validate the keyword parameters of ``model`` and fill in the defaults.

    Raises
    ------
    InputError
        For an unknown key (with a did-you-mean), a key of another model, or a value out
        of range; the field is ``atmosphere.<key>``.
    """
    values: dict[str, Any] = {}
    for key, value in params.items():
        _check_key(model, key)
        values[key] = _value(key, value)
    if model == "table" and values.get("table_file") is None:
        raise InputError(
            "model 'table' needs table_file: a CSV of transmission vs wavelength and airmass",
            field="atmosphere.table_file",
        )
    profile = values.get("atmosphere_profile", "user")
    overridden = sorted({"water_vapour_cm", "ozone_atm_cm"} & set(values))
    if model == "6s" and profile != "user" and overridden:
        warnings.warn(
            f"atmosphere.atmosphere_profile {profile!r} brings its own water and ozone "
            f"columns, so 6S ignores {' and '.join(overridden)}; set "
            "atmosphere_profile: user to use them",
            UserWarning,
            stacklevel=3,
        )
    return AtmosphereParams(**values, given=frozenset(values))


def _check_key(model: AtmosphereModel, key: str) -> None:
    """An InputError unless ``key`` is a parameter of ``model`` (naming the model it is a
    parameter of, or the closest one)."""
    allowed = _ALLOWED[model]
    if key in allowed:
        return
    every = sorted({k for keys in _ALLOWED.values() for k in keys})
    if key in every:
        owners = [m for m, keys in _ALLOWED.items() if key in keys]
        msg = f"{key} applies only to model {' or '.join(owners)}, not {model!r}"
    else:
        msg = f"unknown parameter {key!r}{did_you_mean(key, every)}"
    accepted = ", ".join(allowed) if allowed else "none"
    raise InputError(f"{msg} (accepted for {model!r}: {accepted})", field=f"atmosphere.{key}")


def _value(key: str, value: Any) -> Any:
    """The checked value of parameter ``key``."""
    if key in _RANGES:
        return _number(key, value)
    if key == "atmosphere_profile":
        return _choice(key, value, SIXS_ATMOSPHERE_PROFILES)
    if key == "aerosol_profile":
        return _choice(key, value, SIXS_AEROSOL_PROFILES)
    if key == "airmass_nodes":
        return _nodes(value)
    if key == "fallback_to_spectrl2":
        if not isinstance(value, bool):
            raise InputError(
                f"fallback_to_spectrl2 = {value!r} must be true or false",
                field="atmosphere.fallback_to_spectrl2",
            )
        return value
    return None if value is None else Path(value).expanduser()  # table_file, cache_dir


def _nodes(value: Any) -> tuple[float, ...]:
    try:
        nodes = tuple(sorted(float(v) for v in value))
    except (TypeError, ValueError):
        nodes = ()
    if not nodes or nodes[0] < 1.0 or nodes[-1] > 30.0 or len(set(nodes)) != len(nodes):
        raise InputError(
            f"airmass_nodes = {value!r} must be a list of distinct airmasses in 1..30, "
            "e.g. [1, 2, 4, 8]",
            field="atmosphere.airmass_nodes",
        )
    return nodes
