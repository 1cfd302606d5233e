"""``speclight unmix``: band reflectance factors in, ABUND.nc (docs/upsample-unmix.md) out.

:func:`unmix_measured` reads the factors (:mod:`speclight.estimate.inputs.reflectance_factors`),
takes the endmembers from spectrum files, the scenario's materials or the data
(:func:`.extract_endmembers`), unmixes every epoch (:func:`.unmix`, eq. 6) and returns the
dataset:

``abundance(time, endmember)``
    [1] for ``nnls-norm`` and ``fcls`` and for extracted endmembers (whose signatures are
    reflectance factors themselves), [m2 sr-1] for ``ls`` and ``nnls`` with spectra;
``residual(time)`` [m2 sr-1], ``endmember_signature(endmember, band)``,
``reflectance_factor(time, band)`` [m2 sr-1]
    as documented; epochs with a NaN factor keep their row, with NaN abundances.

Endmember spectra enter through their band signatures weighted by the source spectrum at
the aperture (the Sun's or the lasers', :mod:`.endmember_spectra`), and every epoch is
unmixed with its own epoch's signatures (:func:`.unmix_per_epoch`); ``endmember_signature``
holds those of the mean source spectrum.

With ground truth in the input (``reflectance_factor_material`` or
``laser_reflectance_factor_material``), also the comparison of :mod:`.unmix_truth`:
``true_share`` and ``estimated_share(time, class)``, ``confusion_matrix(true_class,
estimated_class)``, ``confusion_count`` and the attribute ``mean_absolute_share_error``.
"""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr

from speclight.errors import InputError, did_you_mean
from speclight.estimate.inputs.reflectance_factors import (
    ReflectanceFactors,
    dataset_scenario,
    read_reflectance_factors,
)
from speclight.estimate.inputs.source_spectrum import check_light
from speclight.estimate.spectra import accuracy
from speclight.estimate.spectra.endmember_spectra import (
    Endmembers,
    endmembers_from_files,
    endmembers_from_scenario,
)
from speclight.estimate.spectra.endmembers import ENDMEMBER_METHODS, extract_endmembers
from speclight.estimate.spectra.factor_noise import factor_sigma
from speclight.estimate.spectra.unmix_checks import with_checks
from speclight.estimate.spectra.unmix_truth import compare_with_truth
from speclight.estimate.spectra.unmixing import UNMIX_METHODS
from speclight.estimate.spectra.unmixing_epochs import unmix_per_epoch
from speclight.io.user_dataset import read_user_dataset

if TYPE_CHECKING:
    from speclight.scenario import LoadedScenario

#: ``endmembers`` value that takes the scenario's materials.
SCENARIO_ENDMEMBERS = "scenario"


def check_unmix_options(
    *,
    endmembers: list[str] | None,
    extract: str | None,
    n: int | None,
    method: str,
    light: str | None = None,
) -> None:
    """Refuse inconsistent options before any work (one-line :class:`InputError`).

    Parameters
    ----------
    endmembers
        Endmember spectrum files, or ``["scenario"]``; or None with ``extract``.
    extract
        ``purest``, ``atgp``, ``pca`` or ``nfindr``, or None with ``endmembers``.
    n
        Endmembers to extract (with ``extract`` only).
    method
        The unmixing method (:data:`speclight.estimate.UNMIX_METHODS`).
    light
        ``sun``, ``laser`` or None (what the data have).
    """
    check_light(light)
    if method not in UNMIX_METHODS:
        raise InputError(
            f"unknown method '{method}'{did_you_mean(method, UNMIX_METHODS)} "
            f"(choices: {', '.join(UNMIX_METHODS)})",
            field="method",
        )
    if bool(endmembers) == (extract is not None):
        raise InputError(
            "give endmembers=[E1.csv, E2.csv, ...] (or endmembers=['scenario']) or "
            "extract=purest|atgp|pca|nfindr with n=K, one of them",
            field="endmembers",
        )
    if extract is not None:
        if extract not in ENDMEMBER_METHODS:
            raise InputError(
                f"unknown extraction '{extract}'{did_you_mean(extract, ENDMEMBER_METHODS)} "
                f"(choices: {', '.join(ENDMEMBER_METHODS)})",
                field="extract",
            )
        if n is None:
            raise InputError(f"extract='{extract}' needs n=K (the number of endmembers)", field="n")
        if n < 1:
            raise InputError(f"n = {n} must be >= 1", field="n")
    elif n is not None:
        raise InputError(
            "`n` is the number of endmembers to extract; use it with `extract`", field="n"
        )


