"""Shipped reflectance tables of spacecraft materials (``data/materials``).

Four spectra for the reference paper's cube experiment (Nussbaum et al. 2022, section 5.2,
doi:10.3390/aerospace9040214): ``aluminium``, ``kapton_mli``, ``solar_cell`` and
``white_paint``, derived from the shipped optical constants by
``scripts/make_material_spectra.py`` (formulas and sources: ``data/materials/PROVENANCE.md``).
A scenario names one as ``reflectance: {table: solar_cell}``.
"""

from __future__ import annotations

from importlib import resources
from pathlib import Path

from speclight.errors import InputError, did_you_mean

MATERIAL_TABLES: tuple[str, ...] = ("aluminium", "kapton_mli", "solar_cell", "white_paint")


def material_table_path(name: str) -> Path:
    """Path of the shipped table ``name`` (CSV ``wavelength_nm,reflectance``)."""
    if name not in MATERIAL_TABLES:
        raise InputError(
            f"unknown material table '{name}'{did_you_mean(name, MATERIAL_TABLES)} "
            f"(choices: {', '.join(MATERIAL_TABLES)})",
            field="table",
        )
    return Path(str(resources.files("speclight").joinpath("data", "materials", f"{name}.csv")))
