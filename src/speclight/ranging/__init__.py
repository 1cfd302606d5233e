"""Ranging stage: laser transmitters' geometry, the laser-radar link and range histograms.

Plain numpy arrays in and out; the rendering of laser light resolved in range lives in
:mod:`speclight.render.laser_returns`, the pipeline glue in :mod:`speclight.simulate.ranging_stage`.
"""

from speclight.ranging.link import (
    band_histograms,
    cross_section_link_photons,
    mean_offset_m,
    photons_from_intensity,
)
from speclight.ranging.transmitter import TransmitterGeometry, transmitter_geometry

__all__ = [
    "TransmitterGeometry",
    "band_histograms",
    "cross_section_link_photons",
    "mean_offset_m",
    "photons_from_intensity",
    "transmitter_geometry",
]