def unmix_measured(
    measured: str | Path,
    *,
    endmembers: list[str] | None = None,
    extract: str | None = None,
    n: int | None = None,
    method: str = "nnls-norm",
    loaded: LoadedScenario | None = None,
    bin_s: float | None = None,
    progress: bool = False,
    light: str | None = None,
) -> xr.Dataset:
    """Unmix measured light curves into endmember contributions (module doc: the dataset).

    Parameters
    ----------
    measured
        A speclight NetCDF or a CSV of count rates (then ``loaded`` is required).
    endmembers
        Reflectance CSV files (``wavelength_nm,reflectance``), or ``["scenario"]`` for the
        scenario's materials (then ``loaded`` is required).
    extract, n
        Instead of ``endmembers``: extract ``n`` endmembers with ``purest`` (recommended),
        ``atgp``, ``pca`` or ``nfindr``.
    method
        ``ls``, ``nnls``, ``nnls-norm`` (default, the reference paper's best) or ``fcls``.
    loaded
        The scenario (for a CSV input or scenario endmembers; for a NetCDF, default: the
        scenario it was simulated from, its ``scenario_yaml`` attribute).
    bin_s
        Average epochs into bins of this many seconds first.
    progress
        Show the progress bar of the simulation a CSV input needs.
    light
        ``"sun"`` or ``"laser"``: unmix the solar or the laser reflectance factors (None:
        the lasers' where the dataset has no finite solar ones, else the Sun's).

    Raises
    ------
    InputError
        Inconsistent options, a bad file, more endmembers than bands, signatures that
        cannot be told apart.
    """
    check_unmix_options(endmembers=endmembers, extract=extract, n=n, method=method, light=light)
    if endmembers == [SCENARIO_ENDMEMBERS] and loaded is None:
        if Path(measured).suffix.lower() not in (".nc", ".nc4", ".netcdf", ".h5"):
            raise InputError("endmembers=['scenario'] needs loaded=SCENARIO", field="loaded")
        head = read_user_dataset(measured, "MEASURED", what="measurements", variables=())
        if "scenario_yaml" not in head.attrs:
            raise InputError(
                "endmembers=['scenario'] needs loaded=SCENARIO (the dataset does "
                "not carry the scenario it was simulated from)",
                field="loaded",
            )
        loaded = dataset_scenario(head, str(measured))
    data = read_reflectance_factors(measured, loaded, bin_s=bin_s, progress=progress, light=light)
    n_bands = len(data.bands.band_names)
    if extract is not None:
        assert n is not None
        if n > n_bands:
            raise InputError(
                f"n = {n} endmembers is more than the {n_bands} bands; ask for `n` <= {n_bands}",
                field="n",
            )
        sigma = factor_sigma(data.factor, data.rates, loaded or _carried(measured), data.bands)
        found = extract_endmembers(data.factor, n, extract, sigma)  # type: ignore[arg-type]
        _check_independent(found.signatures, found.notes)
        names = [f"{extract}-{k + 1}" for k in range(n)]
        members = Endmembers(names, np.full((n, 0), np.nan), found.signatures)
        origin = f"extracted by {extract} from the reflectance factors"
    else:
        assert endmembers
        if endmembers == [SCENARIO_ENDMEMBERS]:
            assert loaded is not None
            members = endmembers_from_scenario(loaded, data.bands, data.source_W_m2_nm)
            origin = f"materials of scenario {loaded.source}"
        else:
            members = endmembers_from_files(list(endmembers), data.bands, data.source_W_m2_nm)
            origin = "spectra " + ", ".join(str(p) for p in endmembers)
        check_distinct(members)
        if len(members.names) > n_bands:
            raise InputError(
                f"{len(members.names)} endmembers is more than the {n_bands} bands: the "
                f"contributions are not determined; give at most {n_bands}",
                field="endmembers",
            )
    sig = members.signatures if members.signatures_epoch is None else members.signatures_epoch
    result = unmix_per_epoch(data.factor, sig, method)  # type: ignore[arg-type]
    ds = _dataset(data, members, result.abundance, result.residual, method, extract, origin)
    if extract is not None:
        ds.attrs["extraction"] = "; ".join(found.notes) if found.notes else "ok"
    if extract is None:
        sigma = factor_sigma(data.factor, data.rates, loaded or _carried(measured), data.bands)
    ds = with_checks(ds, data.factor, result.abundance, sig, sigma, method)
    if data.material_contribution is not None and data.material_names is not None:
        ds = compare_with_truth(ds, data, members, result.abundance, by_name=extract is None)
    return ds


