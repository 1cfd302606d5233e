"""Ranging stage: laser transmitters' geometry, the laser-radar link and range histograms.

Plain numpy arrays in and out: :mod:`.transmitter` (where a transmitter is seen from the
target), :mod:`.link` (uplink irradiance, downlink to the receiver's bands, histograms and
centre-of-mass offsets), :mod:`.bins` (the range-offset bins). The light transport of laser
light resolved in range lives in :mod:`speclight.render.laser_returns`, the pipeline glue in
:mod:`speclight.simulation.ranging_stage`.
"""

from speclight.ranging.bins import RANGE_BINS, range_bin_edges_m
from speclight.ranging.link import (
    ReceiverReturns,
    band_histograms,
    band_rates,
    downlink_conversion,
    receiver_returns,
    uplink_irradiance_W_m2,
    uplink_spectral_irradiance,
)
from speclight.ranging.transmitter import TransmitterGeometry, transmitter_geometry

__all__ = [
    "RANGE_BINS",
    "ReceiverReturns",
    "TransmitterGeometry",
    "band_histograms",
    "band_rates",
    "downlink_conversion",
    "range_bin_edges_m",
    "receiver_returns",
    "transmitter_geometry",
    "uplink_irradiance_W_m2",
    "uplink_spectral_irradiance",
]
