"""Band responses R_j of a scenario or a dataset: band curve x optics transmission x QE.

Upsampling (eq. 3) and the band signatures of endmember spectra weight a spectrum with the
same responses that produced the counts: the band curve times the optics transmission times
the band's detector quantum efficiency, on the wavelength grid. They are taken from where
``speclight simulate`` computes them (:func:`speclight.simulation.radiometry.instrument_response`)
or read back from its dataset (``band_response``, ``optics_transmission``, ``detector_qe``),
never rebuilt here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight.errors import InputError

if TYPE_CHECKING:
    from speclight.scenario import LoadedScenario

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class BandResponses:
    """The bands of an instrument on a wavelength grid.

    Attributes
    ----------
    band_names
        (B,) band names.
    wavelength_nm
        (L,) the grid [nm].
    response
        (B, L) band response x optics transmission x detector QE [1].
    """

    band_names: list[str]
    wavelength_nm: F64
    response: F64


def scenario_band_responses(loaded: LoadedScenario) -> BandResponses:
    """The scenario's bands on its wavelength grid (as ``speclight simulate`` builds them).

    Raises
    ------
    InputError
        If the scenario has no bands, or a band, optics or QE table cannot be read.
    """
    from speclight.simulation.radiometry import instrument_response, wavelength_grid_nm

    wl = wavelength_grid_nm(loaded.scenario.spectrum)
    if not loaded.scenario.instrument.bands:
        raise InputError(
            "the scenario has no bands; add instrument.bands", field="instrument.bands"
        )
    empty = np.zeros((0, wl.size))
    radiometry = instrument_response(loaded, wl, empty, empty, np.zeros(0))
    response = radiometry.band_response * radiometry.optics[None, :] * radiometry.qe
    return BandResponses(list(radiometry.band_names), wl, np.asarray(response, dtype=np.float64))


def dataset_band_responses(ds: xr.Dataset, source: str = "") -> BandResponses:
    """The bands of a ``speclight simulate`` dataset (``band_response`` x optics x QE).

    Raises
    ------
    InputError
        If the dataset lacks ``band_response`` on (band, wavelength).
    """
    if "band_response" not in ds or "wavelength" not in ds.coords or "band" not in ds.coords:
        raise InputError(
            "not a speclight dataset with band responses (band_response on (band, wavelength))",
            source=source or None,
            field="MEASURED",
        )
    response = ds["band_response"].transpose("band", "wavelength").values.astype(float)
    if "optics_transmission" in ds:
        response = response * ds["optics_transmission"].values.astype(float)[None, :]
    if "detector_qe" in ds:
        response = response * ds["detector_qe"].transpose("band", "wavelength").values
    return BandResponses(
        [str(b) for b in ds["band"].values],
        ds["wavelength"].values.astype(float),
        np.asarray(response, dtype=np.float64),
    )