def _carried(measured: str | Path) -> LoadedScenario | None:
    """The scenario a NetCDF carries (its noise model), or None."""
    if Path(measured).suffix.lower() not in (".nc", ".nc4", ".netcdf", ".h5"):
        return None
    head = read_user_dataset(measured, "MEASURED", what="measurements", variables=())
    return dataset_scenario(head, str(measured)) if "scenario_yaml" in head.attrs else None


def _check_independent(signatures: np.ndarray, notes: tuple[str, ...]) -> None:
    """Refuse extracted signatures that are linearly dependent (the same shape picked twice
    where the data show fewer distinct shapes than asked), with the extraction's notes."""
    rank = int(np.linalg.matrix_rank(signatures))
    if rank < len(signatures):
        why = "; ".join(notes) if notes else "the data span fewer directions"
        raise InputError(
            f"n = {len(signatures)} extracted endmembers are linearly dependent (rank {rank}): "
            f"{why}; ask for n <= {rank}",
            field="n",
        )


def check_distinct(members: Endmembers) -> None:
    """Refuse endmembers whose band signatures are proportional (an unmixing cannot tell
    them apart)."""
    angle = accuracy.spectral_angle_rad(members.signatures, members.signatures)
    np.fill_diagonal(angle, np.inf)
    i, j = np.unravel_index(np.argmin(angle), angle.shape)
    if angle[i, j] < 1e-6:
        raise InputError(
            f"endmembers '{members.names[i]}' and '{members.names[j]}' have proportional band "
            "signatures (the same spectral shape): unmixing cannot tell them apart; drop one",
            field="endmembers",
        )


def _dataset(
    data: ReflectanceFactors,
    members: Endmembers,
    abundance: np.ndarray,
    residual: np.ndarray,
    method: str,
    extract: str | None,
    origin: str,
) -> xr.Dataset:
    from speclight import __version__

    unit_a = "1" if method in ("nnls-norm", "fcls") or extract is not None else "m2 sr-1"
    unit_s = "m2 sr-1" if extract is not None else "1"
    ds = xr.Dataset(
        coords={
            "time": ("time", data.time_utc, {"long_name": "epoch (UTC)", "standard_name": "time"}),
            "endmember": (
                "endmember",
                np.array(members.names, dtype=str),
                {"long_name": "endmember"},
            ),
            "band": (
                "band",
                np.array(data.bands.band_names, dtype=str),
                {"long_name": "photometric band"},
            ),
        }
    )
    ds["abundance"] = (
        ("time", "endmember"),
        abundance,
        {"units": unit_a, "long_name": f"contribution of each endmember ({method}, eq. 6)"},
    )
    ds["residual"] = (
        "time",
        residual,
        {"units": "m2 sr-1", "long_name": "norm over the bands of reflectance_factor - S a"},
    )
    ds["endmember_signature"] = (
        ("endmember", "band"),
        members.signatures,
        {
            "units": unit_s,
            "long_name": "band signature of each endmember (band average of its spectrum "
            "weighted by the detected photons of the mean source spectrum, or the extracted "
            "reflectance factors)",
        },
    )
    ds["reflectance_factor"] = (
        ("time", "band"),
        data.factor,
        {"units": "m2 sr-1", "long_name": "band reflectance factor that was unmixed (eq. 5)"},
    )
    ds = ds.assign_coords(
        wavelength=(
            "wavelength",
            data.bands.wavelength_nm,
            {"units": "nm", "long_name": "wavelength (bin centre)"},
        )
    )
    ds["band_response"] = (
        ("band", "wavelength"),
        data.bands.response,
        {"units": "1", "long_name": "band response x optics transmission x detector QE"},
    )
    if members.spectra.shape[1]:
        ds["endmember_spectrum"] = (
            ("endmember", "wavelength"),
            members.spectra,
            {"units": "1", "long_name": "reflectance spectrum of each endmember"},
        )
    ds.attrs.update(
        {
            "Conventions": "CF-1.10",
            "title": "speclight unmix: endmember contributions per epoch",
            "method": method,
            "source": data.source,
            "light": data.light,
            "endmembers": origin,
            "speclight_version": __version__,
            "history": f"{datetime.now(UTC).isoformat(timespec='seconds')} speclight unmix",
        }
    )
    return ds
