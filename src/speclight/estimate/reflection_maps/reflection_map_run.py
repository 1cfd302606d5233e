"""``speclight reflection-map``: measured light curves in, RMAP.nc (docs/reflection-map.md) out.

:func:`reflection_map_measured` reads the band reflectance factors as ``speclight unmix``
does (:func:`.read_reflectance_factors`: a speclight NetCDF, or a CSV of count rates with a
scenario; the Sun's or the coaxial lasers' factors), takes each epoch's body-frame direction
and averages the epochs on HEALPix pixels (:func:`.reflection_map_core.reflection_map`):

* under the Sun the **phase vector** ``phase_vector_body``; under coaxial lasers (phase angle
  0) the **observer direction** ``observer_direction_body``, where the phase vector is;
* from the NetCDF itself, or, for a CSV (or a NetCDF without them), from the scenario's
  geometry at the measured epochs (:func:`speclight.simulation.geometry_stage.scenario_geometry`:
  orbit, site, Sun and attitude, nothing rendered).

RMAP.nc: ``reflectance_factor(band, pixel)`` [m2 sr-1] (NaN where no epoch),
``reflectance_factor_std(band, pixel)``, ``n_samples(pixel)``, ``range_offset(band, pixel)``
[m] where the input has ranging (``range_offset(time, band)``, placed at the same direction),
the pixel centres ``lon(pixel)``, ``lat(pixel)`` [degree] and the observed track
``track_direction_body(time, xyz)``, ``track_pixel(time)``; attributes ``healpix_nside``,
``healpix_order = "ring"``, ``frame = "body"``. With endmembers (spectrum files or the
scenario's materials, as for ``speclight unmix``) every pixel is unmixed (eq. 6):
``abundance(endmember, pixel)``, ``residual(pixel)``, ``endmember_signature(endmember, band)``;
a pixel's signatures are the mean over its epochs of each epoch's source-weighted signatures
(the atmosphere changes them along a pass). The pixel's mean factor is
``mean_t sum_k g_k(t) s_k(t)``, so this is exact where the contributions ``g_k`` or the
signatures ``s_k`` are the same for the pixel's epochs, and otherwise off by their
covariance within the pixel (small: a pixel's epochs are close in time or in geometry).
"""

from __future__ import annotations

from datetime import UTC, datetime
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.estimate.inputs.cost_limits import time_span_text
from speclight.estimate.inputs.reflectance_factors import (
    ReflectanceFactors,
    bin_factors,
    dataset_scenario,
    read_reflectance_factors,
)
from speclight.estimate.inputs.source_spectrum import check_light
from speclight.estimate.reflection_maps.reflection_map_core import (
    ReflectionMap,
    check_nside,
    pixel_centres_deg,
    pixel_mean,
    reflection_map,
    unit_vectors,
)
from speclight.estimate.spectra.endmember_spectra import (
    endmembers_from_files,
    endmembers_from_scenario,
)
from speclight.estimate.spectra.unmix_run import (
    SCENARIO_ENDMEMBERS,
    check_distinct,
    check_unmix_options,
)
from speclight.estimate.spectra.unmixing_epochs import unmix_per_epoch
from speclight.io.user_dataset import read_user_dataset, values

if TYPE_CHECKING:
    from speclight.scenario import LoadedScenario

F64 = NDArray[np.float64]
NETCDF_SUFFIXES = (".nc", ".nc4", ".netcdf", ".h5")
DIRECTION = {"sun": "phase_vector_body", "laser": "observer_direction_body"}


