"""The ``instrument.imaging`` section: the camera that records frames (docs/frames.md).

``speclight frames OUT.nc -o DIR/`` reads it from the scenario a simulation ran with (the
dataset's ``scenario`` attribute) or from a file of its own (``--imaging``), and turns the
simulated light curve, the target's path on the sky and the kept renders into detector
frames with stars, sky, PSF and noise (:mod:`speclight.instrument.imaging`).
"""

from __future__ import annotations

import math
from datetime import UTC, datetime
from typing import Literal

from pydantic import Field, field_validator, model_validator

from speclight.scenario.sections_geometry import Strict

#: Largest detector side [px]: 16k, the largest monolithic CCDs (10k x 10k and up); a frame
#: of 16k x 16k float64 is 2 GiB, the most a 24 GiB machine should hold twice.
MAX_DETECTOR_PX = 16_384
#: Largest plate scale [arcsec px-1]: one degree per pixel (all-sky cameras are ~0.1 deg).
MAX_PLATE_SCALE_ARCSEC = 3600.0
#: Widest seeing disk [arcsec]: one arcminute, ten times the worst nights at a site.
MAX_SEEING_ARCSEC = 60.0
#: Largest Moffat beta: above ~10 the profile is a Gaussian within 1 % (Moffat 1969).
MAX_MOFFAT_BETA = 100.0
#: Smallest Moffat beta: GalSim's untruncated Moffat needs beta > 1.1 (its flux diverges
#: at beta = 1; GalSim documentation, ``galsim.Moffat``).
MIN_MOFFAT_BETA = 1.1
#: Beta of a Kolmogorov seeing disk fitted by a Moffat (Trujillo et al. 2001, MNRAS 328,
#: 977, doi:10.1046/j.1365-8711.2001.04937.x).
KOLMOGOROV_MOFFAT_BETA = 4.765
#: Most frames one run writes: 10,000 FITS files fill a folder as far as people browse it.
MAX_FRAMES = 10_000
#: Largest fine-grid factor: 16 x 16 sub-pixels already resolve a streak to 1/16 px.
MAX_OVERSAMPLING = 16


class Detector(Strict):
    """The detector: its size, scale and readout."""

    width_px: int = Field(default=512, ge=8, le=MAX_DETECTOR_PX)
    height_px: int = Field(default=512, ge=8, le=MAX_DETECTOR_PX)
    plate_scale_arcsec: float | None = Field(
        default=None,
        gt=0,
        le=MAX_PLATE_SCALE_ARCSEC,
        description="Angle on the sky of one pixel [arcsec]; or pixel_size_um with focal_length_m",
    )
    pixel_size_um: float | None = Field(default=None, gt=0, le=1000)
    focal_length_m: float | None = Field(default=None, gt=0, le=1000)
    position_angle_deg: float = Field(
        default=0.0,
        ge=-360,
        le=360,
        description="Direction of the detector's +y axis on the sky, from north through "
        "east [deg]; 0: north up, east left",
    )
    read_noise_e: float = Field(default=5.0, ge=0, le=1000, description="Per pixel [e- rms]")
    dark_current_e_per_s: float = Field(default=0.0, ge=0, le=1e6, description="Per pixel")
    gain_e_per_adu: float = Field(default=1.0, gt=0, le=1000)
    bias_adu: float = Field(default=100.0, ge=0, le=1e9)
    full_well_e: float = Field(default=100_000.0, gt=0, le=1e9)
    saturation_adu: int = Field(
        default=65_535, ge=1, le=2**31 - 1, description="The ADC's largest value"
    )

    @model_validator(mode="after")
    def _scale(self) -> Detector:
        optics = (self.pixel_size_um, self.focal_length_m)
        if self.plate_scale_arcsec is not None and any(v is not None for v in optics):
            raise ValueError(
                "give plate_scale_arcsec, or pixel_size_um with focal_length_m, not both"
            )
        if self.plate_scale_arcsec is None and None in optics:
            raise ValueError(
                "the plate scale is missing: give plate_scale_arcsec (e.g. 1.5), or "
                "pixel_size_um and focal_length_m (e.g. 9 and 1.2)"
            )
        if self.bias_adu >= self.saturation_adu:
            raise ValueError(
                f"bias_adu = {self.bias_adu:g} must be below saturation_adu = {self.saturation_adu}"
            )
        return self

    @property
    def scale_arcsec(self) -> float:
        """Plate scale [arcsec px-1]."""
        if self.plate_scale_arcsec is not None:
            return self.plate_scale_arcsec
        assert self.pixel_size_um is not None and self.focal_length_m is not None
        return math.degrees(self.pixel_size_um * 1e-6 / self.focal_length_m) * 3600.0


