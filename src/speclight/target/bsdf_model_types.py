"""The records of the table of BSDF models (:mod:`speclight.target.bsdf_models`): a model
and a parameter some models take."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class BsdfParameter:
    """A material parameter that some models take (a key of the scenario's material).

    Attributes
    ----------
    name
        The key (and :class:`~speclight.target.Material` field).
    meaning
        What it is, with its unit and range, for messages and docs.
    bounds
        ``(low, high)``: the value must lie in (low, high] (numbers only); None: no range.
    names_file
        The value may name a file (its SHA-256 goes into the output's ``input_files``).
    """

    name: str
    meaning: str
    bounds: tuple[float, float] | None = None
    names_file: bool = False

    def range_problem(self, value: Any) -> str | None:
        """Why ``value`` is out of :attr:`bounds` (None when it is inside)."""
        if self.bounds is None:
            return None
        low, high = self.bounds
        if not low < float(value) <= high:
            return f"{self.name} = {value!r} must lie in ({low:g}, {high:g}] ({self.meaning})"
        return None


@dataclass(frozen=True)
class BsdfModel:
    """One BSDF model (or one form of it, see the module docstring).

    Attributes
    ----------
    name
        The ``bsdf`` value.
    summary
        One line: what it models, with its reference.
    reflectance
        What the material's ``reflectance`` means for it.
    required, optional
        Parameters it needs / may take (any other given is an error).
    reflectance_kinds
        The :class:`~speclight.target.Reflectance` kinds it accepts (None: any).
    reflectance_default
        The ``reflectance`` a Python spec may leave out (None: it must be given).
    modes
        Render modes that support it (``single``, ``path``).
    polarized_modes
        Render modes in which its polarisation is modelled (``render.polarization``).
    channels
        How the single mode splits it: geometric weight(s) [sr-1] times spectral factor(s).
    engines
        Optional engines it needs in every mode: ``(engine, key)``, the engine's name in
        :data:`speclight.engine_packages.ENGINES` and the material key that asks for it.
    examples
        Representative parameters (scenario material mappings) for docs and the contract test.
    form
        For a model with several forms, which one this is ("" otherwise).
    select
        For a model with several forms: the form for given parameter values.
    check
        A further check of a built material (reads files): ``check(material, field)``.
    """

    name: str
    summary: str
    reflectance: str
    required: tuple[BsdfParameter, ...] = ()
    optional: tuple[BsdfParameter, ...] = ()
    reflectance_kinds: tuple[str, ...] | None = None
    reflectance_default: float | None = None
    modes: tuple[str, ...] = ("single", "path")
    polarized_modes: tuple[str, ...] = ()
    channels: str = ""
    engines: tuple[tuple[str, str], ...] = ()
    examples: tuple[Mapping[str, Any], ...] = ()
    form: str = ""
    select: Callable[[Mapping[str, Any]], BsdfModel] | None = field(default=None, repr=False)
    check: Callable[[Any, str], None] | None = field(default=None, repr=False)

    @property
    def label(self) -> str:
        """``name`` or ``name (form)``: for messages and test ids."""
        return f"{self.name} ({self.form})" if self.form else self.name

    def takes(self, parameter: str) -> bool:
        """True when the model needs or may take ``parameter``."""
        return any(p.name == parameter for p in (*self.required, *self.optional))
