"""From collected electrons to the numbers a camera writes: noise, full well, gain, bias.

Plain arrays. The mean electrons of each pixel (sources, sky, dark current) are drawn from
the Poisson distribution (its normal approximation above
:data:`~speclight.instrument.noise.POISSON_MAX_MEAN`), clipped at the full well (charge
beyond it is lost: no blooming into neighbours), read with Gaussian read noise, divided
by the gain, offset by the bias, rounded to integers and clipped at the ADC's range
``[0, saturation_adu]``. The variance of a pixel in ADU is then
``(mean + read_noise^2) / gain^2 + 1/12`` below saturation (the 1/12 of rounding:
Sheppard 1898). Without noise the mean frame is returned as floats (no rounding).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from speclight.instrument.noise import POISSON_MAX_MEAN

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class Readout:
    """A detector's readout (per pixel).

    Attributes
    ----------
    read_noise_e
        Read noise [e- rms].
    gain_e_per_adu
        Electrons per ADU.
    bias_adu
        Offset added to every pixel [ADU].
    full_well_e
        Charge a pixel holds [e-].
    saturation_adu
        Largest value of the ADC [ADU].
    """

    read_noise_e: float = 5.0
    gain_e_per_adu: float = 1.0
    bias_adu: float = 100.0
    full_well_e: float = 100_000.0
    saturation_adu: int = 65_535


def read_out(
    mean_e: F64, readout: Readout, rng: np.random.Generator | None
) -> tuple[NDArray[np.float64] | NDArray[np.int64], NDArray[np.bool_]]:
    """The frame the camera writes, and which pixels are saturated.

    Parameters
    ----------
    mean_e
        (rows, columns) expected electrons per pixel [e-], >= 0.
    readout
        The detector's readout.
    rng
        Random generator; ``None`` for the noiseless (mean) frame.

    Returns
    -------
    frame, saturated
        Integer ADU (with ``rng``) or float ADU (without), and the mask of pixels at the
        full well or the ADC's top.
    """
    mean = np.asarray(mean_e, dtype=np.float64)
    if rng is None:
        electrons = mean
    else:
        large = mean > POISSON_MAX_MEAN
        electrons = rng.poisson(np.where(large, 0.0, mean)).astype(np.float64)
        if np.any(large):
            electrons[large] = rng.normal(mean[large], np.sqrt(mean[large]))
    full = electrons >= readout.full_well_e
    electrons = np.minimum(electrons, readout.full_well_e)
    if rng is not None:
        electrons = electrons + rng.normal(0.0, readout.read_noise_e, size=mean.shape)
    adu = electrons / readout.gain_e_per_adu + readout.bias_adu
    top = adu >= readout.saturation_adu
    adu = np.clip(adu, 0.0, readout.saturation_adu)
    if rng is None:
        return adu, full | top
    return np.rint(adu).astype(np.int64), full | top