def reflection_map_measured(
    measured: str | Path,
    *,
    nside: int = 16,
    loaded: LoadedScenario | None = None,
    light: str | None = None,
    endmembers: list[str] | None = None,
    method: str = "nnls-norm",
    bin_s: float | None = None,
    progress: bool = False,
) -> xr.Dataset:
    """Reflection map of measured light curves (module doc: the dataset).

    Parameters
    ----------
    measured
        A speclight NetCDF or a CSV of count rates (then ``loaded`` is required).
    nside
        HEALPix resolution, a power of 2 (12 nside^2 pixels; 16: 3072 pixels of 3.7 deg).
    loaded
        The scenario: required for a CSV, and for a NetCDF without the body-frame
        directions; gives the lasers' lines and ``endmembers = ["scenario"]``.
    light
        ``"sun"`` or ``"laser"`` (coaxial lasers); None: the lasers where the data have no
        finite solar factors, else the Sun.
    endmembers
        Reflectance CSV files, or ``["scenario"]``: unmix every pixel (``method``).
    method
        ``ls``, ``nnls``, ``nnls-norm`` (default) or ``fcls``.
    bin_s
        Average the epochs into bins of this many seconds first.
    progress
        Show the simulation's progress bar (CSV input).

    Raises
    ------
    InputError
        A bad ``nside``, ``light`` or option, a bad file, no directions and no scenario.
    """
    nside = check_nside(nside)
    check_light(light)
    check_unmix_options(
        endmembers=endmembers or [SCENARIO_ENDMEMBERS], extract=None, n=None, method=method,
        light=light,
    )  # fmt: skip
    p = Path(measured)
    is_nc = p.suffix.lower() in NETCDF_SUFFIXES
    if endmembers == [SCENARIO_ENDMEMBERS] and loaded is None and is_nc:
        head = read_user_dataset(p, "MEASURED", what="measurements", variables=())
        loaded = dataset_scenario(head, str(p))
    if not is_nc and loaded is not None:  # the scenario's geometry: can it be the target?
        _check_csv_scenario(p, loaded, light)
    data = read_reflectance_factors(p, loaded, bin_s=bin_s, progress=progress, light=light)
    direction, offset, origin = _directions(p, is_nc, data, loaded, bin_s)
    rmap = reflection_map(direction, data.factor, nside)
    if not np.any(rmap.n_samples > 0):
        raise InputError(
            f"no epoch has both a finite reflectance factor and a body-frame direction, so the "
            f"map would be empty: measured {time_span_text(data.time_utc)}"
            + (f"; the scenario's time window {_window(loaded)}" if loaded is not None else "")
            + f"; directions from {origin}",
            source=str(p),
            field="MEASURED",
        )
    ds = _dataset(data, rmap, direction, origin)
    if offset is not None:
        rng = reflection_map(direction, offset, nside)
        ds["range_offset"] = (
            ("band", "pixel"),
            rng.mean,
            {
                "units": "m",
                "long_name": "mean over the pixel's epochs of the laser return's range offset "
                "(mean return range minus range to the centre of mass, one-way)",
            },
        )
    if endmembers:
        if endmembers == [SCENARIO_ENDMEMBERS] and loaded is None:
            raise InputError("endmembers=['scenario'] needs loaded=SCENARIO", field="endmembers")
        ds = _with_abundance(ds, data, rmap.pixel, endmembers, method, loaded)
    return ds


def _window(loaded: LoadedScenario) -> str:
    t = loaded.scenario.time
    return f"{t.start:%Y-%m-%dT%H:%M:%S} .. {t.stop:%Y-%m-%dT%H:%M:%S} UTC"


def _check_csv_scenario(p: Path, loaded: LoadedScenario, light: str | None) -> None:
    """Refuse a scenario that cannot be the target of the CSV (its epochs with a rate)."""
    from speclight.estimate.inputs.geometry_match import check_scenario_sees
    from speclight.estimate.inputs.measured import read_measured

    lc = read_measured(p)
    chosen = light or ("sun" if loaded.scenario.illumination.sun else "laser")
    check_scenario_sees(loaded, p, lc.time_utc[np.isfinite(lc.rate_per_s).any(axis=1)], chosen)


def _directions(
    p: Path,
    is_nc: bool,
    data: ReflectanceFactors,
    loaded: LoadedScenario | None,
    bin_s: float | None,
) -> tuple[F64, F64 | None, str]:
    """Body-frame direction (N, 3) of every epoch of ``data``, the range offsets (N, B) or
    None, and where the directions came from."""
    var = DIRECTION[data.light]
    offset = None
    if is_nc:
        src = str(p)
        ds = read_user_dataset(p, "MEASURED", what="measurements", variables=(var, "range_offset"))
        if "range_offset" in ds:
            offset = values(ds, "range_offset", ("time", "band"), src, "MEASURED")
        if var in ds:
            d = values(ds, var, ("time", "xyz"), src, "MEASURED")
            t0 = ds["time"].values.astype("datetime64[ns]")
            if bin_s is not None:
                _, d = bin_factors(t0, d, bin_s, src)
                if offset is not None:
                    _, offset = bin_factors(t0, offset, bin_s, src)
            return unit_vectors(d), offset, f"{p}: {var}"
        if loaded is None:
            raise InputError(
                f"the dataset has no {var}(time, xyz): give loaded=SCENARIO for the "
                "geometry at its epochs",
                source=str(p),
                field="loaded",
            )
    assert loaded is not None  # a CSV without a scenario is refused when read
    from speclight.simulation.geometry_stage import scenario_geometry

    geo = scenario_geometry(loaded, data.time_utc)
    d = geo.phase_vector_body if data.light == "sun" else geo.observer_direction_body
    return unit_vectors(d), offset, f"scenario {loaded.source}: {var} at the measured epochs"


