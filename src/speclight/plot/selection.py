"""What to plot: dataset checks, the epoch followed through the chain, the image band."""

from __future__ import annotations

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight.errors import InputError, did_you_mean
from speclight.plot.style import observable

GEOMETRY = ("range", "elevation", "phase_angle", "sunlit")


def check_dataset(ds: xr.Dataset, source: str | None = None) -> None:
    """Raise :class:`InputError` unless ``ds`` looks like a speclight output dataset."""
    missing = [n for n in GEOMETRY if n not in ds]
    if "time" not in ds.dims:
        missing.insert(0, "the time dimension")
    if missing:
        raise InputError(
            f"lacks {', '.join(missing)}; expected a dataset written by `speclight simulate` "
            f"(variables {', '.join(GEOMETRY)} on a time dimension)",
            source=source,
        )


def has_spectra(ds: xr.Dataset) -> bool:
    """Whether the dataset has the wavelength-resolved chain (intensity or spectral flux)."""
    return "wavelength" in ds.dims and ("spectral_flux" in ds or "intensity" in ds)


def has_bands(ds: xr.Dataset) -> bool:
    """Whether the dataset has per-band light curves."""
    return ds.sizes.get("band", 0) > 0 and ("count_rate" in ds or "ab_magnitude" in ds)


def has_images(ds: xr.Dataset) -> bool:
    """Whether images were saved (``image_radiance`` or ``image_depth``)."""
    return ds.sizes.get("image_time", 0) > 0 and ("image_radiance" in ds or "image_depth" in ds)


def _bin_width_nm(wavelength_nm: NDArray[np.float64]) -> NDArray[np.float64]:
    if wavelength_nm.size < 2:
        return np.ones_like(wavelength_nm)
    return np.abs(np.gradient(wavelength_nm))


def brightness(ds: xr.Dataset) -> NDArray[np.float64] | None:
    """Band-free brightness per epoch used to pick the epoch to follow.

    The power entering the aperture, :math:`\\int \\Phi_\\lambda d\\lambda` [W], from
    ``spectral_flux``; without it, the irradiance above the atmosphere
    :math:`\\int I_\\lambda d\\lambda / r^2` [W m-2] from ``intensity`` and ``range``.
    ``None`` when the dataset has neither.
    """
    if "wavelength" not in ds.dims:
        return None
    dlam = _bin_width_nm(ds["wavelength"].values)
    if "spectral_flux" in ds:
        flux = ds["spectral_flux"].transpose("time", "wavelength").values
        return np.asarray(flux @ dlam, dtype=np.float64)
    if "intensity" in ds:
        intensity = ds["intensity"].transpose("time", "wavelength").values
        return np.asarray((intensity @ dlam) / ds["range"].values ** 2, dtype=np.float64)
    return None


def brightest_observable_epoch(ds: xr.Dataset) -> int | None:
    """Index of the brightest observable epoch, or ``None`` when no epoch has signal.

    Observable: above the minimum elevation, not in the Earth's shadow, orbit and render
    succeeded (``flags``); brightness as in :func:`brightness`.
    """
    b = brightness(ds)
    if b is None:
        return None
    ok = observable(ds) & np.isfinite(b) & (b > 0)
    if not ok.any():
        return None
    return int(np.argmax(np.where(ok, b, -np.inf)))


def resolve_epoch(ds: xr.Dataset, epoch: int | str | None) -> int | None:
    """Epoch index from ``--epoch``: an index, a UTC time (ISO 8601), or None (brightest).

    A time picks the nearest epoch and must lie within the pass.
    """
    n = ds.sizes["time"]
    if epoch is None:
        return brightest_observable_epoch(ds)
    if isinstance(epoch, str) and epoch.strip().lstrip("-").isdigit():
        epoch = int(epoch)
    if isinstance(epoch, (int, np.integer)):
        if not -n <= int(epoch) < n:
            middle = np.datetime_as_string(ds["time"].values[n // 2], unit="s")
            raise InputError(
                f"epoch index {epoch} is outside the pass; use 0 to {n - 1} "
                f"or a UTC time within it such as {middle}",
                field="--epoch",
            )
        return int(epoch) % n
    t = ds["time"].values
    try:
        when = np.datetime64(str(epoch).rstrip("Z").replace(" ", "T"), "ns")
    except ValueError as exc:
        raise InputError(
            f"epoch {epoch!r} is neither an index nor a UTC time; give e.g. 0 or "
            f"{np.datetime_as_string(t[0], unit='s')}",
            field="--epoch",
        ) from exc
    step = (t[1] - t[0]) if t.size > 1 else np.timedelta64(1, "s")
    if when < t[0] - step or when > t[-1] + step:
        raise InputError(
            f"epoch {epoch} is outside the pass "
            f"({np.datetime_as_string(t[0], unit='s')} to {np.datetime_as_string(t[-1], unit='s')} "
            "UTC); give a time inside it",
            field="--epoch",
        )
    return int(np.argmin(np.abs(t - when)))


def resolve_band(ds: xr.Dataset, band: str | None) -> str | None:
    """Band used for images: the given name (checked), else the first band, else None."""
    names = [str(b) for b in ds["band"].values] if "band" in ds.coords else []
    if band is None:
        return names[0] if names and "band_response" in ds else None
    if band not in names:
        choices = ", ".join(names) if names else "none: this dataset has no bands"
        raise InputError(
            f"unknown band {band!r}{did_you_mean(band, names)} (bands: {choices})",
            field="--band",
        )
    if "band_response" not in ds:
        raise InputError(
            f"band {band!r} has no band_response in this dataset; omit --band to use "
            "the whole wavelength grid",
            field="--band",
        )
    return band


def band_radiance(
    ds: xr.Dataset, image: int, band: str | None, variable: str = "image_radiance"
) -> NDArray[np.float64]:
    """Image radiance of saved image ``image`` integrated over a band [W m-2 sr-1].

    :math:`\\int L_\\lambda R_b(\\lambda) d\\lambda` as a bin sum on the wavelength grid,
    with the band's relative response :math:`R_b`; over the whole grid when ``band``
    is None. ``variable`` names the image (``image_radiance_q`` / ``_u``: its Stokes Q, U).
    """
    radiance = ds[variable].isel(image_time=image).transpose("y", "x", "wavelength")
    weight = _bin_width_nm(ds["wavelength"].values)
    if band is not None:
        weight = weight * np.nan_to_num(ds["band_response"].sel(band=band).values)
    return np.asarray(radiance.values.astype(np.float64) @ weight)
