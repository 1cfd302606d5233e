"""What ``speclight shape`` reads: a DAMIT ``.lc`` file, or speclight light curves with the
geometry of their scenario.

speclight input (``fmt="speclight"``): MEASURED (a speclight NetCDF or a CSV of count rates,
:func:`speclight.estimate.inputs.measured.read_measured`) becomes band reflectance factors [m2 sr-1]
(:func:`speclight.estimate.inputs.reflectance_factors.read_reflectance_factors`: the rates over the
aperture, the range squared, the Sun and the atmosphere: eq. 5 of Nussbaum et al. 2022), calibrated
photometry that no longer depends on the distance. The geometry at the measured epochs comes
from the scenario (the one given, else the one a NetCDF carries) through the pipeline's own
:func:`speclight.simulation.geometry_stage.scenario_geometry`: the Sun's and the observer's
directions at the target (GCRS, rotated to ecliptic J2000), and the epochs moved back by
the light time ``range / c`` (the light left the target then). Each pass (points closer than
:data:`PASS_GAP_S`) is one light curve; the brightness fitted is the mean factor over the
chosen bands, the per-band factors kept for the facet spectra.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import NDArray

from speclight.constants import C_M_S
from speclight.errors import InputError, did_you_mean
from speclight.estimate.shape.damit_lc import read_damit_lc
from speclight.estimate.shape.ecliptic import gcrs_to_ecliptic, julian_date
from speclight.estimate.shape.inversion_data import (
    NOMINAL_SIGMA,
    InversionData,
    build_inversion_data,
    from_damit,
)

if TYPE_CHECKING:
    from speclight.estimate.inputs.band_responses import BandResponses
    from speclight.scenario import LoadedScenario

F64 = NDArray[np.float64]
FORMATS = ("speclight", "damit")
#: A gap longer than this starts a new light curve (a new pass) [s].
PASS_GAP_S = 1800.0


@dataclass(frozen=True)
class ShapeInput:
    """The inversion's data and what came with them.

    Attributes
    ----------
    data
        The points (:class:`.inversion_data.InversionData`).
    band_names
        The bands averaged into the brightness (speclight input), else empty.
    band_factor
        (N, B) the per-band reflectance factors of the points [m2 sr-1], or None.
    band_sigma
        (N, B) their standard deviations [m2 sr-1], or None.
    unit
        Unit of the brightness (``m2 sr-1``, or ``1`` for a DAMIT file).
    source
        What was read, in words.
    loaded
        The scenario (speclight input), else None.
    bands
        The chosen bands' responses (speclight input), else None.
    """

    data: InversionData
    band_names: list[str]
    band_factor: F64 | None
    band_sigma: F64 | None
    unit: str
    source: str
    loaded: LoadedScenario | None = None
    bands: BandResponses | None = None


def check_format(fmt: str) -> None:
    """Raise an InputError naming ``fmt`` unless it is one of :data:`FORMATS`."""
    if fmt not in FORMATS:
        raise InputError(
            f"format '{fmt}'{did_you_mean(fmt, FORMATS)} is not known "
            f"(choices: {', '.join(FORMATS)})",
            field="fmt",
        )


def read_shape_input(
    path: str | Path,
    fmt: str = "speclight",
    loaded: LoadedScenario | None = None,
    bands: list[str] | None = None,
) -> ShapeInput:
    """The light curves of ``path`` in format ``fmt`` (module doc)."""
    check_format(fmt)
    src = str(path)
    if fmt == "damit":
        return ShapeInput(from_damit(read_damit_lc(path), src), [], None, None, "1", src)
    return _speclight_input(Path(path), loaded, bands)


def _speclight_input(
    path: Path, loaded: LoadedScenario | None, bands: list[str] | None
) -> ShapeInput:
    import xarray as xr

    from speclight.attitude.quaternion import quat_rotate
    from speclight.estimate.inputs.measured import read_measured
    from speclight.estimate.inputs.reflectance_factors import (
        dataset_scenario,
        read_reflectance_factors,
    )
    from speclight.simulation.geometry_stage import scenario_geometry

    src = str(path)
    is_nc = path.suffix.lower() in (".nc", ".nc4", ".netcdf", ".h5")
    if loaded is None:
        if not is_nc:
            raise InputError(
                f"{src} is a CSV of count rates: give loaded=SCENARIO "
                "(the geometry and the instrument)",
                field="loaded",
            )
        with xr.open_dataset(path, engine="h5netcdf") as ds:
            loaded = dataset_scenario(ds, src)
    lc = read_measured(path)
    factors = read_reflectance_factors(path, loaded, light="sun")
    names = list(factors.bands.band_names)
    chosen = names if not bands else bands
    for b in chosen:
        if b not in names:
            raise InputError(
                f"band '{b}'{did_you_mean(b, names)} is not measured (bands: {', '.join(names)})",
                field="bands",
            )
    idx = [names.index(b) for b in chosen]
    factor = factors.factor[:, idx]
    sigma = None
    if lc.sigma_per_s is not None and lc.time_utc.size == factors.time_utc.size:
        rate = lc.select_bands(names).rate_per_s[:, idx]
        sig = lc.select_bands(names).sigma_per_s
        assert sig is not None
        with np.errstate(divide="ignore", invalid="ignore"):
            sigma = np.abs(factor / rate) * sig[:, idx]
    geo = scenario_geometry(loaded, time_utc=factors.time_utc)
    q = geo.quaternion_body_to_gcrs
    sun = gcrs_to_ecliptic(quat_rotate(q, geo.sun_direction_body))
    obs = gcrs_to_ecliptic(quat_rotate(q, geo.observer_direction_body))
    emitted_jd = julian_date(factors.time_utc) - geo.range_m / C_M_S / 86400.0
    ok = geo.observable & (geo.sunlit_fraction > 0)
    with np.errstate(invalid="ignore"):
        brightness = np.where(ok, np.mean(factor, axis=1), np.nan)
        mean_sigma = None if sigma is None else np.sqrt(np.sum(sigma**2, axis=1)) / len(idx)
    # passes: a gap of PASS_GAP_S between usable points starts a new light curve
    t_s = (factors.time_utc - factors.time_utc[0]) / np.timedelta64(1, "s")
    usable = np.flatnonzero(np.isfinite(brightness))
    gap = np.zeros(t_s.size, bool)
    gap[usable[1:]] = np.diff(t_s[usable]) > PASS_GAP_S
    curve = np.cumsum(gap).astype(np.int64)
    if mean_sigma is None:
        # no sigmas: the same relative weight for every point (as a DAMIT file)
        means = np.array(
            [
                np.nanmean(brightness[curve == c])
                if np.any(np.isfinite(brightness[curve == c]))
                else 1.0
                for c in range(curve.max() + 1)
            ]
        )
        mean_sigma = NOMINAL_SIGMA * means[curve]
    data = build_inversion_data(
        emitted_jd, brightness, mean_sigma, sun, obs, curve, np.ones(curve.max() + 1, bool), src
    )
    keep = np.isin(emitted_jd, data.time_jd)
    order = np.argsort(emitted_jd[keep], kind="stable")
    band_factor = factor[keep][order]
    band_sigma = None if sigma is None else sigma[keep][order]
    chosen_bands = replace(factors.bands, band_names=chosen, response=factors.bands.response[idx])
    return ShapeInput(
        data,
        chosen,
        band_factor,
        band_sigma,
        "m2 sr-1",
        f"{src}: band reflectance factors ({', '.join(chosen)})",
        loaded,
        chosen_bands,
    )
