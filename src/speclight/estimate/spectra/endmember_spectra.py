"""Endmember reflectance spectra for ``speclight unmix`` and their band signatures.

Spectra come from CSV files (``wavelength_nm,reflectance``, one material per file, named by
the file stem) or from the scenario's materials. Their band signatures are the averages the
band reflectance factor is proportional to (eq. 5, docs/upsample-unmix.md): over each band, weighted
by the detected photons **of the source at the aperture**,
``s_kj = sum rho_k E T R_j l dl / sum E T R_j l dl``
(:func:`speclight.estimate.spectra.ground_truth.material_signatures`, with the source of
:mod:`speclight.estimate.inputs.source_spectrum`). The atmosphere changes ``T`` along a pass, so the
signatures are computed for every epoch (``signatures_epoch``, what the epochs are unmixed
with: exact for materials whose BRDF is their reflectance times a geometric factor,
docs/cube-materials.md); ``signatures`` is the matrix of the mean source spectrum, which
ABUND.nc reports. Without a source (None) both are the plain photon-weighted band averages
of eq. 3, right only for a flat source spectrum.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.inputs.band_responses import BandResponses
from speclight.estimate.inputs.source_spectrum import mean_source_W_m2_nm
from speclight.estimate.spectra.ground_truth import material_signatures

if TYPE_CHECKING:
    from speclight.scenario import LoadedScenario
    from speclight.target.materials import Material

F64 = NDArray[np.float64]


@dataclass(frozen=True)
class Endmembers:
    """Endmember reflectance spectra and their band signatures.

    Attributes
    ----------
    names
        (K,) endmember names.
    spectra
        (K, L) reflectance spectra on the bands' wavelength grid [1] ((K, 0) if extracted).
    signatures
        (K, B) band signatures with the mean source spectrum [1] (module doc), or the
        extracted reflectance factors [m2 sr-1].
    signatures_epoch
        (N, K, B) band signatures with each epoch's source spectrum, or None (then every
        epoch is unmixed with ``signatures``).
    """

    names: list[str]
    spectra: F64
    signatures: F64
    signatures_epoch: F64 | None = None


def _signatures(
    names: list[str], spectra: F64, bands: BandResponses, source_W_m2_nm: F64 | None
) -> Endmembers:
    wl, response = bands.wavelength_nm, bands.response
    if source_W_m2_nm is None:
        return Endmembers(names, spectra, material_signatures(spectra, response, wl))
    mean = material_signatures(spectra, response, wl, mean_source_W_m2_nm(source_W_m2_nm, 1.0))
    per_epoch = material_signatures(spectra, response, wl, source_W_m2_nm)
    return Endmembers(names, spectra, mean, per_epoch)


def endmembers_from_files(
    paths: list[str | Path], bands: BandResponses, source_W_m2_nm: F64 | None = None
) -> Endmembers:
    """Endmembers from reflectance CSV files (``wavelength_nm,reflectance``), named by stem.

    ``source_W_m2_nm`` (N, L): the source spectrum at the aperture per epoch (module doc).

    Raises
    ------
    InputError
        A file that is not such a table (non-finite or negative values, values above 1, too
        few rows), one that does not cover the bands' wavelength grid, or two files with
        the same stem.
    """
    names = [Path(p).stem for p in paths]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        raise InputError(
            f"endmember name(s) {', '.join(twice)} given twice (names are the file stems)",
            field="endmembers",
        )
    from speclight.target.reflectance import Reflectance

    spectra = [
        Reflectance.table_file(p, field="endmembers").evaluate(bands.wavelength_nm) for p in paths
    ]
    return _signatures(names, np.array(spectra, dtype=float), bands, source_W_m2_nm)


def material_spectrum(material: Material, wavelength_nm: F64) -> F64:
    """A material's reflectance spectrum for unmixing [1] (L,).

    The normal-incidence reflectance (:meth:`Reflectance.evaluate`: the albedo of a
    Lambertian surface, the Fresnel reflectance of a conductor at normal incidence, a table);
    for ``plastic`` the diffuse base's reflectance (the coat's few-percent Fresnel
    reflection is left out: it is nearly grey and seen only in glints).
    """
    if material.bsdf == "plastic" and material.diffuse_reflectance is not None:
        return material.diffuse_reflectance.evaluate(wavelength_nm)
    return material.reflectance.evaluate(wavelength_nm)


def endmembers_from_scenario(
    loaded: LoadedScenario, bands: BandResponses, source_W_m2_nm: F64 | None = None
) -> Endmembers:
    """The scenario's materials as endmembers; materials of identical spectrum are one
    endmember named by their names joined with ``,``.

    Raises
    ------
    InputError
        A scenario without a target.
    """
    from speclight.simulation.reflection import build_target

    if loaded.scenario.target is None:
        raise InputError("the scenario has no target materials", field="endmembers")
    target = build_target(loaded)
    names: list[str] = []
    spectra: list[F64] = []
    for m in target.materials:
        spectrum = material_spectrum(m, bands.wavelength_nm)
        same = [i for i, s in enumerate(spectra) if np.array_equal(s, spectrum)]
        if same:
            names[same[0]] += f",{m.name}"
        else:
            names.append(m.name)
            spectra.append(spectrum)
    return _signatures(names, np.array(spectra, dtype=float), bands, source_W_m2_nm)