def _dataset(
    data: ReflectanceFactors, rmap: ReflectionMap, direction: F64, origin: str
) -> xr.Dataset:
    from speclight import __version__

    lon, lat = pixel_centres_deg(rmap.nside)
    ds = xr.Dataset(
        coords={
            "pixel": ("pixel", np.arange(lon.size), {"long_name": "HEALPix pixel (RING)"}),
            "band": (
                "band",
                np.array(data.bands.band_names, dtype=str),
                {"long_name": "photometric band"},
            ),
            "time": ("time", data.time_utc, {"long_name": "epoch (UTC)", "standard_name": "time"}),
            "lon": (
                "pixel",
                lon,
                {
                    "units": "degree",
                    "long_name": "body-frame longitude of the pixel centre (from +x towards +y)",
                },
            ),
            "lat": (
                "pixel",
                lat,
                {
                    "units": "degree",
                    "long_name": "body-frame latitude of the pixel centre (+z at +90)",
                },
            ),
        }
    )
    what = "phase vector" if data.light == "sun" else "observer direction (coaxial lasers)"
    ds["reflectance_factor"] = (
        ("band", "pixel"),
        rmap.mean,
        {
            "units": "m2 sr-1",
            "long_name": f"mean band reflectance factor (eq. 5) of the epochs whose {what} "
            "falls in the pixel",
        },
    )
    ds["reflectance_factor_std"] = (
        ("band", "pixel"),
        rmap.std,
        {"units": "m2 sr-1", "long_name": "sample standard deviation of those epochs' factors"},
    )
    ds["n_samples"] = (
        "pixel",
        rmap.n_samples,
        {"units": "1", "long_name": f"number of epochs whose {what} falls in the pixel"},
    )
    ds["track_direction_body"] = (
        ("time", "xyz"),
        direction,
        {"units": "1", "long_name": f"body-frame {what} of each epoch (unit vector)"},
    )
    ds["track_pixel"] = (
        "time",
        rmap.pixel,
        {"units": "1", "long_name": "pixel of each epoch (-1: left out, no value)"},
    )
    ds.attrs.update(
        {
            "Conventions": "CF-1.10",
            "title": "speclight reflection-map: band reflectance factors on a HEALPix sphere",
            "healpix_nside": rmap.nside,
            "healpix_order": "ring",
            "frame": "body",
            "light": data.light,
            "direction": origin,
            "source": data.source,
            "speclight_version": __version__,
            "history": f"{datetime.now(UTC).isoformat(timespec='seconds')} "
            "speclight reflection-map",
        }
    )
    return ds


def _with_abundance(
    ds: xr.Dataset,
    data: ReflectanceFactors,
    pixel: NDArray[np.int64],
    endmembers: list[str],
    method: str,
    loaded: LoadedScenario | None,
) -> xr.Dataset:
    """Unmix every pixel's mean factors (module doc)."""
    if endmembers == [SCENARIO_ENDMEMBERS]:
        assert loaded is not None
        members = endmembers_from_scenario(loaded, data.bands, data.source_W_m2_nm)
    else:
        members = endmembers_from_files(list(endmembers), data.bands, data.source_W_m2_nm)
    check_distinct(members)
    n_bands = len(data.bands.band_names)
    if len(members.names) > n_bands:
        raise InputError(
            f"{len(members.names)} endmembers is more than the {n_bands} bands; give at most "
            f"{n_bands}",
            field="endmembers",
        )
    n_pix = ds.sizes["pixel"]
    # unmix the mapped pixels only (their signatures: the mean over each pixel's epochs)
    mapped, slot = np.unique(pixel[pixel >= 0], return_inverse=True)
    if members.signatures_epoch is None:
        sig = np.broadcast_to(members.signatures, (mapped.size, *members.signatures.shape))
    else:
        local = np.full(pixel.shape, -1, dtype=np.int64)
        local[pixel >= 0] = slot
        sig, _ = pixel_mean(local, members.signatures_epoch, mapped.size)
    abundance = np.full((n_pix, len(members.names)), np.nan)
    residual = np.full(n_pix, np.nan)
    if mapped.size:
        x = ds["reflectance_factor"].values.T[mapped]
        result = unmix_per_epoch(x, sig, method)  # type: ignore[arg-type]
        abundance[mapped] = result.abundance
        residual[mapped] = result.residual
    unit = "1" if method in ("nnls-norm", "fcls") else "m2 sr-1"
    ds = ds.assign_coords(
        endmember=("endmember", np.array(members.names, dtype=str), {"long_name": "endmember"})
    )
    ds["abundance"] = (
        ("endmember", "pixel"),
        abundance.T,
        {"units": unit, "long_name": f"contribution of each endmember to the pixel ({method})"},
    )
    ds["residual"] = (
        "pixel",
        residual,
        {"units": "m2 sr-1", "long_name": "norm over the bands of reflectance_factor - S a"},
    )
    ds["endmember_signature"] = (
        ("endmember", "band"),
        members.signatures,
        {"units": "1", "long_name": "band signature of each endmember (mean source spectrum)"},
    )
    ds.attrs["method"] = method
    return ds
