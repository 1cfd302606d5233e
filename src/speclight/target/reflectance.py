"""Spectral reflectance specifications: constant, table, inline pairs, or Fresnel from n, k."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from speclight.errors import InputError
from speclight.input_files import read_user_text
from speclight.target.optical_constants import (
    check_nk_name,
    fresnel_reflectance,
    refractive_index,
)

ReflectanceKind = Literal["constant", "table", "conductor", "dielectric"]


@dataclass(frozen=True)
class Reflectance:
    """A spectral reflectance: a number, a table, or the Fresnel reflectance of shipped n, k.

    Build it with :meth:`constant`, :meth:`pairs`, :meth:`table_file`, :meth:`conductor` or
    :meth:`dielectric`. ``kind`` says which; ``value`` holds the constant, ``wavelength_nm`` and
    ``values`` the table, ``material`` the n,k name.
    """

    kind: ReflectanceKind
    value: float = 0.0
    wavelength_nm: tuple[float, ...] = ()
    values: tuple[float, ...] = ()
    material: str = ""
    source: str = ""

    # -- constructors -------------------------------------------------------------------
    @classmethod
    def constant(cls, value: float, *, field: str = "reflectance") -> Reflectance:
        """Spectrally flat reflectance ``value`` in [0, 1]."""
        v = float(value)
        if not 0.0 <= v <= 1.0:
            raise InputError(f"reflectance = {value!r} must be in [0, 1]", field=field)
        return cls(kind="constant", value=v)

    @classmethod
    def pairs(
        cls,
        wavelength_nm: ArrayLike,
        value: ArrayLike,
        *,
        source: str = "",
        field: str = "reflectance",
    ) -> Reflectance:
        """Tabulated reflectance, linearly interpolated between strictly increasing nodes."""
        wl = np.asarray(wavelength_nm, dtype=float).ravel()
        v = np.asarray(value, dtype=float).ravel()
        problem = _pairs_problem(wl, v)
        if problem is not None:
            raise InputError(problem, source=source or None, field=field)
        return cls(kind="table", wavelength_nm=tuple(wl), values=tuple(v), source=source)

    @classmethod
    def table_file(cls, path: str | Path, *, field: str = "reflectance") -> Reflectance:
        """Read a two-column text/CSV table: wavelength [nm], reflectance [0..1].

        Text after ``#`` is a comment and one non-numeric header line is skipped; commas,
        semicolons or whitespace separate the columns.

        Raises
        ------
        InputError
            If the file cannot be read as text (a folder, a FIFO, binary content; see
            :func:`speclight.instrument.tables.read_user_text`), a line is not two finite
            numbers, or the table has fewer than 2 rows.
        """
        p = Path(path)
        src = str(p)
        rows: list[tuple[float, float]] = []
        header_seen = False
        for lineno, line in enumerate(read_user_text(p, field).splitlines(), start=1):
            s = line.split("#", 1)[0].replace(",", " ").replace(";", " ").split()
            if not s:
                continue
            try:
                row = (float(s[0]), float(s[1]))
            except (ValueError, IndexError):
                if rows or header_seen:
                    raise InputError(
                        f"line {lineno} {line.strip()!r} is not two numbers "
                        "(wavelength_nm, reflectance); only the first line may be a header",
                        source=src,
                        field=field,
                    ) from None
                header_seen = True
                continue
            if not np.all(np.isfinite(row)):
                raise InputError(
                    f"line {lineno} {line.strip()!r} holds a value that is not a finite "
                    "number; give a wavelength and a reflectance in [0, 1] on every line",
                    source=src,
                    field=field,
                )
            rows.append(row)
        a = np.array(rows, dtype=float).reshape(-1, 2)
        return cls.pairs(a[:, 0], a[:, 1], source=str(p), field=field)

    @classmethod
    def conductor(cls, name: str) -> Reflectance:
        """Fresnel reflectance of a shipped conductor (Al, Ag, Au)."""
        check_nk_name(name, "conductor")
        return cls(kind="conductor", material=name)

    @classmethod
    def dielectric(cls, name: str) -> Reflectance:
        """Fresnel reflectance of a shipped dielectric (SiO2, Si, GaAs, Kapton)."""
        check_nk_name(name, "dielectric")
        return cls(kind="dielectric", material=name)

    # -- evaluation ---------------------------------------------------------------------
    @property
    def is_fresnel(self) -> bool:
        """True if the reflectance depends on the angle of incidence (n, k kinds)."""
        return self.kind in ("conductor", "dielectric")

    def eta(self, wavelength_nm: ArrayLike) -> NDArray[np.complex128]:
        """Complex refractive index n + i k (Fresnel kinds only)."""
        if not self.is_fresnel:
            raise InputError(f"a {self.kind} reflectance has no refractive index")
        return refractive_index(self.material, wavelength_nm)

    def evaluate(self, wavelength_nm: ArrayLike) -> NDArray[np.float64]:
        """Reflectance at normal incidence, shape of ``wavelength_nm`` [1]."""
        wl = np.asarray(wavelength_nm, dtype=float)
        if self.kind == "constant":
            return np.full(wl.shape, self.value)
        if self.kind == "table":
            t = np.asarray(self.wavelength_nm)
            if np.any(wl < t[0]) or np.any(wl > t[-1]):
                raise InputError(
                    f"reflectance table covers {t[0]:g}-{t[-1]:g} nm but the wavelength grid "
                    f"reaches {wl.min():g}-{wl.max():g} nm; extend the table",
                    source=self.source or None,
                    field="reflectance",
                )
            return np.interp(wl, t, np.asarray(self.values))
        return fresnel_reflectance(1.0, self.eta(wl))

    def at_incidence(self, cos_theta: ArrayLike, wavelength_nm: ArrayLike) -> NDArray[np.float64]:
        """Reflectance at incidence cosines (K,) and wavelengths (L,) -> (K, L) [1].

        Fresnel kinds follow the Fresnel equations; the others do not depend on angle.
        """
        c = np.asarray(cos_theta, dtype=float).reshape(-1, 1)
        wl = np.asarray(wavelength_nm, dtype=float).ravel()
        if self.is_fresnel:
            return fresnel_reflectance(c, self.eta(wl)[None, :])
        return np.broadcast_to(self.evaluate(wl)[None, :], (c.shape[0], wl.size)).copy()


def _pairs_problem(wl: NDArray[np.float64], v: NDArray[np.float64]) -> str | None:
    """What is wrong with a reflectance table's wavelengths [nm] and values, or None."""
    if wl.size != v.size or wl.size < 2:
        return (
            f"reflectance table needs >= 2 (wavelength_nm, value) pairs of equal length, "
            f"got {wl.size} and {v.size}"
        )
    if np.any(np.diff(wl) <= 0) or not np.all(np.isfinite(wl)):
        return "reflectance table wavelength_nm must be finite and strictly increasing"
    if not np.all(np.isfinite(v)):
        return (
            f"reflectance table values must be finite numbers in [0, 1], got "
            f"{np.count_nonzero(~np.isfinite(v))} NaN or inf"
        )
    if np.any(~((v >= 0) & (v <= 1))):
        return (
            f"reflectance table values must be in [0, 1] (got {v.min():g}..{v.max():g}); "
            "give fractions, not percent"
        )
    return None