class Seeing(Strict):
    """The atmosphere's blur: a Moffat (default) or Gaussian disk of the given FWHM."""

    profile: Literal["moffat", "gaussian"] = "moffat"
    fwhm_arcsec: float = Field(default=2.0, gt=0, le=MAX_SEEING_ARCSEC)
    moffat_beta: float = Field(
        default=KOLMOGOROV_MOFFAT_BETA, gt=MIN_MOFFAT_BETA, le=MAX_MOFFAT_BETA
    )


class Psf(Strict):
    """Point-spread function: seeing, the aperture's diffraction, defocus and jitter."""

    seeing: Seeing | None = Field(
        default_factory=Seeing, description="null: no atmosphere (diffraction only)"
    )
    diffraction: bool = Field(
        default=True,
        description="Airy pattern of telescope.aperture_diameter_m with its central "
        "obstruction, at each band's mean wavelength",
    )
    defocus_waves: float = Field(
        default=0.0,
        ge=-50,
        le=50,
        description="Defocus as the Zernike Z4 (Noll) coefficient [waves rms]; needs diffraction",
    )
    jitter_rms_arcsec: float = Field(
        default=0.0, ge=0, le=MAX_SEEING_ARCSEC, description="Pointing jitter per axis"
    )

    @model_validator(mode="after")
    def _something(self) -> Psf:
        if self.seeing is None and not self.diffraction and self.jitter_rms_arcsec == 0:
            raise ValueError(
                "the PSF is empty: give seeing, diffraction: true or jitter_rms_arcsec > 0"
            )
        if self.defocus_waves != 0 and not self.diffraction:
            raise ValueError("defocus_waves needs diffraction: true (it is a pupil aberration)")
        return self


class Sky(Strict):
    """Sky background: the Krisciunas & Schaefer (1991) model, or a fixed brightness."""

    model: Literal["krisciunas-schaefer", "fixed", "none"] = "krisciunas-schaefer"
    v_mag_arcsec2: float | None = Field(
        default=None, ge=0, le=30, description="model fixed: the V surface brightness (Vega)"
    )
    dark_zenith_v_mag_arcsec2: float = Field(
        default=21.587, ge=15, le=24, description="Moonless night sky at the zenith (V, Vega)"
    )
    extinction_v_mag_per_airmass: float = Field(default=0.172, ge=0, le=2)

    @model_validator(mode="after")
    def _fixed(self) -> Sky:
        if (self.model == "fixed") != (self.v_mag_arcsec2 is not None):
            raise ValueError("model: fixed needs v_mag_arcsec2, and v_mag_arcsec2 needs it")
        return self


class Stars(Strict):
    """Stars of the bundled Hipparcos catalogue (ESA 1997; van Leeuwen 2007)."""

    catalogue: Literal["hipparcos", "none"] = "hipparcos"
    faintest_v_mag: float = Field(default=14.0, ge=-2, le=20)


class Imaging(Strict):
    """Frames of the target's field: detector, exposures, PSF, tracking, sky and stars."""

    detector: Detector
    exposure_s: float | None = Field(
        default=None, gt=0, le=86_400, description="Default: instrument.exposure_s"
    )
    cadence_s: float | None = Field(
        default=None, gt=0, le=86_400, description="Start to start; default: exposure_s"
    )
    start: datetime | None = Field(default=None, description="First exposure; default: time.start")
    frames: int | None = Field(
        default=None,
        ge=1,
        le=MAX_FRAMES,
        description="How many; default: as many as fit in the time window",
    )
    bands: list[str] | None = Field(default=None, description="Default: every band")
    psf: Psf = Field(default_factory=Psf)
    tracking: Literal["sidereal", "target"] = "sidereal"
    sky: Sky = Field(default_factory=Sky)
    stars: Stars = Field(default_factory=Stars)
    noise: bool = True
    seed: int = Field(default=0, ge=0, le=2**63 - 1)
    oversampling: int = Field(
        default=4, ge=1, le=MAX_OVERSAMPLING, description="Sub-pixels per pixel and axis"
    )

    @field_validator("start")
    @classmethod
    def _utc(cls, value: datetime | None) -> datetime | None:
        if value is None or value.tzinfo is None:
            return None if value is None else value.replace(tzinfo=UTC)
        return value.astimezone(UTC)

    @model_validator(mode="after")
    def _cadence(self) -> Imaging:
        if (
            self.cadence_s is not None
            and self.exposure_s is not None
            and self.cadence_s < self.exposure_s
        ):
            raise ValueError(
                f"cadence_s = {self.cadence_s:g} must be >= exposure_s = {self.exposure_s:g} "
                "(one camera exposes one frame at a time)"
            )
        return self
