"""What the frames need from a ``speclight simulate`` dataset, as plain arrays.

* the target's track: ``ra``, ``dec``, ``ra_cos_dec_rate``, ``dec_rate`` (topocentric,
  astrometric ICRS), ``elevation``, ``count_rate`` and ``sun_elevation_site``;
* the photometric chain: ``wavelength``, ``band_response``, ``optics_transmission``,
  ``detector_qe``, ``transmission`` and the telescope (from the scenario);
* the kept renders (``render.save_images_at``): ``image_radiance``, ``image_pixel_size``,
  ``image_right_body``, ``image_up_body`` with the ``attitude_quaternion`` and ``range`` of
  their epochs, for resolved targets;
* the scenario itself (the ``scenario_yaml`` attribute) for ``instrument.imaging``.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr
from numpy.typing import NDArray

from speclight.errors import InputError
from speclight.instrument.imaging.target_path import Track
from speclight.instrument.photometry import photon_kernel
from speclight.instrument.telescope import aperture_area_m2

F64 = NDArray[np.float64]

#: Variables every frame needs (written by ``speclight simulate`` with bands).
NEEDED = (
    "ra",
    "dec",
    "ra_cos_dec_rate",
    "dec_rate",
    "elevation",
    "count_rate",
    "band_response",
    "optics_transmission",
    "detector_qe",
    "transmission",
)


@dataclass(frozen=True)
class Photometry:
    """The photometric chain of the bands.

    Attributes
    ----------
    band_names
        Band names (B,).
    wavelength_nm
        (L,) grid [nm].
    band_response, qe
        (B, L) [1].
    optics
        (L,) [1].
    transmission
        (N, L) atmospheric transmission along the line of sight at each epoch [1].
    aperture_diameter_m, obstruction_diameter_m
        Telescope [m].
    """

    band_names: tuple[str, ...]
    wavelength_nm: F64
    band_response: F64
    qe: F64
    optics: F64
    transmission: F64
    aperture_diameter_m: float
    obstruction_diameter_m: float

    @property
    def area_m2(self) -> float:
        """Collecting area [m2]."""
        return aperture_area_m2(self.aperture_diameter_m, self.obstruction_diameter_m)

    def mean_wavelength_nm(self, band: int) -> float:
        """Photon-weighted mean wavelength of a band for a flat f_lambda source [nm]."""
        k = photon_kernel(self.wavelength_nm, self.optics, self.qe[band], self.band_response[band])
        return float((k[0] * self.wavelength_nm).sum() / k[0].sum())


@dataclass(frozen=True)
class KeptImages:
    """Renders kept by the pipeline, M of them.

    Attributes
    ----------
    time_utc
        (M,) epochs.
    light
        (M, B, H, W) detected light per image pixel in each band (any scale).
    pixel_size_m
        (M,) pixel pitch at the target [m].
    right_icrs, up_icrs
        (M, 3) the image's right and up axes in the GCRS (ICRS axes).
    range_m
        (M,) observer-target distance [m].
    """

    time_utc: NDArray[np.datetime64]
    light: F64
    pixel_size_m: F64
    right_icrs: F64
    up_icrs: F64
    range_m: F64


@dataclass(frozen=True)
class FrameInputs:
    """Everything of a dataset the frames use."""

    track: Track
    photometry: Photometry
    images: KeptImages | None
    site: tuple[float, float, float]
    scenario_yaml: str


def load_dataset(path: str | Path) -> xr.Dataset:
    """Read a simulate dataset into memory (:func:`speclight.io.user_dataset.read_user_dataset`:
    clear errors for what is not one)."""
    from speclight.io.user_dataset import read_user_dataset

    return read_user_dataset(path, "DATASET", what="dataset")


def _kept_images(ds: xr.Dataset, photometry: Photometry) -> KeptImages | None:
    if "image_radiance" not in ds or "attitude_quaternion" not in ds:
        return None
    from speclight.attitude.quaternion import quat_rotate

    times = ds["image_time"].values
    at = ds["time"].to_index().get_indexer(times)
    q = ds["attitude_quaternion"].values[at]
    radiance = ds["image_radiance"].values  # (M, H, W, L)
    light = np.empty((radiance.shape[0], len(photometry.band_names), *radiance.shape[1:3]))
    for b in range(len(photometry.band_names)):
        kernel = photon_kernel(
            photometry.wavelength_nm,
            photometry.optics,
            photometry.qe[b],
            photometry.band_response[b],
        )[0]
        weight = photometry.transmission[at] * kernel[None, :]  # (M, L)
        light[:, b] = np.einsum("mhwl,ml->mhw", np.nan_to_num(radiance), weight)
    return KeptImages(
        time_utc=times,
        light=light,
        pixel_size_m=ds["image_pixel_size"].values.astype(np.float64),
        right_icrs=quat_rotate(q, ds["image_right_body"].values),
        up_icrs=quat_rotate(q, ds["image_up_body"].values),
        range_m=ds["range"].values[at].astype(np.float64),
    )


def frame_inputs(ds: xr.Dataset, source: str) -> FrameInputs:
    """The frames' inputs from a simulate dataset.

    Raises
    ------
    InputError
        If the dataset lacks a variable the frames need (older speclight, no bands).
    """
    missing = [name for name in NEEDED if name not in ds]
    if missing:
        raise InputError(
            f"the dataset lacks {', '.join(missing)}: frames need a dataset of `speclight "
            "simulate` (version with topocentric ra/dec) whose scenario has instrument.bands",
            source=source,
        )
    if "scenario_yaml" not in ds.attrs:
        raise InputError("the dataset does not carry its scenario (scenario_yaml)", source=source)
    from speclight.scenario import parse_scenario

    scenario = parse_scenario(str(ds.attrs["scenario_yaml"]), source=f"{source} (scenario_yaml)")
    tel = scenario.scenario.telescope
    obs = scenario.scenario.observer
    f = lambda name: np.asarray(ds[name].values, dtype=np.float64)  # noqa: E731
    rate = f("count_rate")
    known = rate[~np.isnan(rate)]
    if np.any(~np.isfinite(known)) or np.any(known < 0):
        raise InputError(
            "count_rate holds infinite or negative values: a photo-electron rate is >= 0 "
            "(NaN where not observable); give a dataset written by `speclight simulate`",
            source=source,
        )
    for name in ("ra_cos_dec_rate", "dec_rate"):
        if np.any(np.isinf(f(name))):
            raise InputError(f"{name} holds infinite values", source=source)
    track = Track(
        time_utc=ds["time"].values.astype("datetime64[ns]"),
        ra_deg=f("ra"),
        dec_deg=f("dec"),
        ra_cos_dec_rate_deg_s=f("ra_cos_dec_rate"),
        dec_rate_deg_s=f("dec_rate"),
        elevation_deg=f("elevation"),
        count_rate=rate,
        sun_elevation_deg=f("sun_elevation_site") if "sun_elevation_site" in ds else None,
    )
    photometry = Photometry(
        band_names=tuple(str(b) for b in ds["band"].values),
        wavelength_nm=f("wavelength"),
        band_response=f("band_response"),
        qe=f("detector_qe"),
        optics=f("optics_transmission"),
        transmission=np.nan_to_num(f("transmission")),
        aperture_diameter_m=tel.aperture_diameter_m,
        obstruction_diameter_m=tel.obstruction_diameter_m,
    )
    return FrameInputs(
        track=track,
        photometry=photometry,
        images=_kept_images(ds, photometry),
        site=(obs.latitude_deg, obs.longitude_deg, obs.altitude_m),
        scenario_yaml=str(ds.attrs["scenario_yaml"]),
    )
